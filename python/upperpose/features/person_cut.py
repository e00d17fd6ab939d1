"""The person who stays put, cut out of a temporal median image (background estimation).

A temporal median keeps whatever covers a pixel in most samples: the torso and head of a person
who hardly moves. Their face is found (OpenCV's Haar cascade, boxes mostly skin) in the median
image, or, when the head moved too much to leave a face there, in the sample frame that agrees
most with the median inside its face box (the person's most frequent place), a body region
is laid out around it in face units (`PersonTemplate`), and GrabCut separates the person from
the room inside that region by colour; bare arms that stay put outside it are added by the
person's skin colour (`with_bare_arms`). The result marks the pixels of the median image that
show the person; `background.iterative_masked_median` masks them out of the samples where the
person is still there and inpaints what no sample shows.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.change import colour_change
from upperpose.features.checks import Frame, Mask
from upperpose.features.config import FeatureConfig, PersonTemplate
from upperpose.features.faces import (
    STEADY_TOLERANCE,
    FaceBox,
    FaceDetector,
    choose_face,
    same_place,
    steady_face,
)
from upperpose.features.parallel import map_in_threads
from upperpose.features.person_skin import skin_of_face
from upperpose.features.skin import skin_mask


def find_face(frame: Frame, config: FeatureConfig, detect: FaceDetector | None = None) -> FaceBox | None:
    """The frontal face box `(x, y, w, h)` in `frame` that is most skin, or None.

    Runs at full size: at the tracker's downscale the cascade misses some faces of 50 px.
    """
    detect = detect or FaceDetector(downscale=1.0)
    return skin_face(frame, detect(frame), config)


def skin_face(frame: Frame, boxes: list[FaceBox], config: FeatureConfig) -> FaceBox | None:
    """Of the face boxes found in `frame`, the one most skin, if at least `bg_face_min_skin`."""
    return choose_face(boxes, skin_mask(frame, config), min_skin=config.bg_face_min_skin)


def face_of_median(median: Frame, samples: Sequence[Frame], config: FeatureConfig) -> FaceBox | None:
    """The face of the person the median image shows, or None.

    The median's own face when the cascade finds one; else, of the faces in `bg_face_samples`
    samples spread over the clip, the one whose box, or the chest box below it (a person who
    stays put while the head moves), the median agrees with most (share of pixels within
    `bg_person_match`), if at least `bg_face_agreement`. Faces must be mostly skin
    (`bg_face_min_skin`); when no face is, a box the cascade finds in one place in
    `bg_face_steady` of the samples is taken instead (a real face under cool or dim light
    fails the skin rule; false boxes come and go), on the same agreement rule.
    """
    detect = FaceDetector(downscale=1.0)
    face = find_face(median, config, detect)
    if face is not None or not samples:
        return face
    picks = np.linspace(0, len(samples) - 1, min(config.bg_face_samples, len(samples))).round().astype(int)
    picked = [samples[k] for k in dict.fromkeys(picks.tolist())]
    boxes = [detect(sample) for sample in picked]

    def agreeing(sample: Frame, box: FaceBox) -> float:
        return max(agreement(sample, median, region, config) for region in (box, chest_box(box, config)))

    best, best_share = None, config.bg_face_agreement
    for sample, found in zip(picked, boxes):
        box = skin_face(sample, found, config)
        if box is not None and (share := agreeing(sample, box)) >= best_share:
            best, best_share = box, share
    if best is not None:
        return best
    steady = steady_face(boxes, config.bg_face_steady)
    if steady is None:
        return None
    shares = [
        agreeing(sample, steady)
        for sample, found in zip(picked, boxes)
        if any(same_place(b, steady, STEADY_TOLERANCE) for b in found)
    ]
    return steady if max(shares, default=0.0) >= config.bg_face_agreement else None


def chest_box(face: FaceBox, config: FeatureConfig) -> FaceBox:
    """The body template's sure chest below a face box, `(x, y, w, h)`."""
    x, y, w, h = face
    half, top, bottom = config.bg_person.sure_chest
    return (round(x + w / 2 - half * w), round(y + top * h), round(2 * half * w), round((bottom - top) * h))


def agreement(frame: Frame, median: Frame, box: FaceBox, config: FeatureConfig) -> float:
    """Share of the pixels of `box` (clipped to the image) where `frame` and `median` agree."""
    x, y, w, h = box
    x0, y0 = max(x, 0), max(y, 0)
    x1, y1 = min(x + w, frame.shape[1]), min(y + h, frame.shape[0])
    if x1 <= x0 or y1 <= y0:
        return 0.0
    crop = (slice(y0, y1), slice(x0, x1))
    differs = colour_change(
        np.ascontiguousarray(frame[crop]), np.ascontiguousarray(median[crop]), config.bg_person_match
    )
    return 1.0 - cv2.countNonZero(differs) / differs.size


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


def _grabcut_once(small: Frame, labels: Mask, run: int, config: FeatureConfig) -> npt.NDArray[np.bool_]:
    """Where one GrabCut, its k-means seeded with `run`, finds the person."""
    cv2.setRNGSeed(run)  # this thread's generator
    cut = labels.copy()
    background_model = np.zeros((1, 65), np.float64)
    person_model = np.zeros((1, 65), np.float64)
    cv2.grabCut(  # type: ignore[call-overload]
        small, cut, None, background_model, person_model, config.bg_grabcut_iterations, cv2.GC_INIT_WITH_MASK
    )
    return cast(npt.NDArray[np.bool_], (cut == cv2.GC_FGD) | (cut == cv2.GC_PR_FGD))


def person_in_median(image: Frame, samples: Sequence[Frame], config: FeatureConfig) -> Mask | None:
    """The pixels of `image` (a temporal median of `samples`) that show a person, or None.

    Args:
        image: `(H, W, 3)` uint8 BGR.
        samples: the frames the median was taken over (for a face when the median has none).
        config: face settings, body template, GrabCut scale and iterations.

    Returns:
        `(H, W)` uint8, 255 on the person; None when no face is found (nobody stays put).
    """
    face = face_of_median(image, samples, config)
    if face is None:
        return None
    height, width = image.shape[:2]
    person = grabcut_person(image, grabcut_seed((height, width), face, config.bg_person), config)
    if person is not None and config.bg_cut_bare_arms:
        person = with_bare_arms(image, person, face, samples, config)
    return person


def with_bare_arms(image: Frame, person: Mask, face: FaceBox, samples: Sequence[Frame], config: FeatureConfig) -> Mask:
    """`person` with the bare arms that stay put beside it (`PersonTemplate.arm_*`).

    An arm held out from the body for the whole video (a lasting A-pose) lies outside the body
    template, so GrabCut leaves it to the room, the median keeps it in the plate and I_sil never
    sees it. Its skin shows it: a region in the person's skin colour (learnt from the face) that
    touches the cut-out person where the upper arm hangs, reaches out from it as far as a
    forearm, is as thick as one and no larger than an arm and hand is the person's too, when
    the samples show it there nearly always. (An arm the person moves at times lets the median
    see past it anyway, and a skin-coloured pot its hand touches in the median would be taken
    with it.)

    Args:
        image: the median image, `(H, W, 3)` uint8 BGR.
        person: `(H, W)` uint8, 255 on the cut-out person.
        face: the face box `(x, y, w, h)` the cut was seeded from.
        samples: the frames the median was taken over.
        config: the template (`bg_person`), the skin settings and `bg_person_match`.
    """
    template = config.bg_person
    skin_model = skin_of_face(image, face, config)
    if skin_model is None:
        return person
    x, y, w, h = face
    centre = x + w / 2
    half_width, bottom = template.arm_zone
    rows = slice(max(y, 0), max(round(y + bottom * h), 0))
    cols = slice(max(round(centre - half_width * w), 0), max(round(centre + half_width * w), 0))
    skin = np.zeros_like(person)
    skin[rows, cols] = skin_model.mask(image)[rows, cols]
    skin[person > 0] = 0
    count, labels, stats, _ = cv2.connectedComponentsWithStats(skin, connectivity=8)
    if count <= 1:
        return person
    beside = cv2.dilate(person, np.ones((7, 7), np.uint8)) > 0
    beyond = cv2.distanceTransform(cv2.bitwise_not(person), cv2.DIST_L2, 3)
    inside = cv2.distanceTransform(skin, cv2.DIST_L2, 3)
    still: npt.NDArray[np.float32] | None = None  # share of the samples that match the median
    top, low = y + template.arm_contact[0] * h, y + template.arm_contact[1] * h
    out = cast(Mask, person.copy())
    for label in range(1, count):
        if stats[label, cv2.CC_STAT_AREA] > template.arm_max_area * w * h:
            continue
        region = labels == label
        contact_rows = np.nonzero(region & beside)[0]
        if (
            contact_rows.size > 0
            and top <= float(contact_rows.mean()) <= low
            and float(beyond[region].max()) >= template.arm_min_reach * w
            and 2.0 * float(inside[region].mean()) >= template.arm_min_thickness * w
        ):
            if still is None:  # only for a region shaped and placed like an arm (rare)
                still = np.zeros(person.shape, np.float32)
                for sample in samples:
                    still += colour_change(sample, image, config.bg_person_match) == 0
                still /= max(len(samples), 1)
            if float(still[region].mean()) >= template.arm_min_still:
                out[region] = 255
    return out


def grabcut_person(image: Frame, seed: Mask, config: FeatureConfig) -> Mask | None:
    """The person in `image` by GrabCut from `seed` (`cv2.GC_*` labels, as `grabcut_seed`'s).

    Returns:
        `(H, W)` uint8, 255 on the person; None when GrabCut cannot run (no room or no person
        in the seed, or too few pixels for a colour model).
    """
    height, width = image.shape[:2]
    scale = config.bg_grabcut_scale
    small_size = (max(1, round(width / scale)), max(1, round(height / scale)))
    small = cast(Frame, cv2.resize(image, small_size, interpolation=cv2.INTER_AREA))
    labels = cast(Mask, cv2.resize(seed, small_size, interpolation=cv2.INTER_NEAREST))
    room = (labels == cv2.GC_BGD) | (labels == cv2.GC_PR_BGD)
    if room.all() or not room.any():  # GrabCut needs both colour models
        return None
    # GrabCut seeds its colour models by k-means from OpenCV's per-thread random generator, and
    # the cut moves with that seed (01: IoU 0.77-0.91 over three seeds): a pixel is the person
    # when most of `bg_grabcut_runs` cuts from fixed seeds say so. The cuts run in threads of
    # their own, so that seeding their generators leaves the caller's alone.
    try:
        cuts = map_in_threads(lambda run: _grabcut_once(small, labels, run, config), range(config.bg_grabcut_runs))
    except cv2.error:  # too few pixels for one of GrabCut's colour models
        return None
    votes = np.sum(cuts, axis=0)
    person = np.where(2 * votes > config.bg_grabcut_runs, 255, 0).astype(np.uint8)
    return cast(Mask, cv2.resize(person, (width, height), interpolation=cv2.INTER_NEAREST))


__all__ = ["face_of_median", "find_face", "grabcut_person", "grabcut_seed", "person_in_median", "with_bare_arms"]
