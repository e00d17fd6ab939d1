"""Frontal faces: OpenCV's Haar cascade (SPEC 6), and the skin test that drops false detections.

Start-up looks for the person's face; background estimation asks whether a static lead-in
shows anybody. Both accept a box when enough of it is skin: the cascade fires on
bookshelves and pictures, a real face is skin. Start-up also accepts a face the cascade keeps
finding in one place (`SteadyFace`): under cool or dim light a real face can fail the skin
rule. Tracking checks now and then that the model's head is still on the face
(`FaceDetector.near`), near the head and at the person's face size.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

FaceBox = tuple[int, int, int, int]
# The same person's face at another distance or angle: its box within these factors of the
# width expected.
SAME_FACE_SIZES = (0.7, 1.45)
# A face box "in one place": centre and width within this share of its width (SteadyFace,
# steady_face).
STEADY_TOLERANCE = 0.25


def face_centre(face: FaceBox) -> npt.NDArray[np.float64]:
    """Centre of a face box in pixels (about the head joint: the centre of the head)."""
    x, y, w, h = face
    return np.array([x + (w - 1) / 2.0, y + (h - 1) / 2.0])


def faces_near(boxes: list[FaceBox], centre: npt.ArrayLike, width_px: float, reach: float) -> list[FaceBox]:
    """The boxes that may be the face of a person expected at `centre`, nearest first.

    Those `SAME_FACE_SIZES` times `width_px` wide whose centre lies within `reach` face widths
    of `centre`.
    """
    low, high = SAME_FACE_SIZES
    point = np.asarray(centre, dtype=np.float64)
    gaps = [(float(np.hypot(*(face_centre(b) - point))), b) for b in boxes if low * width_px <= b[2] <= high * width_px]
    return [b for gap, b in sorted(gaps, key=lambda g: g[0]) if gap <= reach * width_px]


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

    def near(self, frame: npt.NDArray[np.uint8], centre: npt.ArrayLike, width_px: float, reach: float) -> list[FaceBox]:
        """`faces_near` of the faces in the square `reach` face widths around `centre`.

        Only that square of the frame is searched, shrunk so the face is about 64 pixels wide,
        and only at `SAME_FACE_SIZES`: about a third of the time of a full search at 640x480.
        """
        if not (width_px > 0 and np.isfinite(width_px)):
            return []
        cx, cy = (float(v) for v in np.asarray(centre, dtype=np.float64))
        if not (np.isfinite(cx) and np.isfinite(cy)):
            return []
        height, width = frame.shape[:2]
        half = reach * width_px
        x0, y0 = max(int(cx - half), 0), max(int(cy - half), 0)
        x1, y1 = min(int(cx + half), width), min(int(cy + half), height)
        if x1 - x0 < width_px or y1 - y0 < width_px:
            return []
        grey = cast(npt.NDArray[np.uint8], cv2.cvtColor(np.ascontiguousarray(frame[y0:y1, x0:x1]), cv2.COLOR_BGR2GRAY))
        s = max(1.0, width_px / 64.0)
        if s > 1:
            grey = cast(npt.NDArray[np.uint8], cv2.resize(grey, None, fx=1 / s, fy=1 / s, interpolation=cv2.INTER_AREA))
        low, high = max(12, int(SAME_FACE_SIZES[0] * width_px / s)), int(np.ceil(SAME_FACE_SIZES[1] * width_px / s))
        # Finer scale steps and one neighbour fewer than a full search: a small square's window
        # grid misses faces the full frame's grid finds (at 1.1 and 4, 3 of 6 test faces).
        found = self._cascade.detectMultiScale(
            grey, scaleFactor=1.05, minNeighbors=3, minSize=(low, low), maxSize=(high, high)
        )
        boxes = [(round(x * s) + x0, round(y * s) + y0, round(w * s), round(h * s)) for x, y, w, h in found]
        return faces_near(boxes, centre, width_px, reach)

    def _detect(self, grey: npt.NDArray[np.uint8], s: float) -> list[FaceBox]:
        if s > 1:
            grey = cast(npt.NDArray[np.uint8], cv2.resize(grey, None, fx=1 / s, fy=1 / s, interpolation=cv2.INTER_AREA))
        smallest = max(12, int(self.min_face_px / s))
        found = self._cascade.detectMultiScale(grey, scaleFactor=1.1, minNeighbors=4, minSize=(smallest, smallest))
        return cast(list[FaceBox], [tuple(int(round(v * s)) for v in box) for box in (found if len(found) else [])])


def box_share(box: FaceBox, mask: npt.NDArray[np.uint8]) -> float:
    """The share of a box's pixels (clipped to the image) that are set in `mask`."""
    x, y, w, h = box
    patch = mask[max(y, 0) : y + h, max(x, 0) : x + w]
    return float(np.count_nonzero(patch)) / max(patch.size, 1)


def choose_face(boxes: list[FaceBox], skin: npt.NDArray[np.uint8], min_skin: float = 0.25) -> FaceBox | None:
    """The face box with the most skin inside (a real face is skin; a false detection rarely is)."""
    best, best_share = None, min_skin
    for box in boxes:
        share = box_share(box, skin)
        if share >= best_share:
            best, best_share = box, share
    return best


def same_place(box: FaceBox, reference: FaceBox, tolerance: float) -> bool:
    """Whether `box` has the centre and width of `reference` within `tolerance` of its width."""
    width = reference[2]
    return (
        float(np.hypot(*(face_centre(box) - face_centre(reference)))) < tolerance * width
        and abs(box[2] - width) < tolerance * width
    )


def steady_face(
    boxes_per_frame: Sequence[list[FaceBox]], share: float, tolerance: float = STEADY_TOLERANCE
) -> FaceBox | None:
    """The face box the cascade found in one place and size in at least `share` of the frames.

    For frames spread over a video (no frame order to follow, unlike `SteadyFace`): each box is
    counted in the frames holding a box `same_place` as it; the box counted in most frames wins,
    the largest on ties. None when no box reaches `share` (or `share` is 0: the rule is off).
    """
    if share <= 0 or not boxes_per_frame:
        return None
    candidates = [box for boxes in boxes_per_frame for box in boxes]
    counts = [sum(any(same_place(b, box, tolerance) for b in boxes) for boxes in boxes_per_frame) for box in candidates]
    ranked = sorted(zip(counts, candidates), key=lambda c: (-c[0], -c[1][2]))
    if not ranked or ranked[0][0] < share * len(boxes_per_frame):
        return None
    return ranked[0][1]


class SteadyFace:
    """The largest face box that the cascade has found in one place for some frames in a row.

    A real face stays put from frame to frame while the cascade's false detections (a cushion,
    a patterned shirt) come and go, so steadiness can stand in for the skin test on a face that
    the light leaves with little generic skin (cool or dim light, a bluish webcam). Every place
    keeps its own run of frames, so a false box that comes and goes beside the face (a larger
    one on a patterned shirt) does not break the face's run.

    Args:
        frames: frames in a row a box must keep its place and size (>= 1).
        tolerance: how far its centre and width may move from where the run of frames began, in
            face widths (measured from the run's first box, so a person walking in, a fifth of
            a face width a frame, is not steady).
    """

    def __init__(self, frames: int, tolerance: float = STEADY_TOLERANCE) -> None:
        self.frames, self.tolerance = frames, tolerance
        self.reset()

    def reset(self) -> None:
        """Forgets the faces seen so far."""
        self._runs: list[tuple[FaceBox, int]] = []  # (the run's first box, frames in a row)

    def update(self, boxes: list[FaceBox]) -> FaceBox | None:
        """Takes one frame's face boxes; returns the largest steady one, or None."""
        runs: list[tuple[FaceBox, int]] = []
        for first, streak in self._runs:
            if any(same_place(box, first, self.tolerance) for box in boxes):
                runs.append((first, streak + 1))
        for box in boxes:
            if not any(same_place(box, first, self.tolerance) for first, _ in runs):
                runs.append((box, 1))
        self._runs = runs
        steady = [
            box
            for box in boxes
            if any(streak >= self.frames and same_place(box, first, self.tolerance) for first, streak in runs)
        ]
        return max(steady, key=lambda b: b[2], default=None)
