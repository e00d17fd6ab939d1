"""A hand on skin-coloured hair: one skin blob with the face, split back into head and hand."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.features import POINT_FOUND, POINT_MERGED, Background, FeatureConfig, compute_features
from upperpose.features.blobs import blob_from_pixels
from upperpose.lab.feature_scene import SKIN_BGR

WALL_BGR = (190, 195, 200)
SHIRT_BGR = (150, 90, 50)
BROWN_HAIR_BGR = (45, 70, 110)  # passes the skin rule: R - G = 40, Cr 150, Cb 112
HEAD, FACE_AXES, HAIR_RADIUS = (320, 110), (28, 34), 40
ELBOW = (430, 170)


def joints(hand: tuple[int, int]) -> np.ndarray:
    """Predicted joints (JOINT_NAMES order): shoulders 100 px apart, the left hand at `hand`."""
    return np.array([HEAD, (270, 180), (370, 180), (230, 260), ELBOW, (200, 330), hand], np.float64)


def frame_with_hand(hand: tuple[int, int], draw_hand: bool = True) -> np.ndarray:
    """A face inside brown hair, the right hand far below, the left hand (on a sleeved forearm) at `hand`."""
    frame = np.full((480, 640, 3), WALL_BGR, np.uint8)
    cv2.ellipse(frame, HEAD, (HAIR_RADIUS, HAIR_RADIUS), 0, 180, 360, BROWN_HAIR_BGR, -1)  # the top half
    cv2.ellipse(frame, HEAD, FACE_AXES, 0, 0, 360, SKIN_BGR, -1)
    cv2.circle(frame, (200, 330), 14, SKIN_BGR, -1)
    if draw_hand:
        cv2.line(frame, ELBOW, (hand[0] + 20, hand[1]), SHIRT_BGR, 16)
        cv2.ellipse(frame, hand, (22, 10), 0, 0, 360, SKIN_BGR, -1)
    noise = np.random.default_rng(0).normal(0, 2, frame.shape)
    return np.clip(frame + noise, 0, 255).astype(np.uint8)


@pytest.fixture(scope="module")
def background() -> Background:
    return Background.from_plate(np.full((480, 640, 3), WALL_BGR, np.uint8))


def test_hand_on_hair_is_split_from_the_face(background) -> None:
    hand = (378, 95)  # touches the hair beside the forehead, 11 px of hair from the face
    features = compute_features(frame_with_hand(hand), background, predicted_joints=joints(hand))
    np.testing.assert_array_equal(features.point_status(), [POINT_FOUND] * 3)
    head, left = features.points_array()[[0, 2]]
    assert np.hypot(*(left - hand)) < 5
    # The head keeps its hair: about the blob width and point it has without the hand.
    alone = compute_features(frame_with_hand(hand, draw_hand=False), background, predicted_joints=joints((520, 300)))
    assert np.hypot(*(head - alone.points_array()[0])) < 1.5
    width, alone_width = (f.blobs[f.head.blob].bbox[2] for f in (features, alone))
    assert abs(width - alone_width) <= 0.05 * alone_width
    assert features.head.blob != features.left_hand.blob
    # Without the split the hair joins them into one blob, reported merged.
    unsplit = FeatureConfig(split_chroma=1.0)
    merged = compute_features(frame_with_hand(hand), background, predicted_joints=joints(hand), config=unsplit)
    np.testing.assert_array_equal(merged.point_status(), [POINT_MERGED, POINT_FOUND, POINT_MERGED])


def test_hand_on_the_face_stays_merged(background) -> None:
    hand = (366, 128)  # overlaps the cheek, below the hair: skin on skin
    features = compute_features(frame_with_hand(hand), background, predicted_joints=joints(hand))
    np.testing.assert_array_equal(features.point_status(), [POINT_MERGED, POINT_FOUND, POINT_MERGED])
    assert features.head.blob == features.left_hand.blob


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 59), st.integers(0, 39), st.integers(1, 12)), min_size=1, max_size=4))
def test_a_blob_box_holds_every_pixel_of_every_piece(discs: list[tuple[int, int, int]]) -> None:
    # A split blob's head keeps its hair, which may lie apart from the face: cutting a mask of
    # the box (as the split does) must not drop or overrun any pixel.
    pixels = np.zeros((40, 60), np.uint8)
    for x, y, r in discs:
        cv2.circle(pixels, (x, y), r, 255, -1)
    blob = blob_from_pixels(pixels, (100, 50), 0.5)
    x, y, w, h = blob.bbox
    assert blob.xs.min() >= x and blob.xs.max() < x + w and blob.ys.min() >= y and blob.ys.max() < y + h
    ys, xs = np.nonzero(pixels)
    assert (x, y, w, h) == (xs.min() + 100, ys.min() + 50, xs.max() - xs.min() + 1, ys.max() - ys.min() + 1)
