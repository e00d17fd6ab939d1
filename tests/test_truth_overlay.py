"""Truth and prediction drawn together on chosen frames (upperpose.lab.truth_overlay)."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from upperpose.io.posefile import make_poses
from upperpose.lab.truth_overlay import MINE_COLOUR, TRUTH_COLOUR, crop_box, draw_skeleton, main

W, H, FRAMES = 160, 120, 6
TRUTH = np.array([[80, 20], [60, 45], [100, 45], [50, 70], [110, 70], [45, 95], [115, 95]], dtype=np.float64)


def _poses(path: Path, joints: np.ndarray, unposed: tuple[int, ...] = ()) -> None:
    frames = [
        {
            "frame": k,
            "status": "no_person" if k in unposed else "tracked",
            "joints_2d": None if k in unposed else joints.tolist(),
            "joints_3d": None,
        }
        for k in range(FRAMES)
    ]
    path.write_text(json.dumps(make_poses(W, H, 30.0, frames)))


@pytest.fixture
def clip(tmp_path: Path) -> Path:
    folder = tmp_path / "clip"
    folder.mkdir()
    writer = cv2.VideoWriter(str(folder / "video.mp4"), cv2.VideoWriter_fourcc(*"mp4v"), 30, (W, H))
    for _ in range(FRAMES):
        writer.write(np.full((H, W, 3), 128, np.uint8))
    writer.release()
    _poses(folder / "gt.json", TRUTH)
    return folder


def test_the_crop_holds_every_skeleton_with_its_margin_inside_the_image() -> None:
    a = np.array([[30.0, 40.0], [50.0, 60.0]])
    b = np.array([[45.0, 20.0], [70.0, 55.0]])
    assert crop_box([a, b], (120, 160), margin=10) == (20, 10, 80, 70)
    assert crop_box([a, b], (120, 160), margin=50) == (0, 0, 120, 110)
    assert crop_box([a + 1000.0], (120, 160), margin=5) == (0, 0, 160, 120)  # all off the image


def test_skeletons_are_drawn_at_their_joints() -> None:
    image = np.zeros((H, W, 3), np.uint8)
    draw_skeleton(image, TRUTH, TRUTH_COLOUR)
    for x, y in TRUTH.astype(int):
        assert tuple(image[y, x]) == TRUTH_COLOUR
    assert tuple(image[5, 5]) == (0, 0, 0)


def test_the_command_prints_signed_errors_and_writes_the_sheet(
    clip: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mine = TRUTH.copy()
    mine[5] += (6.0, -8.0)  # the right hand 6 px right of and 8 px above the truth's
    _poses(tmp_path / "mine.json", mine, unposed=(4,))
    out = tmp_path / "sheet.png"
    assert main([str(clip), str(tmp_path / "mine.json"), "--frames", "1,3,4", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    rows = [line for line in printed.splitlines() if line.strip().split(" ")[0] in ("1", "3", "4")]
    assert len(rows) == 2  # frame 4 has no pose in the file
    assert "  +6,  -8" in rows[0] and rows[0].count("  +0,  +0") == 6
    sheet = cv2.imread(str(out))
    assert sheet is not None and sheet.shape[1] > 0
    red = np.all(sheet == MINE_COLOUR, axis=2).sum()
    assert red > 0  # the pose file's skeleton is on the sheet


def test_frames_without_both_poses_or_bad_numbers_are_refused(
    clip: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _poses(tmp_path / "mine.json", TRUTH, unposed=(2,))
    assert main([str(clip), str(tmp_path / "mine.json"), "--frames", "2,40"]) == 1
    assert "no chosen frame" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main([str(clip), str(tmp_path / "mine.json"), "--frames", "2,x"])
