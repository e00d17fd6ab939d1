"""One video of a batch: its outputs, whether a earlier run finished it, and tracking it into a row.

A row is the video's line of the summary, a plain dict (it crosses process and Ray boundaries).
Any error of one video becomes its row's status and error and never stops the batch; Ctrl-C
(KeyboardInterrupt) does stop it, with nothing of the video written.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from upperpose.batch.inputs import Video
from upperpose.exceptions import UpperposeError, one_line
from upperpose.fit.outputs import OutputPaths, smoothing_record, track_to_files
from upperpose.fit.settings import config_to_dict
from upperpose.fit.tracker import TrackerConfig
from upperpose.io.posefile import load_poses
from upperpose.io.video import is_stream_url
from upperpose.result import LOST, TRACKED

DONE, NO_POSE, SKIPPED, FAILED, NOT_RUN = "done", "no_pose", "skipped", "failed", "not_run"
# A clip folder (docs/dataset.md) keeps its clean plate beside the video under this name.
PLATE_NAME = "background.png"
# Settings that do not change the poses: the same seed gives the same poses whatever the threads.
NOT_COMPARED = ("threads",)


@dataclass(frozen=True)
class Options:
    """What every video of a batch is tracked with and which files it gets besides the pose file."""

    config: TrackerConfig
    background: str | None = None
    focal: float | None = None
    smooth: bool = True
    csv: bool = False
    bvh: bool = False
    overlay: bool = False


@dataclass(frozen=True)
class Job:
    """One video with the batch's options."""

    video: Video
    options: Options

    def paths(self, out_dir: Path) -> OutputPaths:
        """The video's outputs under `out_dir`: PLACE.json, .csv, .bvh and .overlay.mp4."""
        base = out_dir / self.video.place
        o = self.options

        def named(suffix: str, wanted: bool = True) -> Path | None:
            return base.with_name(base.name + suffix) if wanted else None

        return OutputPaths(
            base.with_name(base.name + ".json"),
            csv=named(".csv", o.csv),
            bvh=named(".bvh", o.bvh),
            overlay=named(".overlay.mp4", o.overlay),
        )

    def plate(self) -> str | None:
        """The clean plate: the batch's, else a background.png beside the video, else none (estimated)."""
        if self.options.background is not None or is_stream_url(self.video.source):
            return self.options.background
        beside = Path(self.video.source).parent / PLATE_NAME
        return str(beside) if beside.is_file() else None


def row(job: Job, status: str, *, error: str = "", **counts: Any) -> dict[str, Any]:
    """The video's summary line."""
    frames, run_time = counts.get("frames"), counts.get("run_time_s")
    return {
        "video": job.video.source,
        "output": f"{job.video.place}.json",
        "frames": frames,
        "frames_with_pose": counts.get("frames_with_pose"),
        "frames_per_s": round(frames / run_time, 2) if frames and run_time else None,
        "run_time_s": None if run_time is None else round(run_time, 3),
        "clean_plate": counts.get("clean_plate"),
        "status": status,
        "error": error,
    }


def run_job(job: Job, out_dir: Path, on_frame: Callable[[int, int | None, str], None] | None = None) -> dict[str, Any]:
    """Tracks the video into its outputs under `out_dir`; its row, FAILED with the error if it failed.

    Raises:
        KeyboardInterrupt: Ctrl-C or SIGTERM; none of the video's outputs was written.
    """
    o = job.options
    paths = job.paths(out_dir)
    try:
        paths.poses.parent.mkdir(parents=True, exist_ok=True)
        done = track_to_files(
            job.video.source,
            paths,
            config=o.config,
            background=job.plate(),
            focal=o.focal,
            smooth=o.smooth,
            on_frame=on_frame,
        )
    except Exception as err:  # one video's failure is its row, whatever it was
        known = isinstance(err, (UpperposeError, ValueError, OSError))
        return row(
            job, FAILED, error=one_line(err) if known else f"internal error ({type(err).__name__}: {one_line(err)})"
        )
    note = ""
    if not done.posed:
        note = "no person found" if done.no_person == done.frames else "start-up never completed (no steady face)"
        if done.looks:
            note += f"; {done.looks}"
    return row(
        job,
        DONE if done.posed else NO_POSE,
        error=note,
        frames=done.frames,
        frames_with_pose=done.posed,
        run_time_s=done.run_time_s,
        clean_plate=done.clean_plate,
    )


def finished_row(job: Job, out_dir: Path) -> dict[str, Any] | None:
    """The SKIPPED row of a video an earlier run finished with the same settings, else None.

    Finished: its pose file reads back whole and valid, records the settings, seed, smoothing,
    clean plate and focal length this batch would use, and every other output asked for is there.
    """
    paths = job.paths(out_dir)
    try:
        doc = load_poses(paths.poses)
    except (OSError, ValueError):
        return None
    if recorded(doc) != expected(job, doc["width"]):
        return None
    posed = sum(1 for f in doc["frames"] if f["status"] in (TRACKED, LOST))
    wanted = [paths.csv, paths.overlay] + ([paths.bvh] if posed else [])
    if any(p is not None and not p.is_file() for p in wanted):
        return None
    return row(
        job,
        SKIPPED,
        frames=len(doc["frames"]),
        frames_with_pose=posed,
        run_time_s=doc.get("run_time_s"),
        clean_plate=doc.get("clean_plate"),
    )


def recorded(doc: dict[str, Any]) -> dict[str, Any]:
    """What a pose file says about how it was made, as `expected` words it."""
    settings = {k: v for k, v in (doc.get("settings") or {}).items() if k not in NOT_COMPARED}
    camera = doc.get("camera") or {}
    return {
        "settings": settings,
        "smoothing": doc.get("smoothing"),
        "clean_plate": doc.get("clean_plate"),
        "focal": camera.get("focal"),
    }


def expected(job: Job, width: int) -> dict[str, Any]:
    """How this batch would make the video's pose file (the focal length defaults to the width)."""
    settings = {k: v for k, v in config_to_dict(job.options.config).items() if k not in NOT_COMPARED}
    made = {
        "settings": settings,
        "smoothing": smoothing_record(job.options.smooth)[1],
        "clean_plate": job.plate() is not None,
        "focal": float(job.options.focal or width),
    }
    # As the pose file holds it: JSON has lists, not tuples.
    plain: dict[str, Any] = json.loads(json.dumps(made))
    return plain


__all__ = ["DONE", "FAILED", "NOT_RUN", "NO_POSE", "SKIPPED", "Job", "Options", "finished_row", "row", "run_job"]
