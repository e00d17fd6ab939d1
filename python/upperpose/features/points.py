"""Head and hand points from the skin blobs (SPEC 4).

With a prediction (the tracker's joints from the previous frame) each of head, right hand and
left hand is matched to a blob within a gate around its predicted position, a distinct one
unless sharing one costs less (`assign`); a part whose only blob within the gate is taken by
another part shares it too. Parts that share a blob are reported merged and carry no measured
point. A hand's point is the centroid of the far end of its blob along the forearm (predicted
elbow to predicted hand), one hand length long, so that a blob that covers a bare forearm still
gives the hand; along the blob's own long axis instead when that axis points away from both the
predicted elbow and shoulder (`hand_direction`). The head's point is the centre of the largest
disc inside its blob's convex hull, searched in the top head length along the neck-to-head
direction (the head at its widest, with or without the hair; drops a bare neck and chest).

Without a prediction (start-up) the three largest blobs are taken: the topmost is the head,
the others hands by their side of it (image left = the subject's right hand).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.blobs import SkinBlob
from upperpose.features.config import FeatureConfig

POINT_NAMES = ("head", "right_hand", "left_hand")
# What `assign` returns: blob index or None per part, merged flag per part.
Matching = tuple[list[int | None], list[bool]]
# Head (face, with or without the hair) and hand areas in squared shoulder widths: a head about
# 0.4 x 0.6 of a shoulder width, an ellipse; a hand with fingers about 0.5 x 0.2.
PART_AREAS = (0.2, 0.1, 0.1)
# (x0, y0, x1, y1) in pixels: where a part may be when its skin gives no point.
PixelBox = tuple[float, float, float, float]
# Indices into JOINT_NAMES.
HEAD, RIGHT_SHOULDER, LEFT_SHOULDER, RIGHT_ELBOW, LEFT_ELBOW, RIGHT_HAND, LEFT_HAND = range(7)


@dataclass(frozen=True)
class SkinPoint:
    """A head or hand located on a skin blob.

    Attributes:
        xy: (x, y) in pixels. For a merged point this is the merged blob's centroid, a hint
            for drawing only, not a measurement of the part.
        merged: the blob also holds another part (hand on face, hands together), or a hand's
            end is cut by the image's border; the cost must not use `xy`, only the box
            (`FrameFeatures.merged_boxes_array`).
        blob: index of the blob in `FrameFeatures.blobs`.
        box: for a hand merged with the head, (x0, y0, x1, y1) of the blob's pixels clear of the
            predicted head, where the hand can be; for a hand cut by the border, its far end's
            box stretched beyond the border (`beyond_border`); None: anywhere in the blob.
    """

    xy: tuple[float, float]
    merged: bool
    blob: int
    box: PixelBox | None = None


def unit(vector: npt.NDArray[np.float64]) -> npt.NDArray[np.float64] | None:
    """`vector` scaled to length one, or None when it is (nearly) zero or not finite."""
    norm = float(np.hypot(vector[0], vector[1]))
    return vector / norm if np.isfinite(norm) and norm > 1e-6 else None


def far_end_pixels(
    blob: SkinBlob, direction: npt.NDArray[np.float64], length: float
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """The blob's pixels (x, y) within `length` pixels of its far end along `direction`."""
    t = blob.xs * direction[0] + blob.ys * direction[1]
    keep = t >= t.max() - length
    return blob.xs[keep], blob.ys[keep]


def far_end(blob: SkinBlob, direction: npt.NDArray[np.float64], length: float) -> tuple[float, float]:
    """Centroid of the blob's pixels within `length` pixels of its far end along `direction`."""
    xs, ys = far_end_pixels(blob, direction, length)
    return float(xs.mean()), float(ys.mean())


def beyond_border(
    xs: npt.NDArray[np.int64], ys: npt.NDArray[np.int64], size: tuple[int, int], reach: float
) -> PixelBox | None:
    """Where a hand whose far end (pixels `xs`, `ys`) touches the image's border may lie, or None.

    A hand cut by the border (raised out of the frame) has its visible end on the border, not
    at the hand: the box is the far end's bounding box, widened by `reach` pixels along each
    border it touches and stretched a frame's size beyond it.
    """
    height, width = size
    x0, y0, x1, y1 = float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())
    left, top, right, bottom = x0 <= 1, y0 <= 1, x1 >= width - 2, y1 >= height - 2
    if not (left or top or right or bottom):
        return None
    if top or bottom:
        x0, x1 = x0 - reach, x1 + reach
    if left or right:
        y0, y1 = y0 - reach, y1 + reach
    return (
        x0 - width if left else x0,
        y0 - height if top else y0,
        x1 + width if right else x1,
        y1 + height if bottom else y1,
    )


def beyond_image(xy: npt.NDArray[np.float64], size: tuple[int, int]) -> PixelBox | None:
    """Where a hand predicted at `xy` outside the image, with no skin of its own in it, may lie; or None.

    A hand that left the frame shows nothing, and nothing else says where it is: the box is the
    band a frame's size deep beyond the border the prediction is farthest past, a frame's size
    wider than the image on either side, so that the fit keeps the hand out of the image until
    its skin comes back. None when `xy` is in the image (pixel centres at integers) or not finite.
    """
    height, width = size
    x, y = float(xy[0]), float(xy[1])
    if not (math.isfinite(x) and math.isfinite(y)):
        return None
    past = {"left": -0.5 - x, "top": -0.5 - y, "right": x - (width - 0.5), "bottom": y - (height - 0.5)}
    side, depth = max(past.items(), key=lambda kv: kv[1])
    if depth <= 0:
        return None
    x0, y0, x1, y1 = -0.5 - width, -0.5 - height, width - 0.5 + width, height - 0.5 + height
    if side == "left":
        x1 = -0.5
    elif side == "right":
        x0 = width - 0.5
    elif side == "top":
        y1 = -0.5
    else:
        y0 = height - 0.5
    return (x0, y0, x1, y1)


def head_centre(blob: SkinBlob, direction: npt.NDArray[np.float64], length: float) -> tuple[float, float]:
    """Centre of the largest disc inside the blob's convex hull, within its top `length` pixels.

    The head at its widest, whether the hair passed the skin rule (the blob is the whole head) or
    not (the face alone): the centroid of the top of the blob moved with the hairline. The hull
    fills a face partly lost to shade; the search stays in the top of the blob along `direction`
    so that a wider bare chest or shoulders cannot win. Pixels within a pixel of the largest
    radius are averaged: an oval face has a ridge of nearly equal radii along its long axis.
    """
    x, y, w, h = blob.bbox
    region = np.zeros((h + 2, w + 2), np.uint8)  # a 1 px border: the outline is inside
    cv2.fillConvexPoly(region, cv2.convexHull(blob.contour) - (x - 1, y - 1), 255)
    radius = cv2.distanceTransform(region, cv2.DIST_L2, 5)
    ys, xs = np.nonzero(region)
    t = (xs + x - 1) * direction[0] + (ys + y - 1) * direction[1]
    r = np.where(t >= t.max() - length, radius[ys, xs], 0.0)
    keep = r >= r.max() - 1.0
    return float(xs[keep].mean() + x - 1), float(ys[keep].mean() + y - 1)


def principal_direction(blob: SkinBlob) -> npt.NDArray[np.float64] | None:
    """The blob's long axis when it is clearly elongated (eigenvalue ratio > 2.25), else None."""
    if blob.area < 3:
        return None
    cov = np.cov(np.vstack([blob.xs, blob.ys]).astype(np.float64))
    values, vectors = np.linalg.eigh(cov)
    if values[0] <= 0 or values[1] / values[0] > 2.25:
        return np.asarray(vectors[:, 1], dtype=np.float64)
    return None


def assign(
    blobs: list[SkinBlob],
    targets: list[npt.NDArray[np.float64] | None],
    gate: float,
    weights: list[float] | None = None,
    min_areas: list[float] | None = None,
    share_cost: float = math.inf,
) -> Matching:
    """Matches each target position to a blob within `gate`, minimising total distance.

    Each target's distance is weighed by `weights` (default 1); a target only takes blobs of at
    least its `min_areas` pixels (default any). Targets may share a blob at `share_cost` pixels
    per extra holder (default: only distinct blobs), so that a hand lying on the face's blob
    shares it rather than take a free blob far away.

    A target left without a blob while some blob is within its gate shares the nearest such
    blob with the target that holds it. Every target on a shared blob is marked merged.

    Returns:
        (blob index or None per target, merged flag per target).
    """
    candidates: list[list[tuple[int, float]]] = []
    for target, min_area in zip(targets, min_areas or [0.0] * len(targets)):
        near = []
        if target is not None and np.all(np.isfinite(target)):
            for i, blob in enumerate(blobs):
                d = blob.distance_to(target)
                if d <= gate and blob.area >= min_area:
                    near.append((i, d))
        candidates.append(sorted(near, key=lambda c: c[1]))
    best: tuple[float, tuple[int | None, ...]] = (math.inf, (None,) * len(targets))
    options = [[(None, 2.0 * gate)] + c for c in candidates]
    weight = weights or [1.0] * len(targets)
    for combo in itertools.product(*options):
        chosen = [c[0] for c in combo if c[0] is not None]
        cost = sum(w * c[1] for w, c in zip(weight, combo))
        extra = len(chosen) - len(set(chosen))
        if extra:
            if not math.isfinite(share_cost):
                continue
            cost += share_cost * extra
        if cost < best[0]:
            best = (cost, tuple(c[0] for c in combo))
    matched: list[int | None] = list(best[1])
    for k, index in enumerate(best[1]):
        if index is None and candidates[k]:
            matched[k] = candidates[k][0][0]
    merged = [index is not None and matched.count(index) > 1 for index in matched]
    return matched, merged


def clear_of(blob: SkinBlob, centre: npt.NDArray[np.float64], radius: float) -> PixelBox | None:
    """Bounding box (x0, y0, x1, y1) of the blob's pixels farther than `radius` from `centre`.

    None when there are none. A hand merged with the face lies in the blob but not at the
    head's centre: without this its model hand may sit anywhere on the face, and when the
    blobs part the matching can swap them.
    """
    keep = np.hypot(blob.xs - centre[0], blob.ys - centre[1]) > radius
    if not np.any(keep):
        return None
    xs, ys = blob.xs[keep], blob.ys[keep]
    return float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())


def hand_direction(
    blob: SkinBlob,
    predicted: npt.NDArray[np.float64],
    shoulder: npt.NDArray[np.float64],
    elbow: npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]:
    """The direction along which the hand lies at the far end of `blob`.

    The predicted forearm's (`predicted`, unit), unless the blob is elongated and its long
    axis, turned away from the predicted elbow, also points away from the predicted shoulder:
    then that axis. A bare forearm predicted hanging while the real one lies across the chest
    (crossed arms) or points inwards (clapping) would otherwise find its "hand" mid-forearm or
    at the real elbow, the far end along the prediction, and the fit would confirm itself frame
    after frame. The shoulder's check keeps a blob that holds bare upper arm too (short
    sleeves, forearm towards the camera) from sending the point back up the arm.
    """
    axis = principal_direction(blob)
    if axis is None:
        return predicted
    centre = np.asarray(blob.centroid, dtype=np.float64)
    away = axis if float(axis @ (centre - elbow)) >= 0 else -axis
    return away if float(away @ (centre - shoulder)) > 0 else predicted


def hand_slab(
    blob: SkinBlob,
    elbow: npt.NDArray[np.float64],
    hand: npt.NDArray[np.float64],
    shoulder_px: float,
    config: FeatureConfig,
) -> float:
    """Length in pixels of the hand's far-end slab of `blob` along the predicted forearm.

    `hand_length` shoulder widths, shortened as the predicted forearm is foreshortened (an arm
    pointing at the camera): the hand then projects shorter too, and a full-length slab would
    reach back over the bare forearm. Only when the blob reaches the predicted elbow (a bare
    forearm): a blob that is the hand alone (long sleeves) is all hand, whatever the forearm's
    angle, and the wrist may bend the hand back into the image plane.
    """
    full = config.hand_length * shoulder_px
    forearm = float(np.hypot(*(hand - elbow)))
    if not np.isfinite(forearm) or blob.distance_to(elbow) > config.forearm_reach * forearm:
        return full
    shortening = forearm / (config.forearm_length * shoulder_px)
    return full * min(1.0, max(config.hand_min_foreshortening, shortening))


def shoulder_width(joints: npt.NDArray[np.float64], config: FeatureConfig) -> float:
    """The predicted shoulder width in pixels (at least `min_shoulder_px`): the scale of gates."""
    width = float(np.hypot(*(joints[RIGHT_SHOULDER] - joints[LEFT_SHOULDER])))
    return max(width, config.min_shoulder_px) if np.isfinite(width) else config.min_shoulder_px


def point_targets(joints: npt.NDArray[np.float64]) -> list[npt.NDArray[np.float64] | None]:
    """The predicted head, right hand and left hand (POINT_NAMES order)."""
    return [joints[HEAD], joints[RIGHT_HAND], joints[LEFT_HAND]]


def point_weights(config: FeatureConfig) -> list[float]:
    """Weights of the head's and the hands' distances in the matching: the head's priority."""
    return [config.head_priority, 1.0, 1.0]


def point_min_areas(config: FeatureConfig, shoulder_px: float) -> list[float]:
    """Smallest blob in pixels the head and each hand may take (`part_min_share`)."""
    return [config.part_min_share * area * shoulder_px**2 for area in PART_AREAS]


def match_points(blobs: list[SkinBlob], joints: npt.NDArray[np.float64], config: FeatureConfig) -> Matching:
    """Head, right hand and left hand matched to the blobs (`assign`) around predicted 2D joints."""
    shoulder_px = shoulder_width(joints, config)
    gate = config.hand_gate * shoulder_px
    return assign(
        blobs,
        point_targets(joints),
        gate,
        point_weights(config),
        point_min_areas(config, shoulder_px),
        config.blob_share_cost * shoulder_px,
    )


def points_with_prediction(
    blobs: list[SkinBlob],
    joints: npt.NDArray[np.float64],
    config: FeatureConfig,
    matching: Matching | None = None,
    size: tuple[int, int] | None = None,
) -> list[SkinPoint | None]:
    """Head, right hand and left hand from the blobs, given predicted 2D joints (JOINT_NAMES order).

    `matching`: `match_points` of these blobs and joints, when the caller has it already.
    `size`: the image's (height, width); with it, a hand whose far end touches the border is
    reported merged with the box `beyond_border` gives.
    """
    shoulder_px = shoulder_width(joints, config)
    matched, merged = matching if matching is not None else match_points(blobs, joints, config)
    neck = 0.5 * (joints[RIGHT_SHOULDER] + joints[LEFT_SHOULDER])
    directions = [
        unit(joints[HEAD] - neck),
        unit(joints[RIGHT_HAND] - joints[RIGHT_ELBOW]),
        unit(joints[LEFT_HAND] - joints[LEFT_ELBOW]),
    ]
    head_length = config.head_length * shoulder_px
    points: list[SkinPoint | None] = []
    for k in range(3):
        index = matched[k]
        if index is None:
            points.append(None)
            continue
        blob = blobs[index]
        direction = directions[k]
        box = None
        if k > 0 and merged[k] and matched[0] == index:
            box = clear_of(blob, joints[HEAD], head_length)
        if merged[k] or direction is None:
            xy = blob.centroid
        elif k == 0:
            xy = head_centre(blob, direction, head_length)
        else:
            shoulder, elbow, hand = (joints[j + k - 1] for j in (RIGHT_SHOULDER, RIGHT_ELBOW, RIGHT_HAND))
            along = hand_direction(blob, direction, shoulder, elbow)
            length = hand_slab(blob, elbow, hand, shoulder_px, config)
            xs, ys = far_end_pixels(blob, along, length)
            xy = float(xs.mean()), float(ys.mean())
            box = beyond_border(xs, ys, size, length) if size is not None else None
        # A box says where the part may be instead of a point: a hand on the face, or cut by the border.
        points.append(SkinPoint(xy, merged[k] or box is not None, index, box))
    return points


def points_at_startup(blobs: list[SkinBlob], config: FeatureConfig) -> list[SkinPoint | None]:
    """Head and hands from the three largest blobs, without a prediction (§3.3.2)."""
    largest = list(range(min(3, len(blobs))))
    if not largest:
        return [None, None, None]
    head = min(largest, key=lambda i: blobs[i].centroid[1])
    head_blob = blobs[head]
    shoulder_px = max(config.startup_shoulder_faces * head_blob.bbox[2], config.min_shoulder_px)
    head_xy = head_centre(head_blob, np.array([0.0, -1.0]), config.head_length * shoulder_px)
    points: list[SkinPoint | None] = [SkinPoint(head_xy, False, head), None, None]
    hands = sorted((i for i in largest if i != head), key=lambda i: blobs[i].centroid[0])
    if len(hands) == 1:
        slot = 1 if blobs[hands[0]].centroid[0] < head_blob.centroid[0] else 2
        slots = {slot: hands[0]}
    else:
        slots = {1: hands[0], 2: hands[1]} if hands else {}
    for slot, index in slots.items():
        blob = blobs[index]
        outward = unit(np.subtract(blob.centroid, head_blob.centroid))
        axis = principal_direction(blob)
        if axis is not None and outward is not None:
            direction: npt.NDArray[np.float64] | None = axis if float(axis @ outward) >= 0 else -axis
        else:
            direction = outward
        xy = far_end(blob, direction, config.hand_length * shoulder_px) if direction is not None else blob.centroid
        points[slot] = SkinPoint(xy, False, index)
    return points


def hands_beyond_image(
    hands: tuple[SkinPoint | None, SkinPoint | None],
    joints: npt.NDArray[np.float64] | None,
    size: tuple[int, int],
) -> tuple[PixelBox | None, PixelBox | None]:
    """Per hand (right, left) without a skin point, `beyond_image` of its predicted position."""
    if joints is None:
        return (None, None)
    right, left = (beyond_image(joints[j], size) if p is None else None for p, j in zip(hands, (RIGHT_HAND, LEFT_HAND)))
    return (right, left)


def locate_points(
    blobs: list[SkinBlob],
    joints: npt.NDArray[np.float64] | None,
    config: FeatureConfig,
    matching: Matching | None = None,
    size: tuple[int, int] | None = None,
) -> list[SkinPoint | None]:
    """Head, right hand and left hand (POINT_NAMES order); None where a part has no blob.

    Args:
        blobs: valid skin blobs, largest first.
        joints: `(7, 2)` predicted joints in pixels (JOINT_NAMES order), or None at start-up.
        config: gates and lengths.
        matching: `match_points(blobs, joints, config)` when already computed (the split's).
        size: the image's (height, width): a hand cut by the border is then a box, not a point.
    """
    if joints is None:
        return points_at_startup(blobs, config)
    return points_with_prediction(blobs, joints, config, matching, size)
