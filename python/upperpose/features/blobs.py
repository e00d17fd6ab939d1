"""Skin blobs: connected regions of I_skin and their gradient probability P_SB (§3.4.4.2)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.checks import Frame, Mask
from upperpose.features.config import FeatureConfig


@dataclass(frozen=True)
class SkinBlob:
    """One connected skin region.

    Attributes:
        area: number of skin pixels N(S_b).
        centroid: (x, y) mean of its pixels, pixels.
        bbox: (x, y, w, h) bounding box, pixels.
        gradient: P_SB = fraction of its pixels that are set in I_edge (Eq. 3.4.4.2-1).
        xs, ys: pixel coordinates of its pixels (int32), for far-end queries.
        contour: its outer contour, `(N, 1, 2)` int32 as from cv2.findContours.
    """

    area: int
    centroid: tuple[float, float]
    bbox: tuple[int, int, int, int]
    gradient: float
    xs: npt.NDArray[np.int32]
    ys: npt.NDArray[np.int32]
    contour: npt.NDArray[np.int32]

    def distance_to(self, point: npt.ArrayLike) -> float:
        """Distance in pixels from `point` (x, y) to the blob's outline; 0 inside it."""
        px, py = (float(v) for v in np.asarray(point, dtype=np.float64))
        return max(0.0, -cv2.pointPolygonTest(self.contour, (px, py), True))


def stands_out_in_colour(pixels: Mask, origin: tuple[int, int], sub: Mask, config: FeatureConfig) -> bool:
    """Whether a blob is a limb against the room by colour alone (when P_SB misses it).

    True when at least `blob_min_changed` of its pixels are in I_sub and at least
    `blob_min_room_outline` of a `blob_ring`-pixel ring around it is not: the blob differs from
    the plate and its outline is the person's outline. A dark arm in front of a dark sofa has
    hardly any grey-level edge but a clear colour change; a skin-coloured patch of clothing is
    surrounded by more of the person (I_sub), a static object by no change at all.

    Args:
        pixels: `(h, w)` uint8 blob pixels inside its bounding box.
        origin: (x, y) of the bounding box's top-left corner in the image.
        sub: `(H, W)` uint8 I_sub.
        config: thresholds.
    """
    x, y = origin
    h, w = pixels.shape
    area = cv2.countNonZero(pixels)
    if cv2.countNonZero(cv2.bitwise_and(pixels, sub[y : y + h, x : x + w])) < config.blob_min_changed * area:
        return False
    r = config.blob_ring
    height, width = sub.shape
    x0, y0, x1, y1 = max(x - r, 0), max(y - r, 0), min(x + w + r, width), min(y + h + r, height)
    grown = np.zeros((y1 - y0, x1 - x0), np.uint8)
    grown[y - y0 : y - y0 + h, x - x0 : x - x0 + w] = pixels
    inner = grown.copy()
    cv2.dilate(grown, np.ones((2 * r + 1, 2 * r + 1), np.uint8), dst=grown)
    ring = cv2.subtract(grown, inner)
    room = cv2.countNonZero(cv2.bitwise_and(ring, cv2.bitwise_not(sub[y0:y1, x0:x1])))
    return room >= config.blob_min_room_outline * max(cv2.countNonZero(ring), 1)


def is_shade(pixels: Mask, origin: tuple[int, int], frame: Frame, plate: Frame, config: FeatureConfig) -> bool:
    """Whether a blob's change from the plate is a shade: the plate's own colours, darker or lighter.

    A shadow (or a lamp) on skin-coloured furniture changes its brightness but hardly its
    colour: the frame's mean B, G, R over the blob are the plate's times nearly one factor
    (their ratios spread by at most `blob_shade_spread` of their mean). A limb in front of
    the furniture brings its own colour.

    Args:
        pixels: `(h, w)` uint8 blob pixels inside its bounding box.
        origin: (x, y) of the bounding box's top-left corner in the image.
        frame: `(H, W, 3)` uint8 BGR, in the plate's light.
        plate: `(H, W, 3)` uint8 BGR background.
        config: thresholds.
    """
    if config.blob_shade_spread <= 0:
        return False
    x, y = origin
    h, w = pixels.shape
    now = np.array(cv2.mean(frame[y : y + h, x : x + w], mask=pixels)[:3])
    before = np.array(cv2.mean(plate[y : y + h, x : x + w], mask=pixels)[:3])
    if before.min() < 1.0:
        return False
    ratios = now / before
    return float(ratios.max() - ratios.min()) <= config.blob_shade_spread * float(ratios.mean())


def find_skin_blobs(
    skin: Mask,
    edge: Mask,
    config: FeatureConfig,
    sub: Mask | None = None,
    frame: Frame | None = None,
    plate: Frame | None = None,
) -> list[SkinBlob]:
    """The valid skin blobs of I_skin, largest first.

    A blob is an outer contour of `skin` filled (so that eyes and mouth do not split a face),
    intersected with `skin`. Blobs smaller than `blob_min_area` or with P_SB below
    `blob_min_gradient` are dropped: a static skin-coloured object that slipped through the
    background test has hardly any edge change on it. With `sub` given, a blob below that
    P_SB is kept when it stands out from the room in colour (`stands_out_in_colour`), unless,
    with `frame` and `plate` given, that change is only a shade of the plate (`is_shade`).

    Args:
        skin: `(H, W)` uint8 I_skin, nonzero = skin.
        edge: `(H, W)` uint8 I_edge, nonzero = edge (the extractor passes it dilated 3x3, so
            that the blob's outline edges, just outside its skin pixels, count).
        config: thresholds.
        sub: `(H, W)` uint8 I_sub, or None for P_SB alone.
        frame: `(H, W, 3)` uint8 BGR, in the plate's light, for `is_shade`; None skips that test.
        plate: `(H, W, 3)` uint8 BGR background, for `is_shade`; None skips that test.

    Returns:
        Valid blobs sorted by area, largest first.
    """
    contours, _ = cv2.findContours(skin, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    blobs = []
    for contour in contours:
        x, y, w, h = cv2.boundingRect(contour)
        if w * h < config.blob_min_area:
            continue
        region = np.zeros((h, w), np.uint8)
        cv2.drawContours(region, [contour], 0, 255, -1, offset=(-x, -y))
        pixels = cast(Mask, cv2.bitwise_and(region, skin[y : y + h, x : x + w]))
        area = cv2.countNonZero(pixels)
        if area < config.blob_min_area:
            continue
        on_edge = cv2.countNonZero(cv2.bitwise_and(pixels, edge[y : y + h, x : x + w]))
        gradient = on_edge / area
        if gradient < config.blob_min_gradient:
            by_colour = sub is not None and stands_out_in_colour(pixels, (x, y), sub, config)
            if not by_colour or (
                frame is not None and plate is not None and is_shade(pixels, (x, y), frame, plate, config)
            ):
                continue
        blobs.append(blob_from_pixels(pixels, (x, y), gradient, cast(npt.NDArray[np.int32], contour)))
    blobs.sort(key=lambda b: -b.area)
    return blobs


def blob_from_pixels(
    pixels: Mask, origin: tuple[int, int], gradient: float, contour: npt.NDArray[np.int32] | None = None
) -> SkinBlob:
    """A `SkinBlob` from its nonzero `pixels` inside a box whose top-left corner is `origin`.

    Args:
        pixels: `(h, w)` uint8, nonzero = the blob's pixels (at least one).
        origin: (x, y) of the box in the image.
        gradient: its P_SB.
        contour: its outer contour in image coordinates; traced from `pixels` when None.
    """
    x, y = origin
    if contour is None:
        contours, _ = cv2.findContours(pixels, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE, offset=(x, y))
        contour = cast(npt.NDArray[np.int32], max(contours, key=cv2.contourArea))
    ys, xs = np.nonzero(pixels)
    xs = (xs + x).astype(np.int32)
    ys = (ys + y).astype(np.int32)
    centroid = (float(xs.mean()), float(ys.mean()))
    # The box holds every pixel: a blob's pixels may lie in several pieces (a split blob's head
    # keeps its hair), beyond the largest piece's contour.
    cx, cy, cw, ch = cv2.boundingRect(contour)
    left, top = min(cx, int(xs.min())), min(cy, int(ys.min()))
    right, bottom = max(cx + cw, int(xs.max()) + 1), max(cy + ch, int(ys.max()) + 1)
    bbox = (left, top, right - left, bottom - top)
    return SkinBlob(
        len(xs), centroid, bbox, gradient, cast(npt.NDArray[np.int32], xs), cast(npt.NDArray[np.int32], ys), contour
    )
