"""`upperpose features VIDEO --frame N -o sheet.png`."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from upperpose import Pose, cli
from upperpose.lab.feature_scene import render_scene, textured_background

H, W = 240, 320


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    folder = tmp_path_factory.mktemp("clip")
    plate = textured_background(H, W, seed=1)
    path = folder / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30, (W, H))
    poses = []
    for i in range(40):
        if i < 30:
            frame = np.clip(plate + np.random.default_rng(i).normal(0, 2, plate.shape), 0, 255).astype(np.uint8)
            poses.append(None)
        else:
            pose = Pose.a_pose().replace(right_z_up=0.6 + 0.05 * (i - 30))
            scene = render_scene(pose, plate, root=(0.0, 0.15, 1.6), seed=i)
            frame = scene.frame
            poses.append(scene.joints.tolist())
        writer.write(frame)
    writer.release()
    cv2.imwrite(str(folder / "plate.png"), plate)
    frames = [{"frame": i, "status": "tracked" if p else "no_person", "joints_2d": p} for i, p in enumerate(poses)]
    (folder / "gt.json").write_text(json.dumps({"format": "upperpose.poses/1", "frames": frames}))
    return folder


def test_sheet_with_clean_plate_and_poses(clip, tmp_path) -> None:
    out = tmp_path / "sheet.png"
    args = [
        "features",
        str(clip / "clip.avi"),
        "--frame",
        "35",
        "-o",
        str(out),
        "--background",
        str(clip / "plate.png"),
        "--poses",
        str(clip / "gt.json"),
        "--skin",
        "ycrcb",
    ]
    assert cli.main(args) == 0
    sheet = cv2.imread(str(out))
    assert sheet is not None and sheet.shape[1] == 4 * 320 and sheet.shape[0] > 3 * 240


def test_sheet_with_estimated_background_warns(clip, tmp_path, capsys) -> None:
    out = tmp_path / "sheet.png"
    assert cli.main(["features", str(clip / "clip.avi"), "--frame", "0", "-o", str(out)]) == 0
    assert "clean plate" in capsys.readouterr().out
    assert out.exists()


def test_frame_past_the_end_is_an_error(clip, tmp_path, capsys) -> None:
    out = tmp_path / "sheet.png"
    assert cli.main(["features", str(clip / "clip.avi"), "--frame", "400", "-o", str(out)]) == 1
    assert "past its end" in capsys.readouterr().err
    assert not out.exists()
