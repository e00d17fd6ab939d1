"""Validation runs before and after a change, paired by seed (upperpose.lab.ab)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.io.posefile import make_poses
from upperpose.lab.ab import bootstrap_interval, clip_scores, main, paired_means

TRUTH = np.random.default_rng(7).uniform([60, 60], [580, 420], size=(6, 7, 2))


def _write(path: Path, joints: np.ndarray) -> None:
    frames = [
        {"frame": k, "status": "tracked", "joints_2d": j.tolist(), "joints_3d": None} for k, j in enumerate(joints)
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(make_poses(640, 480, 30.0, frames)))


def _run(root: Path, name: str, offsets: dict[str, tuple[float, float]]) -> Path:
    """A folder of pose files: each clip's truth shifted by its constant (dx, dy)."""
    folder = root / name
    for clip, shift in offsets.items():
        _write(folder / f"{clip}.json", TRUTH + np.asarray(shift))
    return folder


@pytest.fixture
def truth(tmp_path: Path) -> Path:
    for clip in ("a", "b", "c"):
        _write(tmp_path / "clips" / clip / "gt.json", TRUTH)
    return tmp_path / "clips"


def test_clip_scores_are_the_mean_absolute_errors_per_axis(tmp_path: Path, truth: Path) -> None:
    scores = clip_scores(_run(tmp_path, "r", {"a": (3.0, -2.0), "b": (0.0, 0.5)}), truth)
    assert sorted(scores) == ["a", "b"]  # c has no pose file: not scored
    np.testing.assert_allclose(scores["a"][:2], [3.0, 2.0])
    np.testing.assert_allclose(scores["b"][:2], [0.0, 0.5])
    assert np.isnan(scores["a"][2])  # no 3D joints


def test_runs_pair_by_seed_and_only_clips_scored_everywhere_count(tmp_path: Path, truth: Path) -> None:
    before = [clip_scores(_run(tmp_path, f"b{s}", {"a": (2.0 + s, 0.0), "b": (1.0, 1.0)}), truth) for s in (0, 1)]
    after = [
        clip_scores(_run(tmp_path, f"a{s}", {"a": (1.0, 0.0), "b": (1.0, 1.0), "c": (9.0, 9.0)}), truth) for s in (0, 1)
    ]
    means = paired_means(before, after)
    assert sorted(means) == ["a", "b"]
    np.testing.assert_allclose(means["a"][0, :2], [2.5, 0.0])  # the mean over both seeds
    np.testing.assert_allclose(means["a"][1, :2], [1.0, 0.0])
    np.testing.assert_allclose(means["b"][1, :2] - means["b"][0, :2], 0.0)
    with pytest.raises(ValueError, match="as many runs"):
        paired_means(before, after[:1])


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-5, 5), min_size=1, max_size=30), st.floats(-3, 3))
def test_the_bootstrap_interval_holds_the_mean_and_moves_with_a_shift(values: list[float], shift: float) -> None:
    low, high = bootstrap_interval(values)
    mean = float(np.mean(values))
    assert min(values) - 1e-9 <= low <= mean + 1e-9 and mean - 1e-9 <= high <= max(values) + 1e-9
    low2, high2 = bootstrap_interval(np.asarray(values) + shift)
    assert low2 == pytest.approx(low + shift, abs=1e-9) and high2 == pytest.approx(high + shift, abs=1e-9)
    assert bootstrap_interval(values) == (low, high)  # deterministic


def test_a_constant_change_has_no_spread() -> None:
    assert bootstrap_interval([0.7] * 12) == pytest.approx((0.7, 0.7))


def test_the_command_reports_the_change_and_refuses_unpaired_runs(
    tmp_path: Path, truth: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = _run(tmp_path, "before", {"a": (4.0, 0.0), "b": (0.0, 4.0), "c": (1.0, 1.0)})
    after = _run(tmp_path, "after", {"a": (1.0, 0.0), "b": (0.0, 1.0), "c": (1.0, 1.0)})
    assert main([str(truth), "--before", str(before), "--after", str(after)]) == 0
    out = capsys.readouterr().out
    assert "x px      1.67 ->    0.67    -1.00" in out  # clips a, b, c: (4 + 0 + 1) / 3 -> (1 + 0 + 1) / 3
    assert "better by more than 0.5 px: 2, worse: 0" in out
    with pytest.raises(SystemExit):
        main([str(truth), "--before", str(before), str(before), "--after", str(after)])
    assert "pair by seed" in capsys.readouterr().err
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main([str(truth), "--before", str(empty), "--after", str(after)]) == 1
    (empty / "a.json").write_text("{")
    assert main([str(truth), "--before", str(empty), "--after", str(after)]) == 1
    assert "a.json: not valid JSON" in capsys.readouterr().err
