"""`upperpose track`: track a video and write the poses (SPEC 9), a CSV and an overlay video."""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from upperpose.fit.pipeline import VideoTracking

NAME = "track"
OPTIMIZERS = ("apso", "pso", "simplex", "apsopf")
HELP = (
    "track the upper body in a video or from a camera: poses as JSON (SPEC 9), optionally CSV, BVH and an "
    "overlay video. Start-up needs a static camera and a visible frontal face; standing in the A-pose "
    "starts it fastest, a clean plate (--background) makes it most accurate"
)


def add_search_arguments(p: argparse.ArgumentParser) -> None:
    """Search options shared by track, demo and bench."""
    p.add_argument("--particles", type=int, default=None, help="particles per search stage (default: the search's)")
    p.add_argument("--iterations", type=int, default=None, help="swarm iterations per stage (default: the search's)")
    p.add_argument(
        "--threads",
        type=int,
        default=None,
        help="worker threads (default: UPPERPOSE_NUM_THREADS, else one per 64 particles, at most one per core)",
    )
    p.add_argument("--seed", type=int, default=None, help="random seed (default 0): the same seed gives the same poses")
    p.add_argument(
        "--optimizer",
        choices=OPTIMIZERS,
        default=None,
        help="search method (default apso); pso, simplex and apsopf are the thesis' baselines (docs/baselines.md)",
    )
    p.add_argument(
        "--sigma",
        type=float,
        default=None,
        help="apsopf: Gaussian redistribution in half-widths of the box (default 1)",
    )
    p.add_argument(
        "--limits",
        choices=("anatomical", "thesis"),
        default=None,
        help="joint angle ranges: anatomical (default) or the thesis' Table 3.5-1",
    )
    p.add_argument(
        "--config",
        metavar="FILE.toml",
        help="settings file (docs/guide.md; `upperpose config` prints the effective settings); options given "
        "on the command line override it",
    )


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument(
        "video",
        nargs="?",
        help="video file to track, a stream URL (rtsp://, http://) or a camera index (0 is the first camera)",
    )
    p.add_argument("--camera", type=int, metavar="N", help="track live from camera N (the same as VIDEO=N)")
    p.add_argument("--background", metavar="IMAGE", help="clean plate: a photo of the empty scene (recommended)")
    p.add_argument("--focal", type=float, metavar="PX", help="focal length in pixels (default: the image width)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.json", help="pose file to write (SPEC 9)")
    p.add_argument("--csv", metavar="OUT.csv", help="also write one CSV row per frame")
    p.add_argument("--overlay", metavar="OUT.mp4", help="also write the video with the fitted model drawn over it")
    p.add_argument(
        "--bvh",
        metavar="OUT.bvh",
        help="also write the angles as BVH on the person's skeleton (for Blender)",
    )
    add_search_arguments(p)
    p.add_argument("--no-skip", action="store_true", help="search every part every frame (ignore the motion flags)")
    add_smoothing_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar or summary")


def add_smoothing_argument(p: argparse.ArgumentParser) -> None:
    """--no-smooth, shared by track and demo."""
    p.add_argument(
        "--no-smooth",
        action="store_true",
        help="write the poses as fitted (default: smoothed in angle space without lag, each frame's "
        "pose known 3 frames later; docs/guide.md)",
    )


def smoothing_of(args: argparse.Namespace) -> tuple[int, dict[str, object] | None]:
    """The smoother's lag and the pose file's description of it."""
    from upperpose.fit.smoothing import DEFAULT_LAG

    if getattr(args, "no_smooth", False):
        return 0, None
    return DEFAULT_LAG, {"method": "savitzky-golay, quadratic, centred, in angle space", "lag_frames": DEFAULT_LAG}


def tracker_config(args: argparse.Namespace):  # type: ignore[no-untyped-def]
    """The TrackerConfig of the settings file (if any) with the command-line options over it."""
    import dataclasses

    from upperpose.commands.limits import check_focal
    from upperpose.fit.settings import load_config
    from upperpose.fit.tracker import TrackerConfig

    for name in ("particles", "iterations", "threads"):
        value = getattr(args, name, None)
        if value is not None and value < 1:
            raise ValueError(f"--{name} must be at least 1, got {value}")
    sigma = getattr(args, "sigma", None)
    if sigma is not None and not (math.isfinite(sigma) and sigma > 0):
        raise ValueError(f"--sigma must be a positive number, got {sigma}")
    seed = getattr(args, "seed", None)
    if seed is not None and not 0 <= seed < 2**64:
        raise ValueError(f"--seed must be within 0..2**64-1, got {seed}")
    check_focal(getattr(args, "focal", None))
    path = getattr(args, "config", None)
    config = load_config(path) if path else TrackerConfig()
    given = {name: getattr(args, name, None) for name in ("particles", "iterations", "threads", "seed")}
    given.update(optimizer=getattr(args, "optimizer", None), sigma=sigma, limits=getattr(args, "limits", None))
    if getattr(args, "no_skip", False):
        given["skip_static"] = False
    return dataclasses.replace(config, **{k: v for k, v in given.items() if v is not None})


def check_writable(*paths: str | None) -> None:
    """Fails early, before any work, when an output's folder is missing or not writable."""
    import os

    given = [Path(p) for p in paths if p is not None]
    for k, p in enumerate(given):
        for q in given[k + 1 :]:
            if p.resolve() == q.resolve():
                raise OSError(f"two outputs name the same file: {p}")
    for path in paths:
        if path is None:
            continue
        p = Path(path)
        folder = p.parent if str(p.parent) else Path(".")
        if p.is_dir():
            raise OSError(f"cannot write {p}: it is a folder")
        if not folder.is_dir():
            raise OSError(f"cannot write {p}: folder {folder} does not exist")
        if not os.access(folder, os.W_OK):
            raise OSError(f"cannot write {p}: folder {folder} is not writable")


class Progress:
    """A one-line progress bar on stderr (only when it is a terminal), with frames per second."""

    def __init__(self, total: int | None, enabled: bool) -> None:
        self.total, self.start, self.last = total, time.perf_counter(), 0.0
        self.enabled = enabled and sys.stderr.isatty()

    def update(self, done: int, status: str) -> None:
        """Redraws at most ten times a second."""
        now = time.perf_counter()
        if not self.enabled or now - self.last < 0.1:
            return
        self.last = now
        fps = done / max(now - self.start, 1e-9)
        if self.total:
            filled = int(30 * done / self.total)
            bar = f"[{'#' * filled}{'.' * (30 - filled)}] {done}/{self.total}"
        else:
            bar = f"{done} frames"
        sys.stderr.write(f"\r{bar}  {fps:5.1f} fps  {status:<12}")
        sys.stderr.flush()

    def finish(self) -> None:
        """Ends the line."""
        if self.enabled:
            sys.stderr.write("\n")
            sys.stderr.flush()


def provenance(run_: VideoTracking) -> dict[str, object]:
    """Pose-file fields that say how the poses were made: version, camera and body."""
    from upperpose import __version__

    camera = run_.camera
    return {
        "upperpose_version": __version__,
        "camera": {"model": camera.kind, "focal": camera.focal, "cx": camera.cx, "cy": camera.cy},
        "body": dict(run_.tracker.body.as_dict()),
    }


def run(args: argparse.Namespace) -> int:
    """Tracks the video; writes the outputs atomically, also after Ctrl-C."""
    from upperpose.exceptions import UpperposeError
    from upperpose.features import CleanPlateWarning
    from upperpose.fit.pipeline import VideoTracking
    from upperpose.fit.settings import config_to_dict
    from upperpose.fit.smoothing import PoseSmoother
    from upperpose.io.bvh import write_bvh
    from upperpose.io.files import interrupts_held
    from upperpose.io.output import PoseRecorder
    from upperpose.io.overlay import OverlayWriter, draw_overlay
    from upperpose.io.video import Frame, parse_source
    from upperpose.result import LOST, NO_PERSON, TRACKED, TrackResult

    if (args.video is None) == (args.camera is None):
        raise ValueError("give either a VIDEO or --camera N")
    source = args.camera if args.camera is not None else parse_source(args.video)
    name = f"camera {source}" if isinstance(source, int) else str(source)
    check_writable(args.output, args.csv, args.overlay, args.bvh)
    config = tracker_config(args)
    lag, smoothing = smoothing_of(args)
    started = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CleanPlateWarning)
        run_ = VideoTracking(source, args.background, focal=args.focal, config=config)
    notes = [str(w.message) for w in caught[:1]]
    if run_.reader.fps_warning:
        notes.append(run_.reader.fps_warning)
    for note in [] if args.quiet else notes:
        print(f"upperpose track: warning: {note}", file=sys.stderr)
    try:  # an overlay that cannot be opened (an unknown extension) ends the run before any record
        overlay = OverlayWriter(args.overlay, run_.reader.width, run_.reader.height, run_.fps) if args.overlay else None
    except BaseException:
        run_.close()
        raise
    recorder = PoseRecorder(
        run_.reader.width,
        run_.reader.height,
        run_.fps,
        source=name if isinstance(source, int) else Path(name).name,
        seed=run_.tracker.search_config.seed,
        clean_plate=run_.clean_plate,
        settings=config_to_dict(config),
        smoothing=smoothing,
    )
    progress = Progress(run_.reader.frame_count, not args.quiet)
    smoother: PoseSmoother[Frame | None] = PoseSmoother(run_.camera, lag)

    def take(result: TrackResult, frame: Frame | None) -> None:
        recorder.add(result)
        if overlay is not None and frame is not None:
            overlay.write(draw_overlay(frame, result, run_.camera, run_.tracker.body))
        progress.update(recorder.frames, result.status)

    interrupted = False
    try:
        for frame, result in run_.frames():
            for done, shown in smoother.push(result, run_.tracker.body, frame if overlay is not None else None):
                take(done, shown)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        # A second Ctrl-C or a SIGTERM while the outputs are written waits until they are whole.
        with interrupts_held():
            for done, shown in smoother.flush():
                take(done, shown)
            progress.finish()
            run_.close()
            run_time = time.perf_counter() - started
            with recorder:
                recorder.extra.update(provenance(run_))
                written = [recorder.write_json(args.output, run_time)]
                if args.csv:
                    written.append(recorder.write_csv(args.csv))
                if args.bvh and recorder.first_posed is not None:
                    written.append(write_bvh(args.bvh, recorder.records(), run_.tracker.body, run_.fps))
            if overlay is not None:
                kept = overlay.close()
                if kept:
                    written.append(kept)
    names = ", ".join(str(p) for p in written)
    if interrupted:
        print(f"upperpose track: interrupted after {recorder.frames} frames; wrote them to {names}", file=sys.stderr)
        return 130
    frames = recorder.frames
    if frames == 0 or recorder.count(NO_PERSON) == frames:
        raise UpperposeError(
            f"no person found in {name} ({frames} frames): start-up needs a visible frontal face; "
            f"wrote an all-'no_person' {args.output}"
        )
    if recorder.count(TRACKED, LOST) == 0:
        raise UpperposeError(
            f"tracking never started in {name} ({frames} frames): a face was seen but never held still "
            f"long enough (the A-pose for {config.confirm_frames} frames in a row, or a steady face for "
            f"{config.face_only_frames}); wrote {args.output} without a pose"
        )
    if not args.quiet:
        tracked, lost = recorder.count(TRACKED), recorder.count(LOST)
        first = recorder.first_posed or 0
        after = frames - first
        print(
            f"Tracked {name}: {frames} frames in {run_time:.1f} s ({frames / run_time:.1f} fps); "
            f"start-up took {first} frames; of the {after} frames after it {tracked} were tracked "
            f"({100 * tracked / max(after, 1):.1f} %) and {lost} lost; "
            f"background from {'the clean plate' if run_.clean_plate else 'the video (estimated)'}; "
            f"wrote {names}."
        )
    return 0
