"""Progress on stderr, shared by `upperpose track` and `upperpose batch`.

On a terminal: tqdm's bar, with the rate and the time left. Elsewhere (a job scheduler's log, a
pipe) a bar redrawn with carriage returns is one endless line, so instead one plain line every
UPPERPOSE_PROGRESS_EVERY seconds (default 10; 0 turns these lines off).
"""

from __future__ import annotations

import math
import os
import sys
import time
from typing import Any, TextIO

from tqdm import tqdm

from upperpose.exceptions import InputError

EVERY_ENV = "UPPERPOSE_PROGRESS_EVERY"
DEFAULT_EVERY_S = 10.0
# The plain line: tqdm's numbers without the bar (a log reader wants the count and the time left).
_PLAIN = "{n_fmt}/{total_fmt}{unit} ({percentage:.0f} %), {rate_fmt}, ETA {remaining}{postfix}"
_PLAIN_OPEN_ENDED = "{n_fmt}{unit}, {rate_fmt}{postfix}"  # a live source: no total, no time left


def plain_every() -> float:
    """Seconds between plain progress lines, from UPPERPOSE_PROGRESS_EVERY (0: none)."""
    text = os.environ.get(EVERY_ENV, "").strip()
    if not text:
        return DEFAULT_EVERY_S
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise InputError(f"{EVERY_ENV} must be a number of seconds >= 0, got {text!r}")
    return value


def write_line(line: str, stream: TextIO | None = None) -> None:
    """Writes a line that stays: above a progress bar on the same stream, which is redrawn below it."""
    tqdm.write(line, file=stream or sys.stderr)


class Progress:
    """Counts up to a total that may change (or be unknown) and shows it on stderr.

    Args:
        label: what is counted, starting each plain line ("upperpose track").
        unit: the counted things, plural ("frames").
        enabled: False shows nothing (`--quiet`).
        stream: where to show it (stderr).
    """

    def __init__(self, label: str, unit: str = "frames", enabled: bool = True, stream: TextIO | None = None) -> None:
        self.stream = stream or sys.stderr
        self.label, self.unit = label, f" {unit}"
        self.done, self.note = 0, ""
        self.total: int | None = None
        self.start = self.last = time.monotonic()
        self.bar: Any = None
        self.every = 0.0
        if enabled and self.stream.isatty():
            self.bar = tqdm(desc=label, unit=self.unit, file=self.stream, dynamic_ncols=True, leave=False)
        elif enabled:
            self.every = plain_every()

    def update(self, done: int, total: int | None, note: str = "") -> None:
        """Sets the count, the total (None: unknown) and a short note shown after them."""
        self.done, self.total, self.note = done, total, note
        if self.bar is not None:
            if self.bar.total != total:
                self.bar.total = total
            self.bar.set_postfix_str(note, refresh=False)
            self.bar.update(done - self.bar.n)
            return
        now = time.monotonic()
        if self.every > 0 and now - self.last >= self.every:
            self.last = now
            write_line(f"{self.label}: {self.text()}", self.stream)

    def text(self) -> str:
        """The count, rate and time left, as the plain lines show them."""
        text = str(
            tqdm.format_meter(
                self.done,
                self.total,
                time.monotonic() - self.start,
                unit=self.unit,
                postfix=self.note or None,
                bar_format=_PLAIN if self.total else _PLAIN_OPEN_ENDED,
            )
        )
        return " ".join(text.split())  # tqdm pads the rate to a column; a log line needs no columns

    def write(self, line: str) -> None:
        """Writes a line that stays (above the bar on a terminal)."""
        write_line(line, self.stream)

    def close(self) -> None:
        """Removes the bar."""
        if self.bar is not None:
            self.bar.close()
            self.bar = None


__all__ = ["DEFAULT_EVERY_S", "EVERY_ENV", "Progress", "plain_every", "write_line"]
