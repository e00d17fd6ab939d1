"""Per-frame image features (SPEC 4) on synthetic frames whose truth is known."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from upperpose import Pose
from upperpose.features import (
    POINT_ABSENT,
    POINT_FOUND,
    POINT_MERGED,
    Background,
    FeatureConfig,
    FeatureExtractor,
    compute_features,
    unpack_rows,
)
from upperpose.features.skin import skin_mask
from upperpose.lab.feature_scene import render_scene, textured_background

A_POSE = Pose.a_pose()
MOVED = A_POSE.replace(right_z_up=0.85, right_x_down=0.3)


def iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / (a | b).sum())


@pytest.fixture(scope="module")
def plate() -> np.ndarray:
    return textured_background(480, 640, seed=7)


@pytest.fixture(scope="module")
def background(plate: np.ndarray) -> Background:
    noisy = np.clip(plate + np.random.default_rng(1).normal(0, 2, plate.shape), 0, 255).astype(np.uint8)
    return Background.from_plate(noisy)


@pytest.fixture(scope="module")
def two_frames(plate: np.ndarray):
    return render_scene(A_POSE, plate, seed=2), render_scene(MOVED, plate, seed=3, short_sleeves=True)


def test_silhouette_matches_true_mask(background, two_frames) -> None:
    first, second = two_frames
    extract = FeatureExtractor(background)
    extract(first.frame)
    features = extract(second.frame, first.joints, first.labels)
    assert iou(features.sil > 0, second.mask) >= 0.9
    assert iou(features.sub > 0, second.mask) >= 0.9
    # I_sil is the union of its parts up to the edge rim trim and the closing: nothing far outside.
    outside = (features.sil > 0) & ~second.mask
    assert outside.sum() < 0.05 * second.mask.sum()


def test_feature_images_are_contiguous_0_255(background, two_frames) -> None:
    features = compute_features(two_frames[1].frame, background, two_frames[0].frame)
    for name, image in features.images().items():
        assert image.dtype == np.uint8 and image.flags.c_contiguous, name
        assert set(np.unique(image)) <= {0, 255}, name
    for bits, image in [
        (features.sil_bits, features.sil),
        (features.edge_bits, features.edge_dilated),
        (features.motion_bits, features.motion_dilated),
    ]:
        assert bits.dtype == np.dtype("<u8") and bits.shape == (480, 10) and bits.flags.c_contiguous
        np.testing.assert_array_equal(unpack_rows(bits, 640), image > 0)


def test_edge_is_change_of_gradient_not_background_texture(background, two_frames) -> None:
    features = compute_features(two_frames[0].frame, background)
    edge = features.edge > 0
    near_person = np.zeros_like(edge)
    ys, xs = np.nonzero(two_frames[0].mask)
    near_person[max(ys.min() - 4, 0) : ys.max() + 5, max(xs.min() - 4, 0) : xs.max() + 5] = True
    assert edge.sum() > 500
    assert (edge & ~near_person).sum() < 0.01 * edge.sum()


def test_motion_is_where_the_arm_moved(plate, background, two_frames) -> None:
    first, second = two_frames[0], render_scene(MOVED, plate, seed=3)
    features = compute_features(second.frame, background, first.frame, first.joints, first.labels)
    moved = first.mask ^ second.mask
    motion = features.motion > 0
    assert (motion & moved).sum() > 0.6 * moved.sum()
    # Nothing beyond the blur's reach (two pixels) from either silhouette.
    near = cv2.dilate((first.mask | second.mask).astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    assert not (motion & ~near).any()
    flags = features.motion_flags
    assert flags is not None
    assert flags["right_arm"].moving and not flags["left_arm"].moving and not flags["torso"].moving
    assert flags["left_arm"].count == 0 and flags["torso"].perimeter > flags["right_arm"].perimeter > 100
    # Thesis' combined image is a subset of motion & skin & edge.
    assert not np.any(features.mot_combined & ~(features.motion & features.skin & features.edge))


def test_first_frame_has_no_motion(background, two_frames) -> None:
    features = compute_features(two_frames[0].frame, background)
    assert not features.motion.any()
    assert features.motion_flags is None


def test_skin_points_at_startup(background, two_frames) -> None:
    first = two_frames[0]
    features = compute_features(first.frame, background)
    assert len(features.blobs) == 3
    truth = first.joints[[0, 5, 6]]
    found = features.points_array()
    # Hands within 10 px of the palm centre; head within a quarter of the shoulder width.
    assert np.hypot(*(found[1] - truth[1])) < 10 and np.hypot(*(found[2] - truth[2])) < 10
    assert np.hypot(*(found[0] - truth[0])) < 0.25 * np.hypot(*(first.joints[1] - first.joints[2]))
    np.testing.assert_array_equal(features.point_status(), [POINT_FOUND] * 3)


def test_hand_point_is_far_end_with_short_sleeves(background, two_frames) -> None:
    first, second = two_frames
    features = compute_features(second.frame, background, first.frame, first.joints)
    blob = features.blobs[features.right_hand.blob]
    truth = second.joints[5]
    assert np.hypot(*(np.array(features.right_hand.xy) - truth)) < 10
    # The blob covers the forearm too: its centroid is far from the hand.
    assert np.hypot(*(np.array(blob.centroid) - truth)) > 25


def test_cover_skin_is_the_skin_without_the_head_blob(background, two_frames) -> None:
    first, second = two_frames
    features = compute_features(second.frame, background, first.frame, first.joints)
    cover = unpack_rows(features.cover_bits, 640) > 0
    skin = features.skin > 0
    head = features.blobs[features.head.blob]
    hand = features.blobs[features.right_hand.blob]
    assert head.area > 300 and not cover[head.ys, head.xs].any()
    assert cover[hand.ys, hand.xs].all()
    outside_head = np.ones_like(skin)
    outside_head[head.ys, head.xs] = False
    np.testing.assert_array_equal(cover, skin & outside_head)


def test_hand_on_face_is_merged(plate, background) -> None:
    pose = Pose(right_x_up=1.9, right_z_up=0.6, right_x_down=2.2, left_z_up=0.6)
    scene = render_scene(pose, plate, seed=4)
    head, hand = scene.joints[0], scene.joints[5]
    assert np.hypot(*(head - hand)) < 40, "pose must put the right hand on the face"
    features = compute_features(scene.frame, background, predicted_joints=scene.joints)
    assert features.head is not None and features.right_hand is not None
    assert features.head.merged and features.right_hand.merged
    assert features.head.blob == features.right_hand.blob
    assert not features.left_hand.merged
    np.testing.assert_array_equal(features.point_status(), [POINT_MERGED, POINT_MERGED, POINT_FOUND])
    assert np.isnan(features.points_array()[:2]).all()


def test_a_hand_predicted_out_of_the_image_is_boxed_beyond_the_border(background, two_frames) -> None:
    # The right hand predicted far beyond the left border, with no skin in its gate: the cost is
    # given the band beyond that border (the search keeps the hand out until its skin returns);
    # it is still an absent point, not a measurement.
    first, _ = two_frames
    predicted = first.joints.copy()
    predicted[5] = (-600.0, 300.0)
    features = compute_features(first.frame, background, predicted_joints=predicted)
    assert features.right_hand is None and features.left_hand is not None
    assert features.hands_beyond == ((-640.5, -480.5, -0.5, 959.5), None)
    assert features.point_status()[1] == POINT_ABSENT
    np.testing.assert_array_equal(features.merged_boxes_array()[1], [-640.5, -480.5, -0.5, 959.5])
    assert np.isnan(features.merged_boxes_array()[2]).all() and np.isnan(features.points_array()[1]).all()
    # Without a prediction (start-up) nothing is beyond.
    assert compute_features(first.frame, background).hands_beyond == (None, None)


def test_static_skin_coloured_object_gives_no_blob(plate) -> None:
    scene_plate = plate.copy()
    scene_plate[40:120, 500:600] = (110, 140, 200)  # a wooden box, R - G = 60
    background = Background.from_plate(scene_plate)
    scene = render_scene(A_POSE, scene_plate, seed=5)
    features = compute_features(scene.frame, background)
    assert features.skin0[40:120, 500:600].all()
    assert not features.skin[40:120, 500:600].any()
    assert len(features.blobs) == 3
    assert all(not (480 <= b.centroid[0] <= 620 and 20 <= b.centroid[1] <= 140) for b in features.blobs)


def test_moving_hand_leaves_no_skin_trail_over_skin_coloured_room(plate) -> None:
    # A hand moving over a wooden panel: where it was a frame before, I_motion fires on
    # skin-coloured room that is back to the plate's colour; that trail is not skin.
    scene_plate = plate.copy()
    scene_plate[200:320, 380:600] = (110, 140, 200)  # R - G = 60, like skin
    rng = np.random.default_rng(6)

    def frame_with_hand(x: int) -> np.ndarray:
        frame = scene_plate.copy()
        cv2.ellipse(frame, (x, 260), (24, 14), 0, 0, 360, (60, 90, 150), -1)  # dark skin
        return np.clip(frame + rng.normal(0, 2, frame.shape), 0, 255).astype(np.uint8)

    was, now = np.zeros((480, 640), np.uint8), np.zeros((480, 640), np.uint8)
    cv2.ellipse(was, (440, 260), (24, 14), 0, 0, 360, 255, -1)
    cv2.ellipse(now, (530, 260), (24, 14), 0, 0, 360, 255, -1)
    features = compute_features(frame_with_hand(530), Background.from_plate(scene_plate), frame_with_hand(440))
    assert features.motion[was > 0].mean() > 200 and features.skin0[was > 0].mean() > 200
    assert not features.skin[was > 0].any()
    assert features.skin[now > 0].mean() > 200
    assert [round(b.centroid[0]) for b in features.blobs] == [530]


def test_skin_blob_on_background_without_edge_change_is_dropped(plate) -> None:
    # A skin-coloured patch that appears in the frame but has no texture change relative to
    # the plate's gradient is dropped by the gradient probability, not by size (with the
    # colour path off: the patch differs from the plate all over and the room all round it,
    # which keeps a limb, test_features_points.py).
    background = Background.from_plate(plate)
    frame = plate.copy()
    frame[200:300, 20:140] = (110, 140, 200)
    config = FeatureConfig(blob_min_gradient=0.2, blob_min_changed=1.1)
    features = compute_features(frame, background, config=config)
    assert features.skin[200:300, 20:140].mean() > 200
    assert features.blobs == []


@pytest.mark.parametrize("space", ["ycrcb", "hsv", "rgb"])
def test_other_skin_spaces_find_the_hands(background, two_frames, space: str) -> None:
    config = FeatureConfig(skin_space=space)
    first = two_frames[0]
    features = compute_features(first.frame, background.with_config(config), config=config)
    truth_skin = np.isin(first.labels, (2, 3)) | (first.mask & (first.labels == 0))
    skin = features.skin > 0
    assert (skin & truth_skin).sum() > 0.8 * truth_skin.sum()
    assert (skin & ~first.mask).sum() < 0.02 * truth_skin.sum()


def test_default_skin_rule_rejects_cloth_the_thesis_rule_takes() -> None:
    # BGR: skin from light to dark, then yellow, purple and orange cloth with 20 <= R - G <= 80.
    skin_tones = [(180, 200, 240), (120, 150, 200), (70, 100, 150), (40, 60, 100), (25, 40, 70)]
    cloth = [(40, 190, 220), (110, 40, 100), (30, 120, 180)]
    patches = np.array([skin_tones + cloth], np.uint8)
    thesis = skin_mask(patches, FeatureConfig(skin_space="rgb"))[0] > 0
    default = skin_mask(patches, FeatureConfig())[0] > 0
    assert thesis.all()
    assert default[: len(skin_tones)].all()
    assert not default[len(skin_tones) :].any()


def test_arm_silhouette_is_outside_the_torso(background, two_frames) -> None:
    first, second = two_frames
    features = compute_features(second.frame, background, first.frame, first.joints, first.labels)
    assert features.arm_sil is not None and features.arm_bits is not None
    torso = np.isin(first.labels, (1, 2, 3))
    assert not (features.arm_sil[torso] > 0).any()
    arms = np.isin(second.labels, (4, 5, 6, 7)) & ~torso
    assert ((features.arm_sil > 0) & arms).sum() > 0.9 * arms.sum()
    # Recut with the torso just fitted, and from the shoulders alone.
    recut = features.with_torso_region(np.isin(second.labels, (1, 2, 3)))
    assert not (recut.arm_sil[np.isin(second.labels, (1, 2, 3))] > 0).any()
    only_shoulders = compute_features(second.frame, background, first.frame, first.joints)
    assert only_shoulders.arm_sil is not None
    mid_x = round(float(first.joints[1:3, 0].mean()))
    assert not (only_shoulders.arm_sil[:, mid_x] > 0).any()


def test_reused_buffers_give_same_features(background, two_frames) -> None:
    first, second = two_frames
    fresh, reused = (
        FeatureExtractor(background),
        FeatureExtractor(background, reuse_buffers=True),
    )
    for extract in (fresh, reused):
        extract(first.frame)
    a, b = (
        fresh(second.frame, first.joints, first.labels),
        reused(second.frame, first.joints, first.labels),
    )
    for name, image in a.images().items():
        np.testing.assert_array_equal(image, b.images()[name], err_msg=name)
    np.testing.assert_array_equal(a.sil_bits, b.sil_bits)
    assert a.points == b.points


def test_blob_gradient_counts_the_dilated_edges(background, two_frames) -> None:
    first, second = two_frames
    features = compute_features(second.frame, background, first.frame)
    assert features.blobs
    for blob in features.blobs:
        assert blob.gradient == pytest.approx(np.mean(features.edge_dilated[blob.ys, blob.xs] > 0))
