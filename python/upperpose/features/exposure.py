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


class ExposureMeter:
    """Measures frames' gains against one plate; the plate's side of the ratio is sampled once.

    Args:
        plate: the clean plate, `(H, W, 3)` BGR.
        step: every `step`-th pixel in both directions is compared.
    """

    def __init__(self, plate: Frame, step: int) -> None:
        self.step = step
        samples = plate[::step, ::step].reshape(-1, 3).astype(np.float32)
        # Per channel: the well-lit sample indices and their plate values (None: too few).
        self._channels: list[tuple[npt.NDArray[np.intp], npt.NDArray[np.float32]] | None] = []
        for c in range(3):
            lit = np.flatnonzero(samples[:, c] >= _MIN_LEVEL)
            self._channels.append((lit, samples[lit, c]) if len(lit) >= 100 else None)

    def gains(self, frame: Frame) -> npt.NDArray[np.float64]:
        """Median per-channel ratio frame / plate over the sampled pixels.

        Returns:
            `(3,)` BGR gains; 1.0 for a channel without enough well-lit plate pixels.
        """
        f = frame[:: self.step, :: self.step].reshape(-1, 3)
        gains = np.ones(3)
        for c, channel in enumerate(self._channels):
            if channel is not None:
                lit, plate_values = channel
                gains[c] = float(np.median(f[lit, c] / plate_values))
        return gains


def channel_gains(frame: Frame, plate: Frame, step: int) -> npt.NDArray[np.float64]:
    """Median per-channel ratio frame / plate over every `step`-th pixel in both directions.

    One call; `ExposureMeter` measures many frames against one plate.

    Returns:
        `(3,)` BGR gains; 1.0 for a channel without enough well-lit plate pixels.
    """
    return ExposureMeter(plate, step).gains(frame)


def needs_compensation(gains: npt.NDArray[np.float64], tolerance: float) -> bool:
    """Whether any channel's gain is off by more than `tolerance` (relative)."""
    return bool(np.any(np.abs(gains - 1.0) > tolerance))


__all__ = ["GREY_WEIGHTS", "ExposureMeter", "channel_gains", "needs_compensation"]
