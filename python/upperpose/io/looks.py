"""What a video looks like, to say why a run found nobody: grey frames, very dark frames.

The start-up needs a frontal face (OpenCV's Haar cascade, which needs contrast) whose box is
partly skin, and the hands are found by their skin colour: a video without colour (an infrared
or black-and-white camera) or one too dark for the cascade cannot start, and "no face" alone
does not tell the user why.
"""

from __future__ import annotations

import numpy as np

from upperpose.io.video import Frame

# Mean spread between a pixel's largest and smallest channel, as a share of the mean level,
# below which a video has no colour: a grey picture decodes with about 3 levels of spread (the
# chroma's rounding) at a level of 100, the validation clips and a real phone video have 0.12-0.55.
# A share, since a dark video's colours are as dark as the rest of it.
GREY_SPREAD = 0.06
# Mean level (0-255) below which a video is too dark for the face detector.
DARK_LEVEL = 35.0


class VideoLooks:
    """Samples every `every`-th frame's colour and brightness.

    Args:
        every: frames between samples (the first frame is always one).
    """

    def __init__(self, every: int = 15) -> None:
        self.every = max(int(every), 1)
        # Sums over the sampled frames, not lists: a live run's memory must not grow.
        self._samples = 0
        self._spread = 0.0
        self._level = 0.0

    def see(self, index: int, frame: Frame) -> None:
        """Samples frame number `index` (BGR) if it is one of the sampled frames."""
        if index % self.every:
            return
        pixels = frame[::4, ::4].astype(np.int16)
        self._samples += 1
        self._spread += float((pixels.max(axis=2) - pixels.min(axis=2)).mean())
        self._level += float(pixels.mean())

    def hint(self) -> str | None:
        """Why a face or skin may not be found in this video, or None when it looks usable."""
        if not self._samples:
            return None
        level, spread = self._level / self._samples, self._spread / self._samples
        if spread < GREY_SPREAD * max(level, 1.0):
            return "the video has no colour (grey frames): the face and hands are found by their skin colour"
        if level < DARK_LEVEL:
            return f"the video is very dark (mean level {level:.0f} of 255): the face detector needs more light"
        return None


__all__ = ["DARK_LEVEL", "GREY_SPREAD", "VideoLooks"]
