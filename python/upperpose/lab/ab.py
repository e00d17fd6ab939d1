r"""Is a change better? Validation runs before and after it, paired by seed, compared per clip.

One validation run changes by a few tenths of a pixel with the seed alone, and a change to the
tracker moves single clips both ways by more than that: a mean over one seed cannot tell a gain
of 0.2 px from noise. This tool takes the same seeds before and after a change and prints, per
clip, the mean over the seeds of x, y (pixels) and the root-relative 3D error (mm) as `upperpose
eval` scores them; then the mean change over the clips with a 95 % bootstrap interval (the clips
resampled, since the seeds of one clip are not independent) and the clips better and worse by
more than `--margin` pixels in the mean of x and y.

    python -m upperpose.lab.ab TRUTH_DIR --before before_0 before_1 before_2 \
        --after after_0 after_1 after_2

Each folder holds one run's `NAME.json` pose files (seeds 0, 1, 2 before the change, the same
seeds after it) for clips `TRUTH_DIR/NAME/gt.json`, the layout of `upperpose.lab.pose_pairs`.
Only clips scored in every folder are compared.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import UpperposeError
from upperpose.lab.evaluate import evaluate
from upperpose.lab.pose_pairs import pose_pairs

FloatArray = npt.NDArray[np.float64]
# Per clip: mean |dx| px, mean |dy| px, root-relative 3D mm (NaN without 3D).
METRICS = ("x px", "y px", "3D mm")


def clip_scores(predictions: Path, truth: Path) -> dict[str, FloatArray]:
    """Each clip's `METRICS` in one folder of pose files; clips without a compared frame are left out."""
    scores = {}
    for name, prediction, true in pose_pairs(predictions, truth):
        s = evaluate(prediction, true)
        if s.compared_frames:
            mm = math.nan if s.mpjpe_3d_mm is None else s.mpjpe_3d_mm
            scores[name] = np.array([s.mean_abs_x_px, s.mean_abs_y_px, mm])
    return scores


def paired_means(
    before: Sequence[dict[str, FloatArray]], after: Sequence[dict[str, FloatArray]]
) -> dict[str, FloatArray]:
    """Per clip scored in every run: `(2, len(METRICS))`, the mean over the runs before and after.

    Raises:
        ValueError: no runs, or not as many runs after as before (runs pair by position).
    """
    if not before or len(before) != len(after):
        raise ValueError(f"need as many runs after as before, at least one: got {len(before)} and {len(after)}")
    common = sorted(set.intersection(*(set(r) for r in [*before, *after])))
    return {name: np.array([np.mean([r[name] for r in side], axis=0) for side in (before, after)]) for name in common}


def bootstrap_interval(
    values: npt.ArrayLike, draws: int = 4000, level: float = 0.95, seed: int = 0
) -> tuple[float, float]:
    """Percentile bootstrap interval of the mean of `values` (resampled with replacement), deterministic."""
    v = np.asarray(values, dtype=np.float64)
    if v.size == 0:
        raise ValueError("no values to resample")
    means = np.random.default_rng(seed).choice(v, size=(draws, v.size), replace=True).mean(axis=1)
    tail = 100.0 * (1.0 - level) / 2.0
    low, high = np.percentile(means, [tail, 100.0 - tail])
    return float(low), float(high)


def main(argv: list[str] | None = None) -> int:
    """Prints the per-clip table and the mean changes; 1 when no clip is scored in every run."""
    parser = argparse.ArgumentParser(prog="python -m upperpose.lab.ab", description=__doc__.split("\n")[0])
    parser.add_argument("truth", type=Path, help="folder of clips NAME/gt.json")
    parser.add_argument("--before", type=Path, nargs="+", required=True, help="pose-file folders before the change")
    parser.add_argument(
        "--after", type=Path, nargs="+", required=True, help="the same seeds after it, in the same order"
    )
    parser.add_argument(
        "--margin", type=float, default=0.5, help="px in the mean of x and y for a clip to count as changed"
    )
    args = parser.parse_args(argv)
    if len(args.before) != len(args.after):
        parser.error(f"--before has {len(args.before)} folders and --after {len(args.after)}: they pair by seed")
    for folder in [*args.before, *args.after]:
        if not folder.is_dir():
            parser.error(f"not a folder: {folder}")
    try:
        before, after = ([clip_scores(f, args.truth) for f in side] for side in (args.before, args.after))
    except (UpperposeError, OSError) as problem:  # a pose file that cannot be read or scored
        print(f"error: {problem}", file=sys.stderr)
        return 1
    means = paired_means(before, after)
    if not means:
        print("no clip is scored in every folder", file=sys.stderr)
        return 1
    print(f"{'clip':30s}  before: x, y, 3D         after: x, y, 3D          change in the mean of x and y")
    for name, (b, a) in means.items():
        cells = f"{b[0]:5.2f} {b[1]:5.2f} {b[2]:6.1f}   {a[0]:5.2f} {a[1]:5.2f} {a[2]:6.1f}"
        print(f"{name:30s}  {cells}   {(a[:2] - b[:2]).mean():+6.2f}")
    table = np.array(list(means.values()))  # (clips, before / after, metric)
    print(
        f"\n{len(means)} clips, {len(args.before)} run(s) a side. After - before, 95 % bootstrap interval over clips:"
    )
    for m, label in enumerate(METRICS):
        scored = np.isfinite(table[:, :, m]).all(axis=1)
        if scored.any():
            old, new = table[scored, 0, m], table[scored, 1, m]
            low, high = bootstrap_interval(new - old)
            change = f"{(new - old).mean():+6.2f}  [{low:+6.2f}, {high:+6.2f}]"
            print(f"  {label:6s} {old.mean():7.2f} -> {new.mean():7.2f}   {change}")
    both = (table[:, 1, :2] - table[:, 0, :2]).mean(axis=1)
    better, worse = int(np.sum(both < -args.margin)), int(np.sum(both > args.margin))
    print(f"  clips better by more than {args.margin:g} px: {better}, worse: {worse}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
