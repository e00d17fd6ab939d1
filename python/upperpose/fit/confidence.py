"""Per-joint confidence in [0, 1]: the chance that the joint is within 10 pixels of the truth.

The evidence is this frame's skin: a hand is supported by its own skin blob, scored by the gap
between the fitted hand and the blob's point, `support = exp(-(gap / (GAP_SCALE x shoulder
width))^2)`, and the head by the head's blob in the same way. Each kind of joint maps its
evidence to the share of such joints found within 10 pixels of the truth on the external
validation set (docs/RESULTS.md, "Confidence"): the numbers below are those measured shares. A
hand whose blob is merged with another part's, or that shows no skin (sleeves), a lost arm, and
the joints without evidence of their own (shoulders, elbows) get the share measured for them.
A joint outside the image is 0.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.features.frame import POINT_FOUND
from upperpose.fit.recovery import ARMS, HAND_JOINT, HAND_POINT

FloatArray = npt.NDArray[np.float64]
GAP_SCALE = 0.25
# (lowest support, share within 10 px), highest first.
HAND_SHARES = ((0.9, 0.78), (0.8, 0.63), (0.6, 0.33), (0.0, 0.15))
HEAD_SHARES = ((0.6, 0.95), (0.0, 0.38))
UNSUPPORTED_HAND = 0.25
HEAD_UNSUPPORTED = 0.38
SHOULDER = 0.45
ELBOW_SUPPORTED = 0.45  # an elbow whose hand sits on its blob (support >= 0.8)
ELBOW = 0.3
LOST = 0.1
HEAD_JOINT = 0
ELBOW_JOINT = {"right_arm": 3, "left_arm": 4}


def support(gap_px: float | None, shoulder_px: float) -> float | None:
    """How well a fitted point sits on its skin evidence, in [0, 1]; None without evidence."""
    if gap_px is None or not np.isfinite(gap_px) or shoulder_px <= 0:
        return None
    return float(np.exp(-((gap_px / (GAP_SCALE * shoulder_px)) ** 2)))


def share(value: float, table: tuple[tuple[float, float], ...]) -> float:
    """The measured share of the first row whose lowest support `value` reaches."""
    return next(s for low, s in table if value >= low)


def joint_confidence(
    joints_2d: FloatArray,
    model_2d: FloatArray,
    features: FrameFeatures,
    gaps: dict[str, float | None],
    lost_parts: tuple[str, ...],
    size: tuple[int, int],
) -> FloatArray:
    """Confidence of the seven reported joints (JOINT_NAMES order).

    Args:
        joints_2d: the reported (anatomical) joints, pixels.
        model_2d: the model points the image's skin points measure, pixels.
        features: this frame's features (skin points).
        gaps: each hand's `recovery.hand_distances` from `model_2d` (the tracker has them).
        lost_parts: the arms that are lost.
        size: the image's (height, width).
    """
    shoulder_px = float(np.hypot(*(model_2d[1] - model_2d[2])))
    out = np.full(7, SHOULDER)
    head = features.head
    head_gap = None if head is None or head.merged else float(np.hypot(*(np.asarray(head.xy) - model_2d[0])))
    head_support = support(head_gap, shoulder_px)
    out[HEAD_JOINT] = HEAD_UNSUPPORTED if head_support is None else share(head_support, HEAD_SHARES)
    points = features.point_status()
    for arm in ARMS:
        hand, elbow = HAND_JOINT[arm], ELBOW_JOINT[arm]
        if arm in lost_parts:
            out[hand] = out[elbow] = LOST
            continue
        # A gap to the nearest free blob (no matched point) is a sign of trouble, not support.
        hand_support = support(gaps[arm], shoulder_px) if points[HAND_POINT[arm]] == POINT_FOUND else None
        out[hand] = UNSUPPORTED_HAND if hand_support is None else share(hand_support, HAND_SHARES)
        out[elbow] = ELBOW_SUPPORTED if hand_support is not None and hand_support >= 0.8 else ELBOW
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


__all__ = ["GAP_SCALE", "LOST", "SHOULDER", "UNSUPPORTED_HAND", "joint_confidence", "share", "support"]
