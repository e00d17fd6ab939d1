"""Progress over a batch on stderr: videos and frames done, frames per second, time left.

One line per finished video; on a terminal, also a line redrawn as frames come in. The time
left is the frames still to track at the rate of this run so far (skipped videos count
neither way).
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

from upperpose.io.video import VideoReader


def frame_count(source: str) -> int | None:
    """The video's frame count as its header says, None when unknown or unreadable."""
    try:
        with VideoReader(source) as reader:
            return reader.frame_count
    except Exception:  # a video that cannot be read fails when it is tracked, with its error
        return None


class BatchProgress:
    """Progress over the videos to track (not the skipped ones).

    Args:
        totals: each video's frame count (None when unknown), by the video's index.
        skipped: videos of the batch already finished.
        enabled: False writes nothing.
        stream: where to write (stderr).
    """

    def __init__(
        self, totals: dict[int, int | None], skipped: int, enabled: bool, stream: TextIO | None = None
    ) -> None:
        self.totals, self.skipped, self.enabled = totals, skipped, enabled
        self.stream = stream or sys.stderr
        self.live = enabled and self.stream.isatty()
        self.frames: dict[int, int] = {}
        self.finished = 0
        self.start = self.last = time.perf_counter()

    def frame(self, index: int, done: int) -> None:
        """Video `index` has `done` frames; redraws the live line at most five times a second."""
        self.frames[index] = done
        now = time.perf_counter()
        if self.live and now - self.last >= 0.2:
            self.last = now
            self.stream.write(f"\r{self._status()}\033[K")
            self.stream.flush()

    def video(self, index: int, row: dict[str, Any]) -> None:
        """Video `index` ended with its summary row."""
        self.finished += 1
        if row.get("frames") is not None:
            self.frames[index] = row["frames"]
            self.totals[index] = row["frames"]
        else:
            self.totals[index] = self.frames.get(index, 0)
        if not self.enabled:
            return
        what = f"{row['frames']} frames ({row['frames_with_pose']} with a pose)" if row.get("frames") else ""
        rate = f", {row['frames_per_s']:.1f} frames/s" if row.get("frames_per_s") else ""
        detail = f": {row['error']}" if row.get("error") else ""
        line = f"[{self.skipped + self.finished}/{self.skipped + len(self.totals)}] {row['video']}: {row['status']}"
        line += f"{', ' + what if what else ''}{rate}{detail}  |  {self._status()}"
        self.stream.write(("\r" if self.live else "") + line + ("\033[K" if self.live else "") + "\n")
        self.stream.flush()

    def _status(self) -> str:
        done = sum(self.frames.values())
        elapsed = time.perf_counter() - self.start
        rate = done / elapsed if elapsed > 0 else 0.0
        # A video whose length is unknown (unreadable header, a stream) counts once it has ended.
        total = sum(t or 0 for t in self.totals.values())
        text = f"videos {self.finished}/{len(self.totals)}, frames {done}/{total}, {rate:.1f} frames/s"
        if rate > 0:
            text += f", ETA {_clock(max(total - done, 0) / rate)}"
        return text


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"


__all__ = ["BatchProgress", "frame_count"]
