"""Lost tracking and recovery (thesis §3.4.9, SPEC 5).

A hand is lost when its model point stays farther than `threshold` shoulder widths (pixels) from
its matched skin point for `frames` frames in a row. The check pauses while the hand's blob is
merged with another part or absent (no evidence either way). A lost arm is searched over its
anatomical ranges until its hand is near its skin point again. Meanwhile the hand is followed by
mean shift on the skin image (the thesis follows each arm by mean shift between frames); its
position is the hand's predicted point for the next frame's blob matching, so that the skin term
pulls the searched arm back onto the hand. The follower is kept off the face, and a followed
hand merged with the face is put at the follower's point (`hands_on_followed_points`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures, SkinPoint

ARMS = ("right_arm", "left_arm")
HAND_JOINT = {"right_arm": 5, "left_arm": 6}
HAND_POINT = {"right_arm": 1, "left_arm": 2}  # index in FrameFeatures.points_array()
_FOUND, _MERGED = 1, 2


def hand_distances(joints_2d: npt.NDArray[np.float64], features: FrameFeatures) -> dict[str, float | None]:
    """Pixels from each fitted hand to its skin evidence (None: no evidence this frame).

    A matched hand point gives the distance to it. A merged hand gives no evidence. A hand
    without a blob within the matching gate is compared with the nearest skin blob that no
    other part holds: when the model's hand is far from the real one, the real hand's blob lies
    outside the gate and would otherwise never count as a miss.
    """
    points, status = features.points_array(), features.point_status()
    held = {p.blob for p in features.points if p is not None}
    out: dict[str, float | None] = {}
    for arm in ARMS:
        k, hand = HAND_POINT[arm], joints_2d[HAND_JOINT[arm]]
        if status[k] == _FOUND and np.all(np.isfinite(points[k])):
            out[arm] = float(np.hypot(*(hand - points[k])))
        elif status[k] == _MERGED or not np.all(np.isfinite(hand)):
            out[arm] = None
        else:
            free = [b.distance_to(hand) for i, b in enumerate(features.blobs) if i not in held]
            out[arm] = min(free) if free else None
    return out


def far_hands(
    joints_2d: npt.NDArray[np.float64], distances: dict[str, float | None], share: float
) -> dict[str, bool | None]:
    """Per arm: is the fitted hand farther than `share` shoulder widths from its skin evidence?

    None where there is no evidence (`hand_distances` gave None or not a number). The shoulder
    width comes from the fitted `joints_2d`, at least 10 px.
    """
    limit = share * max(float(np.hypot(*(joints_2d[1] - joints_2d[2]))), 10.0)
    out: dict[str, bool | None] = {}
    for arm in ARMS:
        distance = distances.get(arm)
        out[arm] = None if distance is None or not np.isfinite(distance) else bool(distance > limit)
    return out


@dataclass
class LostDetector:
    """Per-arm lost state from the distance between fitted and measured hands.

    Args:
        threshold: distance in shoulder widths beyond which a frame counts as a miss.
        frames: consecutive misses that make an arm lost.
    """

    threshold: float = 1.0
    frames: int = 5
    misses: dict[str, int] = field(default_factory=lambda: dict.fromkeys(ARMS, 0))
    lost: dict[str, bool] = field(default_factory=lambda: dict.fromkeys(ARMS, False))

    def update(
        self,
        joints_2d: npt.NDArray[np.float64],
        distances: dict[str, float | None],
        missing: dict[str, bool] | None = None,
    ) -> dict[str, bool]:
        """Feeds one fitted frame.

        Args:
            joints_2d: `(7, 2)` fitted joints, pixels (for the shoulder width).
            distances: arm -> pixels from the fitted hand to its skin evidence, None when there
                is none (hand blob merged, or no skin blob to compare with): the check pauses.
            missing: arm -> a limb-sized part of the silhouette on that arm's side is not
                explained by the model (`unexplained_by_side`); counts as a miss.

        Returns:
            arm name -> lost.
        """
        flags = far_hands(joints_2d, distances, self.threshold)
        for arm in ARMS:
            far = flags[arm]
            if missing is not None and missing.get(arm):
                far = True
            elif far is None:
                continue
            if far:
                self.misses[arm] += 1
                if self.misses[arm] >= self.frames:
                    self.lost[arm] = True
            else:
                self.misses[arm] = 0
                self.lost[arm] = False
        return dict(self.lost)

    def force_lost(self, arm: str) -> None:
        """Marks an arm lost (tests, or a caller with outside knowledge)."""
        self.lost[arm] = True
        self.misses[arm] = self.frames

    def reset(self) -> None:
        """Forgets everything (a new person)."""
        self.misses = dict.fromkeys(ARMS, 0)
        self.lost = dict.fromkeys(ARMS, False)


@dataclass
class DoubtDetector:
    """Arms whose fitted hand stays off its skin evidence, though not far enough to be lost.

    An arm is *doubted* after `frames` frames in a row with its hand farther than `share`
    shoulder widths from its skin evidence (`hand_distances`; a frame without evidence breaks
    the run). A doubted arm gets one search over its anatomical ranges (`take_doubted`), then
    its count starts again. `frames` 0 turns this off.
    """

    share: float = 0.25
    frames: int = 3
    counts: dict[str, int] = field(default_factory=lambda: dict.fromkeys(ARMS, 0))

    def update(self, joints_2d: npt.NDArray[np.float64], distances: dict[str, float | None]) -> None:
        """Feeds one fitted frame (`joints_2d` for the shoulder width, as `LostDetector.update`)."""
        flags = far_hands(joints_2d, distances, self.share)
        for arm in ARMS:
            self.counts[arm] = self.counts[arm] + 1 if flags[arm] else 0

    def take_doubted(self, skip: list[str]) -> list[str]:
        """The doubted arms not in `skip` (lost arms are searched anyway); their counts restart."""
        if self.frames <= 0:
            return []
        doubted = [arm for arm in ARMS if arm not in skip and self.counts[arm] >= self.frames]
        for arm in doubted:
            self.counts[arm] = 0
        return doubted

    def reset(self) -> None:
        """Forgets everything (a new person)."""
        self.counts = dict.fromkeys(ARMS, 0)


def unexplained_by_side(
    silhouette: npt.NDArray[np.uint8], labels: npt.NDArray[np.uint8], neck_x: float, margin: int = 15
) -> dict[str, int]:
    """Silhouette pixels the fitted model does not explain, on each arm's side of the neck.

    Pixels of I_sil farther than `margin` / 2 pixels from the model's projection, above the
    model's lowest row (legs below the torso are not modelled). A whole limb the model has
    put elsewhere shows up here even when its skin point cannot be matched (an arm raised
    overhead while the model's arm hangs down). "right_arm" is the image's left side.
    """
    model = labels > 0
    rows = np.flatnonzero(model.any(axis=1))
    if rows.size == 0:
        return dict.fromkeys(ARMS, 0)
    bottom = int(rows[-1]) + 1
    grown = cv2.dilate(model[:bottom].view(np.uint8), np.ones((margin, margin), np.uint8))
    loose = (silhouette[:bottom] > 0) & (grown == 0)
    split = int(np.clip(round(neck_x), 0, silhouette.shape[1]))
    return {"right_arm": int(np.count_nonzero(loose[:, :split])), "left_arm": int(np.count_nonzero(loose[:, split:]))}


def hands_on_followed_points(features: FrameFeatures, followed: dict[str, npt.NDArray[np.float64]]) -> FrameFeatures:
    """`features` with each followed hand that is merged with the head put at its followed point.

    A hand merged with the face says only that it is somewhere on the face's blob, and a lost
    arm then has no point to be found again on. The follower, kept off the face
    (`HandFollower.step`), sits on the hand beside it (at the ear, on the cheek).

    Args:
        features: the frame's features.
        followed: arm -> the follower's point, pixels (`HandFollower.step`).
    """
    head = features.head

    def placed(arm: str, point: SkinPoint | None) -> SkinPoint | None:
        xy = followed.get(arm)
        if xy is None or head is None or point is None or not point.merged or point.blob != head.blob:
            return point
        return SkinPoint((float(xy[0]), float(xy[1])), False, point.blob)

    right, left = placed("right_arm", features.right_hand), placed("left_arm", features.left_hand)
    if right is features.right_hand and left is features.left_hand:
        return features
    return dataclasses.replace(features, right_hand=right, left_hand=left)


class HandFollower:
    """Mean shift of a window over the skin image, one window per lost hand.

    Args:
        window_faces: window side in shoulder widths.
        iterations: mean-shift iterations per frame.
    """

    def __init__(self, window_side: float = 0.5, iterations: int = 10) -> None:
        self.window_side = window_side
        self._criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, iterations, 1.0)
        self.windows: dict[str, tuple[int, int, int, int]] = {}

    def start(self, arm: str, xy: npt.ArrayLike, shoulder_px: float) -> None:
        """Starts following `arm`'s hand from pixel `xy`."""
        side = max(8, int(round(self.window_side * shoulder_px)))
        x, y = (float(v) for v in np.asarray(xy, dtype=np.float64))
        self.windows[arm] = (int(round(x - side / 2)), int(round(y - side / 2)), side, side)

    def stop(self, arm: str) -> None:
        """Stops following `arm`."""
        self.windows.pop(arm, None)

    def step(
        self, skin: npt.NDArray[np.uint8], face: tuple[npt.ArrayLike, float] | None = None
    ) -> dict[str, npt.NDArray[np.float64]]:
        """Moves each window to the local mode of the skin image; returns arm -> centre (x, y).

        `face`: centre (x, y) and radius in pixels of a disc left out of the skin image. A
        window that reached the face would otherwise stay on it, the largest patch of skin
        around, after the hand has moved away.
        """
        if face is not None:
            centre, radius = face
            fx, fy = (int(round(v)) for v in np.asarray(centre, dtype=np.float64))
            skin = skin.copy()
            cv2.circle(skin, (fx, fy), max(int(round(radius)), 1), 0, -1)
        height, width = skin.shape
        out = {}
        for arm, (x, y, w, h) in list(self.windows.items()):
            x = int(np.clip(x, 0, max(width - w, 0)))
            y = int(np.clip(y, 0, max(height - h, 0)))
            _, window = cv2.meanShift(skin, (x, y, w, h), self._criteria)
            self.windows[arm] = tuple(int(v) for v in window)  # type: ignore[assignment]
            wx, wy, ww, wh = self.windows[arm]
            out[arm] = np.array([wx + (ww - 1) / 2.0, wy + (wh - 1) / 2.0])
        return out

    def reset(self) -> None:
        """Stops following every hand."""
        self.windows.clear()


__all__ = [
    "ARMS",
    "HAND_JOINT",
    "HAND_POINT",
    "DoubtDetector",
    "HandFollower",
    "LostDetector",
    "far_hands",
    "hand_distances",
    "hands_on_followed_points",
    "unexplained_by_side",
]
