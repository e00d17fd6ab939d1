"""`upperpose compare`: the thesis' comparison of optimisers on a data set of clips (SPEC 7)."""

from __future__ import annotations

import argparse
import math
import shlex
import sys

from upperpose.commands.limits import OptionError

NAME = "compare"
HELP = "run every optimiser (APSO, PSO, simplex [1], APSOPF [2]) on every clip and write Table 4.2-1 per method"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    from upperpose.lab.compare import THESIS_SIGMAS

    p.add_argument("dataset", metavar="DATASET_DIR", help="folder of clip folders (video.mp4, gt.json, meta.json)")
    p.add_argument("-o", "--output", metavar="REPORT.md", help="write the report here (default: print it)")
    p.add_argument("--jobs", type=int, default=1, help="runs in parallel processes (default 1)")
    p.add_argument("--frames", type=int, default=None, help="track only the first N frames of each clip")
    p.add_argument(
        "--sigmas",
        type=float,
        nargs="*",
        default=list(THESIS_SIGMAS),
        help="APSOPF sigmas to sweep (default: the thesis' 0.1 ... 1.5; none: no sweep)",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument(
        "--threads",
        type=int,
        default=None,
        help="search threads per run (default: 1 with --jobs > 1, else the search's default)",
    )


def run(args: argparse.Namespace) -> int:
    """Runs the comparison and writes the report atomically."""
    from upperpose.commands.track import check_writable
    from upperpose.io.files import write_atomic
    from upperpose.lab.compare import all_methods, find_clips, format_report, run_all

    for name in ("jobs", "frames", "threads"):
        value = getattr(args, name)
        if value is not None and value < 1:
            raise OptionError(f"--{name} must be at least 1, got {value}")
    for s in args.sigmas:
        if not (math.isfinite(s) and s > 0):
            raise OptionError(f"--sigmas must be positive numbers, got {s}")
    check_writable(args.output)
    clips = find_clips(args.dataset)
    methods = all_methods(args.sigmas)
    threads = args.threads or (1 if args.jobs > 1 else None)

    def progress(r: dict, k: int, n: int) -> None:  # type: ignore[type-arg]
        if not args.quiet:
            s = r["scores"]
            mpjpe = "-" if s["mpjpe_2d_px"] is None else f"{s['mpjpe_2d_px']:.1f} px"
            print(
                f"[{k}/{n}] {r['clip']}, {r['method']}: 2D MPJPE {mpjpe}, "
                f"{r['frames'] / max(r['run_time_s'], 1e-9):.1f} fps",
                file=sys.stderr,
                flush=True,
            )

    results = run_all(
        clips, methods, frames=args.frames, seed=args.seed, jobs=args.jobs, threads=threads, progress=progress
    )
    report = format_report(
        results,
        clips,
        methods,
        args.sigmas,
        dataset=args.dataset,
        frames=args.frames,
        seed=args.seed,
        command=shlex.join(
            ["upperpose", "compare", args.dataset, "--jobs", str(args.jobs), "--seed", str(args.seed)]
            + (["--frames", str(args.frames)] if args.frames else [])
            + ["--sigmas", *(f"{s:g}" for s in args.sigmas)]
        ),
    )
    if args.output:
        write_atomic(args.output, lambda tmp: tmp.write_text(report))
        if not args.quiet:
            print(f"wrote {args.output}", file=sys.stderr)
    else:
        print(report)
    return 0
