"""Bone-length comparison of a prediction with the truth (upperpose.lab.proportions)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import upperpose
from upperpose.io.posefile import make_poses
from upperpose.lab.proportions import bone_lengths, compare_bones, main

ROOT = np.array([0.05, 0.1, 2.2])
CAMERA = upperpose.Camera.for_image(640, 480)


def _poses(body: upperpose.BodyModel, poses: list[np.ndarray], scale: float = 1.0) -> dict[str, object]:
    """A pose document whose 3D joints are the body's at `poses`, scaled about the camera."""
    frames = []
    for k, pose in enumerate(poses):
        joints = scale * upperpose.forward_kinematics(pose, ROOT, body)
        pixels = upperpose.project(CAMERA, joints)
        frames.append({"frame": k, "status": "tracked", "joints_2d": pixels.tolist(), "joints_3d": joints.tolist()})
    return make_poses(640, 480, 30.0, frames)


def _random_poses(seed: int, count: int = 5) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    low, high = np.zeros(13), np.zeros(13)
    low[[4, 5, 6, 9, 10, 11]], high[[4, 5, 6, 9, 10, 11]] = 0.0, 1.5
    return [rng.uniform(low, high) for _ in range(count)]


def test_bone_lengths_of_a_hand_made_skeleton() -> None:
    joints = [
        [0, -0.3, 2],
        [-0.15, 0, 2],
        [0.15, 0, 2],
        [-0.15, 0.3, 2],
        [0.15, 0.28, 2],
        [-0.15, 0.3, 1.75],
        [0.4, 0.28, 2],
    ]
    lengths = bone_lengths(joints)
    assert lengths == pytest.approx({"shoulder_width": 0.3, "upper_arm": 0.29, "forearm": 0.25, "neck": 0.3})


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.7, 1.4))
def test_a_person_scaled_about_the_camera_looks_the_same_size(seed: int, scale: float) -> None:
    body = upperpose.BodyModel()
    poses = _random_poses(seed)
    result = compare_bones(_poses(body, poses, scale), _poses(body, poses))
    assert result is not None
    for name in ("shoulder_width", "upper_arm", "forearm", "neck"):
        assert result["metric"][name] == pytest.approx(scale, rel=1e-9)
        assert result["image"][name] == pytest.approx(1.0, rel=1e-9)
    assert result["depth"]["ratio"] == pytest.approx(scale, rel=1e-9)


def test_a_longer_upper_arm_is_measured_as_such() -> None:
    truth_body = upperpose.BodyModel()
    # The reported upper arm runs from the glenohumeral centre to the elbow: compare it directly.
    longer = upperpose.BodyModel(upper_arm_length=truth_body.upper_arm_length * 1.2)
    poses = _random_poses(3)
    truth, mine = _poses(truth_body, poses), _poses(longer, poses)
    expected = np.median(
        [
            bone_lengths(p["joints_3d"])["upper_arm"] / bone_lengths(t["joints_3d"])["upper_arm"]
            for p, t in zip(mine["frames"], truth["frames"])  # type: ignore[call-overload]
        ]
    )
    result = compare_bones(mine, truth)
    assert result is not None
    assert result["metric"]["upper_arm"] == pytest.approx(expected)
    assert result["metric"]["upper_arm"] > 1.15
    assert result["metric"]["forearm"] == pytest.approx(1.0, abs=1e-9)
    assert result["metric"]["shoulder_width"] == pytest.approx(1.0, abs=1e-9)


def test_no_common_frame_gives_none() -> None:
    body = upperpose.BodyModel()
    truth = _poses(body, _random_poses(1))
    empty = make_poses(640, 480, 30.0, [{"frame": 0, "status": "no_person"}])
    assert compare_bones(empty, truth) is None


def test_command_line_reads_a_folder(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    body = upperpose.BodyModel()
    poses = _random_poses(2)
    (tmp_path / "pred").mkdir()
    (tmp_path / "truth" / "clip").mkdir(parents=True)
    (tmp_path / "pred" / "clip.json").write_text(json.dumps(_poses(body, poses, 1.1)))
    (tmp_path / "truth" / "clip" / "gt.json").write_text(json.dumps(_poses(body, poses)))
    assert main([str(tmp_path / "pred"), str(tmp_path / "truth")]) == 0
    out = capsys.readouterr().out
    assert "clip" in out and "1.10" in out
    assert "mean |ratio - 1|, metric: shoulder_width: 0.100" in out
    assert "mean |ratio - 1|, image: shoulder_width: 0.000" in out
    assert main([str(tmp_path / "truth"), str(tmp_path / "truth")]) == 1
