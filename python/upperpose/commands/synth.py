"""`upperpose synth`: render synthetic clips with known poses, or the whole development set."""

from __future__ import annotations

import argparse
import multiprocessing
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from upperpose.commands.limits import OptionError

NAME = "synth"
HELP = "render a synthetic clip folder (video, ground truth, clean plate, masks), or the development set"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    from upperpose.lab.synth.appearance import BUILDS, HAIR_COLOURS, PATTERNS, SHIRT_COLOURS, SKIN_TONES, SLEEVES
    from upperpose.lab.synth.motions import MOTIONS

    p.add_argument("outdir", help="clip folder to write (with --devset: the folder of the twelve clip folders)")
    p.add_argument("--devset", action="store_true", help="write the 12-clip development set into OUTDIR")
    p.add_argument(
        "--holdout", type=int, default=0, metavar="K",
        help="with --devset: held-out set K >= 1 instead (the same recipes, other seeds and looks)",
    )  # fmt: skip
    p.add_argument("--jobs", type=int, default=2, help="parallel processes for --devset (default 2)")
    p.add_argument("--motion", default="wave_right", help=f"one of: {', '.join(MOTIONS)}")
    p.add_argument("--frames", type=int, default=150)
    p.add_argument("--seed", type=int, default=0, help="seeds every random choice (default 0)")
    p.add_argument("--width", type=int, default=640)
    p.add_argument("--height", type=int, default=480)
    p.add_argument("--fps", type=float, default=30.0)
    p.add_argument("--focal", type=float, default=None, help="focal length in pixels (default: image width)")
    p.add_argument(
        "--depth", type=float, default=None, help="distance of the person, metres (default: 2.0-2.5 from the seed)"
    )
    p.add_argument(
        "--lower",
        type=float,
        default=0.0,
        help="stand the person this many metres lower (0.24 at --depth 1 --focal 860: head and shoulders, "
        "as a webcam frames them; default 0)",
    )
    p.add_argument("--noise", type=float, default=2.5, help="sensor noise, grey levels (default 2.5)")
    p.add_argument("--empty-start", action="store_true", help="empty scene for a second, then the person walks in")
    p.add_argument("--lighting-ramp", action="store_true", help="the light dims and recovers")
    p.add_argument("--step-closer", action="store_true", help="the person steps half a metre closer")
    p.add_argument("--skin", choices=list(SKIN_TONES), help="default: from the seed (as all looks)")
    p.add_argument("--shirt", choices=list(SHIRT_COLOURS))
    p.add_argument("--pattern", choices=list(PATTERNS))
    p.add_argument("--sleeves", choices=list(SLEEVES))
    p.add_argument("--hair", choices=list(HAIR_COLOURS))
    p.add_argument("--build", choices=list(BUILDS))


def _render(name: str, config: object, outdir: str) -> tuple[str, float]:
    from upperpose.lab.synth.dataset import write_clip

    start = time.perf_counter()
    write_clip(config, Path(outdir) / name)  # type: ignore[arg-type]
    return name, time.perf_counter() - start


def run(args: argparse.Namespace) -> int:
    """Renders and writes the clip(s)."""
    import dataclasses

    import numpy as np

    from upperpose.commands.limits import check_focal, check_number, check_size
    from upperpose.io.files import write_image
    from upperpose.lab.synth.appearance import Appearance
    from upperpose.lab.synth.dataset import write_clip
    from upperpose.lab.synth.devset import DEVSET, holdout_set
    from upperpose.lab.synth.motions import MOTIONS
    from upperpose.lab.synth.scene import ClipConfig
    from upperpose.lab.synth.sheet import contact_sheet

    if args.holdout and not args.devset:
        raise OptionError("--holdout goes with --devset")
    if args.holdout < 0:
        raise OptionError(f"--holdout must be a positive integer, got {args.holdout}")
    if args.motion not in MOTIONS:
        raise OptionError(f"unknown motion {args.motion!r}; motions are {', '.join(MOTIONS)}")
    if args.devset:
        if args.jobs < 1:
            raise OptionError(f"--jobs must be at least 1, got {args.jobs}")
        clips = holdout_set(args.holdout) if args.holdout else DEVSET
        label = f"held-out set {args.holdout}" if args.holdout else "development set"
        Path(args.outdir).mkdir(parents=True, exist_ok=True)
        start = time.perf_counter()
        # One thread per worker process: the workers already fill the cores.
        for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ.setdefault(var, "1")
        with ProcessPoolExecutor(max_workers=args.jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = [pool.submit(_render, name, config, args.outdir) for name, config in clips]
            for future in futures:
                name, seconds = future.result()
                print(f"wrote {Path(args.outdir) / name} ({seconds:.1f} s)", flush=True)
        print(f"{label}: {len(clips)} clips in {time.perf_counter() - start:.1f} s")
        sheet = write_image(Path(args.outdir) / "sheet.png", contact_sheet([Path(args.outdir) / n for n, _ in clips]))
        print(f"wrote {sheet} (contact sheet)")
        return 0
    check_size(args.width, args.height, even=True)
    check_number("--fps", args.fps, 1.0, 240.0)
    check_number("--frames", args.frames, 1, 100_000)
    check_number("--depth", args.depth, 0.5, 20.0, "metres")
    check_number("--noise", args.noise, 0.0, 100.0, "grey levels")
    check_number("--lower", args.lower, -1.0, 1.0, "metres")
    check_focal(args.focal)
    looks = {k: getattr(args, k) for k in ("skin", "shirt", "pattern", "sleeves", "hair", "build") if getattr(args, k)}
    appearance = None
    if looks:
        drawn = Appearance.random(np.random.default_rng([args.seed, 2]))
        appearance = dataclasses.replace(drawn, **looks)
    config = ClipConfig(
        motion=args.motion, frames=args.frames, seed=args.seed, width=args.width, height=args.height, fps=args.fps,
        focal=args.focal, appearance=appearance, empty_start=args.empty_start, lighting_ramp=args.lighting_ramp,
        step_closer=args.step_closer, noise=args.noise, depth=args.depth, lower=args.lower,
    )  # fmt: skip

    def progress(done: int, total: int) -> None:
        print(f"\r{done}/{total} frames", end="", file=sys.stderr, flush=True)

    start = time.perf_counter()
    folder = write_clip(config, args.outdir, progress if sys.stderr.isatty() else None)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    print(f"wrote {folder} ({config.frames} frames in {time.perf_counter() - start:.1f} s)")
    return 0
