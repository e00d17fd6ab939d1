"""`upperpose batch`: many videos into pose files and a summary, resumable, locally or on Ray."""

from __future__ import annotations

import argparse
import sys

from upperpose.commands.track import add_tracking_arguments

NAME = "batch"
HELP = (
    "track many videos (files, folders, globs, a .txt list of paths or URLs): one pose file each under "
    "--out-dir in the same folder layout, plus summary.csv and summary.json; a rerun skips finished videos"
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument("inputs", nargs="+", metavar="INPUT", help="video, folder, glob, or .txt file listing videos")
    p.add_argument("--out-dir", required=True, metavar="DIR", help="folder for the outputs and the summary")
    p.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="videos tracked at once on this machine, each in its own process (default 1: in this process)",
    )
    p.add_argument("--backend", choices=("local", "ray"), default="local", help="where videos run (default local)")
    p.add_argument("--address", metavar="ADDR", help="ray: the cluster's address (default: start Ray on this machine)")
    p.add_argument(
        "--collect",
        action="store_true",
        help="ray: workers return the files and this process writes them (default: workers write into DIR, "
        "which must be a folder every node sees at the same path)",
    )
    p.add_argument("--csv", action="store_true", help="also write DIR/PLACE.csv per video")
    p.add_argument("--bvh", action="store_true", help="also write DIR/PLACE.bvh per video")
    p.add_argument("--overlay", action="store_true", help="also write DIR/PLACE.overlay.mp4 per video")
    p.add_argument(
        "--background",
        metavar="IMAGE",
        help="one clean plate for every video (default: a background.png beside each video, else estimated, "
        "see --bg-model)",
    )
    p.add_argument("--focal", type=float, metavar="PX", help="focal length in pixels (default: each video's width)")
    add_tracking_arguments(p)


def run(args: argparse.Namespace) -> int:
    """Runs the batch; exit status 1 when a video failed, 130 after Ctrl-C."""
    from upperpose.batch import BatchInterrupted, BatchResult
    from upperpose.batch import run as run_batch
    from upperpose.batch.job import SKIPPED
    from upperpose.commands.limits import OptionError
    from upperpose.commands.track import tracker_config

    if args.jobs < 1:
        raise OptionError(f"--jobs must be at least 1, got {args.jobs}")
    try:
        result: BatchResult = run_batch(
            args.inputs,
            args.out_dir,
            jobs=args.jobs,
            backend=args.backend,
            address=args.address,
            collect=args.collect,
            config=tracker_config(args),
            background=args.background,
            focal=args.focal,
            smooth=not args.no_smooth,
            csv=args.csv,
            bvh=args.bvh,
            overlay=args.overlay,
            progress=not args.quiet,
        )
    except BatchInterrupted as stop:
        got = stop.result
        finished = len(got.rows) - got.count("not_run") - got.failed
        print(
            f"upperpose batch: interrupted; of {len(got.rows)} videos {finished} are finished (their files whole), "
            f"{got.failed} failed and {got.count('not_run')} not run (no file): rerun the same command to complete "
            "them",
            file=sys.stderr,
        )
        return 130
    rows = result.rows
    failed = [r for r in rows if r["status"] == "failed"]
    if not args.quiet:
        print(
            f"{len(rows)} videos: {len(rows) - result.count(SKIPPED) - len(failed)} tracked, "
            f"{result.count(SKIPPED)} skipped (already done), {len(failed)} failed, in {result.wall_time_s:.1f} s; "
            f"summary in {result.summary[0]}",
            file=sys.stderr,
        )
    for r in failed:
        print(f"upperpose batch: failed: {r['video']}: {r['error']}", file=sys.stderr)
    return 1 if failed else 0
