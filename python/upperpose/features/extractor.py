"""`FeatureExtractor`: the per-frame features of SPEC 4 against one background, frame after frame."""

from __future__ import annotations

import time
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError
from upperpose.features.background import Background, Int16Image, seen_skin, square
from upperpose.features.blobs import find_skin_blobs
from upperpose.features.change import colour_change, plate_distance
from upperpose.features.checks import Frame, Mask, check_frame, check_mask
from upperpose.features.config import FeatureConfig
from upperpose.features.exposure import GREY_WEIGHTS, ExposureMeter, needs_compensation
from upperpose.features.frame import FrameFeatures
from upperpose.features.packing import pack_rows
from upperpose.features.parts import (
    arm_silhouette,
    motion_flags,
    torso_region_from_labels,
    torso_region_from_shoulders,
)
from upperpose.features.person_skin import PersonSkin, skin_of_face
from upperpose.features.points import (
    HEAD,
    LEFT_SHOULDER,
    RIGHT_SHOULDER,
    hands_beyond_image,
    locate_points,
    shoulder_width,
)
from upperpose.features.skin import SkinWork, skin_mask
from upperpose.features.split import split_head_from_hands

# Around the head the generic skin rule holds (hair): a disc of this radius in predicted
# shoulder widths around the predicted head (a head is about half a shoulder width long), or,
# before tracking, in face widths around the face.
HEAD_ZONE_SHOULDERS = 0.45
HEAD_ZONE_FACES = 0.9
OUTPUT_NAMES = (
    "sub",
    "edge",
    "motion",
    "skin0",
    "skin",
    "sil",
    "edge_dilated",
    "motion_dilated",
    "arm_sil",
)


class _Clock:
    """Accumulates CPU seconds of this thread per stage when enabled.

    CPU time, not wall time, so that other processes on the machine do not inflate the breakdown.
    """

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self.times: dict[str, float] = {}
        self.last = time.thread_time() if enabled else 0.0

    def lap(self, name: str) -> None:
        if self.enabled:
            now = time.thread_time()
            self.times[name] = self.times.get(name, 0.0) + now - self.last
            self.last = now


class _Work:
    """Scratch arrays reused from frame to frame (frame-sized allocations cost page faults)."""

    def __init__(self, height: int, width: int) -> None:
        shape, shape3 = (height, width), (height, width, 3)
        self.change = (
            np.empty(shape3, np.uint8),
            np.empty(shape3, np.uint8),
            np.empty(shape, np.uint8),
        )
        self.grey_raw = np.empty(shape, np.uint8)
        self.plate = np.empty(shape3, np.uint8)
        self.relit = np.empty(shape3, np.uint8)
        self.plate_dx = np.empty(shape, np.int16)
        self.plate_dy = np.empty(shape, np.int16)
        self.greys = [np.empty(shape, np.uint8), np.empty(shape, np.uint8)]
        # Distance to the plate of this frame and the previous one (indexed like `greys`).
        self.distances = [np.empty(shape, np.uint8), np.empty(shape, np.uint8)]
        self.int16 = [np.empty(shape, np.int16) for _ in range(5)]
        self.tmp = np.empty(shape, np.uint8)
        self.allowed = np.empty(shape, np.uint8)
        self.skin = SkinWork(height, width)


def _joints_array(joints: npt.ArrayLike | None) -> npt.NDArray[np.float64] | None:
    if joints is None:
        return None
    array = np.asarray(joints, dtype=np.float64)
    if array.shape != (7, 2):
        raise InputError(f"predicted_joints must be (7, 2) pixels in JOINT_NAMES order, got shape {array.shape}")
    return array


class FeatureExtractor:
    """Computes `FrameFeatures` frame after frame against one background.

    Keeps the previous frame's grey image for I_motion (the first frame has no motion) and its
    distance to the plate, and scratch arrays reused between frames.

    Args:
        background: the background model (its derived images are recomputed if it was made
            with another configuration).
        config: thresholds; the background's when None.
        reuse_buffers: write every frame's feature images into the same arrays. Faster (no
            frame-sized allocations), but a `FrameFeatures` is then only valid until the next
            call: copy what you keep. The tracking loop consumes each frame at once.
    """

    def __init__(
        self,
        background: Background,
        config: FeatureConfig | None = None,
        *,
        reuse_buffers: bool = False,
    ) -> None:
        self.config = config or background.config
        self.background = background.with_config(self.config)
        height, width = self.background.size
        self._not_background_skin = cv2.bitwise_not(self.background.skin)
        self._exposure = ExposureMeter(self.background.plate, self.config.exposure_step)
        self._work = _Work(height, width)
        self._has_previous = False
        self._current = 0
        self._dilate = square(self.config.feature_dilate)
        self._trim = square(2 * self.config.sil_edge_trim + 1) if self.config.sil_edge_trim > 0 else None
        self._reuse = reuse_buffers
        self._outputs = self._new_outputs() if reuse_buffers else None
        self.person_skin: PersonSkin | None = None
        self._face_zone: tuple[tuple[float, float], float] | None = None

    @property
    def room_skin(self) -> Mask:
        """`(H, W)` uint8, 255 where the room is taken for skin-coloured.

        The background's skin, and the room in the person's colour once `learn_skin` learnt it.
        """
        return cast(Mask, cv2.bitwise_not(self._not_background_skin))

    def learn_skin(self, frame: Frame, face: tuple[int, int, int, int], whole_face: bool = False) -> PersonSkin | None:
        """Learns the person's skin colour from their face (`config.person_skin`).

        Args:
            frame: the `(H, W, 3)` uint8 BGR frame the face was found in.
            face: the face box `(x, y, w, h)`, pixels.
            whole_face: the generic rule finds little skin in this face (it was taken for its
                steadiness, `faces.SteadyFace`): learn from every pixel of the face's core.

        Returns:
            The model, or None: not learnt (turned off, or too few skin pixels in the face).
            From the next frame on, I_skin0 is that colour outside the head's zone, until
            `forget_skin` or the next `learn_skin`.
        """
        cfg = self.config
        # With an estimated plate too: the estimate may hold some of the person or miss the room
        # behind them, but the generic rule it would fall back on is worse (docs/features.md).
        if not cfg.person_skin:
            return None
        relit = self._plate_for(check_frame(frame, "frame", self.background.size))[3]
        self.person_skin = skin_of_face(relit, face, cfg, whole_face)
        x, y, w, h = face
        self._face_zone = ((x + w / 2, y + h / 2), HEAD_ZONE_FACES * w)
        if self.person_skin is not None:
            # The room in the person's skin colour, as `Background.skin` is in the generic rule's.
            self._not_background_skin = self._not_room_skin(self.person_skin)
        return self.person_skin

    def set_background(self, background: Background) -> None:
        """Compares the next frames with another background of the same size.

        The online background's refresh; the previous frame (I_motion) and a learnt skin
        colour are kept.

        Raises:
            ValueError: a background of another size.
        """
        if background.size != self.background.size:
            raise InputError(f"the new background is {background.size}, the old one {self.background.size}")
        self.background = background.with_config(self.config)
        self._exposure = ExposureMeter(self.background.plate, self.config.exposure_step)
        if self.person_skin is None:
            self._not_background_skin = cv2.bitwise_not(self.background.skin)
        else:
            self._not_background_skin = self._not_room_skin(self.person_skin)

    def _not_room_skin(self, person: PersonSkin) -> Mask:
        """Pixels where the plate shows neither the generic rule's nor the person's skin colour.

        Where the plate is a guess it shows no room (`seen_skin`).
        """
        room = person.mask(self.background.plate, room=True)
        room = seen_skin(room, self.background.unseen, square(self.config.background_skin_dilate))
        return cast(Mask, cv2.bitwise_not(cv2.bitwise_or(room, self.background.skin)))

    def forget_skin(self) -> None:
        """Back to the generic skin rule (the person left)."""
        self.person_skin = None
        self._face_zone = None
        self._not_background_skin = cv2.bitwise_not(self.background.skin)

    def _head_zone(self, joints: npt.NDArray[np.float64] | None) -> tuple[tuple[float, float], float] | None:
        """Disc around the predicted head (else the learnt face) where the generic skin rule holds."""
        if joints is not None and np.all(np.isfinite(joints[[HEAD, RIGHT_SHOULDER, LEFT_SHOULDER]])):
            return (float(joints[HEAD, 0]), float(joints[HEAD, 1])), HEAD_ZONE_SHOULDERS * shoulder_width(
                joints, self.config
            )
        return self._face_zone

    def _person_skin0(
        self, person: PersonSkin, relit: Frame, joints: npt.NDArray[np.float64] | None, out: Mask
    ) -> Mask:
        """I_skin0 once the person's skin is known: their colour, and the generic rule around the head.

        Around the head the generic rule stays: hair that passes it belongs to the head's blob,
        by whose size and centre start-up and the root were measured. It is computed there only.
        """
        skin0 = person.mask(relit, self._work.skin.converted, out)
        head = self._head_zone(joints)
        if head is None:
            return skin0
        (cx, cy), radius = head
        r = max(round(radius), 1)
        height, width = skin0.shape
        x0, y0 = max(round(cx) - r, 0), max(round(cy) - r, 0)
        x1, y1 = min(round(cx) + r + 1, width), min(round(cy) + r + 1, height)
        if x1 <= x0 or y1 <= y0:
            return skin0
        generic = skin_mask(np.ascontiguousarray(relit[y0:y1, x0:x1]), self.config)
        disc = np.zeros_like(generic)
        cv2.circle(disc, (round(cx) - x0, round(cy) - y0), r, 255, -1)
        cv2.bitwise_and(generic, disc, dst=generic)
        cv2.bitwise_or(skin0[y0:y1, x0:x1], generic, dst=skin0[y0:y1, x0:x1])
        return skin0

    def _new_outputs(self) -> dict[str, Mask]:
        height, width = self.background.size
        return {name: np.empty((height, width), np.uint8) for name in OUTPUT_NAMES}

    def reset(self) -> None:
        """Forgets the previous frame (after a cut or a seek)."""
        self._has_previous = False

    def _grey(self, frame: Frame) -> Mask:
        """Grey (blurred) image of `frame` into the next grey buffer; the other keeps the previous."""
        self._current ^= 1
        grey = self._work.greys[self._current]
        blur = self.config.edge_blur
        if blur >= 2:
            cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY, dst=self._work.grey_raw)
            cv2.GaussianBlur(self._work.grey_raw, (blur, blur), 0, dst=grey)
        else:
            cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY, dst=grey)
        return grey

    def _distance(self, frame: Frame, plate: Frame) -> Mask:
        """Distance of `frame` to the plate, into the current distance buffer.

        The other buffer keeps the previous frame's.
        """
        work = self._work
        return plate_distance(frame, plate, work.change[0], work.distances[self._current])

    def _plate_for(self, frame: Frame) -> tuple[Frame, Int16Image, Int16Image, Frame]:
        """Plate, its derivatives and frame, brought to the same light when the light changed.

        The plate and its derivatives are scaled to the frame's light (I_sub, I_edge); the frame
        is scaled to the plate's light for the skin colour rule.
        """
        bg, work = self.background, self._work
        gains = self._exposure.gains(frame)
        if not needs_compensation(gains, self.config.exposure_tolerance):
            return bg.plate, bg.dx, bg.dy, frame
        cv2.multiply(bg.plate, (*(float(g) for g in gains), 1.0), dst=work.plate, dtype=cv2.CV_8U)  # type: ignore[call-overload]
        # The skin rule's bounds are absolute (R - G, Cr, Cb shrink with the light): a dimmed
        # hand falls out of them while the plate-lit colours stay inside.
        cv2.multiply(frame, (*(1.0 / max(float(g), 0.05) for g in gains), 1.0), dst=work.relit, dtype=cv2.CV_8U)  # type: ignore[call-overload]
        grey_gain = float(gains @ GREY_WEIGHTS)
        cv2.multiply(bg.dx, grey_gain, dst=work.plate_dx, dtype=cv2.CV_16S)  # type: ignore[call-overload]
        cv2.multiply(bg.dy, grey_gain, dst=work.plate_dy, dtype=cv2.CV_16S)  # type: ignore[call-overload]
        return work.plate, work.plate_dx, work.plate_dy, work.relit

    def prime(self, previous: Frame) -> None:
        """Sets the previous frame for I_motion without computing its features.

        Raises:
            ValueError: see `__call__`.
        """
        previous = check_frame(previous, "previous", self.background.size)
        self._grey(previous)
        self._distance(previous, self._plate_for(previous)[0])
        self._has_previous = True

    def __call__(
        self,
        frame: Frame,
        predicted_joints: npt.ArrayLike | None = None,
        part_labels: Mask | None = None,
        torso_region: Mask | None = None,
        *,
        timed: bool = False,
    ) -> FrameFeatures:
        """The features of the next frame.

        Args:
            frame: `(H, W, 3)` uint8 BGR frame of the background's size.
            predicted_joints: `(7, 2)` pixels, JOINT_NAMES order: the tracker's prediction for
                this frame (or last frame's fit); None at start-up.
            part_labels: `(H, W)` uint8 labels image of last frame's projected model
                (`render_masks(...)["labels"]`), for the motion flags and, when no
                `torso_region` is given, the torso region of the arm silhouette.
            torso_region: `(H, W)` mask, nonzero inside torso, neck and head; if None it comes
                from `part_labels`, else from the predicted shoulders, else no arm silhouette.
            timed: record CPU seconds per stage in `FrameFeatures.timings`.

        Raises:
            ValueError: a frame that is empty, grayscale, not 3-channel uint8, or not the
                background's size; masks or joints of the wrong shape.
        """
        cfg, bg, work = self.config, self.background, self._work
        size = bg.size
        frame = check_frame(frame, "frame", size)
        joints = _joints_array(predicted_joints)
        labels = check_mask(part_labels, "part_labels", size) if part_labels is not None else None
        region = check_mask(torso_region, "torso_region", size) if torso_region is not None else None
        out = self._outputs if self._reuse and self._outputs is not None else self._new_outputs()
        clock = _Clock(timed)

        grey = self._grey(frame)
        clock.lap("grey")
        plate, plate_dx, plate_dy, relit = self._plate_for(frame)
        clock.lap("exposure")
        # I_sub: per-channel change against the plate, opened (noise) then closed (holes).
        colour_change(frame, plate, cfg.sub_threshold, work.change, out=work.tmp)
        sub = _open_close(work.tmp, cfg.sub_open, cfg.sub_close, work.allowed, out["sub"])
        clock.lap("sub")
        # I_edge: |d/dx frame - d/dx plate| + |d/dy frame - d/dy plate| > threshold (§3.4.2).
        dx, dy, adx, ady, magnitude = work.int16
        cv2.Sobel(grey, cv2.CV_16S, 1, 0, dst=dx, ksize=3)
        cv2.Sobel(grey, cv2.CV_16S, 0, 1, dst=dy, ksize=3)
        cv2.absdiff(dx, plate_dx, dst=adx)
        cv2.absdiff(dy, plate_dy, dst=ady)
        cv2.add(adx, ady, dst=magnitude)
        edge = cast(Mask, cv2.compare(magnitude, cfg.edge_threshold, cv2.CMP_GT, dst=out["edge"]))  # type: ignore[call-overload]
        clock.lap("edge")
        # I_motion: grey difference to the previous frame.
        if self._has_previous:
            cv2.absdiff(grey, work.greys[self._current ^ 1], dst=work.tmp)
            motion = cast(Mask, cv2.compare(work.tmp, cfg.motion_threshold, cv2.CMP_GT, dst=out["motion"]))  # type: ignore[call-overload]
        else:
            motion = out["motion"]
            motion.fill(0)
        self._has_previous = True
        clock.lap("motion")
        # I_skin = I_skin0 & (~background skin | I_motion & ~trail | I_sub), opened; I_skin0 on
        # the frame in the plate's light. A trail: the pixel differed from the plate a frame
        # before and came back towards it, a moving part uncovered the room; skin-coloured room
        # there is not skin.
        if self.person_skin is None:
            skin0 = skin_mask(relit, cfg, work.skin, out["skin0"])
        else:
            skin0 = self._person_skin0(self.person_skin, relit, joints, out["skin0"])
        distance, before = self._distance(frame, plate), work.distances[self._current ^ 1]
        cv2.compare(distance, before, cv2.CMP_GE, dst=work.allowed)
        cv2.compare(before, cfg.sub_threshold, cv2.CMP_LE, dst=work.tmp)  # type: ignore[call-overload]
        cv2.bitwise_or(work.allowed, work.tmp, dst=work.allowed)
        cv2.bitwise_and(work.allowed, motion, dst=work.allowed)
        cv2.bitwise_or(self._not_background_skin, work.allowed, dst=work.allowed)
        cv2.bitwise_or(work.allowed, sub, dst=work.allowed)
        cv2.bitwise_and(skin0, work.allowed, dst=work.tmp)
        skin = _morph(work.tmp, cv2.MORPH_OPEN, cfg.skin_open, out["skin"])
        clock.lap("skin")
        # I_sil = I_sub | I_edge | I_skin (Eq. 3.4.1-1) without its outer edge-only rim, closed.
        cv2.bitwise_or(sub, skin, dst=work.allowed)
        cv2.bitwise_or(work.allowed, edge, dst=work.tmp)
        if self._trim is not None:
            cv2.erode(work.tmp, self._trim, dst=work.tmp)
            cv2.bitwise_or(work.tmp, work.allowed, dst=work.tmp)
        sil = _morph(work.tmp, cv2.MORPH_CLOSE, cfg.sil_close, out["sil"])
        clock.lap("sil")
        edge_dilated = _dilate(edge, self._dilate, out["edge_dilated"])
        motion_dilated = _dilate(motion, self._dilate, out["motion_dilated"])
        clock.lap("dilate")
        # P_SB counts edges within a pixel of the blob: its outline edges lie in a band that the
        # skin mask, shrunk by colour blending and its opening, often stops just short of.
        blobs = find_skin_blobs(skin, edge_dilated, cfg, sub, relit, plate)
        matching = None
        if joints is not None:
            blobs, matching = split_head_from_hands(blobs, relit, joints, cfg)
        clock.lap("blobs")
        head, right_hand, left_hand = locate_points(blobs, joints, cfg, matching, size)
        hands_beyond = hands_beyond_image((right_hand, left_hand), joints, size)
        clock.lap("points")
        flags = motion_flags(motion, labels, cfg) if labels is not None else None
        clock.lap("motion_flags")
        if region is None and labels is not None:
            region = torso_region_from_labels(labels, cfg)
        elif region is None and joints is not None and np.all(np.isfinite(joints[[RIGHT_SHOULDER, LEFT_SHOULDER]])):
            region = torso_region_from_shoulders(joints[RIGHT_SHOULDER], joints[LEFT_SHOULDER], size)
        elif region is not None:
            region = cast(Mask, cv2.compare(region, 0, cv2.CMP_GT))  # type: ignore[call-overload]
        arm = arm_silhouette(sil, region, out["arm_sil"]) if region is not None else None
        clock.lap("arm_sil")
        sil_bits, edge_bits, motion_bits = (
            pack_rows(sil),
            pack_rows(edge_dilated),
            pack_rows(motion_dilated),
        )
        arm_bits = pack_rows(arm) if arm is not None else None
        clock.lap("pack")
        return FrameFeatures(
            sub=sub,
            edge=edge,
            motion=motion,
            skin0=skin0,
            skin=skin,
            sil=sil,
            edge_dilated=edge_dilated,
            motion_dilated=motion_dilated,
            arm_sil=arm,
            sil_bits=sil_bits,
            edge_bits=edge_bits,
            motion_bits=motion_bits,
            arm_bits=arm_bits,
            blobs=blobs,
            head=head,
            right_hand=right_hand,
            left_hand=left_hand,
            hands_beyond=hands_beyond,
            motion_flags=flags,
            timings=clock.times,
        )


def _morph(image: Mask, op: int, size: int, out: Mask) -> Mask:
    """`op` with a `size` square into `out` (a copy when size < 2)."""
    kernel = square(size)
    if kernel is None:
        np.copyto(out, image)
        return out
    return cast(Mask, cv2.morphologyEx(image, op, kernel, dst=out))


def _open_close(image: Mask, open_size: int, close_size: int, scratch: Mask, out: Mask) -> Mask:
    """Opening then closing of `image` into `out`, via `scratch`."""
    return _morph(
        _morph(image, cv2.MORPH_OPEN, open_size, scratch),
        cv2.MORPH_CLOSE,
        close_size,
        out,
    )


def _dilate(image: Mask, kernel: npt.NDArray[np.uint8] | None, out: Mask) -> Mask:
    if kernel is None:
        np.copyto(out, image)
        return out
    return cast(Mask, cv2.dilate(image, kernel, dst=out))


def compute_features(
    frame: Frame,
    background: Background,
    previous: Frame | None = None,
    predicted_joints: npt.ArrayLike | None = None,
    part_labels: Mask | None = None,
    config: FeatureConfig | None = None,
) -> FrameFeatures:
    """The features of one frame given the previous one (a one-off `FeatureExtractor` call).

    Args:
        frame: `(H, W, 3)` uint8 BGR.
        background: the background model.
        previous: the previous frame for I_motion, or None (no motion).
        predicted_joints: `(7, 2)` predicted joints in pixels, or None at start-up.
        part_labels: last frame's projected part labels, or None.
        config: thresholds; the background's when None.

    Raises:
        ValueError: see `FeatureExtractor.__call__`.
    """
    extractor = FeatureExtractor(background, config)
    if previous is not None:
        extractor.prime(previous)
    return extractor(frame, predicted_joints, part_labels)


__all__ = ["FeatureExtractor", "compute_features"]
