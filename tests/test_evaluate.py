"""Scoring: truth against itself is zero, known noise scores what it should, bad input fails cleanly."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from upperpose.cli import main
from upperpose.io.posefile import make_poses, validate_poses, write_poses
from upperpose.lab.evaluate import evaluate, format_table


def truth(n: int = 60, seed: int = 0, empty: int = 0) -> dict[str, Any]:
    """Ground truth with random joints; the first `empty` frames have no person."""
    rng = np.random.default_rng(seed)
    frames = []
    for i in range(n):
        if i < empty:
            frames.append(
                {"frame": i, "status": "no_person", "joints_2d": None, "joints_3d": None, "angles": None, "cost": None}
            )
            continue
        j3 = rng.uniform([-0.5, -0.5, 2.0], [0.5, 0.5, 2.5], (7, 3))
        j2 = j3[:, :2] / j3[:, 2:] * 640 + [319.5, 239.5]
        frames.append(
            {
                "frame": i,
                "status": "tracked",
                "joints_2d": j2.tolist(),
                "joints_3d": j3.tolist(),
                "angles": [0.0] * 13,
                "cost": None,
            }
        )
    return validate_poses(make_poses(640, 480, 30.0, frames))


def shifted(gt: dict[str, Any], dx: float, dy: float) -> dict[str, Any]:
    pred = copy.deepcopy(gt)
    for f in pred["frames"]:
        if f["joints_2d"] is not None:
            f["joints_2d"] = [[x + dx, y + dy] for x, y in f["joints_2d"]]
    return pred


def test_truth_against_itself_scores_zero() -> None:
    gt = truth(empty=5)
    s = evaluate(gt, gt)
    assert s.mean_abs_x_px == 0 and s.mean_abs_y_px == 0 and s.mpjpe_2d_px == 0
    assert s.mpjpe_3d_mm == 0 and s.pck == 1.0 and s.coverage == 1.0
    assert s.gt_pose_frames == 55 and s.compared_frames == 55 and s.missing_frames == []


def test_constant_offset_scores_exactly() -> None:
    gt = truth()
    s = evaluate(shifted(gt, 3.0, -4.0), gt)
    for x, y in s.joint_error_px.values():
        assert x == pytest.approx(3.0) and y == pytest.approx(4.0)
    assert s.mpjpe_2d_px == pytest.approx(5.0)
    assert s.pck == 1.0
    assert evaluate(shifted(gt, 3.0, -4.0), gt, pck_threshold_px=4.9).pck == 0.0


def test_gaussian_noise_scores_what_it_predicts() -> None:
    gt = truth(n=400)
    rng = np.random.default_rng(1)
    sigma = 6.0
    pred = copy.deepcopy(gt)
    for f in pred["frames"]:
        f["joints_2d"] = (np.array(f["joints_2d"]) + rng.normal(0, sigma, (7, 2))).tolist()
    s = evaluate(pred, gt)
    # E|N(0, s)| = s * sqrt(2 / pi); the distance is Rayleigh: mean s * sqrt(pi / 2).
    assert s.mean_abs_x_px == pytest.approx(sigma * np.sqrt(2 / np.pi), rel=0.05)
    assert s.mean_abs_y_px == pytest.approx(sigma * np.sqrt(2 / np.pi), rel=0.05)
    assert s.mpjpe_2d_px == pytest.approx(sigma * np.sqrt(np.pi / 2), rel=0.05)
    assert s.pck == pytest.approx(1 - np.exp(-(10.0**2) / (2 * sigma**2)), abs=0.03)


def test_3d_error_is_root_relative() -> None:
    gt = truth()
    pred = copy.deepcopy(gt)
    for f in pred["frames"]:
        j = np.array(f["joints_3d"]) + [0.3, -0.2, 0.5]  # a whole-body shift costs nothing
        j[0] += [0.0, 0.0, 0.07]  # the head 70 mm off
        f["joints_3d"] = j.tolist()
    s = evaluate(pred, gt)
    assert s.joint_error_3d_mm["head"] == pytest.approx(70.0)
    assert s.joint_error_3d_mm["left_hand"] == pytest.approx(0.0, abs=1e-6)
    assert s.mpjpe_3d_mm == pytest.approx(10.0)


def test_missing_and_unposed_frames_count_against_coverage() -> None:
    gt = truth(n=50, empty=10)
    pred = copy.deepcopy(gt)
    pred["frames"] = [f for f in pred["frames"] if not 20 <= f["frame"] < 30]
    for f in pred["frames"]:
        if f["frame"] in (40, 41):
            f.update(status="lost", joints_2d=None, joints_3d=None)
    pred["frames"].append(
        {"frame": 99, "status": "no_person", "joints_2d": None, "joints_3d": None, "angles": None, "cost": None}
    )
    s = evaluate(validate_poses(pred), gt)
    assert s.gt_pose_frames == 40
    assert s.compared_frames == 28
    assert s.coverage == pytest.approx(28 / 40)
    assert s.missing_frames == list(range(20, 30))
    assert s.unposed_frames == [40, 41]
    assert s.extra_frames == [99]
    assert s.mpjpe_2d_px == 0.0
    text = format_table(s)
    assert "missing from the prediction: 10 frames (20-29)" in text
    assert "28/40" in text


def test_fps_from_run_time() -> None:
    gt = truth(n=60)
    pred = copy.deepcopy(gt)
    pred["run_time_s"] = 12.0
    assert evaluate(pred, gt).fps == pytest.approx(5.0)
    assert evaluate(gt, gt).fps is None


def test_image_size_mismatch_is_an_error() -> None:
    gt = truth()
    pred = copy.deepcopy(gt)
    pred["width"] = 320
    with pytest.raises(ValueError, match="320x480"):
        evaluate(pred, gt)


def test_table_layout_follows_table_4_2_1() -> None:
    text = format_table(evaluate(shifted(truth(), 1.0, 2.0), truth()))
    rows = [line.split("  ")[0].strip() for line in text.splitlines()]
    for label in (
        "Head x (px)",
        "Head y (px)",
        "Right shoulder x (px)",
        "Left hand y (px)",
        "Total average x (px)",
        "Total average y (px)",
        "Frame rate (fps)",
    ):
        assert label in rows
    assert (
        rows.index("Head x (px)")
        < rows.index("Right shoulder x (px)")
        < rows.index("Left hand y (px)")
        < rows.index("Total average x (px)")
    )


def test_cli_json_and_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    gt = truth()
    write_poses(tmp_path / "gt.json", gt)
    write_poses(tmp_path / "pred.json", shifted(gt, 2.0, 0.0) | {"run_time_s": 2.0})
    assert main(["eval", str(tmp_path / "pred.json"), str(tmp_path / "gt.json"), "--json"]) == 0
    scores = json.loads(capsys.readouterr().out)
    assert scores["mean_abs_x_px"] == pytest.approx(2.0) and scores["fps"] == pytest.approx(30.0)
    assert scores["coverage"] == 1.0
    (tmp_path / "bad.json").write_text('{"format": "upperpose.poses/1", "frames": 3}')
    assert main(["eval", str(tmp_path / "bad.json"), str(tmp_path / "gt.json")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.json" in err and "Traceback" not in err
    assert main(["eval", str(tmp_path / "nope.json"), str(tmp_path / "gt.json")]) == 1
    assert "no such file" in capsys.readouterr().err


def moving(n: int = 90) -> dict[str, Any]:
    """Ground truth whose joints move smoothly (a sine per joint and axis)."""
    t = np.arange(n)[:, None, None]
    phase = np.arange(14).reshape(1, 7, 2)
    j2 = 300 + 40 * np.sin(2 * np.pi * t / 30 + phase)
    frames = [
        {"frame": i, "status": "tracked", "joints_2d": j2[i].tolist(), "joints_3d": None, "angles": None, "cost": None}
        for i in range(n)
    ]
    return validate_poses(make_poses(640, 480, 30.0, frames))


def test_motion_errors_of_the_truth_itself() -> None:
    gt = moving()
    s = evaluate(gt, gt)
    assert s.accel_error_px == 0.0 and s.lag_frames == 0


def test_alternating_jitter_has_its_exact_acceleration_error() -> None:
    # +-1 px in x on alternate frames: every second difference of the jitter is +-4 px.
    gt = moving()
    pred = copy.deepcopy(gt)
    for f in pred["frames"]:
        sign = 1 if f["frame"] % 2 else -1
        f["joints_2d"] = [[x + sign, y] for x, y in f["joints_2d"]]
    s = evaluate(pred, gt)
    assert s.accel_error_px == pytest.approx(4.0, abs=1e-9)
    assert s.lag_frames == 0


@pytest.mark.parametrize("delay", [1, 3, -2])
def test_a_delayed_prediction_reports_its_lag(delay: int) -> None:
    gt = moving(120)
    pred = copy.deepcopy(gt)
    by_frame = {f["frame"]: f["joints_2d"] for f in gt["frames"]}
    for f in pred["frames"]:
        f["joints_2d"] = by_frame[min(max(f["frame"] - delay, 0), 119)]
    assert evaluate(pred, gt).lag_frames == delay


def test_acceleration_needs_three_consecutive_frames() -> None:
    gt = moving(10)
    pred = copy.deepcopy(gt)
    for f in pred["frames"]:
        if f["frame"] % 2:
            f["joints_2d"] = None
    s = evaluate(pred, gt)
    assert s.accel_error_px is None and s.lag_frames is None
