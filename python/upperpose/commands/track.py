"""`upperpose track`: track a video and write the poses (SPEC 9), a CSV and an overlay video."""

from __future__ import annotations

import argparse
import logging
import math
import sys
from pathlib import Path

from upperpose.commands.limits import OptionError

NAME = "track"
OPTIMIZERS = ("apso", "pso", "simplex", "apsopf")
HELP = (
    "track the upper body in a video or from a camera: poses as JSON (SPEC 9), optionally CSV, BVH and an "
    "overlay video. Start-up needs a static camera and a visible frontal face, in any upper-body pose (the "
    "A-pose, arms down and slightly out, measures the arms best); a clean plate (--background) makes it "
    "most accurate"
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
    p.add_argument(
        "--background",
        metavar="IMAGE",
        help="clean plate: a photo of the empty scene (recommended; without it the background is estimated "
        "from the video, see --bg-model, or learnt while tracking from a live camera)",
    )
    p.add_argument("--focal", type=float, metavar="PX", help="focal length in pixels (default: the image width)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.json", help="pose file to write (SPEC 9)")
    p.add_argument("--csv", metavar="OUT.csv", help="also write one CSV row per frame")
    p.add_argument("--overlay", metavar="OUT.mp4", help="also write the video with the fitted model drawn over it")
    p.add_argument(
        "--bvh",
        metavar="OUT.bvh",
        help="also write the angles as BVH on the person's skeleton (for Blender)",
    )
    add_tracking_arguments(p)


def add_background_model_argument(p: argparse.ArgumentParser) -> None:
    """--bg-model, shared by track, batch and bench."""
    p.add_argument(
        "--bg-model",
        choices=("online", "prepass"),
        default=None,
        help="without --background: learn the background while tracking (online; always for a live camera) "
        "or estimate it from the whole video first (prepass, the default for files; docs/features.md)",
    )


def add_tracking_arguments(p: argparse.ArgumentParser) -> None:
    """The search options, --bg-model, --no-skip and --no-smooth: how track and batch track a video."""
    add_search_arguments(p)
    add_background_model_argument(p)
    p.add_argument("--no-skip", action="store_true", help="search every part every frame (ignore the motion flags)")
    add_smoothing_argument(p)


def add_smoothing_argument(p: argparse.ArgumentParser) -> None:
    """--no-smooth, shared by track and demo."""
    from upperpose.fit.smoothing import DEFAULT_LAG

    p.add_argument(
        "--no-smooth",
        action="store_true",
        help="write the poses as fitted (default: smoothed in angle space without lag, each frame's "
        f"pose known {DEFAULT_LAG} frames later; docs/guide.md)",
    )


def smoothing_of(args: argparse.Namespace) -> tuple[int, dict[str, object] | None]:
    """The smoother's lag and the pose file's description of it."""
    from upperpose.fit.outputs import smoothing_record

    return smoothing_record(not getattr(args, "no_smooth", False))


def tracker_config(args: argparse.Namespace):  # type: ignore[no-untyped-def]
    """The TrackerConfig of the settings file (if any) with the command-line options over it."""
    import dataclasses

    from upperpose.commands.limits import check_focal
    from upperpose.fit.settings import load_config
    from upperpose.fit.tracker import TrackerConfig

    for name in ("particles", "iterations", "threads"):
        value = getattr(args, name, None)
        if value is not None and value < 1:
            raise OptionError(f"--{name} must be at least 1, got {value}")
    sigma = getattr(args, "sigma", None)
    if sigma is not None and not (math.isfinite(sigma) and sigma > 0):
        raise OptionError(f"--sigma must be a positive number, got {sigma}")
    seed = getattr(args, "seed", None)
    if seed is not None and not 0 <= seed < 2**64:
        raise OptionError(f"--seed must be within 0..2**64-1, got {seed}")
    check_focal(getattr(args, "focal", None))
    path = getattr(args, "config", None)
    config = load_config(path) if path else TrackerConfig()
    given = {name: getattr(args, name, None) for name in ("particles", "iterations", "threads", "seed")}
    given.update(optimizer=getattr(args, "optimizer", None), sigma=sigma, limits=getattr(args, "limits", None))
    if getattr(args, "no_skip", False):
        given["skip_static"] = False
    config = dataclasses.replace(config, **{k: v for k, v in given.items() if v is not None})
    bg_model = getattr(args, "bg_model", None)
    if bg_model is not None:
        from upperpose.features import FeatureConfig

        config = dataclasses.replace(config, features=(config.features or FeatureConfig()).replace(bg_model=bg_model))
    return config


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


def run(args: argparse.Namespace) -> int:
    """Tracks the video; writes the outputs atomically, also after Ctrl-C."""
    from upperpose.exceptions import UpperposeError
    from upperpose.fit.outputs import OutputPaths, track_to_files
    from upperpose.io.progress import Progress
    from upperpose.io.video import parse_source

    if (args.video is None) == (args.camera is None):
        raise OptionError("give either a VIDEO or --camera N")
    source = args.camera if args.camera is not None else parse_source(args.video)
    name = f"camera {source}" if isinstance(source, int) else str(source)
    check_writable(args.output, args.csv, args.overlay, args.bvh)
    config = tracker_config(args)
    paths = OutputPaths(
        Path(args.output),
        csv=Path(args.csv) if args.csv else None,
        bvh=Path(args.bvh) if args.bvh else None,
        overlay=Path(args.overlay) if args.overlay else None,
    )
    progress = Progress("upperpose track", enabled=not args.quiet)

    def show(frames: int, total: int | None, status: str) -> None:
        progress.update(frames, total, status)

    try:
        done = track_to_files(
            source,
            paths,
            config=config,
            background=args.background,
            focal=args.focal,
            smooth=not args.no_smooth,
            keep_partial=True,
            on_frame=show,
            on_warning=logging.getLogger(__name__).warning,
        )
    finally:
        progress.close()
    names = ", ".join(str(p) for p in done.written)
    if done.interrupted:
        print(f"upperpose track: interrupted after {done.frames} frames; wrote them to {names}", file=sys.stderr)
        return 130
    frames = done.frames
    looks = f"; {done.looks}" if done.looks else ""
    if frames == 0 or done.no_person == frames:
        raise UpperposeError(
            f"no person found in {name} ({frames} frames): start-up needs a visible frontal face{looks}; "
            f"wrote an all-'no_person' {args.output}"
        )
    if done.posed == 0:
        raise UpperposeError(
            f"tracking never started in {name} ({frames} frames): a face was seen but never held still "
            f"long enough (a steady face for {max(config.any_pose_frames, 2)} frames and a fit that explains "
            f"the silhouette, the A-pose for {config.confirm_frames} frames in a row, or a steady face for "
            f"{done.face_only_frames}){looks}; wrote {args.output} without a pose"
        )
    if not args.quiet:
        first = done.first_posed or 0
        after = frames - first
        print(
            f"Tracked {name}: {frames} frames in {done.run_time_s:.1f} s ({frames / done.run_time_s:.1f} fps); "
            f"start-up took {first} frames; of the {after} frames after it {done.tracked} were tracked "
            f"({100 * done.tracked / max(after, 1):.1f} %) and {done.lost} lost; "
            f"background from {'the clean plate' if done.clean_plate else 'the video (estimated)'}; "
            f"wrote {names}."
        )
    return 0
