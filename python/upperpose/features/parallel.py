"""Worker threads for the background estimate: numpy's sorts and OpenCV's calls release the GIL.

Work is split into pieces whose results do not depend on how many threads run them, so the
plate is the same bit for bit on any machine.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from upperpose.exceptions import InputError

THREADS_ENV = "UPPERPOSE_NUM_THREADS"
ROWS_PER_BAND = 32

T = TypeVar("T")
R = TypeVar("R")


def worker_count() -> int:
    """`UPPERPOSE_NUM_THREADS` when set (as for the search), else the cores this process may use.

    Raises:
        InputError: the variable is set but is not a positive whole number.
    """
    text = os.environ.get(THREADS_ENV)
    if text is not None:
        try:
            count = int(text.strip())
        except ValueError:
            count = 0
        if count < 1:
            raise InputError(f"{THREADS_ENV} must be a positive whole number, got {text!r}")
        return count
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def map_in_threads(work: Callable[[T], R], items: Sequence[T]) -> list[R]:
    """`[work(item) for item in items]`, run on up to `worker_count()` threads, never the caller's."""
    with ThreadPoolExecutor(max(1, min(worker_count(), len(items)))) as pool:
        return list(pool.map(work, items))


def row_bands(height: int) -> list[slice]:
    """An image's rows in bands of `ROWS_PER_BAND`, to be worked on in parallel."""
    return [slice(top, min(top + ROWS_PER_BAND, height)) for top in range(0, height, ROWS_PER_BAND)]


__all__ = ["THREADS_ENV", "map_in_threads", "row_bands", "worker_count"]
