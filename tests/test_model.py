"""The Python model API: kinematics, projection and rendering against independent references."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import upperpose
from conftest import random_pose
from upperpose.model import penetrates


def test_rest_pose_model_points_match_hand_computed_values(body: upperpose.BodyModel) -> None:
    joints = upperpose.model.model_points(upperpose.Pose(), [0.1, -0.2, 2.5], body)
    expected = np.array(
        [
            [0.1, -0.2 - 0.44, 2.5],
            [0.1 - 0.18, -0.4, 2.5],
            [0.1 + 0.18, -0.4, 2.5],
            [0.1 - 0.18, -0.4 + 0.29, 2.5],
            [0.1 + 0.18, -0.4 + 0.29, 2.5],
            [0.1 - 0.18, -0.4 + 0.63, 2.5],
            [0.1 + 0.18, -0.4 + 0.63, 2.5],
        ]
    )
    np.testing.assert_allclose(joints, expected, atol=1e-9)


def test_rest_pose_anatomical_joints_sit_inside_the_solids(body: upperpose.BodyModel) -> None:
    root = np.array([0.1, -0.2, 2.5])
    joints = upperpose.forward_kinematics(upperpose.Pose(), root, body)
    model = upperpose.model.model_points(upperpose.Pose(), root, body)
    # Centre of the head 0.25 of the head ellipsoid's half height (0.11 m) above the face's centre.
    np.testing.assert_allclose(joints[0] - model[0], [0.0, -0.0275, 0.0], atol=1e-9)
    # Glenohumeral centres 3.5 cm inwards of and 3 cm above the upper-arm cones' tops: inside the
    # torso's width and within the cone's top radius (the deltoid stands outside them).
    np.testing.assert_allclose(joints[1] - root, [-0.145, -0.23, 0.0], atol=1e-9)
    np.testing.assert_allclose(joints[2] - root, [0.145, -0.23, 0.0], atol=1e-9)
    for k in (1, 2):
        assert abs(joints[k, 0] - root[0]) < body.torso_half_width
        assert np.linalg.norm(joints[k] - model[k]) < body.upper_arm_radii[0]
    np.testing.assert_allclose(joints[3:5], model[3:5], atol=1e-12)
    # Palm centres 0.14 of the lower arm (4.76 cm) short of the forearm cones' ends.
    np.testing.assert_allclose(joints[5:] - model[5:], [[0.0, -0.0476, 0.0]] * 2, atol=1e-9)
    # The solids are placed around the model points: the forearm cone ends there, not at the palm.
    cone = upperpose.model.solids(upperpose.Pose(), root, body)[4]
    np.testing.assert_allclose(cone["p1"], model[5], atol=1e-12)


def test_abduction_and_elbow_flexion_by_name(body: upperpose.BodyModel) -> None:
    pose = upperpose.Pose(right_z_up=math.pi / 2, left_x_down=math.pi / 2)
    j = upperpose.forward_kinematics(pose, [0.0, 0.0, 3.0], body)
    palm = 0.14 * 0.34  # the palm centre short of the forearm cone's end, along the forearm
    np.testing.assert_allclose(j[5], [-0.18 - 0.63 + palm, -0.2, 3.0], atol=1e-9)  # right hand out to the side
    np.testing.assert_allclose(j[6], [0.18, 0.09, 3.0 - 0.34 + palm], atol=1e-9)  # left forearm at the camera


def test_pose_accepts_names_dicts_and_arrays() -> None:
    p = upperpose.Pose(right_x_up=0.5)
    assert p["right_x_up"] == 0.5
    assert upperpose.model.pose_array({"right_x_up": 0.5}).tolist() == p.angles.tolist()
    assert p.replace(right_x_up=0.0) == upperpose.Pose()
    assert not p.angles.flags.writeable
    with pytest.raises(ValueError, match="unknown angle 'elbow'"):
        upperpose.Pose(elbow=1.0)


def test_pinhole_weak_and_orthographic_projection_are_exact() -> None:
    pts = np.array([[0.3, -0.2, 2.0], [-1.0, 0.5, 4.0], [0.0, 0.0, -1.0]])
    pin = upperpose.Camera.perspective(600.0, 320.0, 240.0)
    uv = upperpose.project(pin, pts)
    np.testing.assert_array_equal(uv[:2], 600.0 * pts[:2, :2] / pts[:2, 2:] + [320.0, 240.0])
    assert np.isnan(uv[2]).all()  # behind the camera
    weak = upperpose.Camera.weak_perspective(600.0, 320.0, 240.0, reference_depth=3.0)
    np.testing.assert_array_equal(upperpose.project(weak, pts), 200.0 * pts[:, :2] + [320.0, 240.0])
    ortho = upperpose.Camera.orthographic(150.0, 10.0, 20.0)
    np.testing.assert_array_equal(upperpose.project(ortho, pts), 150.0 * pts[:, :2] + [10.0, 20.0])


def test_default_camera_follows_the_spec() -> None:
    cam = upperpose.Camera.for_image(640, 480)
    assert (cam.kind, cam.focal, cam.cx, cam.cy) == ("perspective", 640.0, 319.5, 239.5)
    assert upperpose.Camera.for_image(640, 480, focal=500.0).focal == 500.0


def _reference_silhouette(solid: dict, camera: upperpose.Camera, width: int, height: int) -> np.ndarray:
    """Dense points on the solid's surface, projected one by one; a pixel is in when its centre
    lies in the convex hull of the projected points (each part is convex)."""
    k = 360
    t = np.linspace(0.0, 2.0 * np.pi, k, endpoint=False)
    if solid["kind"] == "frustum":
        rings = []
        for c, r in ((solid["p0"], solid["radii0"]), (solid["p1"], solid["radii1"])):
            rings.append(c + np.outer(np.cos(t) * r[0], solid["e1"]) + np.outer(np.sin(t) * r[1], solid["e2"]))
        pts = np.vstack(rings)
    else:
        u, v = np.meshgrid(t, np.linspace(0.0, np.pi, k // 2))
        unit = np.stack([np.sin(v) * np.cos(u), np.sin(v) * np.sin(u), np.cos(v)], -1).reshape(-1, 3)
        pts = solid["centre"] + unit @ solid["axes"].T
    uv = upperpose.project(camera, pts)
    hull = cv2.convexHull(uv.astype(np.float32)).reshape(-1, 2).astype(np.float64)
    x0, y0 = np.clip(np.floor(hull.min(0)).astype(int) - 1, 0, [width, height])
    x1, y1 = np.clip(np.ceil(hull.max(0)).astype(int) + 2, 0, [width, height])
    ys, xs = np.mgrid[y0:y1, x0:x1]
    inside = np.ones(ys.shape, bool)
    area2 = np.sum(hull[:, 0] * np.roll(hull[:, 1], -1) - hull[:, 1] * np.roll(hull[:, 0], -1))
    for a, b in zip(hull, np.roll(hull, -1, axis=0)):
        cross = (b[0] - a[0]) * (ys - a[1]) - (b[1] - a[1]) * (xs - a[0])
        inside &= np.sign(area2) * cross >= -1e-9
    mask = np.zeros((height, width), np.uint8)
    mask[y0:y1, x0:x1] = inside
    return mask


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_part_silhouettes_match_dense_surface_sampling(seed: int, camera: upperpose.Camera) -> None:
    rng = np.random.default_rng(seed)
    pose = random_pose(rng)
    root = [rng.uniform(-0.3, 0.3), rng.uniform(-0.1, 0.3), rng.uniform(1.8, 3.5)]
    masks = upperpose.render_masks(pose, root, camera, 640, 480)
    for solid in upperpose.solids(pose, root):
        ours = masks[solid["part"]]
        ref = _reference_silhouette(solid, camera, 640, 480)
        union = np.logical_or(ours, ref).sum()
        iou = np.logical_and(ours, ref).sum() / max(union, 1)
        if ref.sum() >= 1000:
            assert iou >= 0.98, (solid["part"], iou)
        else:
            # Small parts: every disagreement lies within one pixel of the reference outline.
            diff = ours != ref
            edge = cv2.dilate(ref, np.ones((3, 3), np.uint8)) != cv2.erode(ref, np.ones((3, 3), np.uint8))
            assert not np.any(diff & ~edge), solid["part"]


def test_masks_are_consistent_with_each_other(camera: upperpose.Camera) -> None:
    pose = upperpose.Pose(right_x_up=0.5, right_y_up=1.2, right_x_down=1.6, left_z_up=0.7)
    m = upperpose.render_masks(pose, [0.0, 0.1, 2.2], camera, 640, 480)
    parts = np.stack([m[name] for name in upperpose.PART_NAMES])
    np.testing.assert_array_equal(m["silhouette"], parts.max(0))
    np.testing.assert_array_equal(m["labels"] > 0, m["silhouette"] > 0)
    # Each visible pixel's label names a part that covers it.
    ys, xs = np.nonzero(m["labels"])
    assert np.all(parts[m["labels"][ys, xs] - 1, ys, xs] == 1)
    # Contours lie on their part, and the union contour is the union of the parts'.
    for name in upperpose.PART_NAMES:
        assert not np.any(m[f"{name}_contour"] & ~m[name].astype(bool))
    contours = np.stack([m[f"{n}_contour"] for n in upperpose.PART_NAMES]).max(0)
    np.testing.assert_array_equal(m["contour"], contours)
    # The right forearm crosses in front of the torso here: it hides the torso where they overlap.
    forearm = upperpose.PART_NAMES.index("right_lower_arm") + 1
    overlap = (m["right_lower_arm"] & m["torso"]).astype(bool)
    assert overlap.sum() > 100 and np.all(m["labels"][overlap] == forearm)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_labels_alone_are_the_masks_labels(seed: int, camera: upperpose.Camera) -> None:
    rng = np.random.default_rng(seed)
    pose = random_pose(rng)
    root = [rng.uniform(-0.3, 0.3), rng.uniform(-0.1, 0.3), rng.uniform(1.2, 3.5)]
    x, y = int(rng.integers(0, 600)), int(rng.integers(0, 440))
    for roi in (None, (x, y, int(rng.integers(1, 641 - x)), int(rng.integers(1, 481 - y)))):
        labels = upperpose.render_labels(pose, root, camera, 640, 480, roi=roi)
        masks = upperpose.render_masks(pose, root, camera, 640, 480, roi=roi)
        assert labels.dtype == np.uint8
        np.testing.assert_array_equal(labels, masks["labels"])
    assert labels.shape == (roi[3], roi[2])


def test_region_of_interest_crops_the_full_render(camera: upperpose.Camera) -> None:
    pose = upperpose.Pose.a_pose()
    full = upperpose.render_masks(pose, [0.0, 0.1, 2.2], camera, 640, 480)
    roi = upperpose.render_masks(pose, [0.0, 0.1, 2.2], camera, 640, 480, roi=(200, 100, 130, 90))
    for key, image in roi.items():
        assert image.shape == (90, 130) and image.dtype == np.uint8
        np.testing.assert_array_equal(image, full[key][100:190, 200:330], err_msg=key)


def test_contour_is_the_visible_one_pixel_boundary(camera: upperpose.Camera) -> None:
    m = upperpose.render_masks(upperpose.Pose(), [0.0, 0.1, 2.2], camera, 640, 480)
    cross = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], np.uint8)
    for k, name in enumerate(upperpose.PART_NAMES):
        part = m[name]
        boundary = part & ~cv2.erode(part, cross, borderValue=0) & 1
        visible = (m["labels"] == k + 1).astype(np.uint8)
        np.testing.assert_array_equal(m[f"{name}_contour"], boundary & visible, err_msg=name)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"pose": np.zeros(12)}, ValueError, r"pose must have shape \(13,\), got \(12,\)"),
        ({"pose": np.full(13, np.nan)}, ValueError, "pose must be finite"),
        ({"pose": np.array(["a"] * 13)}, TypeError, "pose must be a numeric array"),
        ({"root": [0.0, 0.0]}, ValueError, r"root must have shape \(3,\)"),
        ({"root": [0.0, np.inf, 2.0]}, ValueError, "root must be finite"),
        ({"roi": (600, 0, 100, 10)}, ValueError, "region of interest"),
        ({"roi": (0, 0, 0, 10)}, ValueError, "region of interest"),
        ({"width": 0}, ValueError, "width must be a positive integer"),
    ],
)
def test_bad_arguments_are_named(kwargs: dict, error: type, message: str, camera: upperpose.Camera) -> None:
    args = {"pose": np.zeros(13), "root": [0.0, 0.0, 2.0], "camera": camera, "width": 640, "height": 480}
    args.update(kwargs)
    with pytest.raises(error, match=message):
        upperpose.render_masks(**args)


def test_bad_camera_and_body_values_are_named() -> None:
    with pytest.raises(ValueError, match="focal must be finite, got NaN"):
        upperpose.Camera.perspective(float("nan"), 0.0, 0.0)
    with pytest.raises(ValueError, match="reference_depth must be > 0"):
        upperpose.Camera.weak_perspective(500.0, 0.0, 0.0, -1.0)
    with pytest.raises(ValueError, match="upper_arm_length must be > 0, got -0.3"):
        upperpose.BodyModel(upper_arm_length=-0.3)
    with pytest.raises(ValueError, match=r"points must have shape \(N, 3\)"):
        upperpose.project(upperpose.Camera.for_image(64, 48), np.zeros((4, 2)))


def test_body_model_round_trips_through_a_dict() -> None:
    b = upperpose.BodyModel(shoulder_width=0.4, head_radii=[0.08, 0.12, 0.1])
    assert upperpose.BodyModel(**b.as_dict()) == b
    assert b.shoulder_width == 0.4 and b.head_radii == [0.08, 0.12, 0.1]


def test_joint_limit_presets() -> None:
    anatomical = upperpose.joint_limits()
    assert len(anatomical) == 13 and anatomical[upperpose.ANGLE_NAMES.index("right_x_up")] == [(-0.8, 3.1)]
    thesis = upperpose.joint_limits("thesis")
    x_up = thesis[upperpose.ANGLE_NAMES.index("left_x_up")]
    assert x_up == [(0.0, math.pi / 3), (math.pi / 1.4, math.pi)]
    with pytest.raises(ValueError, match="preset must be"):
        upperpose.joint_limits("yoga")


def _segment_gap(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> float:
    """Closest distance of two segments by dense sampling (a reference independent of the core)."""
    s = np.linspace(0.0, 1.0, 801)[:, None]
    p, q = p0 + (p1 - p0) * s, q0 + (q1 - q0) * s
    return float(min(np.linalg.norm(p - qi, axis=1).min() for qi in q))


def test_penetrates_flags_the_trunk_and_arms_closer_than_half_their_radii(body: upperpose.BodyModel) -> None:
    root = np.array([0.0, 0.0, 2.2])
    assert not penetrates(upperpose.Pose(), root, body)
    assert not penetrates(upperpose.Pose.a_pose(), root, body)
    # Adducted across the chest without flexing forwards: the upper arm runs through the torso.
    assert penetrates({"right_z_up": -0.3, "right_y_up": 1.5, "right_x_down": 1.6}, root, body)
    # Forearms swung together in front of the chest: the rule is the arms' closest approach
    # against half their summed mean radii (upper arm and forearm take their own radius).
    d = body.as_dict()
    r = {"upper": sum(d["upper_arm_radii"]) / 2, "lower": sum(d["lower_arm_radii"]) / 2}
    decided = set()
    for swing in np.linspace(0.2, 0.9, 36):
        side = {"y_up": float(swing), "x_up": 0.47, "z_up": 0.32, "x_down": 1.61}
        pose = {f"{s}_{k}": v for s in ("right", "left") for k, v in side.items()}
        j = upperpose.model.model_points(pose, root, body)
        arms = [[(j[1], j[3], "upper"), (j[3], j[5], "lower")], [(j[2], j[4], "upper"), (j[4], j[6], "lower")]]
        slack = min(
            _segment_gap(a0, a1, b0, b1) - 0.5 * (r[ra] + r[rb]) for a0, a1, ra in arms[0] for b0, b1, rb in arms[1]
        )
        if abs(slack) > 1e-3:  # away from the boundary, where sampling decides nothing
            assert penetrates(pose, root, body) == (slack < 0), swing
            decided.add(slack < 0)
    assert decided == {True, False}
    with pytest.raises(ValueError, match="root"):
        penetrates(upperpose.Pose(), [0.0, np.nan, 2.0], body)
