"""The decomposition of the 2D error by constant offsets per clip (upperpose.lab.error_2d)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.io.posefile import make_poses
from upperpose.lab.error_2d import FAR_PX, GROUPS, decompose, main


def _truth(seed: int, frames: int = 8) -> np.ndarray:
    """`(frames, 7, 2)` joints scattered over a 640x480 image."""
    return np.random.default_rng(seed).uniform([50, 50], [590, 430], size=(frames, 7, 2))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from(list(GROUPS)), st.floats(-20, 20), st.floats(-20, 20))
def test_a_constant_offset_of_a_group_is_taken_away_by_that_group_alone(
    seed: int, group: str, dx: float, dy: float
) -> None:
    true = _truth(seed)
    mine = true.copy()
    joints = list(GROUPS[group])
    mine[:, joints] += (dx, dy)
    result = decompose(mine, true)
    share = len(joints) / 7
    np.testing.assert_allclose(result["error"], [share * abs(dx), share * abs(dy)], atol=1e-9)
    np.testing.assert_allclose(result[group], 0.0, atol=1e-9)
    np.testing.assert_allclose(result["all"], 0.0, atol=1e-9)
    for other, theirs in GROUPS.items():
        if not set(theirs) & set(joints):  # a group that shares no joint keeps the whole error
            np.testing.assert_allclose(result[other], result["error"], atol=1e-9)


def test_an_error_that_changes_sign_is_not_an_offset() -> None:
    true = _truth(3, frames=10)
    mine = true.copy()
    mine[0::2, 5, 1] += 6.0  # the right hand 6 px low on even frames, 6 px high on odd ones
    mine[1::2, 5, 1] -= 6.0
    result = decompose(mine, true)
    assert result["error"][1] == pytest.approx(6.0 / 7)
    assert result["hands"][1] == pytest.approx(6.0 / 7)
    assert result["all"][1] == pytest.approx(6.0 / 7)


def test_far_joints_are_counted_with_their_part_of_the_error() -> None:
    true = _truth(5, frames=4)
    mine = true.copy()
    mine[2, 6] += (30.0, 40.0)  # one left hand 50 px off
    mine[1, 0] += (3.0, 4.0)  # one head 5 px off: not far
    share, part = decompose(mine, true)["far"]
    assert share == pytest.approx(1 / 28)
    assert part == pytest.approx((30.0 + 40.0) / (2 * 28))
    assert 50.0 > FAR_PX > 5.0


def _document(joints: np.ndarray, missing: int | None = None) -> dict[str, object]:
    frames: list[dict[str, object]] = []
    for k, j in enumerate(joints):
        posed = k != missing
        frames.append(
            {
                "frame": k,
                "status": "tracked" if posed else "no_person",
                "joints_2d": j.tolist() if posed else None,
                "joints_3d": None,
            }
        )
    return make_poses(640, 480, 30.0, frames)


def test_the_command_pairs_files_and_skips_frames_without_a_pose(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    true = _truth(7, frames=5)
    mine = true.copy()
    mine[:, 1:3, 0] += 4.0  # both shoulders 4 px to the right
    mine[2] += 500.0  # a frame the prediction has no pose for: it must not count
    (tmp_path / "pred").mkdir()
    (tmp_path / "truth" / "walk").mkdir(parents=True)
    (tmp_path / "pred" / "walk.json").write_text(json.dumps(_document(mine, missing=2)))
    (tmp_path / "truth" / "walk" / "gt.json").write_text(json.dumps(_document(true)))
    assert main([str(tmp_path / "pred"), str(tmp_path / "truth")]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("walk "))
    error_x, error_y, head_x, head_y, shoulders_x, shoulders_y = map(float, re.findall(r"\d+\.\d+", row)[:6])
    assert error_x == head_x == pytest.approx(8 / 7, abs=0.005)
    assert error_y == head_y == shoulders_x == shoulders_y == 0.0
    assert main([str(tmp_path / "truth"), str(tmp_path / "pred")]) == 1  # nothing pairs up
