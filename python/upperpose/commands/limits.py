"""Range checks of command-line values, shared by the subcommands (docs/limits.md)."""

from __future__ import annotations

import math

from upperpose.io.video import MAX_SIDE, MIN_SIDE


class OptionError(ValueError):
    """A command-line option's value out of its range: the command line exits 2 with its usage."""


# A focal length outside this range is a typo (a 640-pixel image at 1 px would see 175 degrees).
MIN_FOCAL_PX, MAX_FOCAL_PX = 1.0, 1e5


def check_number(option: str, value: float | None, low: float, high: float, unit: str = "") -> None:
    """Raises ValueError naming `option` unless `value` is None or finite within [low, high]."""
    if value is None:
        return
    if not (isinstance(value, (int, float)) and math.isfinite(value) and low <= value <= high):
        raise OptionError(f"{option} must be within {low:g}..{high:g}{' ' + unit if unit else ''}, got {value}")


def check_focal(value: float | None) -> None:
    """--focal in pixels."""
    check_number("--focal", value, MIN_FOCAL_PX, MAX_FOCAL_PX, "pixels")


def check_size(width: int, height: int, even: bool = False) -> None:
    """--width and --height of an image or video to make (even for video: the encoder needs it)."""
    for option, value in (("--width", width), ("--height", height)):
        check_number(option, value, MIN_SIDE, MAX_SIDE, "pixels")
        if even and value % 2:
            raise OptionError(f"{option} must be even for a video (the encoder halves chroma), got {value}")
