"""Where a pose file's root-relative 3D error comes from: depth or image plane, bias or scatter.

The 3D error of `upperpose eval` is root-relative (root: the shoulders' midpoint) and not
scaled, so it mixes three things one camera tells apart badly: each joint's depth, the person's
size (the root's depth from the face box), and the image-plane placement. Per clip this tool
prints that error and what is left of it

- `true z`: with the truth's root-relative depth put in every joint (the error in x and y alone);
- `true xy`: with the truth's x and y instead (the depth error alone);
- `unbiased z`: with each joint's mean depth offset over the clip taken away (what a constant
  per-clip depth bias costs);
- `scaled`: with the prediction scaled by the truth's over the fitted depth of the shoulders
  (median over the frames: what the person's size costs);

then, over the clips, each joint's mean absolute error and mean signed error (bias) along x, y
and z, in millimetres (camera frame: x right, y down, z away from the camera).

    python -m upperpose.lab.error_3d PRED_DIR TRUTH_DIR

reads every `PRED_DIR/NAME.json` with a `TRUTH_DIR/NAME/gt.json` (frames where both have 3D
joints).
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np
import numpy.typing as npt

from upperpose.lab.pose_pairs import pairs_parser, pose_pairs
from upperpose.model import JOINT_NAMES

FloatArray = npt.NDArray[np.float64]
VARIANTS = ("error", "true z", "true xy", "unbiased z", "scaled")


def paired_joints(
    prediction: dict[str, Any], truth: dict[str, Any], key: str = "joints_3d"
) -> tuple[FloatArray, FloatArray]:
    """`(F, 7, 3)` predicted and true 3D joints of the frames where both have them.

    `key="joints_2d"`: the 2D joints instead, `(F, 7, 2)` pixels.
    """
    predicted = {f["frame"]: f.get(key) for f in prediction["frames"]}
    mine, true = [], []
    for frame in truth["frames"]:
        a, b = predicted.get(frame["frame"]), frame.get(key)
        if a is None or b is None:
            continue
        mine.append(a)
        true.append(b)
    shape = (len(mine), len(JOINT_NAMES), 2 if key == "joints_2d" else 3)
    return np.asarray(mine, dtype=np.float64).reshape(shape), np.asarray(true, dtype=np.float64).reshape(shape)


def root_relative(joints: FloatArray) -> FloatArray:
    """`(F, 7, 3)` joints minus each frame's midpoint of the shoulders."""
    relative: FloatArray = joints - 0.5 * (joints[:, 1:2] + joints[:, 2:3])
    return relative


def decompose(mine: FloatArray, true: FloatArray) -> dict[str, Any]:
    """The root-relative 3D error of one clip and what is left of it in each of `VARIANTS` (mm).

    Args:
        mine: `(F, 7, 3)` predicted joints in metres, F >= 1.
        true: the true joints of the same frames.

    Returns:
        `VARIANTS` -> mean joint error in mm; "abs" and "bias": `(7, 3)` mean absolute and
        signed root-relative error per joint and axis, mm.
    """
    a, b = root_relative(mine), root_relative(true)

    def error(candidate: FloatArray) -> float:
        return float(np.linalg.norm(candidate - b, axis=2).mean() * 1000.0)

    true_z, true_xy, unbiased = a.copy(), a.copy(), a.copy()
    true_z[..., 2] = b[..., 2]
    true_xy[..., :2] = b[..., :2]
    unbiased[..., 2] -= (a[..., 2] - b[..., 2]).mean(axis=0)
    depth = float(np.median(true[:, 1:3, 2].mean(axis=1) / mine[:, 1:3, 2].mean(axis=1)))
    gap = (a - b) * 1000.0
    return {
        "error": error(a),
        "true z": error(true_z),
        "true xy": error(true_xy),
        "unbiased z": error(unbiased),
        "scaled": error(a * depth),
        "abs": np.abs(gap).mean(axis=0),
        "bias": gap.mean(axis=0),
    }


def main(argv: list[str] | None = None) -> int:
    """Prints every clip's decomposition and the means; 1 when no clip could be compared."""
    args = pairs_parser("python -m upperpose.lab.error_3d", __doc__.split("\n")[0]).parse_args(argv)
    rows = []
    print(f"{'clip':28s} " + " ".join(f"{v:>10s}" for v in VARIANTS) + "   (mm)")
    for name, prediction, truth in pose_pairs(args.predictions, args.truth):
        mine, true = paired_joints(prediction, truth)
        if not len(mine):
            print(f"{name:28s} no frame with 3D joints in both")
            continue
        rows.append(decompose(mine, true))
        print(f"{name:28s} " + " ".join(f"{rows[-1][v]:10.1f}" for v in VARIANTS))
    if not rows:
        print("no clip with both a pose file and a truth", file=sys.stderr)
        return 1
    print(f"{'mean':28s} " + " ".join(f"{np.mean([r[v] for r in rows]):10.1f}" for v in VARIANTS))
    print("per joint, mean over the clips, x / y / z mm: |error| and bias")
    for j, name in enumerate(JOINT_NAMES):
        size = np.mean([r["abs"][j] for r in rows], axis=0)
        bias = np.mean([r["bias"][j] for r in rows], axis=0)
        print(
            f"  {name:15s} " + " / ".join(f"{v:4.0f}" for v in size) + "    " + " / ".join(f"{v:+4.0f}" for v in bias)
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
