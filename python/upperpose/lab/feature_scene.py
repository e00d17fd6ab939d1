"""Seeded synthetic scenes with known masks, for tests and the feature benchmark.

A person is the body model's projection (`upperpose.render_masks`) painted in flat colours with
camera noise: shirt on torso and upper arms, skin on head, neck and (with short sleeves)
forearms, an ellipse for each hand beyond the wrist, dark hair on top of the head; over a
smooth random texture. Not a substitute for the ground-truth clips, which look like video.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.model import Camera, PoseLike, model_points, render_masks

SKIN_BGR = (120, 150, 205)
SHIRT_BGR = (150, 90, 50)
HAIR_BGR = (30, 35, 40)


@dataclass(frozen=True)
class Scene:
    """A synthetic frame and what is true about it.

    Attributes:
        frame: `(H, W, 3)` uint8 BGR.
        mask: `(H, W)` bool, the person.
        joints: `(7, 2)` projected joints, pixels, JOINT_NAMES order.
        labels: `(H, W)` uint8 part labels of the body model (render_masks).
    """

    frame: npt.NDArray[np.uint8]
    mask: npt.NDArray[np.bool_]
    joints: npt.NDArray[np.float64]
    labels: npt.NDArray[np.uint8]


def textured_background(height: int, width: int, seed: int = 0) -> npt.NDArray[np.uint8]:
    """A smooth random colour texture with some fine detail; no skin-coloured regions forced."""
    rng = np.random.default_rng(seed)
    coarse = rng.integers(40, 200, (height // 40 + 2, width // 40 + 2, 3)).astype(np.uint8)
    image = cv2.resize(coarse, (width, height), interpolation=cv2.INTER_CUBIC)
    detail = rng.normal(0, 6, (height, width, 3))
    image = np.clip(image.astype(np.float64) * 0.6 + 50 + detail, 0, 255)
    # Neutralise accidental skin: push R - G out of 20..80 where the texture falls into it.
    g, r = image[..., 1], image[..., 2]
    skin = (r - g >= 10) & (r - g <= 90)
    image[..., 1] = np.where(skin, r, g)
    return image.astype(np.uint8)


def paint_hand(
    canvas: npt.NDArray[np.uint8],
    mask: npt.NDArray[np.uint8],
    elbow: npt.NDArray[np.float64],
    hand: npt.NDArray[np.float64],
    length: float,
    colour: tuple[int, int, int],
) -> None:
    """An ellipse `length` long centred at the palm point (`hand`) and extending past it."""
    direction = hand - elbow
    norm = float(np.hypot(*direction))
    if norm < 1e-6:
        direction = np.array([0.0, 1.0])
    else:
        direction = direction / norm
    centre = hand + 0.15 * length * direction
    angle = float(np.degrees(np.arctan2(direction[1], direction[0])))
    box = ((float(centre[0]), float(centre[1])), (length, 0.5 * length), angle)
    cv2.ellipse(canvas, box, colour, -1, cv2.LINE_8)
    cv2.ellipse(mask, box, 1, -1, cv2.LINE_8)


def render_scene(
    pose: PoseLike,
    background: npt.NDArray[np.uint8],
    root: npt.ArrayLike = (0.0, 0.15, 2.2),
    short_sleeves: bool = False,
    noise: float = 2.0,
    seed: int = 0,
    skin: tuple[int, int, int] = SKIN_BGR,
    shirt: tuple[int, int, int] = SHIRT_BGR,
) -> Scene:
    """Paints the posed body over `background` (BGR) and adds Gaussian noise of `noise` grey levels."""
    height, width = background.shape[:2]
    camera = Camera.for_image(width, height)
    masks = render_masks(pose, root, camera, width, height)
    labels = masks["labels"]
    joints = camera.project(model_points(pose, root))
    frame = background.copy()
    colours = {
        1: shirt,
        2: skin,
        3: skin,
        4: shirt,
        5: skin if short_sleeves else shirt,
        6: shirt,
        7: skin if short_sleeves else shirt,
    }
    # Paint far-to-near is not needed: labels already resolve occlusion.
    for value, colour in colours.items():
        frame[labels == value] = colour
    person = (labels > 0).astype(np.uint8)
    head = joints[0]
    head_height = 0.5 * float(np.hypot(*(joints[1] - joints[2])))
    hair = np.zeros_like(person)
    cv2.circle(
        hair,
        (round(head[0]), round(head[1] - 0.55 * head_height)),
        int(0.55 * head_height),
        1,
        -1,
    )
    frame[(hair > 0) & (labels == 3)] = HAIR_BGR
    hand_length = 0.5 * float(np.hypot(*(joints[1] - joints[2])))
    for elbow, hand in ((joints[3], joints[5]), (joints[4], joints[6])):
        paint_hand(frame, person, elbow, hand, hand_length, skin)
    rng = np.random.default_rng(seed)
    noisy = frame.astype(np.float64) + rng.normal(0.0, noise, frame.shape)
    return Scene(np.clip(noisy, 0, 255).astype(np.uint8), person > 0, joints, labels)
