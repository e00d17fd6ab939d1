"""Skin blobs: connected regions of I_skin and their gradient probability P_SB (§3.4.4.2)."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.checks import Mask
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


def find_skin_blobs(skin: Mask, edge: Mask, config: FeatureConfig) -> list[SkinBlob]:
    """The valid skin blobs of I_skin, largest first.

    A blob is an outer contour of `skin` filled (so that eyes and mouth do not split a face),
    intersected with `skin`. Blobs smaller than `blob_min_area` or with P_SB below
    `blob_min_gradient` are dropped: a static skin-coloured object that slipped through the
    background test has hardly any edge change on it.

    Args:
        skin: `(H, W)` uint8 I_skin, nonzero = skin.
        edge: `(H, W)` uint8 I_edge, nonzero = edge (the extractor passes it dilated 3x3, so
            that the blob's outline edges, just outside its skin pixels, count).
        config: thresholds.

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
        pixels = cv2.bitwise_and(region, skin[y : y + h, x : x + w])
        area = cv2.countNonZero(pixels)
        if area < config.blob_min_area:
            continue
        on_edge = cv2.countNonZero(cv2.bitwise_and(pixels, edge[y : y + h, x : x + w]))
        gradient = on_edge / area
        if gradient < config.blob_min_gradient:
            continue
        ys, xs = np.nonzero(pixels)
        xs = (xs + x).astype(np.int32)
        ys = (ys + y).astype(np.int32)
        centroid = (float(xs.mean()), float(ys.mean()))
        blobs.append(SkinBlob(area, centroid, (x, y, w, h), gradient, xs, ys, contour))
    blobs.sort(key=lambda b: -b.area)
    return blobs
