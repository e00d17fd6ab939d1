"""Progress over a batch on stderr: videos and frames done, frames per second, time left.

One line per finished video, and `upperpose.io.progress` over the frames of the whole batch (a
bar on a terminal, else a plain line now and then). The time left is the frames still to track
at the rate of this run so far (skipped videos count neither way).
"""

from __future__ import annotations

from typing import Any, TextIO

from upperpose.io.progress import Progress
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
        self.meter = Progress("upperpose batch", enabled=enabled, stream=stream)
        self.frames: dict[int, int] = {}
        self.finished = 0

    def frame(self, index: int, done: int) -> None:
        """Video `index` has `done` frames."""
        self.frames[index] = done
        self._update()

    def video(self, index: int, row: dict[str, Any]) -> None:
        """Video `index` ended with its summary row."""
        self.finished += 1
        if row.get("frames") is not None:
            self.frames[index] = row["frames"]
            self.totals[index] = row["frames"]
        else:
            self.totals[index] = self.frames.get(index, 0)
        self._update()
        if not self.enabled:
            return
        what = f"{row['frames']} frames ({row['frames_with_pose']} with a pose)" if row.get("frames") else ""
        rate = f", {row['frames_per_s']:.1f} frames/s" if row.get("frames_per_s") else ""
        detail = f": {row['error']}" if row.get("error") else ""
        line = f"[{self.skipped + self.finished}/{self.skipped + len(self.totals)}] {row['video']}: {row['status']}"
        self.meter.write(f"{line}{', ' + what if what else ''}{rate}{detail}  |  {self.meter.text()}")

    def close(self) -> None:
        """Removes the bar."""
        self.meter.close()

    def _update(self) -> None:
        # A video whose length is unknown (unreadable header, a stream) counts once it has ended.
        total = sum(t or 0 for t in self.totals.values())
        self.meter.update(sum(self.frames.values()), total, f"videos {self.finished}/{len(self.totals)}")


__all__ = ["BatchProgress", "frame_count"]
