"""Memory stays flat over a long stream, for `Tracker.update` and for `upperpose track`.

The clip's frames are fed over and over (the tracker starts, tracks, loses and finds the person
again), with the search replaced by the truth double so that the stream is long enough to
measure in a test. Python's heap is traced (tracemalloc) from the end of a warm-up, and the live
traced blocks are counted at both ends of a later window. Both counts hold the tracker's state
rebuilt since tracing began (smoother buffers, the current skin tables), so their difference is
growth, not state: bytes would swing with the state (skin tables of hundreds of kilobytes exist
only after a face was seen), the number of blocks barely does. RSS, which also sees the Rust
core's and OpenCV's allocations, gets a coarse bound. docs/limits.md gives the 30-minute run done
by hand.
"""

from __future__ import annotations

import gc
import tracemalloc
from pathlib import Path

import cv2
import numpy as np
import pytest

import upperpose.fit.tracker as tracker_module
import upperpose.io.video as video_module
from test_track_cli import FakeCamera, clip_frames
from tracker_helpers import TruthFitter, camera_of, clip, truth
from upperpose.cli import main
from upperpose.fit import Tracker, TrackerConfig
from upperpose.io.posefile import load_poses

# Tracing starts after WARM_UP frames; blocks are counted SETTLE frames later and WINDOW frames
# after that, so that state allocated once tracing is on is in both counts.
WARM_UP, SETTLE, WINDOW = 150, 150, 450
# Live heap blocks the window may add. A leak of one object a frame adds 450; the records
# `upperpose track` once held added about 60 a frame. The state the tracker is in at either end
# (skin tables after a face, the smoother's buffer, the other arm's followers) and objects parked
# in CPython's free lists, which tracemalloc counts as live, make up to about 250 either way.
MAX_BLOCK_GROWTH = 400
MAX_RSS_GROWTH = 16_000_000


def rss() -> int:
    """Resident set size of this process, bytes."""
    return int(Path("/proc/self/statm").read_text().split()[1]) * 4096


def live_blocks() -> int:
    """Python heap blocks allocated since tracing started and still alive."""
    gc.collect()
    return sum(stat.count for stat in tracemalloc.take_snapshot().statistics("filename"))


class Meter:
    """Heap blocks and RSS at the start and the end of the window (frames START..END)."""

    START = WARM_UP + SETTLE
    END = START + WINDOW

    def __init__(self) -> None:
        self.blocks: list[int] = []
        self.rss: list[int] = []

    def tick(self, frame: int) -> None:
        if frame == WARM_UP:
            tracemalloc.start()
        if frame in (self.START, self.END):
            self.blocks.append(live_blocks())
            self.rss.append(rss())
        if frame == self.END:
            tracemalloc.stop()

    def growth(self) -> tuple[int, int]:
        return self.blocks[1] - self.blocks[0], self.rss[1] - self.rss[0]


def quiet_fitter() -> TruthFitter:
    """The truth double without its call log, which would grow with the stream by design."""
    fitter = TruthFitter(truth(clip()))
    fitter.calls = _Discard()
    return fitter


class _Discard(list):  # type: ignore[type-arg]
    def append(self, item: object) -> None:
        pass


@pytest.fixture(scope="module")
def frames() -> list[np.ndarray]:
    return clip_frames(clip())


def test_tracker_update_memory_is_flat(frames: list[np.ndarray]) -> None:
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    tracker = Tracker(camera_of(folder), plate, TrackerConfig(), fps=15.0, fitter=quiet_fitter())
    meter, statuses = Meter(), set()
    for i in range(Meter.END + 1):
        meter.tick(i)
        statuses.add(tracker.update(frames[i % len(frames)]).status)
    heap, resident = meter.growth()
    assert statuses == {"no_person", "initialising", "tracked", "lost"}  # every state, many times
    assert heap < MAX_BLOCK_GROWTH, heap
    assert resident < MAX_RSS_GROWTH, resident


def test_track_command_memory_is_flat(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, frames: list[np.ndarray], capsys: pytest.CaptureFixture[str]
) -> None:
    meter = Meter()
    total = Meter.END + 1

    class Stream(FakeCamera):
        """A live camera showing the clip over and over; the meter reads at each frame."""

        def __init__(self) -> None:
            super().__init__(frames)

        def read(self) -> tuple[bool, np.ndarray | None]:
            if self.at >= total:
                return False, None
            meter.tick(self.at)
            self.at += 1
            return True, frames[self.at % len(frames)]

    monkeypatch.setattr(tracker_module, "fit_frame", quiet_fitter())
    monkeypatch.setattr(video_module.cv2, "VideoCapture", lambda source: Stream())
    out = tmp_path / "poses.json"
    argv = [
        "track",
        "0",
        "--background",
        str(clip() / "background.png"),
        "-o",
        str(out),
        "--csv",
        str(tmp_path / "p.csv"),
    ]
    assert main([*argv, "--quiet"]) == 0, capsys.readouterr().err
    heap, resident = meter.growth()
    assert heap < MAX_BLOCK_GROWTH, heap
    assert resident < MAX_RSS_GROWTH, resident
    assert len(load_poses(out)["frames"]) == total
