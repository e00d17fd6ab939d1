"""Writing output files whole or not at all."""

from __future__ import annotations

import contextlib
import os
import signal
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import VideoError


@contextlib.contextmanager
def interrupts_held() -> Iterator[None]:
    """Holds Ctrl-C and SIGTERM back while the body runs.

    For writing the outputs after an interruption: a signal that arrives meanwhile is only
    noted, and raised as `KeyboardInterrupt` when the body has ended.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    arrived: list[int] = []

    def note(signum: int, frame: object) -> None:
        arrived.append(signum)

    previous = {s: signal.signal(s, note) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if arrived:
        raise KeyboardInterrupt


def write_atomic(path: str | os.PathLike[str], write: Callable[[Path], object]) -> Path:
    """Calls `write(tmp)` on a temporary file beside `path`, then renames it onto `path`.

    A reader never sees half a file: either the old file (or none) or the whole new one.
    The temporary file keeps the target's suffix so that writers choosing a format by suffix
    (OpenCV) pick the right one.

    Raises:
        OSError: the folder does not exist or is not writable.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise OSError(f"cannot write {target}: folder {folder} does not exist")
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=target.suffix, dir=folder)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        write(tmp)
        # mkstemp makes private files; give the output the mode a plain open() would.
        os.chmod(tmp, target.stat().st_mode & 0o777 if target.exists() else 0o666 & ~_umask())
        os.replace(tmp, target)
    finally:
        if tmp.exists():
            tmp.unlink()
    return target


def _umask() -> int:
    """The process's file-creation mask (reading it means setting it, so set it back)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_image(path: str | os.PathLike[str], image: npt.NDArray[np.uint8]) -> Path:
    """Writes an image atomically; the format follows the suffix (.png, .jpg, ...)."""

    def write(tmp: Path) -> None:
        if not cv2.imwrite(str(tmp), image):
            raise VideoError(f"cannot encode an image as {Path(path).suffix or 'a file without suffix'}: {path}")

    return write_atomic(path, write)
