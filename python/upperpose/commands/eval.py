"""`upperpose eval`: score a pose file against ground truth (thesis Table 4.2-1 and more)."""

from __future__ import annotations

import argparse
import json

from upperpose.commands.limits import OptionError

NAME = "eval"
HELP = "score predicted poses against ground truth: per-joint pixel errors, MPJPE, PCK, 3D error, coverage, fps"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument("prediction", help="pose file to score (upperpose track output)")
    p.add_argument("truth", help="ground-truth pose file (e.g. a clip folder's gt.json)")
    p.add_argument("--json", action="store_true", help="print the scores as JSON")
    p.add_argument("--pck", type=float, default=10.0, help="PCK radius in pixels (default 10)")


def run(args: argparse.Namespace) -> int:
    """Loads both files, scores, prints."""
    from upperpose.io.posefile import load_poses
    from upperpose.lab.evaluate import evaluate, format_table

    if not args.pck > 0:
        raise OptionError(f"--pck must be positive, got {args.pck}")
    scores = evaluate(load_poses(args.prediction), load_poses(args.truth), args.pck)
    print(json.dumps(scores.to_dict(), indent=1) if args.json else format_table(scores))
    return 0
