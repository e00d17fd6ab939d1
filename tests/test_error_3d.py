"""The decomposition of the root-relative 3D error (upperpose.lab.error_3d) on known offsets."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import upperpose
from upperpose.io.posefile import make_poses
from upperpose.lab.error_3d import decompose, main, paired_joints

ROOT = np.array([0.05, 0.1, 2.2])
CAMERA = upperpose.Camera.for_image(640, 480)


def _joints(seed: int, count: int = 6) -> np.ndarray:
    """`(count, 7, 3)` joints of the default body in random arm poses."""
    rng = np.random.default_rng(seed)
    high = np.zeros(13)
    high[[4, 5, 6, 9, 10, 11]] = 1.5
    body = upperpose.BodyModel()
    return np.array([upperpose.forward_kinematics(rng.uniform(0.0, high), ROOT, body) for _ in range(count)])


def _document(joints: np.ndarray, missing: int | None = None) -> dict[str, object]:
    frames: list[dict[str, object]] = []
    for k, j in enumerate(joints):
        if k == missing:
            frames.append({"frame": k, "status": "no_person", "joints_2d": None, "joints_3d": None})
            continue
        pixels = upperpose.project(CAMERA, j).tolist()
        frames.append({"frame": k, "status": "tracked", "joints_2d": pixels, "joints_3d": j.tolist()})
    return make_poses(640, 480, 30.0, frames)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.02, 0.3))
def test_hands_held_nearer_the_camera_are_a_depth_bias(seed: int, offset: float) -> None:
    true = _joints(seed)
    mine = true.copy()
    mine[:, 5:, 2] -= offset  # both hands, every frame
    result = decompose(mine, true)
    assert result["error"] == pytest.approx(2 * offset * 1000 / 7)
    assert result["true xy"] == pytest.approx(result["error"])
    assert result["true z"] == pytest.approx(0.0, abs=1e-9)
    assert result["unbiased z"] == pytest.approx(0.0, abs=1e-9)
    expected_bias = np.zeros((7, 3))
    expected_bias[5:, 2] = -offset * 1000
    np.testing.assert_allclose(result["bias"], expected_bias, atol=1e-9)
    np.testing.assert_allclose(result["abs"], np.abs(expected_bias), atol=1e-9)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.7, 1.4))
def test_a_person_drawn_too_far_and_too_large_is_a_scale_error(seed: int, scale: float) -> None:
    true = _joints(seed)
    mine = scale * true  # the same image, the person `scale` times as far and as large
    result = decompose(mine, true)
    relative = true - 0.5 * (true[:, 1:2] + true[:, 2:3])
    assert result["error"] == pytest.approx(abs(scale - 1) * np.linalg.norm(relative, axis=2).mean() * 1000)
    assert result["scaled"] == pytest.approx(0.0, abs=1e-9)


def test_frames_without_a_pose_are_left_out(tmp_path: Path) -> None:
    true = _joints(7)
    mine = true.copy()
    mine[:, 6, 0] += 0.05  # the left hand 5 cm to the side
    a, b = paired_joints(_document(mine, missing=2), _document(true))
    assert a.shape == b.shape == (5, 7, 3)
    (tmp_path / "pred").mkdir()
    (tmp_path / "truth" / "clip").mkdir(parents=True)
    (tmp_path / "pred" / "clip.json").write_text(json.dumps(_document(mine, missing=2)))
    (tmp_path / "truth" / "clip" / "gt.json").write_text(json.dumps(_document(true)))
    assert main([str(tmp_path / "pred"), str(tmp_path / "truth")]) == 0
    assert main([str(tmp_path / "truth"), str(tmp_path / "pred")]) == 1  # nothing pairs up


def test_the_table_names_the_left_hand_as_the_joint_off(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    true = _joints(8)
    mine = true.copy()
    mine[:, 6, 0] += 0.05
    (tmp_path / "pred").mkdir()
    (tmp_path / "truth" / "v01").mkdir(parents=True)
    (tmp_path / "pred" / "v01.json").write_text(json.dumps(_document(mine)))
    (tmp_path / "truth" / "v01" / "gt.json").write_text(json.dumps(_document(true)))
    assert main([str(tmp_path / "pred"), str(tmp_path / "truth")]) == 0
    lines = capsys.readouterr().out.splitlines()
    clip = next(line for line in lines if line.startswith("v01 "))
    assert [float(v) for v in clip.split()[1:]] == pytest.approx([50 / 7, 50 / 7, 0.0, 50 / 7, 50 / 7], abs=0.06)
    left_hand = next(line for line in lines if "left_hand" in line)
    assert left_hand.split()[1] == "50" and left_hand.split()[-5] == "+50"
