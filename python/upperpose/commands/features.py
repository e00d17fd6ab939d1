"""`upperpose features`: a contact sheet of every image feature of one video frame."""

from __future__ import annotations

import argparse
import dataclasses
import json
import warnings
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.commands.limits import OptionError
from upperpose.commands.track import add_background_model_argument, tracker_config
from upperpose.exceptions import VideoError
from upperpose.features import (
    SKIN_SPACES,
    Background,
    CleanPlateWarning,
    FeatureConfig,
    FeatureExtractor,
)
from upperpose.features.background import background_from_video
from upperpose.features.frame import FrameFeatures
from upperpose.features.sheet import contact_sheet
from upperpose.fit.pipeline import VideoTracking
from upperpose.fit.tracker_config import TrackerConfig
from upperpose.fit.work_size import WorkSize
from upperpose.io.files import write_image

NAME = "features"
HELP = "write a labelled contact sheet of every image feature of one frame, to see why tracking fails"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument("video", help="the video")
    p.add_argument("--frame", type=int, default=0, help="frame number, from 0 (default: 0)")
    p.add_argument(
        "-o",
        "--output",
        default="features.png",
        help="image to write (default: features.png)",
    )
    p.add_argument(
        "--background",
        metavar="IMAGE",
        help="clean plate: a photo of the scene without the person (default: estimated from the video)",
    )
    p.add_argument(
        "--skin",
        choices=SKIN_SPACES,
        default=None,
        help="skin colour rule (default: rgb+ycrcb, or the --config file's; rgb is the thesis' rule alone)",
    )
    p.add_argument(
        "--poses",
        metavar="JSON",
        help="poses file (SPEC 9 format, e.g. tracker output or ground "
        "truth): the previous frame's joints_2d serve as the prediction for head and hand matching",
    )
    p.add_argument(
        "--as-tracked",
        action="store_true",
        help="track the video up to the frame and show the features the tracker computed there: with "
        "the skin colour it learnt from the face, the background as learnt so far and its own "
        "prediction (slower: every frame before it is tracked)",
    )
    # How --as-tracked tracks, as `upperpose track` would: the same options give the same run.
    p.add_argument("--focal", type=float, metavar="PX", help="with --as-tracked: focal length in pixels")
    p.add_argument("--seed", type=int, default=None, help="with --as-tracked: the tracker's random seed (default 0)")
    p.add_argument("--config", metavar="FILE.toml", help="with --as-tracked: settings file, as for track")
    add_background_model_argument(p)


def read_frames(path: str, index: int) -> tuple[npt.NDArray[np.uint8] | None, npt.NDArray[np.uint8]]:
    """Frames `index - 1` (None for index 0) and `index` of a video.

    Raises:
        VideoError: the video cannot be opened or is shorter than `index + 1` frames.
    """
    capture = cv2.VideoCapture(path)
    if not capture.isOpened():
        raise VideoError(f"cannot open video {path}")
    previous = None
    try:
        for i in range(index + 1):
            ok, frame = capture.read()
            if not ok:
                raise VideoError(f"video {path} has only {i} frames; --frame {index} is past its end")
            if i == index - 1:
                previous = frame
    finally:
        capture.release()
    return cast("npt.NDArray[np.uint8] | None", previous), cast(npt.NDArray[np.uint8], frame)


def predicted_joints(path: str, index: int) -> npt.NDArray[np.float64] | None:
    """joints_2d of frame `index - 1` (or `index` for the first frame) from a poses file, or None."""
    data = json.loads(Path(path).read_text())
    frames = {f["frame"]: f for f in data.get("frames", [])}
    entry = frames.get(max(index - 1, 0))
    if entry is None or entry.get("joints_2d") is None:
        return None
    return np.asarray(entry["joints_2d"], dtype=np.float64)


def tracked_features(
    video: str, index: int, background: str | None, config: TrackerConfig, focal: float | None = None
) -> tuple[npt.NDArray[np.uint8], FrameFeatures, Background, npt.NDArray[np.uint8], WorkSize]:
    """Tracks `video` up to frame `index` (with `config`, at `focal`) and returns what the tracker saw there.

    Returns:
        The frame at the tracker's working size, its features, the background they were
        computed against, the room's pixels taken for skin-coloured and the working size.

    Raises:
        VideoError: the video cannot be read or is shorter than `index + 1` frames.
    """
    with VideoTracking(video, background, focal=focal, config=config) as run:
        count = 0
        for count, (frame, _) in enumerate(run.frames(), start=1):
            if count > index:
                features, room = run.tracker.features, run.tracker.room_skin
                if features is None or room is None or run.tracker.background is None:
                    raise VideoError(f"the tracker computed no features at frame {index} of {video}")
                return run.work.frame(frame), features, run.tracker.background, room, run.work
    raise VideoError(f"video {video} has only {count} frames; --frame {index} is past its end")


def run(args: argparse.Namespace) -> int:
    """Computes the features of the frame and writes the sheet."""
    if args.frame < 0:
        raise OptionError(f"--frame must be >= 0, got {args.frame}")
    if args.as_tracked and args.poses:
        raise OptionError("--as-tracked uses the tracker's own prediction: leave out --poses")
    tracking = [
        f"--{n.replace('_', '-')}" for n in ("focal", "seed", "config", "bg_model") if getattr(args, n) is not None
    ]
    if tracking and not args.as_tracked:
        raise OptionError(f"{', '.join(tracking)} set how --as-tracked tracks: give --as-tracked too")
    if args.as_tracked:
        tracker = tracker_config(args)
        seen_by = tracker.features or FeatureConfig()
        if args.skin is not None:
            seen_by = seen_by.replace(skin_space=args.skin)
            tracker = dataclasses.replace(tracker, features=seen_by)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", CleanPlateWarning)
            frame, features, background, room, work = tracked_features(
                args.video, args.frame, args.background, tracker, args.focal
            )
        for w in caught:
            print(f"upperpose features: warning: {w.message}")
        title = f"{Path(args.video).name}  frame {args.frame}  as tracked  skin rule: {seen_by.skin_space}"
        if work.reduced:
            title += f"  (tracked at {work.work[0]}x{work.work[1]})"
        path = write_image(args.output, contact_sheet(frame, features, background, title, room))
        print(f"wrote {path}")
        return 0
    config = FeatureConfig() if args.skin is None else FeatureConfig(skin_space=args.skin)
    previous, frame = read_frames(args.video, args.frame)
    # The features the tracker sees: a large video's at its working size.
    work = WorkSize.of(frame.shape[1], frame.shape[0], TrackerConfig().work_pixels)
    previous, frame = (None if previous is None else work.frame(previous)), work.frame(frame)
    if args.background:
        plate = cv2.imread(args.background, cv2.IMREAD_COLOR)
        if plate is None:
            raise VideoError(f"cannot read background image {args.background}")
        background = Background.from_plate(work.frame(cast(npt.NDArray[np.uint8], plate)), config)
    else:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", CleanPlateWarning)
            background = background_from_video(args.video, config, size=work.work if work.reduced else None)
        for w in caught:
            print(f"upperpose features: warning: {w.message}")
    joints = predicted_joints(args.poses, args.frame) if args.poses else None
    extract = FeatureExtractor(background, config)
    if previous is not None:
        extract.prime(previous)
    features = extract(frame, None if joints is None else work.to_work(joints))
    title = f"{Path(args.video).name}  frame {args.frame}  skin rule: {config.skin_space}"
    if work.reduced:
        title += f"  (tracked at {work.work[0]}x{work.work[1]})"
    path = write_image(args.output, contact_sheet(frame, features, background, title))
    print(f"wrote {path}")
    return 0
