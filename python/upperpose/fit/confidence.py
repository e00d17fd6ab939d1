"""Per-joint confidence in [0, 1]: how far this frame's image evidence supports each joint.

A hand is supported by its own skin blob: its confidence falls with the distance between the
fitted hand and the blob's point, `exp(-(gap / (GAP_SCALE x shoulder width))^2)`; a hand whose
blob is merged with another part's, or without any skin (sleeves, gloves), gets
`UNSUPPORTED`, and a lost arm `LOST` for its elbow and hand. The head is supported by the
head's skin blob in the same way. An elbow has no evidence of its own: it is as sure as its
hand, capped at `ELBOW_CAP`. Shoulders follow from the torso's fit to the silhouette:
`SHOULDER`. A joint outside the image is 0. The constants are calibrated on the external
validation set (docs/RESULTS.md, "Confidence"): a joint of confidence >= 0.5 should be within
10 pixels of the truth at least 90 % of the time.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.features.frame import POINT_FOUND
from upperpose.fit.recovery import ARMS, HAND_JOINT, HAND_POINT, hand_distances

FloatArray = npt.NDArray[np.float64]
GAP_SCALE = 0.25
UNSUPPORTED = 0.4
LOST = 0.05
ELBOW_CAP = 0.8
SHOULDER = 0.8
HEAD_JOINT = 0
ELBOW_JOINT = {"right_arm": 3, "left_arm": 4}


def support(gap_px: float | None, shoulder_px: float) -> float:
    """Confidence from the gap between a fitted point and its skin evidence (None: no evidence)."""
    if gap_px is None or not np.isfinite(gap_px) or shoulder_px <= 0:
        return UNSUPPORTED
    return float(np.exp(-((gap_px / (GAP_SCALE * shoulder_px)) ** 2)))


def joint_confidence(
    joints_2d: FloatArray,
    model_2d: FloatArray,
    features: FrameFeatures,
    lost_parts: tuple[str, ...],
    size: tuple[int, int],
) -> FloatArray:
    """Confidence of the seven reported joints (JOINT_NAMES order).

    Args:
        joints_2d: the reported (anatomical) joints, pixels.
        model_2d: the model points the image's skin points measure, pixels.
        features: this frame's features (skin points).
        lost_parts: the arms that are lost.
        size: the image's (height, width).
    """
    shoulder_px = float(np.hypot(*(model_2d[1] - model_2d[2])))
    out = np.full(7, SHOULDER)
    head = features.head
    head_gap = None if head is None or head.merged else float(np.hypot(*(np.asarray(head.xy) - model_2d[0])))
    out[HEAD_JOINT] = support(head_gap, shoulder_px)
    gaps = hand_distances(model_2d, features)
    points = features.point_status()
    for arm in ARMS:
        hand, elbow = HAND_JOINT[arm], ELBOW_JOINT[arm]
        if arm in lost_parts:
            out[hand] = out[elbow] = LOST
            continue
        # A gap to the nearest free blob (no matched point) is a sign of trouble, not support.
        matched = points[HAND_POINT[arm]] == POINT_FOUND
        out[hand] = support(gaps[arm], shoulder_px) if matched else UNSUPPORTED
        out[elbow] = min(out[hand], ELBOW_CAP)
    height, width = size
    outside = ~(
        np.isfinite(joints_2d).all(axis=1)
        & (joints_2d[:, 0] >= -0.5)
        & (joints_2d[:, 0] <= width - 0.5)
        & (joints_2d[:, 1] >= -0.5)
        & (joints_2d[:, 1] <= height - 0.5)
    )
    out[outside] = 0.0
    return out


__all__ = ["ELBOW_CAP", "GAP_SCALE", "LOST", "SHOULDER", "UNSUPPORTED", "joint_confidence", "support"]
