"""Per-channel colour change between two frames (I_sub, background estimation)."""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np

from upperpose.features.checks import Frame, Mask


def colour_change(
    a: Frame,
    b: Frame,
    threshold: int,
    work: tuple[Frame, Frame, Mask] | None = None,
    out: Mask | None = None,
) -> Mask:
    """255 where any channel of two BGR frames differs by more than `threshold`, else 0.

    A per-channel test keeps chroma changes that a grey difference would hide (a blue shirt
    over a green wall of the same brightness).

    Args:
        a: `(H, W, 3)` uint8 frame.
        b: `(H, W, 3)` uint8 frame of the same size.
        threshold: largest per-channel difference still counted as unchanged.
        work: optional preallocated ((H, W, 3), (H, W, 3), (H, W)) uint8 scratch arrays.
        out: optional preallocated `(H, W)` uint8 result.
    """
    if work is None:
        diff, over, grey = (
            np.empty_like(a),
            np.empty_like(a),
            np.empty(a.shape[:2], np.uint8),
        )
    else:
        diff, over, grey = work
    cv2.absdiff(a, b, dst=diff)
    cv2.compare(diff, threshold, cv2.CMP_GT, dst=over)  # type: ignore[call-overload]
    cv2.cvtColor(over, cv2.COLOR_BGR2GRAY, dst=grey)  # nonzero iff some channel is 255
    return cast(
        Mask,
        cv2.compare(grey, 0, cv2.CMP_GT, dst=out) if out is not None else cv2.compare(grey, 0, cv2.CMP_GT),  # type: ignore[call-overload]
    )


def plate_distance(frame: Frame, plate: Frame, diff: Frame, out: Mask) -> Mask:
    """Grey of |frame - plate| per pixel (a weighted mean of the B, G, R differences) into `out`.

    Args:
        frame: `(H, W, 3)` uint8 BGR.
        plate: `(H, W, 3)` uint8 BGR of the same size.
        diff: `(H, W, 3)` uint8 scratch array.
        out: `(H, W)` uint8 result.
    """
    cv2.absdiff(frame, plate, dst=diff)
    return cast(Mask, cv2.cvtColor(diff, cv2.COLOR_BGR2GRAY, dst=out))


__all__ = ["colour_change", "plate_distance"]
