"""Drawing the body model over images, the way the thesis' result figures show fits."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError
from upperpose.model import BodyModel, Camera, PoseLike, forward_kinematics, project, render_masks

# BGR colours per part, in PART_NAMES order: torso, neck, head, right upper/lower, left upper/lower.
PART_COLOURS = [
    (200, 160, 60),
    (200, 160, 60),
    (90, 200, 240),
    (60, 60, 230),
    (40, 120, 250),
    (60, 200, 60),
    (140, 230, 60),
]
# Bones between joints (JOINT_NAMES indices) for the stick figure.
BONES = [(1, 2), (1, 3), (3, 5), (2, 4), (4, 6)]


def draw_model(
    image: npt.NDArray[np.uint8],
    pose: PoseLike,
    root: npt.ArrayLike,
    camera: Camera,
    body: BodyModel | None = None,
    alpha: float = 0.45,
) -> npt.NDArray[np.uint8]:
    """Draws the posed model over a copy of a BGR image.

    The parts are tinted, their visible contours outlined and the joints drawn as a stick figure.
    """
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise InputError(f"image must be (H, W, 3) uint8, got {image.shape} {image.dtype}")
    height, width = image.shape[:2]
    masks = render_masks(pose, root, camera, width, height, body)
    out = image.copy()
    labels = masks["labels"]
    tint = np.zeros_like(out)
    for k, colour in enumerate(PART_COLOURS):
        tint[labels == k + 1] = colour
    covered = labels > 0
    out[covered] = (out[covered] * (1.0 - alpha) + tint[covered] * alpha).astype(np.uint8)
    out[masks["contour"] > 0] = (255, 255, 255)
    joints = project(camera, forward_kinematics(pose, root, body))
    pts = [(int(round(x)), int(round(y))) for x, y in joints] if np.all(np.isfinite(joints)) else []
    for a, b in BONES if pts else []:
        cv2.line(out, pts[a], pts[b], (0, 0, 0), 3, cv2.LINE_AA)
        cv2.line(out, pts[a], pts[b], (255, 255, 255), 1, cv2.LINE_AA)
    for p in pts:
        cv2.circle(out, p, 4, (0, 0, 255), -1, cv2.LINE_AA)
    return np.asarray(out, dtype=np.uint8)
