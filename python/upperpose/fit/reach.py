"""Arm poses that put a hand on an image point: seeds for re-finding an arm from its hand.

The search follows an arm inside trajectory windows, so an arm it has put in the wrong place
(folded onto the face while the real one hangs, left behind by a fast swing) stays there as
long as the cost near the wrong pose is lower than anywhere the windows reach. The hand's skin
blob usually still shows where the hand is. `ArmReach` tabulates, once per body, where the
hand and elbow of each arm lie for a grid of arm angles over their anatomical ranges (in the
torso's frame, so the table holds for every torso pose and root); `candidates` returns the
arm angles whose hand projects nearest a given pixel, spread over distinct elbow positions,
so both the forward and the backward solution of the foreshortened arm and several swivels of
the elbow are tried. The tracker scores them with the ordinary cost and searches around the
best (docs/tracker.md).
"""

from __future__ import annotations

import itertools

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.features.points import PART_AREAS, far_end, principal_direction, unit
from upperpose.fit.recovery import HAND_JOINT, HAND_POINT
from upperpose.model import BodyModel, Camera, model_points, penetrates, project, skeleton

FloatArray = npt.NDArray[np.float64]
# Per arm: the slice of its searched angles (y_up, x_up, z_up, x_down) in the pose, and its
# elbow and hand indices in JOINT_NAMES order.
ARM_ANGLES = {"right_arm": slice(3, 7), "left_arm": slice(8, 12)}
ARM_JOINTS = {"right_arm": (3, 5), "left_arm": (4, 6)}
# The grid over y_up, x_up, z_up, x_down (radians), inside the anatomical ranges. Humeral
# rotation is sampled coarsely: it matters only with the elbow bent.
GRID = (
    np.array([-1.2, -0.6, 0.0, 0.6, 1.2]),
    np.linspace(-0.6, 3.0, 10),
    np.linspace(-0.2, 3.0, 9),
    np.linspace(0.0, 2.5, 6),
)


class ArmReach:
    """Where each arm's elbow and hand lie for a grid of arm angles, in the torso's frame.

    Args:
        body: the person's body; the table is made for it (make a new one when it changes).

    Attributes:
        angles: `(N, 4)` y_up, x_up, z_up, x_down of each grid pose that does not pass through
            the torso (the same grid serves both arms: the left arm mirrors the right).
        elbows, hands: per arm, `(N, 3)` elbow and hand (the forearm cone's end, which the
            hand's skin point measures) relative to the root, torso angles zero.
    """

    def __init__(self, body: BodyModel) -> None:
        self.body = body
        rows, elbows, hands = [], [], []
        pose = np.zeros(13)
        origin = np.zeros(3)
        # The rule is checked against the torso with the other arm held out sideways, out of
        # the way (arms passing each other are the search's business); by symmetry one check
        # serves both arms.
        alone = np.zeros(13)
        alone[ARM_ANGLES["left_arm"]] = (0.0, 0.0, 1.57, 0.0)
        for combo in itertools.product(*GRID):
            alone[ARM_ANGLES["right_arm"]] = combo
            if penetrates(alone, origin, body):
                continue
            pose[ARM_ANGLES["right_arm"]] = combo
            pose[ARM_ANGLES["left_arm"]] = combo
            points = model_points(pose, origin, body)
            rows.append(combo)
            elbows.append(points[[3, 4]])
            hands.append(points[[5, 6]])
        self.angles = np.array(rows, dtype=np.float64)
        elbow_table, hand_table = np.array(elbows), np.array(hands)
        self.elbows = {"right_arm": elbow_table[:, 0], "left_arm": elbow_table[:, 1]}
        self.hands = {"right_arm": hand_table[:, 0], "left_arm": hand_table[:, 1]}

    def candidates(
        self,
        arm: str,
        pose: npt.ArrayLike,
        root: npt.ArrayLike,
        camera: Camera,
        target: npt.ArrayLike,
        count: int,
        tolerance_px: float,
        elbow_spread_px: float,
        near_elbow: npt.ArrayLike | None = None,
    ) -> list[FloatArray]:
        """Up to `count` full poses: `pose` with `arm` moved so its hand lies near `target`.

        The grid poses whose hand projects within `tolerance_px` of `target` (pixels), nearest
        first, each kept only when its elbow projects at least `elbow_spread_px` from the
        elbows already kept. With `near_elbow` (pixels), the first pose returned is the one of
        those whose elbow projects nearest it (the elbow kept where it is, the hand moved),
        whatever its hand's rank. The other angles of `pose` (torso, other arm, forearm
        twist) stay.
        """
        base = np.asarray(pose, dtype=np.float64)
        origin = np.asarray(root, dtype=np.float64)
        rotation = skeleton(base, origin, self.body)["torso"]
        hands = project(camera, origin + self.hands[arm] @ rotation.T)
        gaps = np.hypot(*(hands - np.asarray(target, dtype=np.float64)).T)
        gaps[~np.isfinite(gaps)] = np.inf
        order = np.argsort(gaps, kind="stable")
        order = order[gaps[order] <= tolerance_px]
        if order.size == 0:
            return []
        elbows = project(camera, origin + self.elbows[arm][order] @ rotation.T)
        kept: list[int] = []
        if near_elbow is not None and count > 0:
            to_elbow = np.hypot(*(elbows - np.asarray(near_elbow, dtype=np.float64)).T)
            to_elbow[~np.isfinite(to_elbow)] = np.inf
            if np.isfinite(to_elbow).any():
                kept.append(int(np.argmin(to_elbow)))
        for i in range(order.size):
            if len(kept) == count:
                break
            if i not in kept and all(np.hypot(*(elbows[i] - elbows[j])) >= elbow_spread_px for j in kept):
                kept.append(i)
        out = []
        for i in kept:
            candidate = base.copy()
            candidate[ARM_ANGLES[arm]] = self.angles[order[i]]
            out.append(candidate)
        return out


def hand_target(
    features: FrameFeatures,
    arm: str,
    model_2d: npt.ArrayLike,
    hand_length: float = 0.5,
    min_on_person: float = 0.5,
    min_head_share: float = 0.25,
) -> FloatArray | None:
    """Where the image shows `arm`'s hand, pixels; None when it shows nothing usable.

    Its matched skin point when the matching gave it a blob of its own. A hand without a blob,
    or whose blob it shares with another part (the matching, which follows the model, may have
    put it on the face while the real hand shows elsewhere), takes the skin blob no part holds
    that lies nearest the model's hand (the real hand's blob is outside the matching gate
    exactly when the model is far off); its point is the blob's far end from the arm's
    shoulder, `hand_length` shoulder widths long, as the matching measures hands. A shared
    blob and no free one give no target (the blob does not say where the hand is in it).
    Only blobs with at least `min_on_person` of their pixels in the silhouette count, and of
    at least `min_head_share` of the head's blob (of the head's expected area, `PART_AREAS`,
    while the head has no blob of its own): a scrap of skin at the elbow or a skin-coloured
    fleck on the clothes is no hand, and the matching sometimes hands one to a hand.

    Args:
        features: the frame's features.
        arm: "right_arm" or "left_arm".
        model_2d: `(7, 2)` the fitted model points in pixels (`model_points` projected).
        hand_length: the far end's length, in shoulder widths.
        min_on_person: the share of a free blob's pixels that must lie in the silhouette.
        min_head_share: a hand's blob must be at least this share of the head's blob.
    """
    points = np.asarray(model_2d, dtype=np.float64)
    shoulder_px = float(np.hypot(*(points[1] - points[2])))
    head = features.points[0]
    head_area = PART_AREAS[0] * shoulder_px**2 if head is None or head.merged else features.blobs[head.blob].area
    floor = min_head_share * head_area
    point = features.points[HAND_POINT[arm]]
    if point is not None and not point.merged:
        if features.blobs[point.blob].area < floor:
            return None
        return np.asarray(point.xy, dtype=np.float64)
    held = {p.blob for p in features.points if p is not None}
    # A blob off the person (a skin-coloured object in the room) is no hand.
    free = [
        blob
        for i, blob in enumerate(features.blobs)
        if i not in held
        and blob.area >= floor
        and np.count_nonzero(features.sil[blob.ys, blob.xs]) >= min_on_person * blob.area
    ]
    hand = points[HAND_JOINT[arm]]
    if not free or not np.all(np.isfinite(hand)):
        return None
    blob = min(free, key=lambda b: b.distance_to(hand))
    shoulder = points[1 if arm == "right_arm" else 2]
    outward = unit(np.subtract(blob.centroid, shoulder))
    if outward is None:
        return np.asarray(blob.centroid, dtype=np.float64)
    axis = principal_direction(blob)
    direction = outward if axis is None else (axis if float(axis @ outward) >= 0 else -axis)
    return np.asarray(far_end(blob, direction, hand_length * shoulder_px), dtype=np.float64)


def shared_blob_ends(features: FrameFeatures, model_2d: npt.ArrayLike, hand_length: float = 0.5) -> list[FloatArray]:
    """The two ends of a skin blob both hands share and the head does not, pixels; [] otherwise.

    Forearms crossed or held side by side make one blob whose hand points say nothing of where
    the hands are in it; its ends along its long axis (`hand_length` shoulder widths long, as
    the matching measures hands) are where hands can be. [] when the blob is not elongated.
    """
    head, right, left = features.points
    if right is None or left is None or right.blob != left.blob or (head is not None and head.blob == right.blob):
        return []
    blob = features.blobs[right.blob]
    axis = principal_direction(blob)
    if axis is None:
        return []
    points = np.asarray(model_2d, dtype=np.float64)
    length = hand_length * float(np.hypot(*(points[1] - points[2])))
    return [np.asarray(far_end(blob, direction, length), dtype=np.float64) for direction in (axis, -axis)]


def unexplained(model_2d: npt.ArrayLike, target: npt.ArrayLike, radius_px: float) -> bool:
    """Whether neither fitted hand (`model_2d`, pixels) lies within `radius_px` of an arm's target.

    A target near the arm's own hand needs no reaching; one near the other hand may be that
    hand's (touching hands share a blob, and its far end can be either), so it is no evidence
    against this arm.
    """
    hands = np.asarray(model_2d, dtype=np.float64)[list(HAND_JOINT.values())]
    gaps = np.hypot(*(hands - np.asarray(target, dtype=np.float64)).T)
    return bool(np.all(gaps > radius_px))


__all__ = ["ARM_ANGLES", "ARM_JOINTS", "GRID", "ArmReach", "hand_target", "shared_blob_ends", "unexplained"]
