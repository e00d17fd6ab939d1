"""The thesis' comparison (§4.2-4.3; SPEC 7): every optimiser on every clip of a data set.

Each method tracks each clip with the same body model, features, constraints and output, only
the search differs (docs/baselines.md). The report follows Table 4.2-1 (per joint and axis, the
mean absolute pixel error; totals; frames per second), one column per method, plus 2D MPJPE
and coverage, and APSOPF's sigma sweep (Tables 4.2-2..4). Clips run in parallel processes
(spawn start method: a forked child would inherit no rayon threads).
"""

from __future__ import annotations

import hashlib
import json
import math
import multiprocessing
import time
import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from upperpose.exceptions import UpperposeError
from upperpose.lab.evaluate import evaluate
from upperpose.model import JOINT_NAMES

if TYPE_CHECKING:
    from upperpose.fit.search import Limits, Optimizer


@dataclass(frozen=True)
class Method:
    """One column: a search method and its settings."""

    label: str
    optimizer: Optimizer
    limits: Limits = "anatomical"
    sigma: float | None = None


MAIN_METHODS = (
    Method("APSO", "apso"),
    Method("APSO, thesis limits", "apso", limits="thesis"),
    Method("PSO", "pso"),
    Method("Simplex [1]", "simplex"),
    Method("APSOPF [2] σ=1", "apsopf", sigma=1.0),
)
# The sigmas of the thesis' Tables 4.2-2..4.
THESIS_SIGMAS = (0.1, 0.15, 0.2, 0.25, 0.3, 0.5, 0.8, 0.9, 0.95, 1.0, 1.02, 1.05, 1.1, 1.2, 1.5)
# The joints of the sigma tables: right elbow, left elbow, right hand.
SWEEP_JOINTS = ("right_elbow", "left_elbow", "right_hand")


def sweep_method(sigma: float) -> Method:
    """APSOPF at one sigma (σ = 1 is the main table's column)."""
    return MAIN_METHODS[-1] if sigma == 1.0 else Method(f"APSOPF σ={sigma:g}", "apsopf", sigma=sigma)


def all_methods(sigmas: Sequence[float]) -> list[Method]:
    """The main columns, then the sweep's other sigmas."""
    out = list(MAIN_METHODS)
    for s in sigmas:
        m = sweep_method(s)
        if m not in out:
            out.append(m)
    return out


@dataclass(frozen=True)
class Clip:
    """One clip folder: video.mp4, gt.json, meta.json (camera focal), background.png optional."""

    name: str
    video: Path
    truth: Path
    background: Path | None
    focal: float
    centre: tuple[float, float] | None


def find_clips(dataset: str | Path) -> list[Clip]:
    """The clip folders of `dataset` (sub-folders with a video.mp4), sorted by name.

    Raises:
        ValueError: no such folder, no clip in it, or a clip without gt.json or a usable meta.json.
    """
    root = Path(dataset)
    if not root.is_dir():
        raise ValueError(f"{root} is not a folder")
    folders = sorted(p for p in root.iterdir() if (p / "video.mp4").is_file())
    if not folders:
        raise ValueError(f"no clip in {root}: expected sub-folders with video.mp4, gt.json and meta.json")
    clips = []
    for folder in folders:
        for needed in ("gt.json", "meta.json"):
            if not (folder / needed).is_file():
                raise ValueError(f"clip {folder.name} has no {needed}")
        try:
            cam = json.loads((folder / "meta.json").read_text())["camera"]
            focal = float(cam["focal"])
            centre = (float(cam["cx"]), float(cam["cy"])) if "cx" in cam and "cy" in cam else None
        except (json.JSONDecodeError, KeyError, TypeError, ValueError) as err:
            raise ValueError(f"clip {folder.name}: meta.json needs camera.focal ({err!r})") from None
        if not (math.isfinite(focal) and focal > 0):
            raise ValueError(f"clip {folder.name}: camera focal must be a positive number, got {focal}")
        plate = folder / "background.png"
        clips.append(
            Clip(
                folder.name, folder / "video.mp4", folder / "gt.json", plate if plate.is_file() else None, focal, centre
            )
        )
    return clips


def fingerprint(doc: dict[str, Any]) -> str:
    """Hash of a pose document's poses (not its run time): equal iff the poses are identical."""
    frames = [(f["frame"], f["status"], f["angles"], f["joints_2d"], f["joints_3d"]) for f in doc["frames"]]
    return hashlib.sha256(json.dumps(frames).encode()).hexdigest()


def run_one(clip: Clip, method: Method, frames: int | None, seed: int, threads: int | None) -> dict[str, Any]:
    """Tracks one clip with one method (at most `frames` frames) and scores it.

    Returns a plain dict (it crosses process boundaries): clip, method label, scores,
    frames, run_time_s and fingerprint; or clip, method and error. A clip without a clean
    plate is tracked against the background estimated from its video, without a warning.
    """
    from upperpose.features import CleanPlateWarning
    from upperpose.fit.pipeline import VideoTracking
    from upperpose.fit.tracker import TrackerConfig
    from upperpose.io.output import PoseRecorder
    from upperpose.io.posefile import load_poses
    from upperpose.model import Camera

    try:
        config = TrackerConfig(
            seed=seed, threads=threads, optimizer=method.optimizer, sigma=method.sigma, limits=method.limits
        )
        camera = Camera.perspective(clip.focal, *clip.centre) if clip.centre else None
        started = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CleanPlateWarning)  # the report names clips without a plate
            run = VideoTracking(clip.video, clip.background, focal=clip.focal, camera=camera, config=config)
        with run, PoseRecorder(run.reader.width, run.reader.height, run.fps) as recorder:
            for _, result in run.frames():
                recorder.add(result)
                if frames is not None and recorder.frames >= frames:
                    break
            run_time = time.perf_counter() - started
            prediction = recorder.document(run_time)
        truth = load_poses(clip.truth)
        truth["frames"] = [f for f in truth["frames"] if f["frame"] < recorder.frames]
        scores = evaluate(prediction, truth)
    except Exception as err:  # reported by the parent as one line
        return {"clip": clip.name, "method": method.label, "error": f"{type(err).__name__}: {err}"}
    return {
        "clip": clip.name,
        "method": method.label,
        "scores": scores.to_dict(),
        "frames": recorder.frames,
        "run_time_s": run_time,
        "fingerprint": fingerprint(prediction),
    }


def run_all(
    clips: Sequence[Clip],
    methods: Sequence[Method],
    *,
    frames: int | None,
    seed: int,
    jobs: int,
    threads: int | None,
    progress: Callable[[dict[str, Any], int, int], None] | None = None,
) -> list[dict[str, Any]]:
    """Every method on every clip, `jobs` processes at a time; results in (clip, method) order.

    Raises:
        UpperposeError: a run failed (its clip, method and error in one line).
    """
    tasks = [(c, m) for c in clips for m in methods]
    results: list[dict[str, Any]] = []

    def done(r: dict[str, Any]) -> None:
        if "error" in r:
            raise UpperposeError(f"clip {r['clip']}, {r['method']}: {r['error']}")
        results.append(r)
        if progress:
            progress(r, len(results), len(tasks))

    if jobs <= 1:
        for c, m in tasks:
            done(run_one(c, m, frames, seed, threads))
    else:
        with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = [pool.submit(run_one, c, m, frames, seed, threads) for c, m in tasks]
            try:
                for f in futures:
                    done(f.result())
            except BaseException:
                for f in futures:
                    f.cancel()
                raise
    return results


# -- the report --------------------------------------------------------------------------------


def pooled(runs: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """One method's scores over several clips, each clip weighted by its compared frames."""

    def mean(values: list[float | None], weights: list[int]) -> float:
        pairs = [(v, w) for v, w in zip(values, weights) if v is not None and w > 0]
        total = sum(w for _, w in pairs)
        return sum(v * w for v, w in pairs) / total if total else math.nan

    s = [r["scores"] for r in runs]
    n2 = [x["compared_frames"] for x in s]
    n3 = [x["compared_frames_3d"] for x in s]
    out: dict[str, Any] = {
        "joint_error_px": {j: [mean([x["joint_error_px"][j][k] for x in s], n2) for k in (0, 1)] for j in JOINT_NAMES},
        "joint_error_3d_mm": {j: mean([x["joint_error_3d_mm"][j] for x in s], n3) for j in JOINT_NAMES},
        "mpjpe_2d_px": mean([x["mpjpe_2d_px"] for x in s], n2),
        "pck": mean([x["pck"] for x in s], n2),
        "mpjpe_3d_mm": mean([x["mpjpe_3d_mm"] for x in s], n3),
        "coverage": sum(n2) / max(sum(x["gt_pose_frames"] for x in s), 1),
        "fps": sum(r["frames"] for r in runs) / max(sum(r["run_time_s"] for r in runs), 1e-9),
    }
    errors = out["joint_error_px"].values()
    out["mean_abs_x_px"] = sum(e[0] for e in errors) / len(JOINT_NAMES)
    out["mean_abs_y_px"] = sum(e[1] for e in errors) / len(JOINT_NAMES)
    return out


def _cell(v: float | None, digits: int, best: bool = False) -> str:
    if v is None or not math.isfinite(v):
        return "-"
    text = f"{v:.{digits}f}"
    return f"**{text}**" if best else text


def _table(header: list[str], rows: list[tuple[str, list[float | None], int, bool | None]]) -> list[str]:
    """Markdown rows; per row the best value is bold (`lower` True: lowest, False: highest, None: none)."""
    lines = ["| " + " | ".join(header) + " |", "|---|" + "---:|" * (len(header) - 1)]
    for label, values, digits, lower in rows:
        finite = [round(v, digits) for v in values if v is not None and math.isfinite(v)]
        target = (min(finite) if lower else max(finite)) if finite and lower is not None else None
        cells = [_cell(v, digits, v is not None and math.isfinite(v) and round(v, digits) == target) for v in values]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def format_report(
    results: Sequence[dict[str, Any]],
    clips: Sequence[Clip],
    methods: Sequence[Method],
    sigmas: Sequence[float],
    *,
    dataset: str,
    frames: int | None,
    seed: int,
    command: str,
) -> str:
    """The Markdown report."""
    by = {(r["clip"], r["method"]): r for r in results}
    main = list(MAIN_METHODS)
    scores = {m.label: pooled([by[(c.name, m.label)] for c in clips]) for m in methods}
    total_frames = sum(by[(c.name, main[0].label)]["frames"] for c in clips)
    lines = [
        "# Optimiser comparison (thesis §4.2, Table 4.2-1 layout)",
        "",
        f"Data set `{dataset}`: {len(clips)} clips ({', '.join(c.name for c in clips)}); "
        + (f"the first {frames} frames of each" if frames else "all frames")
        + f" ({total_frames} frames per method); seed {seed}; tracker and search defaults otherwise."
        + "".join(
            f" {c.name} has no clean plate: its background is estimated from the video."
            for c in clips
            if c.background is None
        ),
        f"Command: `{command}`",
        "",
        'Errors are pooled over the clips, each weighted by its compared frames; "3D" is the '
        'root-relative 3D error in mm that replaces the table\'s undefined "z in pixels" (SPEC 8). '
        "Frame rate: frames / wall time of the whole run (decode, features, search, output), with "
        "the runs sharing the machine. Best of each row in bold. Methods: docs/baselines.md.",
        "",
        "## Table 4.2-1: mean absolute error per joint and axis",
        "",
    ]
    rows: list[tuple[str, list[float | None], int, bool | None]] = []
    for name in JOINT_NAMES:
        label = name.replace("_", " ").capitalize()
        rows.append((f"{label} x (px)", [scores[m.label]["joint_error_px"][name][0] for m in main], 1, True))
        rows.append((f"{label} y (px)", [scores[m.label]["joint_error_px"][name][1] for m in main], 1, True))
        rows.append((f"{label} 3D (mm)", [scores[m.label]["joint_error_3d_mm"][name] for m in main], 0, True))
    rows += [
        ("**Total average x (px)**", [scores[m.label]["mean_abs_x_px"] for m in main], 2, True),
        ("**Total average y (px)**", [scores[m.label]["mean_abs_y_px"] for m in main], 2, True),
        ("Total average 3D (mm)", [scores[m.label]["mpjpe_3d_mm"] for m in main], 0, True),
        ("Frame rate (fps)", [scores[m.label]["fps"] for m in main], 1, False),
        ("2D MPJPE (px)", [scores[m.label]["mpjpe_2d_px"] for m in main], 2, True),
        ("PCK@10px (%)", [100 * scores[m.label]["pck"] for m in main], 1, False),
        ("coverage (%)", [100 * scores[m.label]["coverage"] for m in main], 1, False),
    ]
    lines += _table(["Body part", *(m.label for m in main)], rows)
    lines += ["", "## 2D MPJPE per clip (px)", ""]
    clip_rows: list[tuple[str, list[float | None], int, bool | None]] = [
        (c.name, [by[(c.name, m.label)]["scores"]["mpjpe_2d_px"] for m in main], 1, True) for c in clips
    ]
    lines += _table(["clip", *(m.label for m in main)], clip_rows)
    if sigmas:
        lines += [
            "",
            "## Sigma sweep of APSOPF [2] (thesis Tables 4.2-2..4)",
            "",
            "Mean absolute error in pixels, pooled over the clips; APSO for reference.",
            "",
        ]
        header = ["method"]
        for j in SWEEP_JOINTS:
            label = j.replace("_", " ").capitalize()
            header += [f"{label} x", f"{label} y"]
        header += ["2D MPJPE", "coverage (%)"]
        sweep = [MAIN_METHODS[0]] + [sweep_method(s) for s in sorted(set(sigmas))]
        lines += ["| " + " | ".join(header) + " |", "|---|" + "---:|" * (len(header) - 1)]
        for m in sweep:
            sc = scores[m.label]
            cells = [f"{sc['joint_error_px'][j][k]:.1f}" for j in SWEEP_JOINTS for k in (0, 1)]
            cells += [f"{sc['mpjpe_2d_px']:.2f}", f"{100 * sc['coverage']:.1f}"]
            label = "APSO (ours)" if m is MAIN_METHODS[0] else f"σ = {m.sigma:g}"
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
    digest = hashlib.sha256("".join(r["fingerprint"] for r in results).encode()).hexdigest()
    lines += [
        "",
        "## Reproducibility",
        "",
        f"Fingerprint of all {len(results)} runs' poses: `{digest[:16]}`. The same data, options "
        "and seed give the same fingerprint and the same errors, whatever `--jobs` and the thread "
        "count; the frame rates are wall time and vary between runs.",
        "",
    ]
    return "\n".join(lines)
