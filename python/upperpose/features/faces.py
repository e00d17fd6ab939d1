"""Frontal faces: OpenCV's Haar cascade (SPEC 6), and the skin test that drops false detections.

Start-up looks for the person's face; background estimation asks whether a static lead-in
shows anybody. Both accept a box only when enough of it is skin: the cascade fires on
bookshelves and pictures, a real face is skin.
"""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

FaceBox = tuple[int, int, int, int]


class FaceDetector:
    """OpenCV's frontal-face Haar cascade on a downscaled grey frame.

    Args:
        downscale: the frame is shrunk by this factor first (2 = half size; about 4x faster);
            None: to about 427 pixels wide (1.5 for 640), never enlarged; the cascade sees
            faces of 24 pixels and more, so faces from 36 pixels at 640 wide.
        min_face_px: smallest face width to report, in full-size pixels.
    """

    def __init__(self, downscale: float | None = None, min_face_px: int = 24) -> None:
        path = cv2.data.haarcascades + "haarcascade_frontalface_default.xml"  # type: ignore[attr-defined]
        self._cascade = cv2.CascadeClassifier(path)
        if self._cascade.empty():
            raise RuntimeError(f"cannot load the Haar cascade {path} (opencv-python-headless>=4.10,<5 is needed)")
        self.downscale = downscale
        self.min_face_px = min_face_px

    def __call__(self, frame: npt.NDArray[np.uint8]) -> list[FaceBox]:
        """Face boxes `(x, y, w, h)` in full-size pixels, largest first.

        When the downscaled frame shows no face, the full-size one is searched too: the
        cascade's smallest face is 24 pixels, so a person a few metres away (a 30-36 pixel face
        at 640 wide) is only seen at full size.
        """
        grey = cast(npt.NDArray[np.uint8], cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY))
        s = self.downscale or max(1.0, frame.shape[1] / 427.0)
        boxes = self._detect(grey, s)
        if not boxes and s > 1:
            boxes = self._detect(grey, 1.0)
        return sorted(boxes, key=lambda b: -b[2])

    def _detect(self, grey: npt.NDArray[np.uint8], s: float) -> list[FaceBox]:
        if s > 1:
            grey = cast(npt.NDArray[np.uint8], cv2.resize(grey, None, fx=1 / s, fy=1 / s, interpolation=cv2.INTER_AREA))
        smallest = max(12, int(self.min_face_px / s))
        found = self._cascade.detectMultiScale(grey, scaleFactor=1.1, minNeighbors=4, minSize=(smallest, smallest))
        return cast(list[FaceBox], [tuple(int(round(v * s)) for v in box) for box in (found if len(found) else [])])


def choose_face(boxes: list[FaceBox], skin: npt.NDArray[np.uint8], min_skin: float = 0.25) -> FaceBox | None:
    """The face box with the most skin inside (a real face is skin; a false detection rarely is)."""
    best, best_share = None, min_skin
    for x, y, w, h in boxes:
        patch = skin[max(y, 0) : y + h, max(x, 0) : x + w]
        share = float(np.count_nonzero(patch)) / max(patch.size, 1)
        if share >= best_share:
            best, best_share = (x, y, w, h), share
    return best
