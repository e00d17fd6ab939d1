"""Head and hand points from skin blobs: matching, far end, merged blobs (SPEC 4)."""

from __future__ import annotations

import cv2
import numpy as np

from upperpose.features import FeatureConfig, find_skin_blobs, locate_points

CONFIG = FeatureConfig()


def joints(head, right_hand, left_hand, right_elbow=None, left_elbow=None) -> np.ndarray:
    """Predicted joints (JOINT_NAMES order) with shoulders 100 px apart below the head."""
    rs, ls = (head[0] - 50, head[1] + 70), (head[0] + 50, head[1] + 70)
    re = right_elbow or (rs[0] - 10, rs[1] + 60)
    le = left_elbow or (ls[0] + 10, ls[1] + 60)
    return np.array([head, rs, ls, re, le, right_hand, left_hand], np.float64)


def blobs_of(*shapes) -> list:
    skin = np.zeros((480, 640), np.uint8)
    for draw in shapes:
        draw(skin)
    edge = cv2.morphologyEx(skin, cv2.MORPH_GRADIENT, np.ones((3, 3), np.uint8))
    return find_skin_blobs(skin, edge, CONFIG)


def face(skin):
    cv2.ellipse(skin, (320, 100), (28, 36), 0, 0, 360, 255, -1)


def test_three_separate_blobs_are_matched() -> None:
    blobs = blobs_of(
        face,
        lambda s: cv2.circle(s, (200, 300), 14, 255, -1),
        lambda s: cv2.circle(s, (440, 310), 14, 255, -1),
    )
    head, right, left = locate_points(blobs, joints((318, 104), (205, 295), (436, 305)), CONFIG)
    assert not (head.merged or right.merged or left.merged)
    assert np.hypot(right.xy[0] - 200, right.xy[1] - 300) < 3
    assert np.hypot(left.xy[0] - 440, left.xy[1] - 310) < 3
    assert abs(head.xy[0] - 320) < 2


def test_hands_together_are_merged() -> None:
    def together(s):
        return cv2.ellipse(s, (320, 330), (30, 14), 0, 0, 360, 255, -1)

    blobs = blobs_of(face, together)
    head, right, left = locate_points(blobs, joints((320, 100), (305, 330), (335, 330)), CONFIG)
    assert right.merged and left.merged and right.blob == left.blob
    assert not head.merged


def test_hand_near_face_but_separate_is_not_merged() -> None:
    def hand(s):
        return cv2.circle(s, (372, 112), 12, 255, -1)  # 12 px gap to the face

    blobs = blobs_of(face, hand, lambda s: cv2.circle(s, (200, 300), 14, 255, -1))
    # The prediction of the left hand lies between face and hand: the assignment still separates them.
    head, _, left = locate_points(blobs, joints((320, 100), (200, 300), (360, 110)), CONFIG)
    assert not head.merged and not left.merged
    assert np.hypot(left.xy[0] - 372, left.xy[1] - 112) < 3


def test_far_end_of_a_forearm_blob() -> None:
    # Bare forearm from (200, 250) to (140, 370) ending in the hand: the point is near the hand.
    def forearm(s):
        return cv2.line(s, (200, 250), (140, 370), 255, 22)

    def hand(s):
        return cv2.circle(s, (133, 384), 15, 255, -1)

    blobs = blobs_of(face, forearm, hand)
    prediction = joints((320, 100), (138, 378), (500, 300), right_elbow=(202, 246))
    _, right, left = locate_points(blobs, prediction, CONFIG)
    assert left is None  # nothing near the predicted left hand
    blob = blobs[right.blob]
    assert np.hypot(right.xy[0] - 133, right.xy[1] - 384) < 10
    assert np.hypot(blob.centroid[0] - 133, blob.centroid[1] - 384) > 40


def test_no_blob_within_gate_is_absent() -> None:
    blobs = blobs_of(face)
    head, right, left = locate_points(blobs, joints((320, 100), (100, 450), (560, 450)), CONFIG)
    assert head is not None and right is None and left is None


def test_startup_assigns_by_side_of_head() -> None:
    blobs = blobs_of(
        face,
        lambda s: cv2.circle(s, (200, 330), 14, 255, -1),
        lambda s: cv2.circle(s, (460, 330), 16, 255, -1),
    )
    head, right, left = locate_points(blobs, None, CONFIG)
    assert head.xy[1] < 120 and right.xy[0] < 260 and left.xy[0] > 400
    one_hand = blobs_of(face, lambda s: cv2.circle(s, (460, 330), 16, 255, -1))
    head, right, left = locate_points(one_hand, None, CONFIG)
    assert right is None and left is not None
    assert locate_points([], None, CONFIG) == [None, None, None]
