"""How well a pose file's body matches the person's: bone lengths against the truth's.

Per-person calibration (issue 24) is judged by the lengths between the reported joints:
shoulder width (shoulder to shoulder), upper arm (shoulder to elbow), forearm (elbow to palm)
and neck (the shoulders' midpoint to the head), each the median over the frames where both the
prediction and the truth have 3D joints, both arms averaged. One camera fixes a person's size
only up to their distance, so two ratios are given:

- `metric`: predicted length / true length, in metres, as written in the pose file;
- `image`: the same divided by the ratio of the shoulders' predicted to true depth, which is
  how long the bone looks in the image relative to the truth (1.0 when the model is drawn at
  the person's size, whatever the depth).

    python -m upperpose.lab.proportions PRED_DIR TRUTH_DIR

reads every `PRED_DIR/NAME.json` with a `TRUTH_DIR/NAME/gt.json` and prints one row per clip
and the mean absolute deviation from 1 of each ratio.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np
import numpy.typing as npt

from upperpose.lab.pose_pairs import pairs_parser, pose_pairs

BONES = ("shoulder_width", "upper_arm", "forearm", "neck")
# JOINT_NAMES order.
_HEAD, _RS, _LS, _RE, _LE, _RH, _LH = range(7)


def bone_lengths(joints_3d: npt.ArrayLike) -> dict[str, float]:
    """The lengths of `BONES` for one frame's `(7, 3)` joints (both arms averaged)."""
    j = np.asarray(joints_3d, dtype=np.float64)

    def length(a: int, b: int) -> float:
        return float(np.linalg.norm(j[a] - j[b]))

    return {
        "shoulder_width": length(_RS, _LS),
        "upper_arm": 0.5 * (length(_RS, _RE) + length(_LS, _LE)),
        "forearm": 0.5 * (length(_RE, _RH) + length(_LE, _LH)),
        "neck": float(np.linalg.norm(j[_HEAD] - 0.5 * (j[_RS] + j[_LS]))),
    }


def compare_bones(prediction: dict[str, Any], truth: dict[str, Any]) -> dict[str, dict[str, float]] | None:
    """Metric and image ratios of the predicted to the true bone lengths (None: no common 3D frame)."""
    predicted = {f["frame"]: f.get("joints_3d") for f in prediction["frames"]}
    ratios: dict[str, list[float]] = {name: [] for name in BONES}
    depths: list[float] = []
    for frame in truth["frames"]:
        mine, true = predicted.get(frame["frame"]), frame.get("joints_3d")
        if not mine or not true:
            continue
        a, b = bone_lengths(mine), bone_lengths(true)
        for name in BONES:
            ratios[name].append(a[name] / b[name])
        shoulders = np.asarray(mine, dtype=np.float64)[[_RS, _LS], 2].mean()
        depths.append(float(shoulders / np.asarray(true, dtype=np.float64)[[_RS, _LS], 2].mean()))
    if not depths:
        return None
    depth = float(np.median(depths))
    metric = {name: float(np.median(values)) for name, values in ratios.items()}
    return {
        "metric": metric,
        "image": {name: value / depth for name, value in metric.items()},
        "depth": {"ratio": depth},
    }


def main(argv: list[str] | None = None) -> int:
    """Prints the ratios of every clip of a folder of pose files; 1 when none could be compared."""
    args = pairs_parser("python -m upperpose.lab.proportions", __doc__.split("\n")[0]).parse_args(argv)
    rows = []
    print(
        f"{'clip':28s} {'depth':>6s}  metric: "
        + " ".join(f"{b[:8]:>8s}" for b in BONES)
        + "  image: "
        + " ".join(f"{b[:8]:>8s}" for b in BONES)
    )
    for name, prediction, truth in pose_pairs(args.predictions, args.truth):
        result = compare_bones(prediction, truth)
        if result is None:
            print(f"{name:28s} no frame with 3D joints in both")
            continue
        rows.append(result)
        metric = " ".join(f"{result['metric'][b]:8.2f}" for b in BONES)
        image = " ".join(f"{result['image'][b]:8.2f}" for b in BONES)
        print(f"{name:28s} {result['depth']['ratio']:6.2f}          {metric}         {image}")
    if not rows:
        print("no clip with both a pose file and a truth", file=sys.stderr)
        return 1
    for kind in ("metric", "image"):
        spread = " ".join(f"{b}: {np.mean([abs(r[kind][b] - 1.0) for r in rows]):.3f}" for b in BONES)
        print(f"mean |ratio - 1|, {kind}: {spread}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
