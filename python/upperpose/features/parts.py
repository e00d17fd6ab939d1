"""Features that need the body model's last projection.

Per-part motion flags (§3.4.3) and the arm silhouette outside the torso region (§3.4.5).  Part masks
come as one labels image like `upperpose.render_masks(...)["labels"]`: 0 for no part, `k + 1` for
part `PART_NAMES[k]` (torso, neck, head, right upper arm, right lower arm, left upper arm, left
lower arm).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.checks import Mask
from upperpose.features.config import FeatureConfig

# Motion groups of §3.4.3 as inclusive ranges of labels values (PART_NAMES index + 1).
MOTION_GROUPS: dict[str, tuple[int, int]] = {
    "torso": (1, 3),
    "right_arm": (4, 5),
    "left_arm": (6, 7),
}
# The torso region cut out of the arm silhouette: torso, neck and head.
TORSO_LABELS = (1, 3)


@dataclass(frozen=True)
class MotionFlag:
    """Motion of one part group (torso = torso + neck + head, right arm, left arm).

    Attributes:
        count: I_motion pixels inside the group's previous projection, dilated.
        perimeter: boundary pixels of the group's previous projection.
        moving: `count > motion_perimeter_fraction * perimeter`: search this part this frame.
    """

    count: int
    perimeter: int
    moving: bool


def group_mask(labels: Mask, group: tuple[int, int]) -> Mask:
    """255 where `labels` is within the inclusive range `group`."""
    return cast(Mask, cv2.inRange(labels, group[0], group[1]))


def motion_flags(motion: Mask, labels: Mask, config: FeatureConfig) -> dict[str, MotionFlag]:
    """Per-group motion flags from I_motion and the previous projection's labels image.

    Args:
        motion: `(H, W)` uint8 I_motion, nonzero = motion.
        labels: `(H, W)` uint8 part labels of last frame's projected model.
        config: dilation and the perimeter fraction.

    Returns:
        {"torso": MotionFlag, "right_arm": ..., "left_arm": ...}; a group not in view has
        count 0, perimeter 0 and is not moving.
    """
    height, width = labels.shape
    margin = config.motion_dilate // 2 + 1
    kernel = np.ones((max(config.motion_dilate, 1),) * 2, np.uint8)
    # One scan of the whole image for the body's box; the groups are then cut from that box.
    bx, by, bw, bh = cv2.boundingRect(labels)
    body = labels[by : by + bh, bx : bx + bw]
    flags = {}
    for name, group in MOTION_GROUPS.items():
        x, y, w, h = cv2.boundingRect(group_mask(body, group)) if bw and bh else (0, 0, 0, 0)
        if w == 0 or h == 0:
            flags[name] = MotionFlag(0, 0, False)
            continue
        x, y = x + bx, y + by
        x0, y0 = max(x - margin, 0), max(y - margin, 0)
        x1, y1 = min(x + w + margin, width), min(y + h + margin, height)
        crop = group_mask(labels[y0:y1, x0:x1], group)
        boundary = cv2.subtract(
            crop,
            cv2.erode(crop, np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT),
        )
        perimeter = cv2.countNonZero(boundary)
        count = cv2.countNonZero(cv2.bitwise_and(cv2.dilate(crop, kernel), motion[y0:y1, x0:x1]))
        flags[name] = MotionFlag(count, perimeter, count > config.motion_perimeter_fraction * perimeter)
    return flags


def torso_region_from_labels(labels: Mask, config: FeatureConfig) -> Mask:
    """The torso region (torso, neck, head of the projected model), optionally eroded; 255 = inside."""
    region = group_mask(labels, TORSO_LABELS)
    if config.arm_torso_erode > 0:
        size = 2 * config.arm_torso_erode + 1
        region = cast(Mask, cv2.erode(region, np.ones((size, size), np.uint8)))
    return region


def torso_region_from_shoulders(
    right_shoulder: npt.ArrayLike, left_shoulder: npt.ArrayLike, size: tuple[int, int]
) -> Mask:
    """The band between the two shoulders, perpendicular to the shoulder line, across the whole image.

    A torso region when only the shoulder joints are known. 255 = inside.
    """
    height, width = size
    rs = np.asarray(right_shoulder, dtype=np.float64)
    ls = np.asarray(left_shoulder, dtype=np.float64)
    region = np.zeros((height, width), np.uint8)
    line = ls - rs
    norm = float(np.hypot(*line))
    if not np.isfinite(norm) or norm < 1.0:
        return region
    across = np.array([-line[1], line[0]]) / norm * 4.0 * (height + width)
    polygon = np.array([rs - across, ls - across, ls + across, rs + across])
    cv2.fillConvexPoly(region, np.round(polygon).astype(np.int32), 255)
    return region


def arm_silhouette(silhouette: Mask, torso_region: Mask, out: Mask | None = None) -> Mask:
    """I_sil outside the torso region (§3.4.5); 255 = arm silhouette.

    Args:
        silhouette: `(H, W)` uint8 I_sil, 0 or 255.
        torso_region: `(H, W)` uint8, 255 inside the torso region, 0 outside.
        out: optional preallocated result.
    """
    if out is None:
        return cast(Mask, cv2.subtract(silhouette, torso_region))
    return cast(Mask, cv2.subtract(silhouette, torso_region, dst=out))
