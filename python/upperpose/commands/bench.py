"""`upperpose bench`: end-to-end frames per second, split into decode, features, search, output."""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from upperpose.commands.track import add_background_model_argument, add_search_arguments

NAME = "bench"
HELP = "end-to-end tracking speed: per-frame time (median, p90) split into decode, features, search, output"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument("video", nargs="?", help="video to track (default: a synthetic 640x480 clip)")
    p.add_argument("--background", metavar="IMAGE", help="clean plate (default: the synthetic clip's, else none)")
    p.add_argument(
        "--no-plate",
        action="store_true",
        help="track without a clean plate (the background from --bg-model)",
    )
    p.add_argument("--focal", type=float, metavar="PX", help="focal length in pixels")
    p.add_argument("--frames", type=int, default=150, help="frames of the synthetic clip (default 150)")
    p.add_argument(
        "--no-skip", action="store_true", help="only measure with motion-flag skipping off (default: both ways)"
    )
    add_search_arguments(p)
    add_background_model_argument(p)


def measure(
    video: Path, background: str | None, focal: float | None, args: argparse.Namespace, skip: bool
) -> dict[str, float]:
    """Tracks `video` once; returns medians, p90 and fps of the tracked frames."""
    import numpy as np

    from upperpose.commands.track import tracker_config
    from upperpose.fit.pipeline import VideoTracking
    from upperpose.io.output import PoseRecorder
    from upperpose.result import LOST, TRACKED

    args.no_skip = not skip
    start = time.perf_counter()  # fps(run) includes the background's set-up (a pre-pass)
    run_ = VideoTracking(video, background, focal=focal, config=tracker_config(args), keep_times=True)
    recorder = PoseRecorder(run_.reader.width, run_.reader.height, run_.fps)
    statuses, output = [], []
    try:
        for _, result in run_.frames():
            t0 = time.perf_counter()
            recorder.add(result)
            output.append(time.perf_counter() - t0)
            statuses.append(result.status)
    finally:
        run_.close()
        recorder.close()
    wall = time.perf_counter() - start
    t = run_.times
    keep = np.array([s in (TRACKED, LOST) for s in statuses])
    if not keep.any():
        keep[:] = True
    split = {
        "decode": np.array(t.decode)[keep],
        "features": np.array(t.features)[keep],
        "search": np.array(t.search)[keep],
        "output": (np.array(t.output) + np.array(output))[keep],
    }
    total = sum(split.values())
    return {
        "frames": float(len(statuses)),
        "tracked": float(keep.sum()),
        "median_ms": 1000 * float(np.median(total)),
        "p90_ms": 1000 * float(np.percentile(total, 90)),
        "fps_median": 1.0 / float(np.median(total)),
        "fps_overall": len(statuses) / wall,
        **{f"{k}_ms": 1000 * float(np.median(v)) for k, v in split.items()},
        **{f"{k}_mean_ms": 1000 * float(np.mean(v)) for k, v in split.items()},
    }


def run(args: argparse.Namespace) -> int:
    """Measures and prints a table."""
    from upperpose.lab.synth import ClipConfig, write_clip

    with tempfile.TemporaryDirectory(prefix="upperpose-bench-") as tmp:
        background = args.background
        if args.video:
            video = Path(args.video)
        else:
            clip = Path(tmp) / "clip"
            print(f"rendering a {args.frames}-frame 640x480 synthetic clip ...", flush=True)
            write_clip(ClipConfig(motion="wave_right", frames=args.frames, seed=11), clip)
            video, background = clip / "video.mp4", background or str(clip / "background.png")
        if args.no_plate:
            background = None
        modes = [False] if args.no_skip else [True, False]
        rows = []
        for skip in modes:
            r = measure(video, background, args.focal, args, skip)
            rows.append((skip, r))
    print(f"\nupperpose bench {video.name}: per tracked frame, wall milliseconds (median of each stage)")
    header = ("skipping", "frames", "decode", "features", "search", "output", "total", "p90", "fps(median)", "fps(run)")
    print("{:<9} {:>6} {:>7} {:>9} {:>7} {:>7} {:>7} {:>7} {:>12} {:>9}".format(*header))
    for skip, r in rows:
        print(
            f"{'on' if skip else 'off':<9} {int(r['tracked']):>6} {r['decode_ms']:7.1f} {r['features_ms']:9.1f} "
            f"{r['search_ms']:7.1f} {r['output_ms']:7.1f} {r['median_ms']:7.1f} {r['p90_ms']:7.1f} "
            f"{r['fps_median']:12.1f} {r['fps_overall']:9.1f}"
        )
    print(
        "total = median of the per-frame sum (features include learning the background without a plate); "
        "fps(median) = 1 / total; fps(run) = all frames / wall time incl. the background's set-up and start-up"
    )
    return 0
