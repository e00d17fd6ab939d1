"""Finding the person while nobody is tracked, and the fit that tracking starts from.

The flow of start-up (thesis §3.3, Fig. 3.6-1): per frame a frontal face is sought and, while
it holds still, the A-pose check runs (`startup.py`); the check passing `confirm_frames` in a
row measures the body from the A-pose, a stable face that fails it is fitted from any pose
(`acquire.py`), and a face alone starts tracking after `face_only_frames`. A start-up fit must
explain the frame (the silhouette and a skin blob at each hand) to start from any pose.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from upperpose.features import FeatureConfig, FeatureExtractor, FrameFeatures
from upperpose.features.faces import SteadyFace, box_share
from upperpose.fit.acquire import agreement, global_fit, restart_seed
from upperpose.fit.fitter import PARTS, FitLike, Fitter, FrameSearch
from upperpose.fit.recovery import ARMS, HAND_JOINT
from upperpose.fit.root import RootEstimator
from upperpose.fit.search import SearchConfig, reseeded
from upperpose.fit.startup import (
    FaceBox,
    StartupFit,
    any_pose_points,
    check_apose,
    choose_face,
    face_centre,
    fit_bodies,
    hand_candidates,
    hand_point,
    head_raised,
    measure_body,
    startup_points,
    widened,
)
from upperpose.fit.state import StateMachine
from upperpose.fit.tracker_config import TrackerConfig
from upperpose.model import BodyModel, Camera, Pose, model_points, project

log = logging.getLogger(__name__)
FloatArray = npt.NDArray[np.float64]
# The model's part labels of a pose, root and body at the frame's size (the tracker renders them).
RenderLabels = Callable[[FloatArray, FloatArray, BodyModel], npt.NDArray[np.uint8]]


def torso_cost(fit: FitLike) -> float:
    """The cost of a fit's torso stage (torso, neck and head)."""
    return float(fit.stage_costs["torso"])


@dataclass(frozen=True)
class Sighting:
    """One frame's look for the person: the face, whether it held still, the A-pose check."""

    face: FaceBox | None
    stable: bool
    passed: bool
    points: FloatArray  # head, right and left hand points of the A-pose check (NaN: none)


@dataclass(frozen=True)
class Start:
    """The start-up fit tracking begins from, and what it was fitted to."""

    features: FrameFeatures  # any-pose points when it was fitted from any pose
    face: FaceBox
    chosen: StartupFit
    pose: FloatArray  # last frame's pose for the first prediction


@dataclass(frozen=True)
class Attempt:
    """What start-up did with a frame: the start (None: not yet) and whether it searched."""

    start: Start | None
    searched: bool


def starting_root(camera: Camera, start: Start) -> RootEstimator:
    """The root estimator of a new person: the start-up fit's root and the head's skin blob.

    The blob's size and its offset from the face centre count only when the blob holds the
    face's centre and is at most 1.6 face widths wide.
    """
    face, features = start.face, start.features
    centre = face_centre(face)
    head_blob_width, head_blob_height, bias = None, None, np.zeros(2)
    head = features.head
    if head is not None and not head.merged:
        blob = features.blobs[head.blob]
        if blob.distance_to(centre) == 0.0 and blob.bbox[2] <= 1.6 * face[2]:
            head_blob_width, head_blob_height = float(blob.bbox[2]), float(blob.bbox[3])
            bias = np.asarray(head.xy) - centre
    body, root = start.chosen.body, start.chosen.root
    return RootEstimator(camera, body, root, head_blob_width, head_blob_height, bias, head_size_px=float(face[2]))


class PersonFinder:
    """Looks for the person frame by frame and fits the frame tracking starts on.

    Args:
        camera: the camera.
        config: the tracker's settings.
        state: the tracker's status, moved on by the start-up check.
        fitter: the search.
        search_config: the search settings every fit uses.
        base_body: the dimensions the measurement starts from.
        fps: frame rate (the start-up search's trajectory windows).
        render_labels: the model's part labels at the frame's size.
    """

    def __init__(
        self,
        camera: Camera,
        config: TrackerConfig,
        state: StateMachine,
        fitter: Fitter,
        search_config: SearchConfig,
        base_body: BodyModel,
        fps: float,
        render_labels: RenderLabels,
    ) -> None:
        self.camera = camera
        self.config = config
        self.state = state
        self._fitter = fitter
        self._search_config = search_config
        self._base_body = base_body
        self._fps = fps
        self._render_labels = render_labels
        self.reset()

    def reset(self) -> None:
        """Forgets the face seen so far (a new person)."""
        self._face_streak = 0
        self._face_widths: list[float] = []
        self._last_face: FaceBox | None = None
        self._steady = SteadyFace(self.config.steady_face_frames) if self.config.steady_face_frames > 0 else None

    def see(
        self, frame: npt.NDArray[np.uint8], features: FrameFeatures, faces: list[FaceBox], extractor: FeatureExtractor
    ) -> Sighting:
        """Chooses the person's face, learns its skin colour and runs the A-pose check."""
        face = choose_face(faces, features.skin)
        steady = None
        if self._steady is not None:
            # Only boxes on the person: a face-like picture in the room is steady too.
            steady = self._steady.update([box for box in faces if box_share(box, features.sil) >= 0.5])
        # A face too cool or dim for the skin rule, found in one place frame after frame, is
        # the person's too; its own colour then says what skin is.
        whole_face = face is None and steady is not None
        face = steady if whole_face else face
        # The person's own skin colour, from each face until tracking starts: start-up then
        # measures the same skin blobs the tracking will see.
        if face is None:
            extractor.forget_skin()
        else:
            extractor.learn_skin(frame, face, whole_face=whole_face)
        passed = stable = False
        points = np.full((3, 2), np.nan)
        if face is not None:
            stable = (
                self._last_face is not None
                and np.hypot(*(face_centre(face) - face_centre(self._last_face))) < 0.5 * face[2]
            )
            self._face_streak = self._face_streak + 1 if stable or self._last_face is None else 1
            self._face_widths = ([*self._face_widths, float(face[2])] if stable else [float(face[2])])[-10:]
            points = startup_points(face, features.blobs, extractor.config)
            # Not while the face moves half its width a frame: a person walking in is measured
            # mid-stride.
            passed = stable and check_apose(points, face[2]).passed
        else:
            self._face_streak = 0
        self._last_face = face
        return Sighting(face, stable, passed, points)

    def attempt(
        self,
        features: FrameFeatures,
        seen: Sighting,
        feature_config: FeatureConfig,
        index: int,
        face_only_frames: int,
    ) -> Attempt:
        """Moves the status on by the sighting and, when tracking may start, fits the frame.

        `face_only_frames`: frames of a stable face after which start-up goes ahead anyway.
        """
        cfg = self.config
        face = seen.face
        if self.state.startup(face is not None, seen.passed) and face is not None:
            pose = Pose.a_pose().angles
            chosen = self._measure(features, face, seen.points, pose, index)
            wide = any_pose_points(features, face, feature_config)
            if cfg.any_pose_frames > 0 and not self._explains(wide, face, chosen, index, "A-pose", feature_config):
                # The check passes on other poses too (a hand raised beside the head is still
                # "below" it): a fit from any pose that explains the frame, and costs less in the
                # same image regions, is taken instead.
                other = self._acquire(wide, face, index)
                if self._explains(wide, face, other, index, "any-pose", feature_config) and self._rescored(
                    wide, other, index
                ) < self._rescored(wide, chosen, index):
                    features, chosen, pose = wide, other, np.asarray(other.fit.pose, dtype=np.float64)
            return Attempt(Start(features, face, chosen, pose), searched=True)
        if face is not None and seen.stable and not seen.passed and 0 < cfg.any_pose_frames <= self._face_streak:
            # Not in the A-pose: fit any pose; start when the fit explains the silhouette, or
            # anyway once the face has been stable for `face_only_frames`.
            features = any_pose_points(features, face, feature_config)
            chosen = self._acquire(features, face, index)
            if not (
                self._explains(features, face, chosen, index, "any-pose", feature_config)
                or self._face_streak >= face_only_frames
            ):
                return Attempt(None, searched=True)
            self.state.start()
            start = Start(features, face, chosen, np.asarray(chosen.fit.pose, dtype=np.float64))
            return Attempt(start, searched=True)
        if face is not None and seen.stable and not seen.passed and self._face_streak >= face_only_frames:
            # Any-pose fits off: the face-only start-up, from the A-pose with average arms.
            self.state.start()
            chosen = self._measure(features, face, np.full((3, 2), np.nan), Pose.a_pose().angles, index)
            return Attempt(Start(features, face, chosen, Pose.a_pose().angles), searched=True)
        return Attempt(None, searched=False)

    def _explains(
        self,
        features: FrameFeatures,
        face: FaceBox,
        chosen: StartupFit,
        index: int,
        what: str,
        feature_config: FeatureConfig,
    ) -> bool:
        """Whether a start-up fit explains the frame: the silhouette, and a skin blob at each hand.

        The silhouette hardly tells a straight raised arm from a bent one; the hands do: each
        fitted hand must lie near the `hand_point` (far end) of some blob that may be a hand
        (`hand_candidates`). Not only the skin points' blobs: the largest blob on a side, which
        they take, is sometimes a bare forearm apart from its hand (v03). Without any such
        blob there is no evidence either way.
        """
        cfg = self.config
        pose, root = np.asarray(chosen.fit.pose, dtype=np.float64), np.asarray(chosen.fit.root, dtype=np.float64)
        share = agreement(features.sil, self._render_labels(pose, root, chosen.body))
        joints = project(self.camera, model_points(pose, root, chosen.body))
        limit = cfg.acquire_hand_share * max(float(np.hypot(*(joints[1] - joints[2]))), 10.0)
        candidates = hand_candidates(face, features.blobs, below=False)
        points = [hand_point(face, features.blobs[i], feature_config) for i in candidates]
        far = [
            arm
            for arm in ARMS
            if points and min(float(np.hypot(*(joints[HAND_JOINT[arm]] - p))) for p in points) > limit
        ]
        log.debug(
            "frame %d: %s fit, %.2f of it on the silhouette, %.2f of the silhouette explained, hands far: %s",
            index,
            what,
            share.on_silhouette,
            share.explained,
            far,
        )
        return share.passes(cfg.acquire_on_silhouette, cfg.acquire_explained) and not far

    def _rescored(self, features: FrameFeatures, chosen: StartupFit, index: int) -> float:
        """A start-up fit's cost in the full-range search's regions (comparable between fits)."""
        search = FrameSearch(self._fitter, chosen.body, self.camera, self._search_config, index, 1.0 / self._fps)
        return search.fair_cost(features, np.asarray(chosen.fit.pose), np.asarray(chosen.fit.root))

    def _startup_fit_args(self, index: int) -> dict[str, Any]:
        angle_scales = np.ones(13)
        if self.config.startup_frontal:
            angle_scales[0] = 0.0
        return dict(
            mode="trajectory",
            window_scale=self.config.startup_window_scale,
            frame_interval=1.0 / self._fps,
            search=PARTS,
            frame_index=index,
            config=self._search_config,
            angle_window_scales=angle_scales,
        )

    def _placer(self, face: FaceBox, points: FloatArray) -> Callable[[BodyModel], tuple[BodyModel, FloatArray]]:
        face_width = float(np.median(self._face_widths)) if self._face_widths else None

        def placed(candidate: BodyModel) -> tuple[BodyModel, FloatArray]:
            # The arm lengths are measured from the candidate's shoulders, the head put on the face.
            return measure_body(self.camera, face, points, candidate, face_width_px=face_width)

        return placed

    def _measure(
        self, features: FrameFeatures, face: FaceBox, points: FloatArray, pose: FloatArray, index: int
    ) -> StartupFit:
        """Chooses the body's width, then the head's height, by fitting the frame around `pose`."""
        cfg = self.config
        placed = self._placer(face, points)
        # Searched around `pose` with wide windows rather than over the whole anatomical ranges:
        # in the A-pose, a turned torso with an arm along it fits a frontal silhouette almost as
        # well.
        fit_args = self._startup_fit_args(index)
        widths = [widened(self._base_body, k) for k in cfg.startup_width_scales or (1.0,)]
        chosen = fit_bodies(self._fitter, features, pose, widths, self.camera, placed, **fit_args)
        # Then the head's height above the shoulders, at the chosen width: the face box's depth
        # is about 10 % off and heads sit differently on necks, which leaves the shoulders off
        # their silhouette in y. Judged by the torso's stage alone: the arms' costs, with their
        # lengths re-measured from each candidate's shoulders, drown the shoulders' difference.
        heights = [head_raised(chosen.candidate, k) for k in cfg.startup_head_scales]
        return fit_bodies(self._fitter, features, pose, heights, self.camera, placed, chosen, torso_cost, **fit_args)

    def _acquire(self, features: FrameFeatures, face: FaceBox, index: int) -> StartupFit:
        """The person's pose from any starting pose, then their width and head height around it.

        `features` should hold `any_pose_points` (the head on the face, hands at any height).
        """
        cfg = self.config
        points = np.full((3, 2), np.nan)  # the hands' distances measure arm lengths only in the A-pose
        body, root = self._placer(face, points)(self._base_body)
        trajectory = self._startup_fit_args(index)

        def one(pose: FloatArray, at: FloatArray, mode: str, parts: tuple[str, ...], restart: int) -> FitLike:
            args = dict(trajectory, search=parts)
            if mode != "trajectory":
                args.update(mode=mode, window_scale=1.0)
            if restart:
                args["config"] = reseeded(self._search_config, restart_seed(self._search_config.seed, restart))
            return self._fitter(features, pose, np.ascontiguousarray(at, dtype=np.float64), body, self.camera, **args)

        best = global_fit(one, [Pose.a_pose().angles], root, cfg.acquire_restarts)
        return self._measure(features, face, points, np.asarray(best.pose, dtype=np.float64), index)


__all__ = ["Attempt", "PersonFinder", "Sighting", "Start", "starting_root", "torso_cost"]
