"""The face detector looks at full size when the downscaled frame shows no face."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from upperpose.features.faces import FaceDetector, SteadyFace, faces_near

skimage_data = pytest.importorskip("skimage.data")


def small_face_scene(face_px: int) -> np.ndarray:
    """A grey 640x480 frame with the astronaut's face (from scikit-image) about face_px wide."""
    photo = cv2.cvtColor(skimage_data.astronaut(), cv2.COLOR_RGB2BGR)
    x, y, w, h = FaceDetector()(photo)[0]
    crop = photo[max(0, y - w // 2) : y + h + w // 2, max(0, x - w // 2) : x + w + w // 2]
    small = cv2.resize(crop, None, fx=face_px / w, fy=face_px / w, interpolation=cv2.INTER_AREA)
    frame = np.full((480, 640, 3), 128, np.uint8)
    frame[200 : 200 + small.shape[0], 300 : 300 + small.shape[1]] = small
    return frame


def test_a_face_the_downscaled_pass_misses_is_found_at_full_size() -> None:
    frame = small_face_scene(60)
    detector = FaceDetector()
    grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    assert detector._detect(grey, 640 / 427) == []
    (x, y, w, h), *_ = detector(frame)
    assert 300 <= x and x + w <= 300 + 2 * 60 and 200 <= y and abs(w - 60) <= 12


def test_an_empty_frame_has_no_face_at_any_scale() -> None:
    assert FaceDetector()(np.full((480, 640, 3), 128, np.uint8)) == []


def test_near_finds_the_face_around_a_point_at_its_size_only() -> None:
    frame = small_face_scene(60)
    detector = FaceDetector()
    (x, y, w, h), *_ = detector(frame)
    centre = np.array([x + w / 2, y + h / 2])
    # Searched from 1.5 face widths below the face (a head that slid down the chest).
    (nx, ny, nw, nh), *_ = detector.near(frame, centre + [0.0, 1.5 * w], w, 3.0)
    assert abs(nx - x) <= 0.15 * w and abs(ny - y) <= 0.15 * w and abs(nw - w) <= 0.2 * w
    assert detector.near(frame, centre + [0.0, 4.0 * w], w, 3.0) == []  # the face is outside the square
    assert detector.near(frame, centre, 2.5 * w, 3.0) == []  # a face this size is not the person's
    assert detector.near(frame, [np.nan, 0.0], w, 3.0) == [] and detector.near(frame, centre, 0.0, 3.0) == []


def test_faces_near_keeps_the_persons_size_within_reach_nearest_first() -> None:
    boxes = [(260, 100, 40, 40), (112, 150, 36, 36), (110, 100, 80, 80), (100, 100, 40, 40)]
    # Expected a 40 px face centred at (130, 140): the 80 px box is another size; the box at
    # x 260 lies 3.8 face widths off, beyond a reach of 3; the others 0.6 and 0.7 (nearest first).
    assert faces_near(boxes, (130.0, 140.0), 40.0, 3.0) == [(100, 100, 40, 40), (112, 150, 36, 36)]
    assert faces_near(boxes, (130.0, 140.0), 40.0, 4.0)[-1] == (260, 100, 40, 40)


def test_a_steady_face_counts_after_its_frames_and_a_jump_or_a_gap_starts_again() -> None:
    steady = SteadyFace(3)
    face, nudged, jumped = (100, 80, 40, 40), (104, 82, 42, 42), (130, 80, 40, 40)
    assert [steady.update([face]), steady.update([nudged])] == [None, None]
    assert steady.update([face, (10, 10, 20, 20)]) == face  # the largest box, third frame in a row
    assert steady.update([jumped]) is None  # moved 0.75 of its width: a new run
    assert [steady.update([jumped]), steady.update([jumped])] == [None, jumped]
    assert steady.update([]) is None and steady.update([jumped]) is None  # a frame without a face
    steady.reset()
    assert [steady.update([face]) for _ in range(3)] == [None, None, face]
    assert SteadyFace(1).update([face]) == face


def test_a_false_box_that_comes_and_goes_does_not_break_the_faces_run() -> None:
    # A larger false detection on the shirt in frames 2 and 3 (0-based): the face still counts
    # from its first frame, and the false box, never steady, is not returned though larger.
    steady = SteadyFace(4)
    face, shirt = (100, 80, 40, 40), (80, 200, 60, 60)
    frames = [[face], [face], [shirt, face], [shirt, face], [face]]
    assert [steady.update(boxes) for boxes in frames] == [None, None, None, face, face]
    # Two steady boxes: the larger.
    steady = SteadyFace(2)
    assert [steady.update([face, shirt]) for _ in range(2)] == [None, shirt]


def test_a_face_walking_in_is_never_steady() -> None:
    # A fifth of its width a frame: each step is small, the run drifts out of place.
    steady = SteadyFace(3)
    assert all(steady.update([(100 + 8 * k, 80, 40, 40)]) is None for k in range(20))
