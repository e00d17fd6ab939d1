"""Tracking one video into its files: the pose file (SPEC 9), optionally a CSV, BVH and overlay.

Shared by `upperpose track` and `upperpose batch`. The other files are written before the pose
file, so a pose file on disk means its run finished writing everything it was asked for. After
Ctrl-C (or an error) the caller chooses: keep the frames so far (`track`: an interrupted live
session is still worth its poses) or write nothing (`batch`: a partial pose file must not look
like a finished video to a rerun, which redoes the video instead).
"""

from __future__ import annotations

import logging
import os
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from upperpose._upperpose import __version__
from upperpose.features import CleanPlateWarning
from upperpose.fit.pipeline import BackgroundLike, VideoTracking
from upperpose.fit.settings import config_to_dict
from upperpose.fit.smoothing import DEFAULT_LAG, DEFAULT_MAX_STEP, PoseSmoother
from upperpose.fit.tracker import TrackerConfig
from upperpose.io.bvh import write_bvh
from upperpose.io.files import interrupts_held
from upperpose.io.looks import VideoLooks
from upperpose.io.output import PoseRecorder
from upperpose.io.overlay import OverlayWriter, draw_overlay
from upperpose.io.video import Frame
from upperpose.model import BodyModel
from upperpose.result import LOST, NO_PERSON, TRACKED, TrackResult

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class OutputPaths:
    """Where one video's outputs go: the pose file, and the optional CSV, BVH and overlay video."""

    poses: Path
    csv: Path | None = None
    bvh: Path | None = None
    overlay: Path | None = None

    def given(self) -> list[Path]:
        """The paths asked for, the pose file first."""
        return [p for p in (self.poses, self.csv, self.bvh, self.overlay) if p is not None]


@dataclass(frozen=True)
class Tracked:
    """How a tracked video went: frame counts by status, run time and the files written.

    `face_only_frames` is the stable-face frames after which start-up went ahead without its
    blob check (fewer while the background is learnt).
    """

    frames: int
    tracked: int
    lost: int
    no_person: int
    first_posed: int | None
    run_time_s: float
    clean_plate: bool
    face_only_frames: int
    written: tuple[Path, ...]
    interrupted: bool
    looks: str | None = None  # why the video may defeat start-up (`upperpose.io.looks`), or None

    @property
    def posed(self) -> int:
        """Frames with a pose ("tracked" or "lost")."""
        return self.tracked + self.lost


def smoothing_record(smooth: bool) -> tuple[int, dict[str, object] | None]:
    """The smoother's lag and the pose file's description of it (None: not smoothed)."""
    if not smooth:
        return 0, None
    method = (
        "local quadratic, tricube weights, centred (one-sided at the ends of a run), in angle space; "
        "each part's window ends where its angles jump by more than max_step_rad"
    )
    return DEFAULT_LAG, {"method": method, "lag_frames": DEFAULT_LAG, "max_step_rad": DEFAULT_MAX_STEP}


def provenance(run_: VideoTracking, body: BodyModel | None = None) -> dict[str, object]:
    """Pose-file fields that say how the poses were made: version, camera and body (the tracker's when None)."""
    camera = run_.camera
    return {
        "upperpose_version": __version__,
        "camera": {"model": camera.kind, "focal": camera.focal, "cx": camera.cx, "cy": camera.cy},
        "body": dict((body or run_.tracker.body).as_dict()),
    }


class BodyHistory:
    """The body dimensions the posed frames were fitted with: the pose file's "bodies".

    One entry per change, from the first posed frame on: start-up measures the body, and a new
    start-up (after the person left, or was lost and found again from scratch) measures it again.
    """

    def __init__(self) -> None:
        self._entries: list[tuple[int, BodyModel]] = []

    def see(self, result: TrackResult, body: BodyModel) -> None:
        """Notes the body a frame's pose was fitted with."""
        if result.pose is None or (self._entries and self._entries[-1][1] is body):
            return
        if not self._entries or self._entries[-1][1].as_dict() != body.as_dict():
            self._entries.append((result.frame, body))

    def last(self) -> BodyModel | None:
        """The body of the last posed frame (None without one)."""
        return self._entries[-1][1] if self._entries else None

    def records(self) -> list[dict[str, Any]]:
        """`{"frame": first frame, "body": dimensions}` per body, in order."""
        return [{"frame": frame, "body": dict(body.as_dict())} for frame, body in self._entries]


def track_to_files(
    source: str | os.PathLike[str] | int,
    paths: OutputPaths,
    *,
    config: TrackerConfig,
    background: BackgroundLike = None,
    focal: float | None = None,
    smooth: bool = True,
    keep_partial: bool = False,
    on_frame: Callable[[int, int | None, str], None] | None = None,
    on_warning: Callable[[str], None] | None = None,
) -> Tracked:
    """Tracks `source` and writes its outputs, each whole or not at all.

    Args:
        source: a video file, stream URL or camera index.
        paths: the outputs to write.
        config: tracker settings (recorded in the pose file with the seed).
        background: the clean plate; see `VideoTracking`.
        focal: focal length in pixels (default: the image width).
        smooth: smooth the written poses (`upperpose.fit.smoothing`).
        keep_partial: after Ctrl-C or an error, still write the frames so far (else nothing).
        on_frame: called after each written frame with the frames done, the video's frame count
            (None when unknown: a live source) and the frame's status.
        on_warning: told when the background is estimated from the video (no clean plate) and
            when the video's frame rate is absurd.

    Returns:
        The counts; `interrupted` is True only when `keep_partial` kept an interrupted run.

    Raises:
        KeyboardInterrupt: Ctrl-C (or SIGTERM) and not `keep_partial`; nothing was written.
        VideoError, ValueError, OSError: see `VideoTracking`, or an output cannot be written.
    """
    lag, smoothing = smoothing_record(smooth)
    started = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CleanPlateWarning)
        run_ = VideoTracking(source, background, focal=focal, config=config)
    notes = [str(w.message) for w in caught[:1]] + ([run_.reader.fps_warning] if run_.reader.fps_warning else [])
    if on_warning is not None:
        for note in notes:
            on_warning(note)
    size = (run_.reader.width, run_.reader.height)
    try:  # an overlay that cannot be opened (an unknown extension) ends the run before any record
        overlay = OverlayWriter(paths.overlay, *size, run_.fps) if paths.overlay is not None else None
    except BaseException:
        run_.close()
        raise
    name = f"camera {source}" if isinstance(source, int) else Path(source).name
    recorder = PoseRecorder(
        run_.reader.width,
        run_.reader.height,
        run_.fps,
        source=name,
        seed=run_.tracker.search_config.seed,
        clean_plate=run_.clean_plate,
        settings=config_to_dict(config),
        smoothing=smoothing,
    )
    # Each frame leaves the smoother `lag` frames late, with the body it was fitted with: by then
    # the tracker's may be another person's, or the averages after the person left.
    smoother: PoseSmoother[tuple[Frame | None, BodyModel]] = PoseSmoother(run_.camera, lag)
    log.debug(
        "%s: %dx%d at %.3g fps, %s frames, clean plate: %s",
        name,
        *size,
        run_.fps,
        run_.reader.frame_count or "unknown",
        "yes" if run_.clean_plate else "no (estimated from the video)",
    )
    lost: set[str] = set()
    looks = VideoLooks()
    bodies = BodyHistory()

    def take(result: TrackResult, shown: tuple[Frame | None, BodyModel]) -> None:
        frame, body = shown
        posed_before = recorder.first_posed is not None
        recorder.add(result)
        # The events a user asks about after a run (-v): when start-up ended, when an arm went and came back.
        if not posed_before and recorder.first_posed is not None:
            log.info("start-up found the person: tracking from frame %d", result.frame)
        now = set(result.lost_parts)
        for arm in sorted(now - lost):
            log.info("frame %d: lost the %s; searching for it over its full range", result.frame, arm.replace("_", " "))
        for arm in sorted(lost - now):
            log.info("frame %d: recovered the %s", result.frame, arm.replace("_", " "))
        lost.clear()
        lost.update(now)
        if overlay is not None and frame is not None:
            overlay.write(draw_overlay(frame, result, run_.camera, body))
        if on_frame is not None:
            on_frame(recorder.frames, run_.reader.frame_count, result.status)

    finished = interrupted = False
    written: list[Path] = []
    run_time = 0.0
    try:
        for frame, result in run_.frames():
            looks.see(result.frame, frame)
            body = run_.tracker.body
            bodies.see(result, body)
            for done, shown in smoother.push(result, body, (frame if overlay is not None else None, body)):
                take(done, shown)
        finished = True
    except KeyboardInterrupt:
        if not keep_partial:
            raise
        interrupted = True
    finally:
        # A second Ctrl-C or a SIGTERM while the outputs are written waits until they are whole.
        with interrupts_held():
            run_.close()
            if finished or keep_partial:
                for done, shown in smoother.flush():
                    take(done, shown)
                run_time = time.perf_counter() - started
                written = _write(recorder, overlay, paths, run_, run_time, bodies)
                log.info(
                    "%s: %d frames in %.1f s; wrote %s", name, recorder.frames, run_time, ", ".join(map(str, written))
                )
            elif overlay is not None:
                overlay.close(keep=False)
            recorder.close()
    return Tracked(
        frames=recorder.frames,
        tracked=recorder.count(TRACKED),
        lost=recorder.count(LOST),
        no_person=recorder.count(NO_PERSON),
        first_posed=recorder.first_posed,
        run_time_s=run_time,
        clean_plate=run_.clean_plate,
        face_only_frames=run_.tracker.face_only_frames,
        written=tuple(written),
        interrupted=interrupted,
        looks=looks.hint(),
    )


def _write(
    recorder: PoseRecorder,
    overlay: OverlayWriter | None,
    paths: OutputPaths,
    run_: VideoTracking,
    run_time: float,
    bodies: BodyHistory,
) -> list[Path]:
    """Writes the outputs, the pose file last; returns them, the pose file first.

    The pose file's `body` and the BVH's skeleton are the last posed frame's body (the tracker's
    returns to the averages when the person leaves); frames fitted with an earlier one
    (`bodies`) replay in the BVH with its dimensions.
    """
    body = bodies.last() or run_.tracker.body
    others: list[Path] = []
    if paths.csv is not None:
        others.append(recorder.write_csv(paths.csv))
    if paths.bvh is not None and recorder.first_posed is not None:
        others.append(write_bvh(paths.bvh, recorder.records(), body, run_.fps))
    if overlay is not None:
        kept = overlay.close()
        if kept:
            others.append(kept)
    recorder.extra.update(provenance(run_, body))
    recorder.extra["bodies"] = bodies.records()
    return [recorder.write_json(paths.poses, run_time), *others]


__all__ = ["BodyHistory", "OutputPaths", "Tracked", "provenance", "smoothing_record", "track_to_files"]
