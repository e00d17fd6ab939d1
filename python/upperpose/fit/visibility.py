"""Which reported joints the image shows: "observed", or "unobserved" (outside the image, or on a lost arm).

An unobserved joint's coordinates are the model's continuation, not something seen: the pose
stays whole (angles, BVH, overlays, scoring) and the `visibility` field says which joints to
take with caution.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from upperpose.result import OBSERVED, UNOBSERVED, VISIBILITIES

ARM_JOINTS = {"right_arm": (3, 5), "left_arm": (4, 6)}  # elbow, hand (JOINT_NAMES order)


def inside_image(joints_2d: npt.NDArray[np.float64], size: tuple[int, int]) -> npt.NDArray[np.bool_]:
    """Per joint: finite and on the image (pixel centres at integers, so edges at -0.5 and size - 0.5)."""
    height, width = size
    x, y = joints_2d[:, 0], joints_2d[:, 1]
    with np.errstate(invalid="ignore"):
        inside = (x >= -0.5) & (x <= width - 0.5) & (y >= -0.5) & (y <= height - 0.5)
    return np.isfinite(joints_2d).all(axis=1) & inside


def visibility(joints_2d: npt.NDArray[np.float64], lost_parts: tuple[str, ...], size: tuple[int, int]) -> list[str]:
    """Each joint's visibility: unobserved when outside the image or the elbow or hand of a lost arm."""
    seen = inside_image(joints_2d, size)
    for arm in lost_parts:
        seen[list(ARM_JOINTS[arm])] = False
    return [OBSERVED if s else UNOBSERVED for s in seen]


__all__ = ["OBSERVED", "UNOBSERVED", "VISIBILITIES", "inside_image", "visibility"]
