"""The background model: a clean plate, its derivative images and its skin mask, computed once.

Without a clean plate the plate is estimated from the video (`estimate_plate`): if the video
opens on a static scene with no face in it, the median of that lead-in is the plate; otherwise a
temporal median with the person masked out: the person who stays put is cut out of the median
image (`person_cut`) and masked in every sample that still shows them there; each sample's
foreground against the current plate is masked too, and the median is taken over what remains,
repeated. Pixels that no sample shows without the person are filled by inpainting from their
surroundings. Neither method sees what is really behind a person who never moves, hence the
`CleanPlateWarning`.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple, cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError, VideoError
from upperpose.features.change import colour_change
from upperpose.features.checks import Frame, Mask, check_frame, check_mask
from upperpose.features.config import FeatureConfig
from upperpose.features.faces import FaceDetector
from upperpose.features.order_stats import kth_smallest
from upperpose.features.parallel import map_in_threads, row_bands
from upperpose.features.person_cut import find_face, person_in_median
from upperpose.features.skin import skin_mask

Int16Image = npt.NDArray[np.int16]


class CleanPlateWarning(UserWarning):
    """The background was estimated from the video; a photo of the empty scene is better."""


# Share of a frame beyond which it does not show the video's room: a person covers well under
# half of the frame.
NOT_THE_ROOM = 0.5


def square(size: int) -> npt.NDArray[np.uint8] | None:
    """A `size` x `size` structuring element, or None for sizes below 2 (no operation)."""
    return np.ones((size, size), np.uint8) if size >= 2 else None


def grey_for_edges(frame: Frame, blur: int) -> npt.NDArray[np.uint8]:
    """The grey image the edge feature differentiates: BGR to grey, then an optional blur."""
    grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    return cast(npt.NDArray[np.uint8], cv2.GaussianBlur(grey, (blur, blur), 0) if blur >= 2 else grey)


def sobel_pair(grey: npt.NDArray[np.uint8]) -> tuple[Int16Image, Int16Image]:
    """3x3 Sobel derivatives in x and y as int16 images."""
    return cast(Int16Image, cv2.Sobel(grey, cv2.CV_16S, 1, 0, ksize=3)), cast(
        Int16Image, cv2.Sobel(grey, cv2.CV_16S, 0, 1, ksize=3)
    )


@dataclass(frozen=True)
class Background:
    """A background plate with everything derived from it that the per-frame features reuse.

    Attributes:
        plate: `(H, W, 3)` uint8 BGR image of the empty scene.
        dx, dy: `(H, W)` int16 Sobel derivatives of its (blurred) grey image.
        skin: `(H, W)` uint8, 255 where the plate itself is skin-coloured (dilated), so that
            static skin-coloured objects are not taken for skin; never where it is `unseen`.
        config: the configuration these were computed with.
        estimated: True when the plate was estimated from the video, not given.
        method: how the plate was made: "given", "lead-in median" or "masked median".
        unseen: `(H, W)` uint8, 255 where the plate is a guess (inpainted where the person
            stood in every sample), or None; not room skin (`seen_skin`).
    """

    plate: Frame
    dx: Int16Image
    dy: Int16Image
    skin: Mask
    config: FeatureConfig
    estimated: bool = False
    method: str = "given"
    notes: list[str] = field(default_factory=list)
    unseen: Mask | None = None

    @property
    def size(self) -> tuple[int, int]:
        """(height, width) in pixels."""
        return (int(self.plate.shape[0]), int(self.plate.shape[1]))

    @classmethod
    def from_plate(
        cls,
        plate: Frame,
        config: FeatureConfig | None = None,
        *,
        estimated: bool = False,
        method: str = "given",
        unseen: Mask | None = None,
    ) -> Background:
        """Derivative images and skin mask of a clean plate.

        Args:
            plate: `(H, W, 3)` uint8 BGR image of the scene without the person.
            config: thresholds; defaults when None.
            estimated: whether the plate was estimated rather than photographed.
            method: a short description of how the plate was made.
            unseen: `(H, W)`, nonzero where the plate is a guess (the attribute above).

        Raises:
            ValueError: the plate is not an `(H, W, 3)` uint8 image, or `unseen` not `(H, W)`.
        """
        config = config or FeatureConfig()
        plate = check_frame(plate, "background")
        dx, dy = sobel_pair(grey_for_edges(plate, config.edge_blur))
        if unseen is not None:
            unseen = cast(Mask, np.where(check_mask(unseen, "unseen", plate.shape[:2]) > 0, 255, 0).astype(np.uint8))
        skin = seen_skin(skin_mask(plate, config), unseen, square(config.background_skin_dilate))
        for image in (plate, dx, dy, skin) + (() if unseen is None else (unseen,)):
            image.setflags(write=False)
        return cls(plate, dx, dy, skin, config, estimated, method, unseen=unseen)

    def with_config(self, config: FeatureConfig) -> Background:
        """The same plate with its derived images recomputed for another configuration."""
        if config == self.config:
            return self
        return Background.from_plate(
            self.plate, config, estimated=self.estimated, method=self.method, unseen=self.unseen
        )


def seen_skin(skin: Mask, unseen: Mask | None, kernel: npt.NDArray[np.uint8] | None) -> Mask:
    """`skin` dilated by `kernel` (None: not), then cleared where the plate is a guess (`unseen`).

    Where the plate is a guess its colours were drawn in from around the person, often from the
    person (their neck, a hoodie): taken for skin-coloured room, they would hide the hands held
    in front of the body. The price: skin-coloured room right beside the person (a sofa), which
    the guess's rim reaches over, is taken for skin there.
    """
    if kernel is not None:
        skin = cast(Mask, cv2.dilate(skin, kernel))
    return skin if unseen is None else cast(Mask, cv2.bitwise_and(skin, cv2.bitwise_not(unseen)))


def median_pair(stack: npt.NDArray[np.uint8]) -> tuple[Frame, Frame]:
    """Per-pixel medians of `(N, H, W, 3)` uint8 samples.

    Returns:
        (median, lower): `np.median`'s (the mean of the two middle values, truncated, for even
        N) and the lower median (the middle value, the smaller of the two for even N).
    """
    n = len(stack)
    lower = np.empty(stack.shape[1:], np.uint8)
    upper = lower if n % 2 else np.empty_like(lower)

    def band(rows: slice) -> None:
        lower[rows] = kth_smallest(stack[:, rows], (n - 1) // 2)
        if upper is not lower:
            upper[rows] = kth_smallest(stack[:, rows], n // 2)

    map_in_threads(band, row_bands(stack.shape[1]))
    median = ((lower.astype(np.uint16) + upper) // 2).astype(np.uint8)
    return median, lower


def masked_median(
    stack: npt.NDArray[np.uint8], foreground: npt.NDArray[np.bool_], fallback: Frame, lower: Frame | None = None
) -> Frame:
    """Per-pixel (lower) median over the samples where `foreground` is False.

    Args:
        stack: `(N, H, W, 3)` uint8 samples.
        foreground: `(N, H, W)` bool, True where a sample shows the person.
        fallback: `(H, W, 3)` value for pixels where every sample is foreground.
        lower: the stack's lower median (`median_pair`), when already known.

    Returns:
        `(H, W, 3)` uint8.
    """
    out: Frame = (median_pair(stack)[1] if lower is None else lower).copy()

    def band(rows: slice) -> None:
        # Only pixels some sample masks need sorting. A masked value becomes 255, the largest:
        # the first `valid` sorted values are then exactly the unmasked ones, in order.
        touched = foreground[:, rows].any(axis=0)
        if not touched.any():
            return
        values = stack[:, rows][:, touched]
        masked = foreground[:, rows][:, touched]
        values[masked] = 255
        values.sort(axis=0)
        valid = (~masked).sum(axis=0)
        index = np.maximum(valid - 1, 0) // 2
        median = np.take_along_axis(values, index[None, :, None].repeat(3, axis=2), axis=0)[0]
        out[rows][touched] = np.where((valid > 0)[:, None], median, fallback[rows][touched])

    map_in_threads(band, row_bands(stack.shape[1]))
    return out


def foreground_against(stack: npt.NDArray[np.uint8], plate: Frame, config: FeatureConfig) -> npt.NDArray[np.bool_]:
    """Each sample's pixels that differ from `plate` (dilated): `(N, H, W)` bool."""
    kernel = square(config.bg_mask_dilate)
    masks = []
    for sample in stack:
        fg = colour_change(sample, plate, config.bg_threshold)
        masks.append(cv2.dilate(fg, kernel) if kernel is not None else fg)
    return np.stack(masks) > 0


def person_still_there(
    stack: npt.NDArray[np.uint8], median: Frame, person: Mask, config: FeatureConfig
) -> npt.NDArray[np.bool_]:
    """Per sample, the pixels of the median's person that the sample still shows (dilated).

    Where a sample differs from the median inside the person, the person moved away there (and
    the sample may show the room behind): those pixels are left to the median.

    Returns:
        `(N, H, W)` bool.
    """
    kernel = square(config.bg_person_dilate)
    masks = []
    for sample in stack:
        there = cv2.bitwise_and(person, cv2.bitwise_not(colour_change(sample, median, config.bg_person_match)))
        masks.append(cv2.dilate(there, kernel) if kernel is not None else there)
    return np.stack(masks) > 0


def fill_unseen(plate: Frame, foreground: npt.NDArray[np.bool_], config: FeatureConfig) -> tuple[Frame, Mask]:
    """`plate` with the pixels that are foreground in every sample inpainted from around them.

    Returns:
        The plate and those pixels (255): where it shows a guess, not the room.
    """
    unseen = cast(Mask, foreground.all(axis=0).astype(np.uint8) * np.uint8(255))
    if not unseen.any():
        return plate, unseen
    return cast(Frame, cv2.inpaint(plate, unseen, config.bg_inpaint_radius, cv2.INPAINT_TELEA)), unseen


class MedianPlate(NamedTuple):
    """A plate from `iterative_masked_median`.

    Attributes:
        plate: `(H, W, 3)` uint8 BGR.
        cut: whether a person was cut out of the median.
        unseen: `(H, W)` uint8, 255 where no sample showed the room (inpainted), or None.
    """

    plate: Frame
    cut: bool
    unseen: Mask | None


def iterative_masked_median(samples: Sequence[Frame], config: FeatureConfig) -> MedianPlate:
    """Temporal median with the person masked out.

    Median; the person who stays put cut out of it (`bg_cut_person`); then `bg_iterations`
    rounds of marking each sample's foreground against the current plate (and the cut-out
    person where the sample still shows them) and taking the median of the rest. With a cut-out
    person, pixels masked in every sample are inpainted.
    """
    stack = np.stack(samples)
    median, lower = median_pair(stack)
    person = person_in_median(median, samples, config) if config.bg_cut_person else None
    if person is None:
        plate = median
        for _ in range(config.bg_iterations):
            plate = masked_median(stack, foreground_against(stack, plate, config), plate, lower)
        return MedianPlate(plate, False, None)
    still = person_still_there(stack, median, person, config)
    plate, unseen = fill_unseen(masked_median(stack, still, median, lower), still, config)
    for _ in range(config.bg_iterations):
        foreground = still | foreground_against(stack, plate, config)
        plate, unseen = fill_unseen(masked_median(stack, foreground, plate, lower), foreground, config)
    return MedianPlate(plate, True, unseen)


def shows_a_face(frames: Sequence[Frame], config: FeatureConfig) -> bool:
    """Whether any of `frames` holds a frontal face whose box is mostly skin (a person)."""
    detect = FaceDetector(downscale=1.0)
    return any(find_face(f, config, detect) is not None for f in frames)


def static_prefix(lead: Sequence[Frame], config: FeatureConfig) -> int:
    """Number of lead-in frames, from the first, that hardly differ from the first."""
    first = lead[0]
    limit = config.bg_static_fraction * first.shape[0] * first.shape[1]
    for i, frame in enumerate(lead):
        if cv2.countNonZero(colour_change(frame, first, config.bg_threshold)) > limit:
            return i
    return len(lead)


def showing_the_room(frames: list[Frame], config: FeatureConfig) -> list[Frame]:
    """The frames that show the room most of the video shows.

    Each kept frame differs from the frames' median (on a sparse grid) in less than
    `NOT_THE_ROOM` of its pixels, where a person stands. A webcam's black first frames, a fade,
    a flash or a cut differ from it almost everywhere, and where the person masks most samples
    out of the median they would take over. All frames are kept when fewer than three pass.
    """
    if len(frames) < 3:
        return frames
    grid = np.stack([f[::4, ::4] for f in frames])
    median = median_pair(grid)[0]
    area = median.shape[0] * median.shape[1]
    kept = [
        f
        for f, g in zip(frames, grid)
        if cv2.countNonZero(colour_change(g, median, config.bg_threshold)) < NOT_THE_ROOM * area
    ]
    return kept if len(kept) >= 3 else frames


def median_samples(lead: Sequence[Frame], samples: Sequence[Frame], config: FeatureConfig) -> list[Frame]:
    """The frames the masked median is taken over: the samples and the first frame that show the room."""
    return showing_the_room(list(samples) + list(lead[:1]), config)


def estimate_plate(
    lead: Sequence[Frame], samples: Sequence[Frame], config: FeatureConfig
) -> tuple[Frame, str, Mask | None]:
    """Estimates the empty scene from the video's lead-in frames and frames sampled over it all.

    Args:
        lead: the frames of the first `bg_lead_seconds`, in order (may be empty).
        samples: frames spread over the whole video.
        config: thresholds.

    Returns:
        The plate, the method used ("lead-in median", "masked median, person cut out" or
        "masked median") and the pixels it guessed (`MedianPlate.unseen`; None: none).
    """
    if lead:
        n = static_prefix(lead, config)
        if n >= max(3, len(lead) // 4):
            plate = median_pair(np.stack(lead[:n]))[0]
            area = plate.shape[0] * plate.shape[1]
            changed = [cv2.countNonZero(colour_change(s, plate, config.bg_threshold)) / area for s in samples]
            someone_enters = max(changed, default=0.0) > 0.01
            # The room the lead-in shows must be the room of the video: most samples differ from
            # it only where the person is. A camera's black first frames are still and empty too.
            the_room = bool(changed) and float(np.median(changed)) < NOT_THE_ROOM
            if someone_enters and the_room and not shows_a_face([lead[0], lead[n // 2], lead[n - 1]], config):
                return plate, "lead-in median", None
    plate, cut, unseen = iterative_masked_median(median_samples(lead, samples, config), config)
    return plate, "masked median, person cut out" if cut else "masked median", unseen


def sample_video(
    path: str | os.PathLike[str], config: FeatureConfig, size: tuple[int, int] | None = None
) -> tuple[list[Frame], list[Frame], float]:
    """Reads a video once: its lead-in frames and up to `bg_max_samples` frames spread over it.

    `size`: (width, height) to shrink the kept frames to (the tracker's working size), if given.

    Returns:
        (lead-in frames, samples, frames per second).

    Raises:
        VideoError: the video cannot be opened or has no frames.
    """
    capture = cv2.VideoCapture(str(path))
    if not capture.isOpened():
        raise VideoError(f"cannot open video {path}")
    try:
        fps = capture.get(cv2.CAP_PROP_FPS) or 30.0
        count = int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
        step = max(1, math.ceil(count / config.bg_max_samples)) if count > 0 else 1
        lead_count = max(1, round(config.bg_lead_seconds * fps))
        lead: list[Frame] = []
        samples: list[Frame] = []
        index = 0
        while True:
            if not (index < lead_count or index % step == 0):
                if not capture.grab():  # decoded to stay in step, never converted to BGR
                    break
            else:
                ok, frame = capture.read()
                if not ok:
                    break
                if size is not None:
                    frame = cv2.resize(frame, size, interpolation=cv2.INTER_AREA)
                if index < lead_count:
                    lead.append(cast(Frame, frame))
                if index % step == 0:
                    samples.append(cast(Frame, frame))
            index += 1
    finally:
        capture.release()
    if not samples:
        raise VideoError(f"video {path} has no frames")
    if len(samples) > config.bg_max_samples:
        keep = np.linspace(0, len(samples) - 1, config.bg_max_samples).round().astype(int)
        samples = [samples[i] for i in keep]
    return lead, samples, float(fps)


def estimate_background(
    lead: Sequence[Frame], samples: Sequence[Frame], config: FeatureConfig | None = None
) -> Background:
    """A background estimated from video frames, with a `CleanPlateWarning`.

    Args:
        lead: frames of the video's first `bg_lead_seconds` (may be empty).
        samples: at least one frame; frames spread over the whole video.
        config: thresholds; defaults when None.

    Raises:
        ValueError: no samples, or frames that are not `(H, W, 3)` uint8 of one size.
    """
    config = config or FeatureConfig()
    if len(samples) == 0:
        raise InputError("background estimation needs at least one frame")
    size = check_frame(samples[0], "frame 0").shape[:2]
    samples = [check_frame(s, f"sample {i}", size) for i, s in enumerate(samples)]
    lead = [check_frame(f, f"lead-in frame {i}", size) for i, f in enumerate(lead)]
    plate, method, unseen = estimate_plate(lead, samples, config)
    warnings.warn(
        f"no clean plate given: the background was estimated from the video ({method}); "
        "a photo of the empty scene (--background) gives better silhouettes, "
        "and an estimate can only guess the room behind a person who hardly moves",
        CleanPlateWarning,
        stacklevel=2,
    )
    return Background.from_plate(plate, config, estimated=True, method=method, unseen=unseen)


def background_from_video(
    path: str | os.PathLike[str],
    config: FeatureConfig | None = None,
    plate: Frame | None = None,
    size: tuple[int, int] | None = None,
) -> Background:
    """The background for a video: `plate` when given, else estimated (with a `CleanPlateWarning`).

    `size`: (width, height) to estimate at, the video's frames shrunk to it (None: their own).

    Raises:
        VideoError: the video cannot be read.
        ValueError: the plate is not an `(H, W, 3)` uint8 image.
    """
    config = config or FeatureConfig()
    if plate is not None:
        return Background.from_plate(plate, config)
    lead, samples, _ = sample_video(path, config, size)
    return estimate_background(lead, samples, config)
