"""The background learnt while tracking, for when there is no clean plate (a live camera, a file).

A running mean per pixel. Each frame the pixels away from the person move towards the frame:
outside the tracked model's projection grown by a margin (before the first fit, outside the
body region around each recently detected face, `body_region`), and, where a pixel has been
seen before, outside skin and motion too (a hand the fit missed, a trail). Pixels under the
person keep their values. The rate is 1/n over the first n frames (a plain mean while the model
is young), then `bg_online_rate` (follows slow light changes), and `bg_online_change_rate` where
the frame differs from the model (the room uncovered where the person stood at the start).

The first frame is the start: the person around each face (GrabCut inside the body region, and
the skin there) is filled by inpainting from around them, and each filled pixel is taken as it is
the first time it is seen away from the person. Or a plate estimated from the whole video before
tracking is (`from_estimate`): learning then fades the ghosts of the person it kept. The arrays
are allocated once: memory does not grow with the video. See docs/features.md.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.background import Background, square
from upperpose.features.checks import Frame, Mask, check_frame
from upperpose.features.config import FeatureConfig
from upperpose.features.faces import FaceBox
from upperpose.features.person_cut import grabcut_person, grabcut_seed
from upperpose.features.skin import skin_mask

METHOD = "online"


def body_region(shape: tuple[int, int], faces: Sequence[FaceBox], config: FeatureConfig) -> Mask:
    """255 where the person of each face may be: head, torso and everything the arms can reach.

    The head and torso as `PersonTemplate`'s probable-background band; the arms as a disc of
    `bg_online_reach` face widths around each shoulder (an arm is about four face widths long,
    and the person may stand in any pose).
    """
    region = np.zeros(shape, bool)
    template = config.bg_person
    for face in faces:
        region |= grabcut_seed(shape, face, template) != cv2.GC_BGD
    out = region.astype(np.uint8) * np.uint8(255)
    for x, y, w, h in faces:
        cx, shoulder_y = x + w / 2, y + template.sure_chest[1] * h
        for side in (-1, 1):
            centre = (round(cx + side * template.sure_chest[0] * 2 * w), round(shoulder_y))
            cv2.circle(out, centre, round(config.bg_online_reach * w), 255, -1)
    return cast(Mask, out)


def first_hole(frame: Frame, faces: Sequence[FaceBox], config: FeatureConfig) -> Mask:
    """The pixels of the first frame to fill by inpainting rather than learn: the person.

    GrabCut (`bg_online_grabcut_runs` runs) separates the person from the room inside each
    face's `body_region`, seeded by the face's `PersonTemplate`; the cut is grown by
    `bg_person_dilate`. Where GrabCut cannot run, the whole body region.
    """
    height, width = frame.shape[:2]
    region = body_region((height, width), faces, config)
    if not faces:
        return region
    seed = np.full((height, width), cv2.GC_BGD, np.uint8)
    for face in faces:
        own = grabcut_seed((height, width), face, config.bg_person)
        np.copyto(seed, own, where=own != cv2.GC_BGD)
    seed[(region > 0) & (seed == cv2.GC_BGD)] = cv2.GC_PR_BGD
    person = grabcut_person(frame, seed, config.replace(bg_grabcut_runs=config.bg_online_grabcut_runs))
    if person is None:
        return region
    if config.bg_online_hold_skin:
        # Bare arms in front of wooden furniture go to the room's colour model: skin within the
        # reach is held too (room held by mistake is learnt once seen beside the model).
        cv2.bitwise_or(person, cv2.bitwise_and(skin_mask(frame, config), region), dst=person)
    kernel = square(config.bg_person_dilate)
    return cast(Mask, cv2.dilate(person, kernel) if kernel is not None else person)


class OnlineBackground:
    """A per-pixel running mean of the scene away from the person, refreshed as a `Background`.

    Args:
        frame: the first frame, `(H, W, 3)` uint8 BGR.
        faces: face boxes `(x, y, w, h)` in it; their body regions are inpainted, not learnt.
        config: thresholds (`bg_online_*`, `bg_person`, `bg_inpaint_radius`).

    Raises:
        ValueError: the frame is not an `(H, W, 3)` uint8 image.
    """

    def __init__(self, frame: Frame, faces: Sequence[FaceBox] = (), config: FeatureConfig | None = None) -> None:
        cfg = config or FeatureConfig()
        frame = check_frame(frame, "frame")
        hole = first_hole(frame, faces, cfg)
        plate = cast(Frame, cv2.inpaint(frame, hole, cfg.bg_inpaint_radius, cv2.INPAINT_TELEA) if hole.any() else frame)
        background = Background.from_plate(np.array(plate), cfg, estimated=True, method=METHOD)
        self._start(plate, cast(Mask, cv2.bitwise_not(hole)), 1, background)

    @classmethod
    def from_estimate(cls, background: Background) -> OnlineBackground:
        """Goes on learning from a plate estimated before tracking (`background.estimate_plate`).

        The estimate keeps what the median kept: where the person stood in most samples but not
        always, a ghost of them. Learning while tracking replaces it wherever the room shows
        away from the person. Every pixel counts as seen and the model as mature (the estimate
        already sums the video): from the first frame the rate is `bg_online_rate`, or
        `bg_online_change_rate` where the frame differs from the plate. The estimate's guessed
        pixels (`Background.unseen`) stay a guess until learnt where the frame agrees with them.
        """
        model = cls.__new__(cls)
        seen = np.full(background.size, 255, np.uint8)
        refined = dataclasses.replace(background, method=f"{background.method}, refined while tracking")
        model._start(background.plate, seen, round(1.0 / background.config.bg_online_rate), refined)
        return model

    def _start(self, plate: Frame, seen: Mask, frames: int, background: Background) -> None:
        self.config = cfg = background.config
        height, width = plate.shape[:2]
        self.mean = np.asarray(plate, np.float32)
        self.seen = seen
        self.frames = frames
        self.last_learn_ms = 0.0  # CPU time of the last `learn`, refresh included
        self._fresh = 0  # frames learnt since the last refresh
        self._kernel = square(2 * cfg.bg_online_margin + 1)
        self._busy_kernel = square(cfg.bg_online_busy_dilate)
        self._held = np.empty((height, width), np.uint8)
        self._busy = np.empty((height, width), np.uint8)
        self._mask = np.empty((height, width), np.uint8)
        # Where the plate is still a guess (`Background.unseen`), kept up to date while learning.
        self.guessed: Mask | None = None if background.unseen is None else background.unseen.copy()
        self.background = background

    def learn(self, frame: Frame, person: Mask | None, busy: Mask | None = None, changed: Mask | None = None) -> bool:
        """Learns from one frame away from the person.

        Args:
            frame: `(H, W, 3)` uint8 BGR of the model's size.
            person: `(H, W)` nonzero on the person (the model's projection, or the body regions
                around the faces before tracking), grown by `bg_online_margin` here; None when
                nobody is known to be there.
            busy: `(H, W)` nonzero on pixels that may be the person even so (skin, motion),
                grown by `bg_online_busy_dilate`; held where a pixel was seen before (a pixel
                never seen is taken outside `person` whatever it shows: otherwise skin-coloured
                room that the inpainting got wrong would stay skin).
            changed: `(H, W)` nonzero where the frame differs from the background (I_sub):
                learnt at `bg_online_change_rate` (room uncovered where the person stood when
                the model started; furniture moved), the rest at the slow rate.

        Returns:
            Whether `background` was refreshed (every `bg_online_refresh` frames).
        """
        start = time.thread_time()
        cfg = self.config
        held, mask = self._held, self._mask
        if person is None:
            held.fill(0)
        else:
            cv2.compare(person, 0, cv2.CMP_GT, dst=held)  # type: ignore[call-overload]
            if self._kernel is not None:
                cv2.dilate(held, self._kernel, dst=held)
        cv2.bitwise_not(held, dst=mask)
        cv2.bitwise_and(mask, self.seen, dst=mask)
        if busy is not None:
            grown = busy if self._busy_kernel is None else cv2.dilate(busy, self._busy_kernel, dst=self._busy)
            cv2.bitwise_and(mask, cv2.bitwise_not(grown, dst=self._busy), dst=mask)
        self.frames += 1
        if self.guessed is not None:
            # A guess the room agrees with where it is learnt is no longer a guess: it stays one
            # where not learnt or changed (in the spare buffer, no allocation a frame).
            keep = cv2.bitwise_not(mask, dst=self._busy)
            if changed is not None:
                cv2.bitwise_or(keep, changed, dst=keep)
            cv2.bitwise_and(self.guessed, keep, dst=self.guessed)
        rate = max(1.0 / self.frames, cfg.bg_online_rate)
        if changed is not None and cfg.bg_online_change_rate > rate:
            # Changed pixels go first at the faster rate, the rest at the slow one.
            fast = cv2.bitwise_and(mask, changed, dst=self._busy)
            cv2.accumulateWeighted(frame, self.mean, cfg.bg_online_change_rate, mask=fast)
            cv2.bitwise_xor(mask, fast, dst=mask)
        cv2.accumulateWeighted(frame, self.mean, rate, mask=mask)
        # First sight of a pixel the start filled in: take it as it is.
        cv2.bitwise_or(held, self.seen, dst=mask)
        cv2.bitwise_not(mask, dst=mask)
        if cv2.countNonZero(mask):
            cv2.accumulateWeighted(frame, self.mean, 1.0, mask=mask)
            cv2.bitwise_or(self.seen, mask, dst=self.seen)
        self._fresh += 1
        refresh = self._fresh >= cfg.bg_online_refresh
        if refresh:
            self._fresh = 0
            plate = cast(Frame, cv2.convertScaleAbs(self.mean))
            self.background = Background.from_plate(
                plate, cfg, estimated=True, method=self.background.method, unseen=self.guessed
            )
        self.last_learn_ms = 1000 * (time.thread_time() - start)
        return refresh

    @property
    def unseen(self) -> float:
        """Share of the pixels never seen away from the person (still the start's inpainting)."""
        return 1.0 - cv2.countNonZero(self.seen) / self.seen.size

    def arrays(self) -> dict[str, npt.NDArray[np.generic]]:
        """The model's state (for checking that memory does not grow)."""
        derived = {k: v for k, v in vars(self.background).items() if isinstance(v, np.ndarray)}
        guessed = {} if self.guessed is None else {"guessed": self.guessed}
        return {"mean": self.mean, "seen": self.seen, **guessed, **derived}


__all__ = ["METHOD", "OnlineBackground", "body_region"]
