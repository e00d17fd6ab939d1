"""`upperpose demo`: the main job on a built-in example, with no input needed.

Renders a short synthetic clip with known poses, tracks it with its clean plate, writes the
poses, an overlay video and a contact sheet, and prints the accuracy table against the truth.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from upperpose.commands.limits import OptionError
from upperpose.commands.track import add_search_arguments, add_smoothing_argument

NAME = "demo"
HELP = "make a short synthetic clip, track it, write poses, overlay video and contact sheet, print the accuracy"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument("-o", "--output", default="upperpose-demo", help="folder to write into (default: ./upperpose-demo)")
    p.add_argument("--motion", default="wave_right", help="motion of the synthetic clip (default: wave_right)")
    p.add_argument("--frames", type=int, default=150, help="length of the clip in frames (default 150)")
    add_search_arguments(p)
    add_smoothing_argument(p)


def run(args: argparse.Namespace) -> int:
    """Synthesises, tracks, draws and scores."""
    from upperpose.commands.track import check_writable, smoothing_of, tracker_config
    from upperpose.fit.pipeline import VideoTracking
    from upperpose.fit.smoothing import PoseSmoother
    from upperpose.io.files import write_image
    from upperpose.io.output import PoseRecorder
    from upperpose.io.overlay import OverlayWriter, contact_sheet, draw_overlay
    from upperpose.io.posefile import load_poses
    from upperpose.io.video import Frame
    from upperpose.lab.evaluate import evaluate, format_table
    from upperpose.lab.synth import ClipConfig, load_meta, write_clip
    from upperpose.model import BodyModel, Camera
    from upperpose.result import TrackResult

    if not 30 <= args.frames <= 3000:
        raise OptionError(f"--frames must be within 30..3000, got {args.frames}")
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    check_writable(str(out / "poses.json"))
    clip = out / "clip"
    t0 = time.perf_counter()
    print(f"rendering a {args.frames}-frame synthetic clip ({args.motion}) into {clip} ...", flush=True)
    write_clip(ClipConfig(motion=args.motion, frames=args.frames, seed=7), clip)
    meta = load_meta(clip)
    cam = meta["camera"]
    camera = Camera.perspective(cam["focal"], cam["cx"], cam["cy"])
    print(f"rendered in {time.perf_counter() - t0:.0f} s; tracking ...", flush=True)

    started = time.perf_counter()
    run_ = VideoTracking(clip / "video.mp4", clip / "background.png", camera=camera, config=tracker_config(args))
    recorder = PoseRecorder(
        run_.reader.width, run_.reader.height, run_.fps, source="clip/video.mp4", seed=run_.tracker.search_config.seed
    )
    overlay = OverlayWriter(out / "overlay.mp4", run_.reader.width, run_.reader.height, run_.fps)
    total = run_.reader.frame_count or args.frames
    picks = {round(i * (total - 1) / 7) for i in range(8)}
    tiles = []
    lag, smoothing = smoothing_of(args)
    recorder.extra["smoothing"] = smoothing
    smoother: PoseSmoother[tuple[Frame, BodyModel]] = PoseSmoother(camera, lag)

    def take(result: TrackResult, shown: tuple[Frame, BodyModel]) -> None:
        frame, body = shown  # the body the frame was fitted with: it leaves the smoother late
        recorder.add(result)
        drawn = draw_overlay(frame, result, camera, body)
        overlay.write(drawn)
        if result.frame in picks:
            tiles.append(drawn)

    try:
        for frame, result in run_.frames():
            body = run_.tracker.body
            for done, shown in smoother.push(result, body, (frame, body)):
                take(done, shown)
        for done, shown in smoother.flush():
            take(done, shown)
    finally:
        run_.close()
        overlay.close()
        with recorder:
            recorder.write_json(out / "poses.json", time.perf_counter() - started)
    write_image(out / "sheet.png", contact_sheet(tiles))
    scores = evaluate(load_poses(out / "poses.json"), load_poses(clip / "gt.json"))
    print()
    print(format_table(scores))
    print()
    print(f"wrote {out / 'poses.json'}, {out / 'overlay.mp4'}, {out / 'sheet.png'} (clip and truth in {clip})")
    return 0
