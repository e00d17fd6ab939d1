"""`upperpose features VIDEO --frame N -o sheet.png`."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from upperpose import Pose, cli
from upperpose.commands import features as features_command
from upperpose.commands.features import tracked_features
from upperpose.exceptions import VideoError
from upperpose.fit import TrackerConfig
from upperpose.fit.pipeline import VideoTracking
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


def test_as_tracked_shows_the_trackers_own_features_of_that_frame(clip, tmp_path) -> None:
    # The sheet's features are the ones the tracker computed at frame 35 (same frame, not one
    # off), and its prediction found the head's skin within a few pixels of the truth's head.
    video, plate = str(clip / "clip.avi"), str(clip / "plate.png")
    frame, features, background, _, _ = tracked_features(video, 35, plate, TrackerConfig())
    with VideoTracking(video, plate) as run:
        seen = [(image, run.tracker.features) for _, (image, _) in zip(range(36), run.frames())]
    image, expected = seen[35]
    assert expected is not None and not background.estimated
    assert np.array_equal(frame, image)
    assert np.array_equal(features.sub, expected.sub) and np.array_equal(features.skin, expected.skin)
    truth = json.loads((clip / "gt.json").read_text())["frames"][35]["joints_2d"]
    assert features.head is not None
    assert np.hypot(*(np.asarray(features.head.xy) - np.asarray(truth[0]))) < 15.0
    out = tmp_path / "sheet.png"
    assert cli.main(["features", video, "--frame", "35", "--as-tracked", "--background", plate, "-o", str(out)]) == 0
    assert cv2.imread(str(out)).shape[1] == 4 * 320


def test_as_tracked_tracks_as_track_would_with_the_same_options(clip, tmp_path, monkeypatch, capsys) -> None:
    # --focal, --seed, --config and --bg-model reach the tracking; the skin rule of the settings
    # file holds unless --skin is given. Without --as-tracked they are refused.
    calls = []

    def recorded(video, index, background, config, focal=None):  # type: ignore[no-untyped-def]
        calls.append((config, focal))
        raise VideoError("stop here")

    monkeypatch.setattr(features_command, "tracked_features", recorded)
    settings = tmp_path / "settings.toml"
    settings.write_text('[features]\nskin_space = "hsv"\n')
    video, out = str(clip / "clip.avi"), str(tmp_path / "sheet.png")
    args = ["features", video, "--as-tracked", "--focal", "500", "--seed", "3", "--bg-model", "online"]
    assert cli.main([*args, "--config", str(settings), "-o", out]) == 1
    assert cli.main([*args, "--config", str(settings), "--skin", "rgb", "-o", out]) == 1
    (first, focal), (second, _) = calls
    assert focal == 500.0 and first.seed == 3 and first.features.bg_model == "online"
    assert first.features.skin_space == "hsv" and second.features.skin_space == "rgb"
    capsys.readouterr()
    with pytest.raises(SystemExit) as refused:
        cli.main(["features", video, "--focal", "500", "-o", out])
    assert refused.value.code == 2 and "--as-tracked" in capsys.readouterr().err


def test_as_tracked_refuses_poses_and_frames_past_the_end(clip, tmp_path, capsys) -> None:
    out = tmp_path / "sheet.png"
    video = str(clip / "clip.avi")
    with pytest.raises(SystemExit) as refused:  # argparse's usage line and exit 2, as for any bad option
        cli.main(["features", video, "--as-tracked", "--poses", str(clip / "gt.json"), "-o", str(out)])
    assert refused.value.code == 2
    assert "--poses" in capsys.readouterr().err
    assert cli.main(["features", video, "--as-tracked", "--frame", "40", "-o", str(out)]) == 1
    assert "has only 40 frames" in capsys.readouterr().err
    assert not out.exists()
