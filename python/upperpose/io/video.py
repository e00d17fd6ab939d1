"""Reading videos frame by frame, with one clear `VideoError` per way a file can be bad."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError, VideoError

Frame = npt.NDArray[np.uint8]
DEFAULT_FPS = 30.0
# Frame sides outside this range cannot hold a person the features can find, or exhaust memory.
MIN_SIDE, MAX_SIDE = 32, 8192
MAX_CAMERA_INDEX = 1023


class VideoReader:
    """Streams the frames of a video file (or a camera index) one at a time.

    Memory does not grow with the video's length: one frame is held at a time. The first frame
    is decoded on opening, so that an empty or undecodable file fails at once with a message.

    Args:
        source: a path to a video file, a stream URL OpenCV opens (rtsp://, http://), or an
            integer camera index.

    Raises:
        VideoError: the file is missing, is a folder, cannot be decoded, or holds no frames.
    """

    def __init__(self, source: str | os.PathLike[str] | int) -> None:
        if isinstance(source, bool) or not isinstance(source, (int, str, os.PathLike)):
            raise TypeError(f"video must be a path or a camera index, got {type(source).__name__}")
        if isinstance(source, int) and not 0 <= source <= MAX_CAMERA_INDEX:
            raise InputError(f"camera index must be within 0..{MAX_CAMERA_INDEX}, got {source}")
        self.name = f"camera {source}" if isinstance(source, int) else str(source)
        self.live = isinstance(source, int) or is_stream_url(source)
        if not isinstance(source, int) and not self.live:
            path = Path(source)
            if not path.exists():
                raise VideoError(f"no such video: {path}")
            if path.is_dir():
                raise VideoError(f"{path} is a folder, not a video")
            if path.stat().st_size == 0:
                raise VideoError(f"{path} is empty (0 bytes)")
        self._cap = cv2.VideoCapture(source if isinstance(source, int) else str(source))
        if not self._cap.isOpened():
            self._cap.release()
            if isinstance(source, int):
                raise VideoError(f"no camera {source}: none is connected at that index, or it is in use")
            if self.live:
                raise VideoError(f"cannot open the stream {self.name}: unreachable, or a protocol OpenCV lacks")
            raise VideoError(f"cannot read {self.name}: not a video OpenCV can decode (missing codec or corrupt file)")
        ok, first = self._cap.read()
        if not ok or first is None or first.ndim != 3 or first.shape[2] != 3:
            self._cap.release()
            raise VideoError(f"{self.name} has no decodable frames (empty or corrupt video)")
        self._first: Frame | None = cast(Frame, first)
        self.height, self.width = int(first.shape[0]), int(first.shape[1])
        if not (MIN_SIDE <= self.width <= MAX_SIDE and MIN_SIDE <= self.height <= MAX_SIDE):
            self._cap.release()
            raise VideoError(
                f"{self.name} is {self.width}x{self.height}: upperpose takes {MIN_SIDE}..{MAX_SIDE} pixels a side"
            )
        fps = float(self._cap.get(cv2.CAP_PROP_FPS) or 0.0)
        self.fps = fps if np.isfinite(fps) and 1.0 <= fps <= 1000.0 else DEFAULT_FPS
        # A rate outside 1..1000 is a broken header or a camera that reports none: said, not hidden.
        self.fps_warning = (
            None
            if self.fps == fps
            else f"{self.name} reports {fps:g} fps, outside 1..1000: timed as {DEFAULT_FPS:g} fps"
        )
        count = int(self._cap.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
        self.frame_count: int | None = count if count > 0 else None

    def __iter__(self) -> Iterator[Frame]:
        """Yields BGR `(H, W, 3)` uint8 frames until the video ends (a corrupt tail ends it)."""
        if self._first is not None:
            first, self._first = self._first, None
            yield first
        while True:
            ok, frame = self._cap.read()
            if not ok or frame is None:
                return
            yield cast(Frame, frame)

    def close(self) -> None:
        """Releases the decoder."""
        self._cap.release()

    def __enter__(self) -> VideoReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def is_stream_url(source: str | os.PathLike[str]) -> bool:
    """Whether `source` names a network stream (rtsp://, http://, ...) rather than a file."""
    return isinstance(source, str) and "://" in source and not Path(source).exists()


def parse_source(text: str) -> str | int:
    """A command-line video argument: a camera index for a bare number that is not a file."""
    return int(text) if text.isdigit() and not Path(text).exists() else text


def read_background(path: str | os.PathLike[str], size: tuple[int, int]) -> Frame:
    """Reads a clean-plate image and checks it matches the video's `(height, width)`.

    Raises:
        VideoError: missing or unreadable image.
        ValueError: the image is not the video's size.
    """
    p = Path(path)
    if not p.is_file():
        raise VideoError(f"no such background image: {p}")
    try:
        image = cv2.imread(str(p), cv2.IMREAD_COLOR)
    except cv2.error:  # OpenCV refuses images over 2^30 pixels with an assertion, not None
        raise VideoError(f"cannot read the background image {p}: too large (over 2^30 pixels) or corrupt") from None
    if image is None:
        raise VideoError(f"cannot read the background image {p}: not an image OpenCV can decode")
    if image.shape[:2] != tuple(size):
        raise InputError(
            f"the background image {p} is {image.shape[1]}x{image.shape[0]} "
            f"but the video is {size[1]}x{size[0]}: use a photo of the same view at the video's size"
        )
    return np.ascontiguousarray(image, dtype=np.uint8)


__all__ = ["DEFAULT_FPS", "Frame", "VideoReader", "is_stream_url", "parse_source", "read_background"]
