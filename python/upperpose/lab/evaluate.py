"""Scoring a pose file against ground truth: the layout of the thesis' Table 4.2-1, and more.

Per joint and image axis, the mean absolute pixel difference between predicted and true
joints over the frames where both have a 2D pose; their averages; 2D MPJPE and PCK; the
root-relative 3D error in millimetres (root: the midpoint of the shoulders) where both carry
3D joints (it replaces the table's undefined "z in pixels", SPEC 8); the share of ground-truth
poses the prediction covers; the acceleration error (jitter: the mean 2D distance between the
predicted and the true second differences over three consecutive compared frames) and the lag
(the frame shift that best lines the predicted joint velocities up with the true ones); and
frames per second when the prediction records its run time.
Frames are matched by their "frame" number; a ground-truth pose with no predicted pose (a
missing frame, or a frame without joints) counts against coverage only.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from upperpose.exceptions import InputError
from upperpose.model import JOINT_NAMES

PCK_THRESHOLD_PX = 10.0
MAX_LAG_FRAMES = 5
# Pixels or metres; beyond this, squared differences of coordinates overflow float64 in sums.
MAX_COORDINATE = 1e9
_LABELS = [n.replace("_", " ").capitalize() for n in JOINT_NAMES]


@dataclass
class Scores:
    """The result of `evaluate`. Pixel errors are NaN when no frame could be compared.

    Attributes:
        joint_error_px: joint name -> [mean |dx|, mean |dy|] in pixels.
        joint_error_3d_mm: joint name -> mean root-relative 3D error in mm (None without 3D).
        mean_abs_x_px: average of the per-joint x errors (Table 4.2-1 "Total average x").
        mean_abs_y_px: the same for y.
        mpjpe_2d_px: mean Euclidean joint error in pixels.
        pck: share of joints within `pck_threshold_px` of the truth.
        pck_threshold_px: the PCK radius, pixels.
        mpjpe_3d_mm: mean root-relative 3D joint error in mm (None without 3D on both sides).
        gt_frames: frames in the ground truth.
        gt_pose_frames: ground-truth frames with a pose (the ones scored).
        compared_frames: of those, frames where the prediction has a 2D pose.
        compared_frames_3d: of those, frames where both have 3D joints.
        coverage: compared_frames / gt_pose_frames.
        missing_frames: ground-truth frame numbers absent from the prediction.
        unposed_frames: ground-truth pose frames whose prediction is present but has no pose.
        extra_frames: predicted frame numbers absent from the ground truth.
        accel_error_px: mean |second difference of the prediction - that of the truth| per joint,
            pixels per frame squared, over frames whose neighbours are compared too (None
            without three consecutive compared frames).
        lag_frames: the shift in frames (positive: the prediction trails the truth) within
            +-MAX_LAG_FRAMES that maximises the correlation of predicted and true joint
            velocities (None without enough consecutive frames or motion).
        fps: predicted frames / run_time_s, None when the prediction has no run time.
    """

    joint_error_px: dict[str, list[float]]
    joint_error_3d_mm: dict[str, float | None]
    mean_abs_x_px: float
    mean_abs_y_px: float
    mpjpe_2d_px: float
    pck: float
    pck_threshold_px: float
    mpjpe_3d_mm: float | None
    gt_frames: int
    gt_pose_frames: int
    compared_frames: int
    compared_frames_3d: int
    coverage: float
    missing_frames: list[int]
    unposed_frames: list[int]
    extra_frames: list[int]
    accel_error_px: float | None
    lag_frames: int | None
    fps: float | None

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON values (NaN becomes None)."""

        def clean(v: Any) -> Any:
            if isinstance(v, float) and not np.isfinite(v):
                return None
            if isinstance(v, dict):
                return {k: clean(x) for k, x in v.items()}
            if isinstance(v, list):
                return [clean(x) for x in v]
            return v

        return clean(asdict(self))  # type: ignore[no-any-return]


def evaluate(prediction: dict[str, Any], truth: dict[str, Any], pck_threshold_px: float = PCK_THRESHOLD_PX) -> Scores:
    """Scores a validated prediction against validated ground truth (see `upperpose.io.posefile`).

    Raises:
        ValueError: the two files describe different image sizes, the truth has no pose, or
            coordinates too large to score.
    """
    if (prediction["width"], prediction["height"]) != (truth["width"], truth["height"]):
        raise ValueError(
            f"prediction is for {prediction['width']}x{prediction['height']} images, "
            f"ground truth for {truth['width']}x{truth['height']}: pixel errors would mean nothing"
        )
    predicted = {f["frame"]: f for f in prediction["frames"]}
    gt_numbers = {f["frame"] for f in truth["frames"]}
    posed = [f for f in truth["frames"] if f["joints_2d"] is not None]
    if not posed:
        raise ValueError("the ground truth has no frame with a pose: nothing to score")
    missing = sorted(f["frame"] for f in posed if f["frame"] not in predicted)
    unposed = sorted(
        f["frame"] for f in posed if f["frame"] in predicted and predicted[f["frame"]]["joints_2d"] is None
    )
    pairs = [
        (predicted[f["frame"]], f)
        for f in posed
        if f["frame"] in predicted and predicted[f["frame"]]["joints_2d"] is not None
    ]
    for p, t in pairs:
        _check_scorable(p, "prediction")
        _check_scorable(t, "ground truth")
    n_joints = len(JOINT_NAMES)
    if pairs:
        diff = np.array([p["joints_2d"] for p, _ in pairs]) - np.array([t["joints_2d"] for _, t in pairs])
        per_joint = np.abs(diff).mean(axis=0)  # (7, 2)
        dist = np.linalg.norm(diff, axis=2)
        mpjpe, pck = float(dist.mean()), float((dist <= pck_threshold_px).mean())
    else:
        per_joint = np.full((n_joints, 2), np.nan)
        mpjpe, pck = float("nan"), float("nan")
    pairs_3d = [(p, t) for p, t in pairs if p["joints_3d"] is not None and t["joints_3d"] is not None]
    per_joint_3d: list[float | None] = [None] * n_joints
    mpjpe_3d = None
    if pairs_3d:
        p3 = np.array([p["joints_3d"] for p, _ in pairs_3d])
        t3 = np.array([t["joints_3d"] for _, t in pairs_3d])
        p3 -= (p3[:, 1:2] + p3[:, 2:3]) / 2  # root: midpoint of the shoulders
        t3 -= (t3[:, 1:2] + t3[:, 2:3]) / 2
        err = np.linalg.norm(p3 - t3, axis=2) * 1000.0
        per_joint_3d = [float(v) for v in err.mean(axis=0)]
        mpjpe_3d = float(err.mean())
    accel, lag = _motion_errors({t["frame"]: (p["joints_2d"], t["joints_2d"]) for p, t in pairs})
    run_time = prediction.get("run_time_s")
    fps = len(prediction["frames"]) / run_time if run_time else None
    return Scores(
        joint_error_px={n: [float(v) for v in per_joint[j]] for j, n in enumerate(JOINT_NAMES)},
        joint_error_3d_mm=dict(zip(JOINT_NAMES, per_joint_3d)),
        mean_abs_x_px=float(per_joint[:, 0].mean()),
        mean_abs_y_px=float(per_joint[:, 1].mean()),
        mpjpe_2d_px=mpjpe,
        pck=pck,
        pck_threshold_px=float(pck_threshold_px),
        mpjpe_3d_mm=mpjpe_3d,
        gt_frames=len(truth["frames"]),
        gt_pose_frames=len(posed),
        compared_frames=len(pairs),
        compared_frames_3d=len(pairs_3d),
        coverage=len(pairs) / len(posed),
        missing_frames=missing,
        unposed_frames=unposed,
        extra_frames=sorted(set(predicted) - gt_numbers),
        accel_error_px=accel,
        lag_frames=lag,
        fps=fps,
    )


def _check_scorable(frame: dict[str, Any], which: str) -> None:
    """Refuses coordinates so large that their errors would overflow.

    An overflowing error would become a null MPJPE next to a finite coverage.
    """
    for key in ("joints_2d", "joints_3d"):
        if frame[key] is not None and np.abs(np.asarray(frame[key], dtype=float)).max() > MAX_COORDINATE:
            raise InputError(
                f"{which} frame {frame['frame']}: {key} beyond +-{MAX_COORDINATE:g} cannot be scored "
                "(no image or room is that large)"
            )


def _motion_errors(joints: dict[int, tuple[Any, Any]]) -> tuple[float | None, int | None]:
    """Acceleration error and lag from frame -> (predicted, true) 2D joints of compared frames."""
    runs: list[list[int]] = []
    for n in sorted(joints):
        if runs and n == runs[-1][-1] + 1:
            runs[-1].append(n)
        else:
            runs.append([n])
    accel: list[Any] = []
    velocity: list[tuple[Any, Any]] = []
    for run in runs:
        if len(run) < 2:
            continue
        pred = np.array([joints[n][0] for n in run], dtype=float)
        true = np.array([joints[n][1] for n in run], dtype=float)
        velocity.append((np.diff(pred, axis=0), np.diff(true, axis=0)))
        if len(run) >= 3:
            gap = np.diff(pred, 2, axis=0) - np.diff(true, 2, axis=0)
            accel.append(np.linalg.norm(gap, axis=2).ravel())
    accel_error = float(np.concatenate(accel).mean()) if accel else None
    return accel_error, _lag(velocity)


def _lag(velocity: list[tuple[Any, Any]]) -> int | None:
    """The shift (prediction behind truth > 0) that maximises the velocities' correlation."""
    best: tuple[float, int] | None = None
    for shift in range(-MAX_LAG_FRAMES, MAX_LAG_FRAMES + 1):
        dot = norm_p = norm_t = 0.0
        for vp, vt in velocity:
            n = len(vp) - abs(shift)
            if n <= 0:
                continue
            a = vp[shift:] if shift >= 0 else vp[:shift]
            b = vt[: len(vt) - shift] if shift >= 0 else vt[-shift:]
            dot += float((a * b).sum())
            norm_p += float((a * a).sum())
            norm_t += float((b * b).sum())
        if norm_p > 0 and norm_t > 0:
            corr = dot / np.sqrt(norm_p * norm_t)
            if best is None or corr > best[0] + 1e-12:
                best = (corr, shift)
    return None if best is None else best[1]


def _fmt(v: float | None, digits: int = 2) -> str:
    return "-" if v is None or not np.isfinite(v) else f"{v:.{digits}f}"


def _ranges(numbers: list[int]) -> str:
    """'3-7, 9' style summary of frame numbers (at most a few ranges)."""
    if not numbers:
        return ""
    spans: list[tuple[int, int]] = []
    for n in numbers:
        if spans and n == spans[-1][1] + 1:
            spans[-1] = (spans[-1][0], n)
        else:
            spans.append((n, n))
    text = ", ".join(f"{a}" if a == b else f"{a}-{b}" for a, b in spans[:6])
    return text + (", ..." if len(spans) > 6 else "")


def format_table(scores: Scores) -> str:
    """The scores as text: Table 4.2-1's rows (x, y, and 3D in place of z), then a summary."""
    rows = [("Body part", "Error")]
    for label, name in zip(_LABELS, JOINT_NAMES):
        x, y = scores.joint_error_px[name]
        rows += [(f"{label} x (px)", _fmt(x)), (f"{label} y (px)", _fmt(y))]
        rows.append((f"{label} 3D (mm)", _fmt(scores.joint_error_3d_mm[name], 1)))
    rows += [
        ("Total average x (px)", _fmt(scores.mean_abs_x_px)),
        ("Total average y (px)", _fmt(scores.mean_abs_y_px)),
        ("Total average 3D (mm)", _fmt(scores.mpjpe_3d_mm, 1)),
        ("Frame rate (fps)", _fmt(scores.fps, 1)),
    ]
    width = max(len(r[0]) for r in rows)
    lines = [f"{a:<{width}}  {b:>10}" for a, b in rows]
    lines.insert(1, "-" * (width + 12))
    lines.insert(len(lines) - 4, "-" * (width + 12))
    lines += [
        "",
        f"2D MPJPE: {_fmt(scores.mpjpe_2d_px, 2)} px   PCK@{scores.pck_threshold_px:g}px: {_fmt(scores.pck * 100, 1)} %"
        + ("" if scores.mpjpe_3d_mm is None else f"   3D MPJPE (root-relative): {_fmt(scores.mpjpe_3d_mm, 1)} mm"),
        f"acceleration error: {_fmt(scores.accel_error_px, 2)} px/frame^2   lag: "
        + ("-" if scores.lag_frames is None else f"{scores.lag_frames} frames"),
        f"coverage: {scores.compared_frames}/{scores.gt_pose_frames} ground-truth poses "
        f"({_fmt(scores.coverage * 100, 1)} %); ground truth has {scores.gt_frames} frames",
    ]
    if scores.missing_frames:
        lines.append(
            f"missing from the prediction: {len(scores.missing_frames)} frames ({_ranges(scores.missing_frames)})"
        )
    if scores.unposed_frames:
        lines.append(
            f"present but without a pose: {len(scores.unposed_frames)} frames ({_ranges(scores.unposed_frames)})"
        )
    if scores.extra_frames:
        lines.append(
            f"not in the ground truth (ignored): {len(scores.extra_frames)} frames ({_ranges(scores.extra_frames)})"
        )
    return "\n".join(lines)
