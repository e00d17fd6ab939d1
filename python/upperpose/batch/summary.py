"""The batch's summary: DIR/summary.csv (one row per video) and DIR/summary.json (rows and totals).

Both are written whole or not at all, also after Ctrl-C (then the videos not reached are
"not_run"). Statuses: done, no_pose (tracked, but no frame has a pose: the error column says
why), skipped (an earlier run finished it with the same settings), failed (the error column
says why), not_run.
"""

from __future__ import annotations

import csv
import json
from collections import Counter
from pathlib import Path
from typing import Any

from upperpose._upperpose import __version__
from upperpose.batch.job import FAILED
from upperpose.io.files import write_atomic

COLUMNS = ("video", "frames", "frames_with_pose", "frames_per_s", "status", "error", "output")
FORMAT = "upperpose.batch/1"


def totals(rows: list[dict[str, Any]], wall_time_s: float) -> dict[str, Any]:
    """Counts by status, frames, and this run's throughput (skipped videos excluded)."""
    ran = [r for r in rows if r["run_time_s"] is not None and r["status"] != "skipped"]
    frames = sum(r["frames"] or 0 for r in ran)
    return {
        "videos": len(rows),
        "by_status": dict(Counter(r["status"] for r in rows)),
        "failed": sum(r["status"] == FAILED for r in rows),
        "frames": sum(r["frames"] or 0 for r in rows),
        "frames_with_pose": sum(r["frames_with_pose"] or 0 for r in rows),
        "wall_time_s": round(wall_time_s, 3),
        "tracked_this_run": {
            "videos": len(ran),
            "frames": frames,
            "videos_per_hour": round(3600 * len(ran) / wall_time_s, 1) if wall_time_s > 0 else None,
            "frames_per_s": round(frames / wall_time_s, 2) if wall_time_s > 0 else None,
        },
    }


def write_summary(out_dir: Path, rows: list[dict[str, Any]], head: dict[str, Any], wall_time_s: float) -> list[Path]:
    """Writes summary.csv and summary.json into `out_dir`; `head` describes the run (backend, settings)."""

    def write_csv(tmp: Path) -> None:
        with tmp.open("w", encoding="utf-8", newline="") as f:
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(COLUMNS)
            writer.writerows([("" if r[c] is None else r[c]) for c in COLUMNS] for r in rows)

    document = {
        "format": FORMAT,
        "upperpose_version": __version__,
        **head,
        "totals": totals(rows, wall_time_s),
        "videos": rows,
    }
    text = json.dumps(document, indent=1) + "\n"
    return [
        write_atomic(out_dir / "summary.csv", write_csv),
        write_atomic(out_dir / "summary.json", lambda tmp: tmp.write_text(text, encoding="utf-8")),
    ]


__all__ = ["COLUMNS", "FORMAT", "totals", "write_summary"]
