"""How much of a pose file's 2D error is a constant offset per clip, and of which joints.

A joint reported in the same wrong place relative to the person all clip long (shoulders set
too wide for this person, elbows too high) is a calibration error; the rest (a hand lost for a
while, jitter) is not. Per clip this tool prints the mean absolute error in x and y of the
frames `upperpose eval` scores, and what is left of it when each group of joints (head,
shoulders, elbows, hands, all) has its mean signed offset over the clip taken away: what a
perfect per-person calibration of that group could win, at most. Also the share of the joints
more than `FAR_PX` off and their part of the error (gross failures, which no calibration mends).

    python -m upperpose.lab.error_2d PRED_DIR TRUTH_DIR

reads every `PRED_DIR/NAME.json` with a `TRUTH_DIR/NAME/gt.json`, as `upperpose.lab.error_3d`.
"""

from __future__ import annotations

import sys

import numpy as np
import numpy.typing as npt

from upperpose.lab.error_3d import paired_joints
from upperpose.lab.pose_pairs import pairs_parser, pose_pairs

FloatArray = npt.NDArray[np.float64]
GROUPS = {"head": (0,), "shoulders": (1, 2), "elbows": (3, 4), "hands": (5, 6), "all": tuple(range(7))}
FAR_PX = 25.0


def decompose(mine: FloatArray, true: FloatArray) -> dict[str, FloatArray]:
    """One clip's mean absolute 2D error and what is left without each group's constant offset.

    Args:
        mine: `(F, 7, 2)` predicted joints in pixels, F >= 1.
        true: the true joints of the same frames.

    Returns:
        "error" and each of `GROUPS` -> `(2,)` mean absolute error in x and y, pixels;
        "far" -> `(2,)`: the share of the joints more than `FAR_PX` off, and their part of the
        mean of the x and y errors.
    """
    gap = mine - true
    out = {"error": np.abs(gap).mean(axis=(0, 1))}
    for name, joints in GROUPS.items():
        centred = gap.copy()
        centred[:, joints] -= gap[:, joints].mean(axis=0)
        out[name] = np.abs(centred).mean(axis=(0, 1))
    far = np.linalg.norm(gap, axis=2) > FAR_PX
    out["far"] = np.array([far.mean(), np.abs(gap[far]).sum() / (2 * far.size)])
    return out


def main(argv: list[str] | None = None) -> int:
    """Prints every clip's decomposition and the means; 1 when no clip could be compared."""
    args = pairs_parser("python -m upperpose.lab.error_2d", __doc__.split("\n")[0]).parse_args(argv)
    columns = ("error", *GROUPS)
    rows = []
    print(f"{'clip':28s} " + " ".join(f"{c:>11s}" for c in columns) + f"  >{FAR_PX:g} px: share, part")
    for name, prediction, truth in pose_pairs(args.predictions, args.truth):
        mine, true = paired_joints(prediction, truth, "joints_2d")
        if not len(mine):
            print(f"{name:28s} no frame with 2D joints in both")
            continue
        rows.append(decompose(mine, true))
        print(f"{name:28s} " + _cells(rows[-1], columns))
    if not rows:
        print("no clip with both a pose file and a truth", file=sys.stderr)
        return 1
    mean = {key: np.mean([r[key] for r in rows], axis=0) for key in rows[0]}
    print(f"{'mean':28s} " + _cells(mean, columns))
    return 0


def _cells(row: dict[str, FloatArray], columns: tuple[str, ...]) -> str:
    share, part = row["far"]
    return " ".join(f"{row[c][0]:5.2f}/{row[c][1]:5.2f}" for c in columns) + f"  {100 * share:5.1f} %, {part:4.2f}"


if __name__ == "__main__":
    sys.exit(main())
