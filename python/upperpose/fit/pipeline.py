"""`track_video`: a video file (or camera) in, one `TrackResult` per frame out, streamed.

Python drives the frame loop (STYLE 2): decode, features, search and output alternate frame by
frame, so memory does not grow with the video's length and Ctrl-C lands between frames.
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError
from upperpose.features import Background, CleanPlateWarning, FeatureConfig, background_from_video
from upperpose.fit.tracker import Fitter, Tracker, TrackerConfig, TrackResult
from upperpose.fit.work_size import WorkSize
from upperpose.io.video import Frame, VideoReader, is_stream_url, read_background
from upperpose.model import BodyModel, Camera

BackgroundLike = Background | npt.NDArray[np.uint8] | str | os.PathLike[str] | None


def load_background(
    background: BackgroundLike,
    video: str | os.PathLike[str] | int,
    size: tuple[int, int],
    config: FeatureConfig | None,
    work: WorkSize | None = None,
) -> tuple[Background | None, bool]:
    """The background model and whether it came from a clean plate.

    Args:
        background: a `Background`, a plate image, a path to one, or None: no clean plate, with
            a `CleanPlateWarning`; the result is then a plate estimated from the whole video
            first (`bg_model` "prepass", the default for files) or None: the tracker learns the
            background while tracking (`bg_model` "online", and always for a live source).
        video: the video (to estimate from).
        size: the video's `(height, width)`.
        config: feature thresholds.
        work: the working size the frames are tracked at; the background is made at it (a
            plate of the video's size is shrunk, an estimate is made from shrunk frames).

    Raises:
        ValueError: a plate of another size than the video.
        VideoError: unreadable image or video.
    """
    config = config or FeatureConfig()
    work = work or WorkSize.of(size[1], size[0], 0)
    if background is None:
        if isinstance(video, int) or is_stream_url(video) or config.bg_model == "online":
            warnings.warn(
                "no clean plate given: the background is learnt from the video while tracking; "
                "a photo of the empty scene (--background) gives better silhouettes",
                CleanPlateWarning,
                stacklevel=2,
            )
            return None, False
        return background_from_video(video, config, size=work.work if work.reduced else None), False
    if isinstance(background, Background):
        plate = background.plate
    else:
        plate = background if isinstance(background, np.ndarray) else read_background(background, size)
    plate_size = (int(plate.shape[0]), int(plate.shape[1]))
    if plate_size != tuple(size):
        raise InputError(f"the background is {plate_size[1]}x{plate_size[0]} but the video is {size[1]}x{size[0]}")
    if not isinstance(background, Background):
        return Background.from_plate(work.frame(plate), config), True
    if not work.reduced:
        return background, True
    b = background
    return Background.from_plate(work.frame(plate), b.config, estimated=b.estimated, method=b.method), True


@dataclass
class StageTimes:
    """Wall seconds per frame and stage: decode, features, search, output (filled by the caller).

    Features include learning the background when there is no clean plate.
    """

    decode: list[float] = field(default_factory=list)
    features: list[float] = field(default_factory=list)
    search: list[float] = field(default_factory=list)
    output: list[float] = field(default_factory=list)

    def add(self, decode: float, result: TrackResult) -> None:
        """Records decode time and the tracker's own split of one frame."""
        t = result.timings
        self.decode.append(decode)
        self.features.append(t.get("features", 0.0) + t.get("startup", 0.0) + t.get("background", 0.0))
        self.search.append(t.get("search", 0.0))
        self.output.append(t.get("other", 0.0))


class VideoTracking:
    """A video opened for tracking: reader, background, camera and tracker, set up together.

    Args:
        video: path to a video file, or a camera index.
        background: see `load_background`.
        focal: focal length in pixels (default: the image width, SPEC 3).
        camera: a ready camera (overrides `focal`).
        config: tracker settings.
        body: body dimensions to start the start-up measurement from.
        fitter: the search (tests inject a double); `upperpose.fit_frame` when None.
        keep_times: record each frame's stage times in `times` (`upperpose bench`); off by
            default, since the lists grow with the video.

    Raises:
        VideoError: missing, unreadable, corrupt or empty video; unreadable background.
        ValueError: background of another size; bad settings.
    """

    def __init__(
        self,
        video: str | os.PathLike[str] | int,
        background: BackgroundLike = None,
        *,
        focal: float | None = None,
        camera: Camera | None = None,
        config: TrackerConfig | None = None,
        body: BodyModel | None = None,
        fitter: Fitter | None = None,
        keep_times: bool = False,
    ) -> None:
        if focal is not None and not (np.isfinite(focal) and focal > 0):
            raise InputError(f"focal length must be a positive number of pixels, got {focal}")
        self.config = config or TrackerConfig()
        self.reader = VideoReader(video)
        try:
            size = (self.reader.height, self.reader.width)
            self.work = WorkSize.of(self.reader.width, self.reader.height, self.config.work_pixels)
            self.background, self.clean_plate = load_background(
                background, video, size, self.config.features, self.work
            )
            self.camera = camera or Camera.for_image(self.reader.width, self.reader.height, focal)
            self.tracker = Tracker(
                self.work.camera(self.camera),
                self.background,
                self.config,
                fps=self.reader.fps,
                body=body,
                fitter=fitter,
            )
        except BaseException:
            self.reader.close()
            raise
        self.times, self.keep_times = StageTimes(), keep_times

    @property
    def fps(self) -> float:
        """The video's frame rate."""
        return self.reader.fps

    def frames(self) -> Iterator[tuple[Frame, TrackResult]]:
        """Yields (frame, result) per frame, recording the per-stage times in `times` if kept."""
        frames = iter(self.reader)
        while True:
            t0 = time.perf_counter()
            frame = next(frames, None)
            decode = time.perf_counter() - t0
            if frame is None:
                return
            result = self.work.result(self.tracker.update(self.work.frame(frame)))
            if self.keep_times:
                self.times.add(decode, result)
            yield frame, result

    def close(self) -> None:
        """Releases the video."""
        self.reader.close()

    def __enter__(self) -> VideoTracking:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def track_video(
    video: str | os.PathLike[str] | int,
    background: BackgroundLike = None,
    *,
    focal: float | None = None,
    camera: Camera | None = None,
    config: TrackerConfig | None = None,
    fitter: Fitter | None = None,
) -> Iterator[TrackResult]:
    """Tracks a video frame by frame, streaming one `TrackResult` per frame.

    Args:
        video: path to a video file, or an integer camera index (live).
        background: a clean plate (path, image or `Background`); None estimates it from the
            video with a `CleanPlateWarning` (a photo of the empty scene is better).
        focal: focal length in pixels (default: the image width).
        camera: a ready camera (overrides `focal`).
        config: tracker settings.
        fitter: the search; `upperpose.fit_frame` when None.

    Yields:
        One result per frame, in order. Nothing is kept between frames.

    Raises:
        VideoError, ValueError: see `VideoTracking`.
    """
    with VideoTracking(video, background, focal=focal, camera=camera, config=config, fitter=fitter) as run:
        for _, result in run.frames():
            yield result


__all__ = ["StageTimes", "VideoTracking", "load_background", "track_video"]
