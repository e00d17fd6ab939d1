"""Argument checks for frames and masks: clear ValueErrors before any OpenCV call."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError

Frame = npt.NDArray[np.uint8]
Mask = npt.NDArray[np.uint8]


def check_frame(frame: object, name: str = "frame", size: tuple[int, int] | None = None) -> Frame:
    """Checks that `frame` is an `(H, W, 3)` uint8 BGR image, optionally of `size` = (H, W).

    Returns:
        The frame, C-contiguous (copied only if it was not).

    Raises:
        TypeError: not a numpy array.
        ValueError: empty, grayscale, not 3 channels, not uint8, or the wrong size.
    """
    if not isinstance(frame, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, got {type(frame).__name__}")
    if frame.size == 0:
        raise InputError(f"{name} is empty (shape {frame.shape})")
    if frame.ndim == 2 or (frame.ndim == 3 and frame.shape[2] == 1):
        raise InputError(f"{name} is grayscale {frame.shape}; features need a (H, W, 3) BGR colour frame")
    if frame.ndim != 3 or frame.shape[2] != 3:
        raise InputError(f"{name} must be (H, W, 3) BGR, got shape {frame.shape}")
    if frame.dtype != np.uint8:
        raise InputError(f"{name} must be uint8, got {frame.dtype}")
    if size is not None and frame.shape[:2] != tuple(size):
        raise InputError(f"{name} is {frame.shape[1]}x{frame.shape[0]} but the background is {size[1]}x{size[0]}")
    return np.ascontiguousarray(frame)


def check_mask(mask: object, name: str, size: tuple[int, int]) -> Mask:
    """Checks that `mask` is an `(H, W)` integer or bool array of `size`; returns it as uint8.

    Raises:
        TypeError: not a numpy array.
        ValueError: wrong shape, dtype or size.
    """
    if not isinstance(mask, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, got {type(mask).__name__}")
    if mask.ndim != 2 or mask.shape != tuple(size):
        raise InputError(f"{name} must have shape {tuple(size)}, got {mask.shape}")
    if mask.dtype.kind not in "biu":
        raise InputError(f"{name} must be an integer or bool mask, got {mask.dtype}")
    return np.ascontiguousarray(mask, dtype=np.uint8)
