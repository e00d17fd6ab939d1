"""Skin colour rules (I_skin0): the thesis' R - G band and the YCrCb / HSV alternatives.

Each rule takes optional preallocated scratch and output arrays (the per-frame extractor reuses
them: fresh allocations of frame-sized arrays cost more than the arithmetic here).
"""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np

from upperpose.features.checks import Frame, Mask
from upperpose.features.config import FeatureConfig


class SkinWork:
    """Scratch arrays for the skin rules of frames of one size."""

    def __init__(self, height: int, width: int) -> None:
        self.diff = np.empty((height, 3 * width - 2), np.uint8)
        self.r_minus_g = np.empty((height, width), np.uint8)
        self.converted = np.empty((height, width, 3), np.uint8)
        self.second = np.empty((height, width), np.uint8)


def skin_rgb(
    frame: Frame,
    rg_min: int,
    rg_max: int,
    work: SkinWork | None = None,
    out: Mask | None = None,
) -> Mask:
    """`rg_min <= R - G <= rg_max` on a BGR frame (§2.5); 255 = skin.

    R - G is computed on the interleaved bytes (byte 3k+2 minus byte 3k+1, saturating at 0),
    which avoids splitting the channels.
    """
    height, width = frame.shape[:2]
    work = work or SkinWork(height, width)
    out = out if out is not None else np.empty((height, width), np.uint8)
    rows = frame.reshape(height, width * 3)
    cv2.subtract(rows[:, 2:], rows[:, 1:-1], dst=work.diff)
    np.copyto(work.r_minus_g, work.diff[:, 0::3])
    if rg_min == 0:
        return cast(Mask, cv2.compare(work.r_minus_g, rg_max, cv2.CMP_LE, dst=out))  # type: ignore[call-overload]
    return cast(Mask, cv2.inRange(work.r_minus_g, rg_min, rg_max, dst=out))


def skin_ycrcb(
    frame: Frame,
    low: tuple[int, int, int],
    high: tuple[int, int, int],
    work: SkinWork | None = None,
    out: Mask | None = None,
) -> Mask:
    """Skin as a box in OpenCV's 8-bit YCrCb; 255 = skin."""
    work = work or SkinWork(*frame.shape[:2])
    out = out if out is not None else np.empty(frame.shape[:2], np.uint8)
    cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb, dst=work.converted)
    return cast(Mask, cv2.inRange(work.converted, np.array(low, np.uint8), np.array(high, np.uint8), dst=out))


def skin_hsv(
    frame: Frame,
    hue_max: int,
    min_sv: tuple[int, int],
    max_s: int,
    work: SkinWork | None = None,
    out: Mask | None = None,
) -> Mask:
    """Skin as reddish-to-orange hue with moderate saturation in OpenCV HSV; 255 = skin."""
    work = work or SkinWork(*frame.shape[:2])
    out = out if out is not None else np.empty(frame.shape[:2], np.uint8)
    cv2.cvtColor(frame, cv2.COLOR_BGR2HSV, dst=work.converted)
    low = np.array([0, min_sv[0], min_sv[1]], np.uint8)
    cv2.inRange(work.converted, low, np.array([hue_max, max_s, 255], np.uint8), dst=out)
    low[0] = 180 - hue_max
    cv2.inRange(work.converted, low, np.array([180, max_s, 255], np.uint8), dst=work.second)
    return cast(Mask, cv2.bitwise_or(out, work.second, dst=out))


def skin_mask(
    frame: Frame,
    config: FeatureConfig,
    work: SkinWork | None = None,
    out: Mask | None = None,
) -> Mask:
    """I_skin0 of a BGR frame with the colour rule `config.skin_space`; `(H, W)` uint8, 255 = skin."""
    if config.skin_space == "ycrcb":
        return skin_ycrcb(frame, config.ycrcb_min, config.ycrcb_max, work, out)
    if config.skin_space == "rgb+ycrcb":
        work = work or SkinWork(*frame.shape[:2])
        rgb = skin_rgb(frame, config.rgb_rg_min, config.rgb_rg_max, work, out)
        # Chroma only: the R - G band already bounds the colour, and skin in shadow is darker
        # than the YCrCb rule's brightness floor.
        low, high = (0, *config.ycrcb_min[1:]), (255, *config.ycrcb_max[1:])
        ycrcb = skin_ycrcb(frame, low, high, work, work.second)
        return cast(Mask, cv2.bitwise_and(rgb, ycrcb, dst=rgb))
    if config.skin_space == "hsv":
        return skin_hsv(frame, config.hsv_hue_max, config.hsv_min_sv, config.hsv_max_s, work, out)
    return skin_rgb(frame, config.rgb_rg_min, config.rgb_rg_max, work, out)
