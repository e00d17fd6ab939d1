"""Collecting per-frame results and writing them: the pose file of SPEC 9 and a CSV, atomically.

Both files are written whole or not at all (`write_atomic`); after Ctrl-C the caller writes
the frames done so far, so an interrupted run still leaves valid files. The records wait in a
temporary file, not in memory.
"""

from __future__ import annotations

import csv
import io
import json
import os
import tempfile
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from upperpose.exceptions import InputError
from upperpose.io.files import write_atomic
from upperpose.io.posefile import frame_line, make_poses, validate_frame, validate_poses, write_pose_lines
from upperpose.model import ANGLE_NAMES, JOINT_NAMES
from upperpose.result import LOST, TRACKED, TrackResult


def csv_header() -> list[str]:
    """Column names: frame, status, cost, 7 x (x, y) px, 7 x (X, Y, Z) m, 13 angles, 7 confidences, 7 visibilities."""
    cols = ["frame", "status", "cost"]
    cols += [f"{j}_{a}" for j in JOINT_NAMES for a in ("x", "y")]
    cols += [f"{j}_{a}" for j in JOINT_NAMES for a in ("X", "Y", "Z")]
    cols += list(ANGLE_NAMES) + [f"{j}_confidence" for j in JOINT_NAMES]
    return cols + [f"{j}_visibility" for j in JOINT_NAMES]


class PoseRecorder:
    """Collects frame records and writes them as the pose file (SPEC 9) and a CSV.

    The records go to an anonymous temporary file as they come, so memory does not grow with
    the video; each is validated when added, so writing at the end cannot fail on a frame.

    Args:
        width, height: frame size in pixels.
        fps: the video's frame rate.
        extra: further top-level fields (e.g. "source", "seed", "settings").
    """

    def __init__(self, width: int, height: int, fps: float, **extra: Any) -> None:
        self.width, self.height, self.fps = width, height, fps
        self.extra = extra
        self._spool = tempfile.TemporaryFile("w+", encoding="utf-8")
        self._counts: Counter[str] = Counter()
        self._last_frame = -1
        self.first_posed: int | None = None
        """The number of the first frame with a pose ("tracked" or "lost"), once there is one."""

    def add(self, result: TrackResult) -> None:
        """Appends one frame."""
        self.add_record(result.to_record())

    def add_record(self, record: dict[str, Any]) -> None:
        """Appends one frame given as its pose-file entry.

        Raises:
            ValueError: the entry does not follow the schema, or its number is not after the last.
        """
        checked = validate_frame(record, self.frames)
        if checked["frame"] <= self._last_frame:
            raise InputError(f"frame {checked['frame']} comes after frame {self._last_frame}: frames must increase")
        self._spool.seek(0, io.SEEK_END)
        self._spool.write(frame_line(record) + "\n")
        self._last_frame = checked["frame"]
        self._counts[checked["status"]] += 1
        if self.first_posed is None and checked["status"] in (TRACKED, LOST):
            self.first_posed = checked["frame"]

    @property
    def frames(self) -> int:
        """Frames recorded."""
        return sum(self._counts.values())

    def count(self, *statuses: str) -> int:
        """Frames with any of `statuses`."""
        return sum(self._counts[s] for s in statuses)

    def records(self) -> Iterator[dict[str, Any]]:
        """The frames recorded so far, read back in order."""
        for line in self._lines():
            yield json.loads(line)

    def document(self, run_time_s: float) -> dict[str, Any]:
        """The SPEC 9 document of the frames so far (in memory: for short clips)."""
        return make_poses(self.width, self.height, self.fps, list(self.records()), **self._head_extra(run_time_s))

    def write_json(self, path: str | os.PathLike[str], run_time_s: float) -> Path:
        """Writes the pose file atomically, streaming the frames from the temporary file."""
        head = make_poses(self.width, self.height, self.fps, [], **self._head_extra(run_time_s))
        validate_poses(head)
        del head["frames"]
        return write_pose_lines(path, head, self._lines())

    def write_csv(self, path: str | os.PathLike[str]) -> Path:
        """Writes one CSV row per frame atomically; frames without a pose leave their cells empty."""

        def write(tmp: Path) -> None:
            with tmp.open("w", encoding="utf-8", newline="") as f:
                writer = csv.writer(f, lineterminator="\n")
                writer.writerow(csv_header())
                writer.writerows(csv_row(r) for r in self.records())

        return write_atomic(path, write)

    def close(self) -> None:
        """Deletes the temporary file (also done when the recorder is garbage-collected)."""
        self._spool.close()

    def __enter__(self) -> PoseRecorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _head_extra(self, run_time_s: float) -> dict[str, Any]:
        return {"run_time_s": round(run_time_s, 4), **self.extra}

    def _lines(self) -> Iterator[str]:
        self._spool.flush()
        self._spool.seek(0)
        for line in self._spool:
            yield line.rstrip("\n")


def csv_row(r: dict[str, Any]) -> list[Any]:
    """One frame's CSV cells (csv_header's columns)."""
    row: list[Any] = [r["frame"], r["status"], "" if r["cost"] is None else f"{r['cost']:.6g}"]
    has_pose = r["status"] in (TRACKED, LOST) and r["joints_2d"] is not None
    for key, dims in (("joints_2d", 2), ("joints_3d", 3)):
        row += [f"{v:.6g}" for p in r[key] for v in p] if has_pose and r[key] is not None else [""] * (7 * dims)
    row += [f"{v:.6g}" for v in r["angles"]] if has_pose and r["angles"] is not None else [""] * len(ANGLE_NAMES)
    confidence = r.get("confidence")
    row += [f"{v:.3g}" for v in confidence] if has_pose and confidence is not None else [""] * len(JOINT_NAMES)
    visibility = r.get("visibility")
    row += list(visibility) if has_pose and visibility is not None else [""] * len(JOINT_NAMES)
    return row


__all__ = ["PoseRecorder", "csv_header", "csv_row"]
