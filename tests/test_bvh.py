"""BVH export: read back by an independent reader (bvhio), its forward kinematics gives the joints."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import upperpose
from tracker_helpers import TruthFitter, clip, truth
from upperpose.cli import main
from upperpose.io.bvh import euler_zyx_degrees, write_bvh
from upperpose.io.posefile import load_poses
from upperpose.lab.bvh_roundtrip import bvh_joints, round_trip_mm

pytest.importorskip("bvhio")


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), build=st.sampled_from(["average", "slim", "broad"]))
def test_random_poses_round_trip_within_a_micrometre(
    tmp_path_factory: pytest.TempPathFactory, seed: int, build: str
) -> None:
    rng = np.random.default_rng(seed)
    scale = {"average": 1.0, "slim": 0.9, "broad": 1.1}[build]
    body = upperpose.BodyModel(shoulder_width=0.36 * scale, upper_arm_length=0.29 * scale)
    low = np.array([min(a for a, _ in ranges) for ranges in upperpose.joint_limits("anatomical")])
    high = np.array([max(b for _, b in ranges) for ranges in upperpose.joint_limits("anatomical")])
    poses = rng.uniform(low, high, (8, 13))
    roots = rng.uniform([-0.3, -0.2, 1.5], [0.3, 0.3, 3.5], (8, 3))
    path = tmp_path_factory.mktemp("bvh") / "poses.bvh"
    write_bvh(path, [{"angles": p.tolist(), "root": r.tolist()} for p, r in zip(poses, roots)], body, 30.0)
    for got, pose, root in zip(bvh_joints(path), poses, roots):
        np.testing.assert_allclose(got, upperpose.forward_kinematics(pose, root, body), atol=1e-6)


def test_euler_angles_rebuild_the_rotation() -> None:
    rng = np.random.default_rng(1)
    for _ in range(200):
        z, y, x = rng.uniform(-np.pi, np.pi), rng.uniform(-1.5, 1.5), rng.uniform(-np.pi, np.pi)
        rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
        ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
        rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
        np.testing.assert_allclose(euler_zyx_degrees(rz @ ry @ rx), np.degrees([z, y, x]), atol=1e-9)


def test_frames_without_a_pose_hold_the_nearest_earlier_one(tmp_path: Path) -> None:
    pose = upperpose.Pose.a_pose().angles.tolist()
    frames = [{"angles": None, "root": None}, {"angles": pose, "root": [0.0, 0.1, 2.0]}, {"angles": None, "root": None}]
    path = write_bvh(tmp_path / "p.bvh", frames, upperpose.BodyModel(), 15.0)
    rows = path.read_text().split("Frame Time: ")[1].splitlines()[1:]
    assert len(rows) == 3 and rows[0] == rows[1] == rows[2]
    with pytest.raises(ValueError, match="no frame has a pose"):
        write_bvh(tmp_path / "q.bvh", frames[:1], upperpose.BodyModel(), 15.0)
    assert not (tmp_path / "q.bvh").exists()


def test_track_writes_a_bvh_matching_its_pose_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import upperpose.fit.tracker as tracker_module

    monkeypatch.setattr(tracker_module, "fit_frame", TruthFitter(truth(clip())))
    folder = clip()
    out, bvh = tmp_path / "poses.json", tmp_path / "poses.bvh"
    args = ["track", str(folder / "video.mp4"), "--background", str(folder / "background.png"), "-o", str(out)]
    assert main([*args, "--bvh", str(bvh), "--quiet"]) == 0, capsys.readouterr().err
    doc = load_poses(out)
    assert doc["upperpose_version"] == upperpose.__version__
    assert set(doc["camera"]) == {"model", "focal", "cx", "cy"} and doc["body"]["upper_arm_length"] > 0
    # One start-up, one body throughout: the BVH's skeleton.
    first = next(f["frame"] for f in doc["frames"] if f.get("angles") is not None)
    assert doc["bodies"] == [{"frame": first, "body": doc["body"]}]
    largest_mm, _, posed = round_trip_mm(out, bvh)
    assert posed > 10 and largest_mm < 1.0
    assert json.loads(out.read_text())["frames"][0]["frame"] == 0
