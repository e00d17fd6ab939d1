"""Per-joint confidence in [0, 1]: the chance that the written joint is within 10 pixels of the truth.

Each joint falls in one group by its evidence, and the group's number is the share of such joints
found within 10 px of the truth on the external validation set (docs/RESULTS.md, "Confidence"),
taken conservatively: the 10th percentile over resamplings of the clips, since the clips differ
far more than the frames of one clip do.

The evidence, per joint:
- head: the gap between the model's head point and the head's own skin blob, in shoulder widths
  (no blob of its own, or merged with a hand: one number);
- hand: the gap to its own skin blob, and whether its arm is *settled*: its hand moved less than
  `JUMP_LIMIT` shoulder widths since the last frame, less than `EXCESS_LIMIT` arm areas of
  silhouette beside it are unexplained, and it has been neither lost nor moved by a recovery
  (lost-arm search, reach, untangling) for `SETTLE_FRAMES` frames. A hand merged with another
  part, one that shows no skin (sleeves) and a lost one get one number each;
- elbow: its hand's evidence (the elbow has none of its own);
- shoulder: one number (the torso fit gives nothing that separates good from bad shoulders).
A joint outside the image is 0.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.features.frame import POINT_FOUND, POINT_MERGED
from upperpose.fit.recovery import ARMS, HAND_JOINT, HAND_POINT
from upperpose.fit.visibility import inside_image

FloatArray = npt.NDArray[np.float64]
Table = tuple[tuple[float, float], ...]  # (gap up to, shoulder widths; share), nearest first

SETTLE_FRAMES = 10
JUMP_LIMIT = 0.15
EXCESS_LIMIT = 0.2
HEAD_JOINT = 0
ELBOW_JOINT = {"right_arm": 3, "left_arm": 4}

# Shares measured on the validation set, seed 0: the 10th percentile over resamplings of the clips.
TABLES: dict[str, Table] = {
    "head": ((0.05, 0.97), (0.1, 0.91), (0.15, 0.85), (math.inf, 0.29)),
    "hand_settled": ((0.05, 0.87), (0.08, 0.81), (0.1, 0.76), (0.15, 0.45), (0.2, 0.17), (0.3, 0.05), (math.inf, 0.03)),
    "hand_unsettled": ((0.1, 0.41), (0.15, 0.24), (0.2, 0.07), (0.3, 0.05), (math.inf, 0.02)),
    "elbow_settled": ((0.15, 0.45), (math.inf, 0.25)),
    "elbow_unsettled": ((0.1, 0.46), (0.3, 0.31), (math.inf, 0.15)),
}
FIXED: dict[str, float] = {
    "head_unsupported": 0.23,
    "shoulder": 0.34,
    "hand_merged": 0.13,
    "hand_no_skin": 0.0,
    "hand_lost": 0.07,
    "elbow_merged": 0.15,
    "elbow_no_skin": 0.0,
    "elbow_lost": 0.23,
    "outside": 0.0,
}


def lookup(table: Table, gap: float) -> float:
    """The share of the first row whose gap reaches `gap`."""
    return next(s for upto, s in table if gap < upto)


def group_share(group: str, gap: float | None) -> float:
    """A group's share: from its table by `gap` (shoulder widths), or its one number."""
    if group in TABLES:
        if gap is None:
            raise ValueError(f"confidence group {group!r} needs a gap")
        return lookup(TABLES[group], gap)
    return FIXED[group]


class JointConfidence:
    """Groups each frame's joints by their evidence and gives each its group's share.

    Keeps per arm the frames since it was last lost or moved by a recovery, and last frame's
    hands; `reset` when the person is gone.
    """

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forgets the history: the next frame's arms count as settled for as long as possible."""
        self._since = dict.fromkeys(ARMS, SETTLE_FRAMES)
        self._hands: FloatArray | None = None

    def groups(
        self,
        joints_2d: FloatArray,
        model_2d: FloatArray,
        features: FrameFeatures,
        gaps: dict[str, float | None],
        lost_parts: tuple[str, ...],
        moved: tuple[str, ...],
        excess: dict[str, float],
        size: tuple[int, int],
    ) -> list[tuple[str, float | None]]:
        """Each joint's group and gap in shoulder widths (None where the group has no table).

        Args:
            joints_2d: the reported (anatomical) joints, pixels.
            model_2d: the model points the image's skin points measure, pixels.
            features: this frame's features (skin points).
            gaps: each hand's `recovery.hand_distances` from `model_2d`.
            lost_parts: the arms that are lost.
            moved: the arms a recovery (lost-arm search, reach, untangling) moved this frame.
            excess: per arm, the unexplained silhouette on its side beyond the usual, in arm areas.
            size: the image's (height, width).
        """
        shoulder_px = max(float(np.hypot(*(model_2d[1] - model_2d[2]))), 1.0)
        jumps = (
            {a: float(np.hypot(*(model_2d[HAND_JOINT[a]] - self._hands[HAND_JOINT[a]]))) / shoulder_px for a in ARMS}
            if self._hands is not None
            else dict.fromkeys(ARMS, 0.0)
        )
        self._hands = model_2d.copy()
        out: list[tuple[str, float | None]] = [("shoulder", None)] * 7
        head = features.head
        if head is None or head.merged:
            out[HEAD_JOINT] = ("head_unsupported", None)
        else:
            out[HEAD_JOINT] = ("head", float(np.hypot(*(np.asarray(head.xy) - model_2d[0]))) / shoulder_px)
        status = features.point_status()
        for arm in ARMS:
            hand, elbow = HAND_JOINT[arm], ELBOW_JOINT[arm]
            self._since[arm] = 0 if arm in lost_parts or arm in moved else self._since[arm] + 1
            gap = gaps.get(arm)
            if arm in lost_parts:
                kind, rel = "lost", None
            elif status[HAND_POINT[arm]] == POINT_MERGED:
                kind, rel = "merged", None
            elif status[HAND_POINT[arm]] != POINT_FOUND or gap is None:
                # No blob matched: a gap to the nearest free blob is a sign of trouble, not support.
                kind, rel = "no_skin", None
            else:
                settled = self._since[arm] >= SETTLE_FRAMES and jumps[arm] < JUMP_LIMIT and excess[arm] < EXCESS_LIMIT
                kind, rel = ("settled" if settled else "unsettled"), gap / shoulder_px
            out[hand], out[elbow] = (f"hand_{kind}", rel), (f"elbow_{kind}", rel)
        for j in np.flatnonzero(~inside_image(joints_2d, size)):
            out[j] = ("outside", None)
        return out


def shares(found: list[tuple[str, float | None]]) -> FloatArray:
    """Confidence of the seven reported joints from their groups and gaps (`JointConfidence.groups`)."""
    return np.array([group_share(group, gap) for group, gap in found])


__all__ = [
    "EXCESS_LIMIT",
    "FIXED",
    "JUMP_LIMIT",
    "SETTLE_FRAMES",
    "TABLES",
    "JointConfidence",
    "group_share",
    "lookup",
    "shares",
]
