"""Collecting per-frame results and writing them: the pose file of SPEC 9 and a CSV, atomically.

Both files are written whole or not at all (`write_atomic`); after Ctrl-C the caller writes
the frames done so far, so an interrupted run still leaves valid files.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path
from typing import Any

from upperpose.io.files import write_atomic
from upperpose.io.posefile import make_poses, write_poses
from upperpose.model import ANGLE_NAMES, JOINT_NAMES
from upperpose.result import LOST, TRACKED, TrackResult


def csv_header() -> list[str]:
    """Column names: frame, status, cost, 7 x (x, y) pixels, 7 x (X, Y, Z) metres, 13 angles."""
    cols = ["frame", "status", "cost"]
    cols += [f"{j}_{a}" for j in JOINT_NAMES for a in ("x", "y")]
    cols += [f"{j}_{a}" for j in JOINT_NAMES for a in ("X", "Y", "Z")]
    return cols + list(ANGLE_NAMES)


class PoseRecorder:
    """Accumulates frame records (small dicts, not images) and writes them.

    Args:
        width, height: frame size in pixels.
        fps: the video's frame rate.
        extra: further top-level fields (e.g. "source", "seed", "body").
    """

    def __init__(self, width: int, height: int, fps: float, **extra: Any) -> None:
        self.width, self.height, self.fps = width, height, fps
        self.extra = extra
        self.records: list[dict[str, Any]] = []

    def add(self, result: TrackResult) -> None:
        """Appends one frame."""
        self.records.append(result.to_record())

    @property
    def frames(self) -> int:
        """Frames recorded."""
        return len(self.records)

    def count(self, *statuses: str) -> int:
        """Frames with any of `statuses`."""
        return sum(r["status"] in statuses for r in self.records)

    def document(self, run_time_s: float) -> dict[str, Any]:
        """The SPEC 9 document of the frames so far."""
        return make_poses(
            self.width, self.height, self.fps, list(self.records), run_time_s=round(run_time_s, 4), **self.extra
        )

    def write_json(self, path: str | os.PathLike[str], run_time_s: float) -> Path:
        """Writes the pose file atomically (validated against SPEC 9 first)."""
        return write_poses(path, self.document(run_time_s))

    def write_csv(self, path: str | os.PathLike[str]) -> Path:
        """Writes one CSV row per frame atomically; frames without a pose leave their cells empty."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(csv_header())
        for r in self.records:
            row: list[Any] = [r["frame"], r["status"], "" if r["cost"] is None else f"{r['cost']:.6g}"]
            has_pose = r["status"] in (TRACKED, LOST) and r["joints_2d"] is not None
            for key, dims in (("joints_2d", 2), ("joints_3d", 3)):
                cells = (
                    [f"{v:.6g}" for p in r[key] for v in p] if has_pose and r[key] is not None else [""] * (7 * dims)
                )
                row += cells
            row += (
                [f"{v:.6g}" for v in r["angles"]] if has_pose and r["angles"] is not None else [""] * len(ANGLE_NAMES)
            )
            writer.writerow(row)
        text = buffer.getvalue()

        def write(tmp: Path) -> None:
            tmp.write_text(text, encoding="utf-8")

        return write_atomic(path, write)


__all__ = ["PoseRecorder", "csv_header"]
