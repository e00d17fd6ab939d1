"""`run`: a batch of videos from inputs to pose files and a summary, on one backend."""

from __future__ import annotations

import contextlib
import dataclasses
import os
import time
from collections.abc import Generator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from upperpose.batch.inputs import find_videos
from upperpose.batch.job import DONE, FAILED, NO_POSE, NOT_RUN, Job, Options, finished_row, row
from upperpose.batch.progress import BatchProgress, frame_count
from upperpose.batch.summary import write_summary
from upperpose.exceptions import InputError
from upperpose.fit.settings import config_to_dict
from upperpose.fit.tracker import TrackerConfig
from upperpose.io.files import interrupts_held

BACKENDS = ("local", "ray")


@dataclass(frozen=True)
class BatchResult:
    """What a batch did: one summary row per video (input order) and the summary files."""

    rows: list[dict[str, Any]]
    summary: list[Path]
    wall_time_s: float

    @property
    def failed(self) -> int:
        """Videos that failed."""
        return sum(r["status"] == FAILED for r in self.rows)

    def count(self, status: str) -> int:
        """Videos with `status`."""
        return sum(r["status"] == status for r in self.rows)


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM) ended the batch; `result` has the summary written so far."""

    def __init__(self, result: BatchResult) -> None:
        super().__init__("batch interrupted")
        self.result = result


def run(
    inputs: Sequence[str | os.PathLike[str]],
    out_dir: str | os.PathLike[str],
    *,
    jobs: int = 1,
    backend: str = "local",
    address: str | None = None,
    collect: bool = False,
    config: TrackerConfig | None = None,
    background: str | os.PathLike[str] | None = None,
    focal: float | None = None,
    smooth: bool = True,
    csv: bool = False,
    bvh: bool = False,
    overlay: bool = False,
    progress: bool = False,
) -> BatchResult:
    """Tracks every video the inputs name into `out_dir`, skipping those finished before.

    Args:
        inputs: videos, folders (searched recursively), globs, list files (.txt: one path or
            URL a line) and URLs.
        out_dir: where the outputs go, in the inputs' folder layout: PLACE.json (the pose file),
            with `csv`, `bvh`, `overlay` also PLACE.csv, PLACE.bvh, PLACE.overlay.mp4; and
            summary.csv, summary.json.
        jobs: local backend: videos tracked at once, each in its own process (1: in this one).
        backend: "local" or "ray" (one Ray task per video).
        address: ray: the cluster's address (None: the Ray of this process, else a new local one).
        collect: ray: the tasks return the files and this process writes them (else the
            workers write into `out_dir`, which they must see at the same path).
        config: tracker settings; its `threads` defaults to 1 (one core per video).
        background: one clean plate for every video; None: a background.png beside the
            video, else estimated from the video.
        focal: focal length in pixels for every video (default: each video's width).
        smooth: smooth the written poses.
        csv: also write the CSV.
        bvh: also write the BVH.
        overlay: also write the overlay video.
        progress: report progress on stderr.

    Returns:
        The rows and summary files. A video that fails is a row with status "failed" and its
        error; it does not stop the batch.

    Raises:
        InputError: bad arguments, or inputs naming no video.
        BatchInterrupted: Ctrl-C or SIGTERM; finished videos are whole, unfinished ones absent.
    """
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise InputError(f"jobs must be at least 1, got {jobs!r}")
    if backend not in BACKENDS:
        raise InputError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    if backend != "ray" and (address is not None or collect):
        raise InputError("address and collect are for the ray backend")
    if backend == "ray" and jobs != 1:
        raise InputError("jobs is for the local backend: Ray runs as many tasks as the cluster has CPUs")
    started = time.perf_counter()
    videos = find_videos([str(i) for i in inputs])
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"the output folder {out} is a file")
    out.mkdir(parents=True, exist_ok=True)
    config = config or TrackerConfig()
    if config.threads is None:
        config = dataclasses.replace(config, threads=1)
    # Absolute, for workers whose current folder is another (Ray).
    plate = None if background is None else str(Path(background).resolve())
    options = Options(config, plate, focal, smooth, csv, bvh, overlay)
    work = [Job(video, options) for video in videos]
    rows: dict[int, dict[str, Any]] = {}
    for index, job in enumerate(work):
        skipped = finished_row(job, out)
        if skipped is not None:
            rows[index] = skipped
    todo = [(i, job) for i, job in enumerate(work) if i not in rows]
    totals = {i: frame_count(job.video.source) if progress else None for i, job in todo}
    meter = BatchProgress(totals, len(rows), progress)
    interrupted = False
    try:
        with contextlib.closing(_backend(backend, todo, out, jobs, address, collect, meter)) as results:
            for index, ended in results:
                rows[index] = ended
                meter.video(index, ended)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        meter.close()
    with interrupts_held():
        ordered = [rows.get(i) or _unrecorded(job, out) for i, job in enumerate(work)]
        wall = time.perf_counter() - started
        head = {
            "backend": backend,
            "jobs": jobs,
            "inputs": [str(i) for i in inputs],
            "settings": config_to_dict(config),
            "interrupted": interrupted,
        }
        result = BatchResult(ordered, write_summary(out, ordered, head, wall), wall)
    if interrupted:
        raise BatchInterrupted(result)
    return result


def _unrecorded(job: Job, out: Path) -> dict[str, Any]:
    """The row of a video whose result never came back (Ctrl-C): finished meanwhile, or not run."""
    # A worker may finish writing after the interrupt (its last file is written whole first).
    found = finished_row(job, out)
    if found is None:
        return row(job, NOT_RUN)
    return {**found, "status": DONE if found["frames_with_pose"] else NO_POSE}


def _backend(
    backend: str,
    todo: list[tuple[int, Job]],
    out: Path,
    jobs: int,
    address: str | None,
    collect: bool,
    meter: BatchProgress,
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    if backend == "ray":
        from upperpose.batch.ray_backend import run_ray

        return run_ray(todo, out, address=address, collect=collect)
    from upperpose.batch.local import run_local

    return run_local(todo, out, jobs, meter)


__all__ = ["BACKENDS", "BatchInterrupted", "BatchResult", "run"]
