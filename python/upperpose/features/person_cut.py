"""The person who stays put, cut out of a temporal median image (background estimation).

A temporal median keeps whatever covers a pixel in most samples: the torso and head of a person
who hardly moves. Their face is found (OpenCV's Haar cascade, boxes mostly skin), a body region
is laid out around it in face units (`PersonTemplate`), and GrabCut separates the person from
the room inside that region by colour. The result marks the pixels of the median image that
show the person; `background.iterative_masked_median` masks them out of the samples where the
person is still there and inpaints what no sample shows.
"""

from __future__ import annotations

import cv2
import numpy as np

from upperpose.features.checks import Frame, Mask
from upperpose.features.config import FeatureConfig, PersonTemplate
from upperpose.features.faces import FaceBox, FaceDetector, choose_face
from upperpose.features.skin import skin_mask


def find_face(frame: Frame, config: FeatureConfig) -> FaceBox | None:
    """The frontal face box `(x, y, w, h)` in `frame` that is most skin, or None.

    Runs at full size: at the tracker's downscale the cascade misses some faces of 50 px.
    """
    detect = FaceDetector(downscale=1.0)
    return choose_face(detect(frame), skin_mask(frame, config), min_skin=config.bg_face_min_skin)


def grabcut_seed(shape: tuple[int, int], face: FaceBox, template: PersonTemplate) -> Mask:
    """GrabCut labels (`cv2.GC_*`) of an image of `shape` from a face box and the body template.

    Returns:
        `(H, W)` uint8: sure background, then the probable-background band, the probable person
        and the sure person painted over each other.
    """
    height, _ = shape
    x, y, w, h = face
    cx = x + w / 2
    seed = np.full(shape, cv2.GC_BGD, np.uint8)

    def body(label: int, radii: tuple[float, float], top: float, half_widths: tuple[float, float]) -> None:
        centre = (round(cx), round(y + template.head_centre * h))
        cv2.ellipse(seed, centre, (round(radii[0] * w), round(radii[1] * h)), 0, 0, 360, label, -1)
        t, b = half_widths[0] * w, half_widths[1] * w
        corners = [(cx - t, y + top * h), (cx + t, y + top * h), (cx + b, height), (cx - b, height)]
        cv2.fillPoly(seed, [np.round(corners).astype(np.int32)], label)

    def rectangle(label: int, left: float, top: float, right: float, bottom: float) -> None:
        cv2.rectangle(seed, (round(left), round(top)), (round(right), round(bottom)), label, -1)

    body(cv2.GC_PR_BGD, template.reach_head_radii, template.reach_top, template.reach_half_widths)
    body(cv2.GC_PR_FGD, template.head_radii, template.torso_top, template.torso_half_widths)
    neck_half, neck_top, neck_bottom = template.neck
    rectangle(cv2.GC_PR_FGD, cx - neck_half * w, y + neck_top * h, cx + neck_half * w, y + neck_bottom * h)
    left, top, right, bottom = template.sure_face
    rectangle(cv2.GC_FGD, x + left * w, y + top * h, x + right * w, y + bottom * h)
    chest_half, chest_top, chest_bottom = template.sure_chest
    if y + chest_top * h < height:  # a face low in the frame leaves no chest in view
        rectangle(cv2.GC_FGD, cx - chest_half * w, y + chest_top * h, cx + chest_half * w, y + chest_bottom * h)
    return seed


def person_in_image(image: Frame, config: FeatureConfig) -> Mask | None:
    """The pixels of `image` (a temporal median) that show a person, or None without a face.

    Args:
        image: `(H, W, 3)` uint8 BGR.
        config: face skin share, body template, GrabCut scale and iterations.

    Returns:
        `(H, W)` uint8, 255 on the person; None when no face is found (nobody stays put).
    """
    face = find_face(image, config)
    if face is None:
        return None
    height, width = image.shape[:2]
    seed = grabcut_seed((height, width), face, config.bg_person)
    scale = config.bg_grabcut_scale
    small_size = (max(1, round(width / scale)), max(1, round(height / scale)))
    small = cv2.resize(image, small_size, interpolation=cv2.INTER_AREA)
    labels = cv2.resize(seed, small_size, interpolation=cv2.INTER_NEAREST)
    room = (labels == cv2.GC_BGD) | (labels == cv2.GC_PR_BGD)
    if room.all() or not room.any():  # GrabCut needs both colour models
        return None
    background_model = np.zeros((1, 65), np.float64)
    person_model = np.zeros((1, 65), np.float64)
    cv2.grabCut(
        small, labels, None, background_model, person_model, config.bg_grabcut_iterations, cv2.GC_INIT_WITH_MASK
    )
    person = np.where((labels == cv2.GC_FGD) | (labels == cv2.GC_PR_FGD), 255, 0).astype(np.uint8)
    return cv2.resize(person, (width, height), interpolation=cv2.INTER_NEAREST)


__all__ = ["find_face", "grabcut_seed", "person_in_image"]
