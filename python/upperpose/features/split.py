"""Skin blobs that join the head and a hand through pixels of neither's colour (hair).

Hair whose colour passes the skin rule (brown, blond) joins a hand laid on it to the face: the
point matcher then gives head and hand one blob and reports both merged, while their skin does
not touch. Such a blob is split when the pixels of neither the face's nor the hand's colour
separate them: a hand on the face, or on the neck, touches skin of nearly its own or the
face's colour and stays one blob (merged); a hand on hair does not.

Colours are chromaticities, (R, G) / (R + G + B): shading darkens skin but hardly changes
them, so a shaded contact between hand and face is not taken for hair.
"""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.blobs import SkinBlob, blob_from_pixels
from upperpose.features.checks import Frame, Mask
from upperpose.features.config import FeatureConfig
from upperpose.features.points import Matching, match_points, point_targets, shoulder_width

# Smallest colour sample around a predicted part, pixels (when the part lies off the blob).
_MIN_SAMPLE = 10


def chromaticity(bgr: npt.NDArray[np.uint8]) -> npt.NDArray[np.float64]:
    """`(N, 2)` (r, g) = (R, G) / (R + G + B) of `(N, 3)` BGR pixels."""
    values = bgr.astype(np.float64)
    total = values.sum(axis=1, keepdims=True) + 1.0
    return cast(npt.NDArray[np.float64], values[:, [2, 1]] / total)


def part_colour(
    blob: SkinBlob, chroma: npt.NDArray[np.float64], point: npt.NDArray[np.float64], radius: float
) -> npt.NDArray[np.float64]:
    """Median chromaticity of the blob's pixels within `radius` of a predicted part.

    At least its `_MIN_SAMPLE` nearest pixels, so that a part lying off the blob has a colour.
    """
    distance = np.hypot(blob.xs - point[0], blob.ys - point[1])
    k = min(_MIN_SAMPLE, len(distance)) - 1
    near = distance <= max(radius, float(np.partition(distance, k)[k]))
    return np.asarray(np.median(chroma[near], axis=0), dtype=np.float64)


def component_at(labels: npt.NDArray[np.int32], point: npt.NDArray[np.float64]) -> int:
    """Label of the labelled pixel nearest to `point` (box coordinates); 0 when none is."""
    ys, xs = np.nonzero(labels)
    if len(xs) == 0:
        return 0
    nearest = int(np.argmin((xs - point[0]) ** 2 + (ys - point[1]) ** 2))
    return int(labels[ys[nearest], xs[nearest]])


def split_at_colour(
    blob: SkinBlob,
    frame: Frame,
    head: npt.NDArray[np.float64],
    hand: npt.NDArray[np.float64],
    radius: float,
    config: FeatureConfig,
) -> tuple[SkinBlob, SkinBlob] | None:
    """The head's and the hand's pieces of `blob`, or None when it does not come apart.

    Pixels further than `split_chroma` from both the face's and the hand's colour (sampled
    within `radius` of the predicted head and hand) are left out; the blob comes apart when the
    head and the hand then lie in different 8-connected pieces, each at least `blob_min_area`,
    side by side: a hand piece that wraps round the head piece (their convex hulls share more
    than `split_max_overlap` of its area) is hair rim that kept a skin-like colour where it
    blends with the room, not a hand beside the head. The head's piece keeps its hair
    (`head_with_hair`).
    """
    chroma = chromaticity(frame[blob.ys, blob.xs])
    face, skin = (part_colour(blob, chroma, p, radius) for p in (head, hand))
    nearest = np.minimum(np.hypot(*(chroma - face).T), np.hypot(*(chroma - skin).T))
    keep = nearest <= config.split_chroma
    x, y, w, h = blob.bbox
    mask = np.zeros((h, w), np.uint8)
    mask[blob.ys[keep] - y, blob.xs[keep] - x] = 255
    _, labels = cast(tuple[int, npt.NDArray[np.int32]], cv2.connectedComponents(mask, connectivity=8, ltype=cv2.CV_32S))
    origin = np.array([x, y], np.float64)
    ours = component_at(labels, head - origin)
    theirs = component_at(labels, hand - origin)
    if ours == theirs or 0 in (ours, theirs):
        return None
    pieces = [(labels == label).astype(np.uint8) * 255 for label in (ours, theirs)]
    if min(cv2.countNonZero(p) for p in pieces) < config.blob_min_area:
        return None
    face_piece, hand_piece = (blob_from_pixels(p, (x, y), blob.gradient) for p in pieces)
    if hull_overlap(face_piece, hand_piece, blob.bbox) > config.split_max_overlap * hand_piece.area:
        return None
    return blob_from_pixels(head_with_hair(blob, *pieces), (x, y), blob.gradient), hand_piece


def head_with_hair(blob: SkinBlob, face: Mask, hand: Mask) -> Mask:
    """The head's pixels of a split blob (in its box): the rest of the blob nearer the face.

    The rest of the blob, without the hand's piece, where it is nearer the face's piece than
    the hand's. The head keeps its hair, so that its blob is about the one it has without the
    hand (its width gives the root depth, its widest disc the head point); the left-out pixels
    at the hand's outline (colour blended with the hair) go to neither, not widening the head.
    """
    x, y, w, h = blob.bbox
    whole = np.zeros((h, w), np.uint8)
    whole[blob.ys - y, blob.xs - x] = 255
    to_face, to_hand = (cv2.distanceTransform(cv2.bitwise_not(m), cv2.DIST_L2, 3) for m in (face, hand))
    nearer = np.where(to_face <= to_hand, 255, 0).astype(np.uint8)
    return cast(Mask, cv2.bitwise_and(cv2.subtract(whole, hand), nearer))


def hull_overlap(a: SkinBlob, b: SkinBlob, box: tuple[int, int, int, int]) -> int:
    """Pixels shared by the convex hulls of two blobs inside `box` (x, y, w, h)."""
    x, y, w, h = box
    hulls = [np.zeros((h, w), np.uint8) for _ in range(2)]
    for hull, blob in zip(hulls, (a, b)):
        cv2.fillConvexPoly(hull, cv2.convexHull(blob.contour) - (x, y), 255)
    return cv2.countNonZero(cv2.bitwise_and(*hulls))


def split_head_from_hands(
    blobs: list[SkinBlob], frame: Frame, joints: npt.NDArray[np.float64], config: FeatureConfig
) -> tuple[list[SkinBlob], Matching]:
    """The blobs, with head-and-hand blobs split into their pieces where colour allows.

    A blob is tried when the matcher (`match_points`) would share it between the head and a hand
    (`split_at_colour`). Returns the blobs largest first and their matching, which
    `locate_points` then need not compute again.

    Args:
        blobs: valid skin blobs, largest first.
        frame: `(H, W, 3)` BGR frame the skin rule saw.
        joints: `(7, 2)` predicted joints in pixels (JOINT_NAMES order).
        config: the gate, colour distance and sample radius.
    """
    blobs = list(blobs)
    matched, merged = match_points(blobs, joints, config)
    targets = point_targets(joints)
    if not all(t is not None and np.all(np.isfinite(t)) for t in targets):
        return blobs, (matched, merged)
    radius = config.split_sample * shoulder_width(joints, config)
    for hand in (1, 2):
        shared = matched[0]
        if shared is None or not merged[0] or matched[hand] != shared:
            continue
        head_target = cast(npt.NDArray[np.float64], targets[0])  # not None: checked above
        hand_target = cast(npt.NDArray[np.float64], targets[hand])
        pieces = split_at_colour(blobs[shared], frame, head_target, hand_target, radius, config)
        if pieces is not None:
            blobs[shared : shared + 1] = pieces
            blobs.sort(key=lambda b: -b.area)
            matched, merged = match_points(blobs, joints, config)
    return blobs, (matched, merged)
