"""Global light changes against the clean plate: a dimming lamp, a camera's auto exposure.

A plate photographed under other light makes the whole frame "foreground". The frame's gain
per colour channel relative to the plate is the median ratio over a sparse grid of pixels: the
person covers well under half of the frame, so the median belongs to the background. When some
gain is off by more than the tolerance, the features compare against the plate (and its
derivatives) scaled by it.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from upperpose.features.checks import Frame

# OpenCV's BGR -> grey weights: the gain of the grey image the edge feature differentiates.
GREY_WEIGHTS = np.array([0.114, 0.587, 0.299])
# Plate values below this are too dark for a ratio (compression noise dominates).
_MIN_LEVEL = 24


def channel_gains(frame: Frame, plate: Frame, step: int) -> npt.NDArray[np.float64]:
    """Median per-channel ratio frame / plate over every `step`-th pixel in both directions.

    Returns:
        `(3,)` BGR gains; 1.0 for a channel without enough well-lit plate pixels.
    """
    f = frame[::step, ::step].reshape(-1, 3).astype(np.float32)
    p = plate[::step, ::step].reshape(-1, 3).astype(np.float32)
    gains = np.ones(3)
    for c in range(3):
        lit = p[:, c] >= _MIN_LEVEL
        if np.count_nonzero(lit) >= 100:
            gains[c] = float(np.median(f[lit, c] / p[lit, c]))
    return gains


def needs_compensation(gains: npt.NDArray[np.float64], tolerance: float) -> bool:
    """Whether any channel's gain is off by more than `tolerance` (relative)."""
    return bool(np.any(np.abs(gains - 1.0) > tolerance))


__all__ = ["GREY_WEIGHTS", "channel_gains", "needs_compensation"]
