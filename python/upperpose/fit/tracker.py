"""`Tracker`: video frames in, 3D upper-body poses out, one `update(frame)` at a time.

The loop of the thesis' flowchart (Fig. 3.6-1): while nobody is tracked, look for a frontal face
and the A-pose (start-up, §3.3), or fit any pose around the face (`fit/acquire.py`); then per
frame predict the pose (constant velocity), extract the features around the prediction,
estimate the root, search the moving parts (motion flags, §3.4.3) inside trajectory windows,
and check for lost hands (§3.4.9), which are searched over their anatomical ranges until
found. See docs/tracker.md.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol, cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose._upperpose import joint_limits
from upperpose.exceptions import InputError
from upperpose.features import Background, FeatureConfig, FeatureExtractor, FrameFeatures, skin_mask
from upperpose.features.checks import check_frame
from upperpose.features.online import OnlineBackground, body_region
from upperpose.fit.acquire import agreement, global_fit, restart_seed
from upperpose.fit.confidence import JointConfidence
from upperpose.fit.reach import ArmReach, hand_target, unexplained
from upperpose.fit.recovery import (
    ARMS,
    HAND_JOINT,
    HAND_POINT,
    DoubtDetector,
    HandFollower,
    LostDetector,
    hand_distances,
    unexplained_by_side,
)
from upperpose.fit.root import RootEstimator
from upperpose.fit.search import Limits, Mode, Optimizer, SearchConfig, fit_frame, reseeded
from upperpose.fit.startup import (
    FaceBox,
    FaceDetector,
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
    pixels_per_metre,
    startup_points,
    widened,
)
from upperpose.fit.state import StateMachine
from upperpose.fit.visibility import visibility
from upperpose.model import (
    BodyModel,
    Camera,
    Pose,
    check_camera_fits,
    forward_kinematics,
    model_points,
    project,
    render_masks,
)
from upperpose.result import NO_PERSON, TrackResult

log = logging.getLogger(__name__)
FloatArray = npt.NDArray[np.float64]
PARTS = ("torso", "right_arm", "left_arm")
# Without a plate, the body around a detected face is not learnt for this many frames after the
# face was last detected: the cascade misses a face now and then, and a pixel never seen would be
# learnt at once (half a second at 30 fps).
FACE_HOLD_FRAMES = 15
# Angle indices per searched part (ANGLE_NAMES order).
PART_ANGLES = {"torso": slice(0, 3), "right_arm": slice(3, 8), "left_arm": slice(8, 13)}


class FitLike(Protocol):
    """What a fitter returns (`upperpose.FrameFit` or a test double)."""

    @property
    def pose(self) -> Any: ...
    @property
    def root(self) -> Any: ...
    @property
    def joints_3d(self) -> Any: ...
    @property
    def joints_2d(self) -> Any: ...
    @property
    def cost(self) -> float: ...
    @property
    def stage_costs(self) -> dict[str, float]: ...


Fitter = Callable[..., FitLike]


@dataclass(frozen=True)
class StaticFit:
    """A fit made without searching (nothing moved, or a test double)."""

    pose: FloatArray
    root: FloatArray
    joints_3d: FloatArray
    joints_2d: FloatArray
    cost: float
    stage_costs: dict[str, float] = field(default_factory=dict)
    terms: dict[str, Any] = field(default_factory=dict)
    evaluations: int = 0


@dataclass(frozen=True)
class TrackerConfig:
    """Settings of the tracker (the search's own settings go to `upperpose.SearchConfig`).

    Attributes:
        particles, iterations, threads, seed, limits, optimizer, sigma: passed to `SearchConfig`
            when `search` is None (None keeps the search's default). `optimizer` is "apso" (ours),
            "pso", "simplex" or "apsopf" (the thesis' baselines, docs/baselines.md); `sigma` is
            APSOPF's Gaussian redistribution.
        root_window: half-width in metres of the torso stage's search over the root's X and Y
            around the estimate of `RootEstimator` (also used after start-up and losses).
        search: a ready `upperpose.SearchConfig`; overrides the fields above.
        search_options: keyword arguments of `upperpose.SearchConfig` that override the fields
            above (for example `{"weights": {"edge": 1.0}, "seed": 3}`), when `search` is None.
        features: feature thresholds; the background's when None.
        skip_static: search only the parts whose motion flag is set (§3.4.3); False searches
            every part every frame.
        confirm_frames: frames in a row the start-up check must pass.
        face_only_frames: after this many frames in a row with a stable face but no start
            (neither the A-pose check nor a fit that explains the silhouette), start anyway
            with the best fit from any pose.
        face_only_frames_learnt: `face_only_frames` while the background is learnt (no clean
            plate): until the first fit the room behind the person is a guess (inpainted), and
            skin-coloured room there joins the hands' blobs, so the checks rarely pass.
        any_pose_frames: from this many frames in a row with a stable face on, a frame that
            fails the A-pose check is fitted from any pose (`upperpose.fit.acquire`); 0 turns
            this off (the A-pose check, or `face_only_frames`, then starts tracking).
        acquire_restarts: full-range searches of the arms per any-pose fit.
        acquire_on_silhouette, acquire_explained, acquire_hand_share: a start-up fit explains
            the frame when at least `acquire_on_silhouette` of its projection lies on the
            silhouette, `acquire_explained` of the silhouette (above the projection's lowest
            row) lies near the projection, and neither hand lies farther than
            `acquire_hand_share` shoulder widths from its skin point. An any-pose fit starts
            tracking only then; an A-pose fit that does not is replaced by an any-pose fit
            that does.
        leave_frames: frames in a row without the person before going back to "no_person".
        presence_share: the person is present while at least this share of the model's last
            projection is covered by the silhouette, or the head's skin blob lies within a
            shoulder width of the model's head.
        lost_threshold, lost_frames: lost detection (SPEC 5: one shoulder width, several frames).
        unexplained_share: an arm also counts a miss when the silhouette on its side that the
            model leaves unexplained exceeds its level of the first ten tracked frames (the
            person's shape is not the model's) by this share of one arm's projected area.
        velocity_damping: share of last frame's velocity kept in the prediction.
        recovery_window_scale: trajectory windows are widened by this factor on the frame after
            a recovery.
        startup_window_scale: the first frame is searched around the A-pose with trajectory
            windows widened by this factor.
        startup_width_scales: the torso and shoulder widths tried at start-up, as factors of
            the adult averages; the fit with the lowest cost is kept (a model of the wrong
            width fits best turned, and then stays turned). Empty: the averages.
        startup_head_scales: then the head's height above the shoulders, as factors of the
            averages besides 1 (the width's fit), at the chosen width; the fit whose torso
            stage costs least is kept (the face box's depth is about 10 % off, which leaves
            the shoulders too high or low); only +-5 %: further out, the cost chose wrongly
            on bodies other than the model's own. Empty: the averages.
        startup_frontal: fit the start-up frame with the torso's turn held at zero. Off by
            default: the turn's own window (+-0.05 rad x 3) is already narrow, and holding it
            costs more frames than it saves (docs/tracker.md).
        velocity_window_gain: an arm's trajectory windows are widened by 1 + gain x its last
            frame-to-frame change (largest angle change, in units of 0.15 rad at 30 fps), so
            that a fast wave does not outrun them.
        fair_recovery: a lost arm's full-range fit replaces the trajectory fit only when it
            costs less in the same image regions (a stage's cost depends on its region: the
            Sil term counts every mismatch inside it, and the full-range regions are larger).
        doubt_share, doubt_frames: an arm whose fitted hand has been farther than `doubt_share`
            shoulder widths from its skin evidence for `doubt_frames` frames in a row (short of
            lost) is searched once over its anatomical ranges, like a lost arm; that fit is
            taken when it costs less and its hand lies nearer the skin point. `doubt_frames` 0
            turns this off.
        reach_share, reach_candidates: an arm whose fitted hand lies farther than `reach_share`
            shoulder widths from its hand's skin point (or, with no blob matched, from the
            nearest skin blob no part holds) is also sought from there: up to
            `reach_candidates` arm poses that put the hand on that point (`fit.reach`) are
            scored, and the best is searched in widened windows; the result is taken when it
            costs less and its hand lies nearer the point. `reach_candidates` 0 turns this off.
        untangle_hands: when both hands hold skin blobs of their own and the fitted hands lie
            crossed in the image, the other labelling of the two blobs is also tried (both arms
            sought from the swapped points as above); the lower cost wins. Needs the reach.
    """

    particles: int | None = None
    iterations: int | None = None
    threads: int | None = None
    seed: int = 0
    limits: Limits = "anatomical"
    optimizer: Optimizer = "apso"
    sigma: float | None = None
    root_window: float = 0.04
    search: SearchConfig | None = None
    features: FeatureConfig | None = None
    skip_static: bool = True
    confirm_frames: int = 3
    face_only_frames: int = 15
    face_only_frames_learnt: int = 3
    any_pose_frames: int = 2
    acquire_restarts: int = 4
    acquire_on_silhouette: float = 0.85
    acquire_explained: float = 0.85
    acquire_hand_share: float = 0.5
    leave_frames: int = 8
    presence_share: float = 0.3
    lost_threshold: float = 1.0
    lost_frames: int = 5
    unexplained_share: float = 0.6
    velocity_damping: float = 0.7
    recovery_window_scale: float = 2.0
    startup_window_scale: float = 3.0
    startup_width_scales: tuple[float, ...] = (0.75, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2)
    startup_head_scales: tuple[float, ...] = (0.95, 1.05)
    startup_frontal: bool = False
    velocity_window_gain: float = 0.5
    fair_recovery: bool = True
    doubt_share: float = 0.25
    doubt_frames: int = 3
    reach_share: float = 0.5
    reach_candidates: int = 6
    untangle_hands: bool = True
    search_options: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        def whole(name: str, low: int, value: object) -> None:
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise InputError(f"{name} must be an integer >= {low}, got {value!r}")

        def real(name: str, value: object, low: float, high: float = math.inf, open_low: bool = False) -> None:
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            if not ok or not (value > low if open_low else value >= low) or value > high:  # type: ignore[operator]
                bound = (f"> {low:g}" if open_low else f">= {low:g}") + (
                    "" if high == math.inf else f" and <= {high:g}"
                )
                raise InputError(f"{name} must be a finite number {bound}, got {value!r}")

        for name in ("particles", "iterations", "threads"):
            if getattr(self, name) is not None:
                whole(name, 1, getattr(self, name))
        whole("seed", 0, self.seed)
        if self.seed >= 2**64:
            raise InputError(f"seed must be below 2**64, got {self.seed}")
        whole("confirm_frames", 1, self.confirm_frames)
        for name in (
            "face_only_frames",
            "face_only_frames_learnt",
            "leave_frames",
            "lost_frames",
            "doubt_frames",
            "reach_candidates",
            "any_pose_frames",
        ):
            whole(name, 0, getattr(self, name))
        whole("acquire_restarts", 0, self.acquire_restarts)
        for name in ("presence_share", "velocity_damping", "acquire_on_silhouette", "acquire_explained"):
            real(name, getattr(self, name), 0.0, 1.0)
        for name in ("root_window", "unexplained_share", "doubt_share", "velocity_window_gain", "acquire_hand_share"):
            real(name, getattr(self, name), 0.0)
        for name in ("lost_threshold", "recovery_window_scale", "startup_window_scale", "reach_share"):
            real(name, getattr(self, name), 0.0, open_low=True)
        if self.sigma is not None:
            real("sigma", self.sigma, 0.0, open_low=True)
        for name in ("startup_width_scales", "startup_head_scales"):
            for k, v in enumerate(getattr(self, name)):
                real(f"{name}[{k}]", v, 0.0, open_low=True)
        self.search_config()  # the search's own ranges (at most 10,000 particles, ...) live in the core

    def search_config(self) -> SearchConfig:
        """The `upperpose.SearchConfig` to use."""
        if self.search is not None:
            return self.search
        given = {
            "particles": self.particles,
            "iterations": self.iterations,
            "threads": self.threads,
            "sigma": self.sigma,
        }
        kwargs = {
            "seed": self.seed,
            "limits": self.limits,
            "optimizer": self.optimizer,
            "root_window": self.root_window,
            "initial_root_window": self.root_window,
            **{k: v for k, v in given.items() if v is not None},
        }
        return SearchConfig(**{**kwargs, **self.search_options})


def torso_cost(fit: FitLike) -> float:
    """The cost of a fit's torso stage (torso, neck and head)."""
    return float(fit.stage_costs["torso"])


def _nearer_hand_point(
    features: FrameFeatures, new: FitLike, old: FitLike, arm: str, camera: Camera, body: BodyModel
) -> bool:
    """Whether `new` puts the arm's hand nearer its matched (unmerged) skin point than `old`.

    The model's hand is the forearm cone's end (`model_points`), which the skin point measures.
    """
    point = features.points[HAND_POINT[arm]]
    if point is None or point.merged:
        return False
    xy = np.asarray(point.xy)
    joint = HAND_JOINT[arm]
    hands = [project(camera, model_points(f.pose, f.root, body))[joint] for f in (new, old)]
    gap = [float(np.hypot(*(xy - hand))) for hand in hands]
    return gap[0] < gap[1]


def _limit_hull(preset: Limits) -> tuple[FloatArray, FloatArray]:
    limits = joint_limits(preset)
    low = np.array([min(a for a, _ in intervals) for intervals in limits])
    high = np.array([max(b for _, b in intervals) for intervals in limits])
    return low, high


class Tracker:
    """Tracks one person's upper body frame by frame (a live camera or a file).

    Args:
        camera: the camera (`Camera.for_image(w, h, focal)`).
        background: a `Background`, or a clean plate `(H, W, 3)` uint8 BGR image; None learns
            the background from the frames while tracking (`features.online`; no clean plate).
        config: tracker settings.
        fps: frame rate, for the search's trajectory windows when `update` gets no timestamps.
        body: dimensions to start the start-up measurement from (adult averages when None).
        fitter: the search; `upperpose.fit_frame` when None (injectable for tests).
        face_detector: callable frame -> face boxes; OpenCV's Haar cascade when None.

    One Tracker per thread and per video.
    """

    # Per-person state, set by _reset_person() and _start().
    _body: BodyModel
    _pose: FloatArray
    _previous_pose: FloatArray
    _root: RootEstimator
    _last_root: FloatArray | None
    _labels: npt.NDArray[np.uint8] | None
    _last_joints: FloatArray | None
    _last_cost: float
    _last_points: FloatArray
    _followed: dict[str, FloatArray]
    _recovered: bool
    _loose_baseline: list[list[float]]
    _face_streak: int
    _face_widths: list[float]
    _last_face: FaceBox | None
    _reach: ArmReach | None

    def __init__(
        self,
        camera: Camera,
        background: Background | npt.NDArray[np.uint8] | None,
        config: TrackerConfig | None = None,
        *,
        fps: float = 30.0,
        body: BodyModel | None = None,
        fitter: Fitter | None = None,
        face_detector: Callable[[npt.NDArray[np.uint8]], list[FaceBox]] | None = None,
    ) -> None:
        self.camera = camera
        self.config = config or TrackerConfig()
        cfg = self.config
        # Without a background the first frame starts the online model and the features.
        self._online: OnlineBackground | None = None
        self._first_faces: list[FaceBox] | None = None
        self._features: FrameFeatures | None = None
        self._held_faces: tuple[list[FaceBox], int] = ([], 0)  # last detected faces, frames left
        self._extract: FeatureExtractor | None = None
        self.background: Background | None = None
        self.size = (0, 0)  # (height, width), known from the background or the first frame
        if background is not None:
            self._set_background(background)
        self.fps = float(fps) if fps and fps > 0 else 30.0
        self._fitter: Fitter = fitter or fit_frame
        self._search_config = cfg.search_config()
        self._detect_faces = face_detector or FaceDetector()
        self._base_body = body or BodyModel()
        self._low, self._high = _limit_hull(cfg.limits)
        self._half_camera = (
            Camera.perspective(camera.focal / 2, (camera.cx + 0.5) / 2 - 0.5, (camera.cy + 0.5) / 2 - 0.5)
            if camera.kind == "perspective"
            else None
        )
        self.state = StateMachine(confirm_frames=cfg.confirm_frames, leave_frames=cfg.leave_frames)
        self._lost = LostDetector(cfg.lost_threshold, cfg.lost_frames)
        self._doubt = DoubtDetector(cfg.doubt_share, cfg.doubt_frames)
        self._follow = HandFollower()
        self._confidence = JointConfidence()
        self._frame = 0
        self._last_time: float | None = None
        self._reset_person()

    # -- public state -------------------------------------------------------------------------

    @property
    def status(self) -> str:
        """The status of the last frame."""
        return self.state.status

    @property
    def body(self) -> BodyModel:
        """The person's measured body model (the start-up averages before start-up)."""
        return self._body

    @property
    def learns_background(self) -> bool:
        """Whether the background is learnt from the frames (no clean plate was given)."""
        return self._online is not None or self._extract is None

    @property
    def face_only_frames(self) -> int:
        """Frames of a stable face after which start-up goes ahead without the blob check."""
        cfg = self.config
        return cfg.face_only_frames_learnt if self.learns_background else cfg.face_only_frames

    def reset(self) -> None:
        """Forgets the person and the previous frame (after a cut or a seek)."""
        self.state.reset()
        if self._extract is not None:
            self._extract.reset()
        self._reset_person()

    def force_lost(self, arm: str) -> None:
        """Marks an arm lost, as if the lost detector had fired (for tests and experiments)."""
        if arm not in ARMS:
            raise InputError(f"arm must be one of {ARMS}, got {arm!r}")
        self._lost.force_lost(arm)
        if self._last_joints is not None:
            self._follow.start(arm, self._last_joints[HAND_JOINT[arm]], self._shoulder_px())

    # -- the frame loop -----------------------------------------------------------------------

    @property
    def search_config(self) -> SearchConfig:
        """The search settings every fit of this tracker uses (its seed is the one that counts)."""
        return self._search_config

    def update(self, frame: npt.NDArray[np.uint8], timestamp: float | None = None) -> TrackResult:
        """Tracks one frame.

        Args:
            frame: `(H, W, 3)` uint8 BGR, the background's size.
            timestamp: capture time in seconds (live cameras); frames are 1/fps apart when None.

        Returns:
            The result for this frame.

        Raises:
            ValueError: a frame of the wrong size or type.
        """
        index = self._frame
        self._frame += 1
        interval = 1.0 / self.fps
        if timestamp is not None:
            if self._last_time is not None and timestamp > self._last_time:
                interval = float(np.clip(timestamp - self._last_time, 1e-3, 1.0))
            self._last_time = timestamp
        if self._extract is None:
            self._start_background(frame)
        if self.state.has_person:
            result = self._track(frame, index, interval)
        else:
            result = self._look_for_person(frame, index)
        if self._online is not None:
            t0 = time.perf_counter()
            self._learn_background(frame)
            result.timings["background"] = time.perf_counter() - t0
        return result

    # -- the background without a clean plate -------------------------------------------------

    @property
    def _extractor(self) -> FeatureExtractor:
        if self._extract is None:
            raise RuntimeError("the features start with the first frame")
        return self._extract

    def _set_background(self, background: Background | npt.NDArray[np.uint8]) -> None:
        if not isinstance(background, Background):
            background = Background.from_plate(np.asarray(background), self.config.features or FeatureConfig())
        self.background = background
        self.size = background.size
        check_camera_fits(self.camera, self.size[1], self.size[0])
        self._extract = FeatureExtractor(background, self.config.features, reuse_buffers=True)

    def _start_background(self, frame: npt.NDArray[np.uint8]) -> None:
        """Starts the online background from the first frame, the body around its face left out."""
        config = self.config.features or FeatureConfig()
        frame = check_frame(frame, "frame")
        self._first_faces = self._detect_faces(frame)
        face = choose_face(self._first_faces, skin_mask(frame, config))
        self._online = OnlineBackground(frame, [face] if face is not None else [], config)
        self._set_background(self._online.background)

    def _learn_background(self, frame: npt.NDArray[np.uint8]) -> None:
        """Teaches the online background this frame away from the person.

        The person: the model's projection once tracked, else the body region around the faces
        detected in the last `FACE_HOLD_FRAMES` frames; skin and motion are held too where the
        model has seen the room.
        """
        online, features = cast(OnlineBackground, self._online), self._features
        faces, left = self._held_faces
        self._held_faces = (faces, left - 1) if left > 1 else ([], 0)
        if self._labels is not None:
            person = self._labels
        elif left > 0:
            person = body_region(self.size, faces, online.config)
        else:
            person = None
        busy: npt.NDArray[np.uint8] | None = None
        changed = None
        if features is not None:
            busy, changed = np.bitwise_or(features.skin, features.motion), features.sub
        if online.learn(frame, person, busy, changed):
            self._extractor.set_background(online.background)
            self.background = online.background

    # -- start-up -----------------------------------------------------------------------------

    def _look_for_person(self, frame: npt.NDArray[np.uint8], index: int) -> TrackResult:
        cfg = self.config
        t0 = time.perf_counter()
        features = self._features = self._extractor(frame)
        t1 = time.perf_counter()
        boxes = self._first_faces if self._first_faces is not None else self._detect_faces(frame)
        self._first_faces = None
        if boxes:
            self._held_faces = (boxes, FACE_HOLD_FRAMES)
        face = choose_face(boxes, features.skin)
        # The person's own skin colour, from each face until tracking starts: start-up then
        # measures the same skin blobs the tracking will see.
        if face is None:
            self._extractor.forget_skin()
        else:
            self._extractor.learn_skin(frame, face)
        passed = stable = False
        points = np.full((3, 2), np.nan)
        if face is not None:
            stable = (
                self._last_face is not None
                and np.hypot(*(face_centre(face) - face_centre(self._last_face))) < 0.5 * face[2]
            )
            self._face_streak = self._face_streak + 1 if stable or self._last_face is None else 1
            self._face_widths = ([*self._face_widths, float(face[2])] if stable else [float(face[2])])[-10:]
            points = startup_points(face, features.blobs, self._extractor.config)
            # Not while the face moves half its width a frame: a person walking in is measured
            # mid-stride.
            passed = stable and check_apose(points, face[2]).passed
        else:
            self._face_streak = 0
        self._last_face = face
        t2 = time.perf_counter()
        timings = {"features": t1 - t0, "startup": t2 - t1}
        if self.state.startup(face is not None, passed) and face is not None:
            pose = Pose.a_pose().angles
            chosen = self._measure(features, face, points, pose, index)
            wide = any_pose_points(features, face, self._extractor.config)
            if cfg.any_pose_frames > 0 and not self._explains(wide, face, chosen, index, "A-pose"):
                # The check passes on other poses too (a hand raised beside the head is still
                # "below" it): a fit from any pose that explains the frame, and costs less in the
                # same image regions, is taken instead.
                other = self._acquire(wide, face, index)
                if self._explains(wide, face, other, index, "any-pose") and self._rescored(
                    wide, other, index
                ) < self._rescored(wide, chosen, index):
                    features, chosen, pose = wide, other, np.asarray(other.fit.pose, dtype=np.float64)
            fit = self._begin(features, face, chosen, pose)
        elif face is not None and stable and not passed and 0 < cfg.any_pose_frames <= self._face_streak:
            # Not in the A-pose: fit any pose; start when the fit explains the silhouette, or
            # anyway once the face has been stable for `face_only_frames`.
            features = any_pose_points(features, face, self._extractor.config)
            chosen = self._acquire(features, face, index)
            if not (
                self._explains(features, face, chosen, index, "any-pose") or self._face_streak >= self.face_only_frames
            ):
                timings.update(search=time.perf_counter() - t2)
                return TrackResult(index, self.state.status, timings=timings)
            self.state.start()
            fit = self._begin(features, face, chosen, np.asarray(chosen.fit.pose, dtype=np.float64))
        elif face is not None and stable and not passed and self._face_streak >= self.face_only_frames:
            # Any-pose fits off: the face-only start-up, from the A-pose with average arms.
            self.state.start()
            chosen = self._measure(features, face, np.full((3, 2), np.nan), Pose.a_pose().angles, index)
            fit = self._begin(features, face, chosen, Pose.a_pose().angles)
        else:
            return TrackResult(index, self.state.status, timings=timings)
        t3 = time.perf_counter()
        timings.update(search=t3 - t2)
        result = self._accept(fit, features, index, PARTS, timings)
        timings["other"] = time.perf_counter() - t3
        return result

    def _explains(self, features: FrameFeatures, face: FaceBox, chosen: StartupFit, index: int, what: str) -> bool:
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
        points = [hand_point(face, features.blobs[i], self._extractor.config) for i in candidates]
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
        fit = chosen.fit
        pose, root = np.ascontiguousarray(fit.pose, dtype=np.float64), np.ascontiguousarray(fit.root, dtype=np.float64)
        args = dict(self._startup_fit_args(index), mode="initial", window_scale=1.0, search=())
        return float(self._fitter(features, pose, root, chosen.body, self.camera, **args).cost)

    def _startup_fit_args(self, index: int) -> dict[str, Any]:
        angle_scales = np.ones(13)
        if self.config.startup_frontal:
            angle_scales[0] = 0.0
        return dict(
            mode="trajectory",
            window_scale=self.config.startup_window_scale,
            frame_interval=1.0 / self.fps,
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

    def _begin(self, features: FrameFeatures, face: FaceBox, chosen: StartupFit, pose: FloatArray) -> FitLike:
        """Sets up the per-person state from the start-up fit; `pose` is last frame's pose."""
        body, root, fit = chosen.body, chosen.root, chosen.fit
        centre = face_centre(face)
        head_blob_width, bias = None, np.zeros(2)
        head = features.head
        if head is not None and not head.merged:
            blob = features.blobs[head.blob]
            if blob.distance_to(centre) == 0.0 and blob.bbox[2] <= 1.6 * face[2]:
                head_blob_width = float(blob.bbox[2])
                bias = np.asarray(head.xy) - centre
        self._body = body
        self._root = RootEstimator(self.camera, body, root, head_blob_width, bias, head_size_px=float(face[2]))
        self._pose = np.array(pose, dtype=np.float64)
        self._previous_pose = self._pose.copy()
        self._lost.reset()
        self._doubt.reset()
        self._corrected: tuple[str, ...] = ()
        self._follow.reset()
        self._reach = None
        self._confidence.reset()
        return cast(FitLike, fit)

    # -- tracking -----------------------------------------------------------------------------

    def _predict(self) -> FloatArray:
        velocity = self._pose - self._previous_pose
        return np.clip(self._pose + self.config.velocity_damping * velocity, self._low, self._high)

    def _shoulder_px(self) -> float:
        if self._last_joints is None:
            return 60.0
        return float(np.hypot(*(self._last_joints[1] - self._last_joints[2])))

    def _track(self, frame: npt.NDArray[np.uint8], index: int, interval: float) -> TrackResult:
        t0 = time.perf_counter()
        prediction = self._predict()
        predicted_joints = project(self.camera, model_points(prediction, self._root.root, self.body))
        for arm, xy in self._followed.items():
            predicted_joints[HAND_JOINT[arm]] = xy
        features = self._features = self._extractor(frame, predicted_joints, self._labels)
        root = self._root.update(features, prediction, self._last_root)
        t1 = time.perf_counter()

        lost = [arm for arm in ARMS if self._lost.lost[arm]]
        flags = features.motion_flags
        if self.config.skip_static and flags is not None:
            moving = [p for p in PARTS if flags[p].moving]
        else:
            moving = list(PARTS)
        # A part that does not move keeps last frame's pose, not an extrapolation.
        for part in PARTS:
            if part not in moving:
                prediction[PART_ANGLES[part]] = self._pose[PART_ANGLES[part]]
        # A lost arm is searched both ways: in its trajectory window and over its anatomical
        # ranges (§3.4.9); the lower cost wins, so a false alarm costs time, not accuracy.
        trajectory = tuple(p for p in PARTS if p in moving or p in lost)
        scale = self.config.recovery_window_scale if self._recovered else 1.0
        if trajectory:
            fit: FitLike = self._fit(
                features, prediction, root, "trajectory", trajectory, index, interval, scale, self._arm_scales(interval)
            )
        else:
            fit = self._static_fit(prediction, root)
        doubted = self._doubt.take_doubted(lost)
        self._corrected = ()
        if lost or doubted:
            wide = self._fit(
                features, np.asarray(fit.pose), np.asarray(fit.root), "initial", tuple(lost + doubted), index, interval
            )
            # A stage's cost depends on its region (Sil counts every mismatch inside it, Ratio
            # the silhouette there), and the wide search's regions are larger (everything the
            # arm can reach). Score the trajectory fit in the same regions before comparing.
            if self.config.fair_recovery:
                narrow_cost = self._fair_cost(features, np.asarray(fit.pose), np.asarray(fit.root), index, interval)
            else:
                narrow_cost = float(fit.cost)
            # A doubted arm's new pose must also bring its hand nearer its skin point: a lower
            # cost alone took pointing arms (07) off to wrong minima.
            if float(wide.cost) < narrow_cost and all(
                _nearer_hand_point(features, wide, fit, a, self.camera, self.body) for a in doubted
            ):
                fit = wide
                self._corrected = tuple(lost + doubted)
        fit, reached = self._reach_hands(features, fit, index, interval)
        fit, features, untangled = self._untangle_hands(features, fit, index, interval)
        self._corrected = tuple(dict.fromkeys(self._corrected + reached + untangled))
        t2 = time.perf_counter()
        searched = tuple(p for p in PARTS if p in trajectory or p in doubted)
        result = self._accept(fit, features, index, searched, {"features": t1 - t0, "search": t2 - t1})
        result.timings["other"] = time.perf_counter() - t2
        return result

    def _reach_hands(
        self, features: FrameFeatures, fit: FitLike, index: int, interval: float
    ) -> tuple[FitLike, tuple[str, ...]]:
        """Seeks each arm whose hand is far from its skin evidence from that evidence.

        Returns the fit to keep and the arms it moved.
        """
        cfg = self.config
        if cfg.reach_candidates <= 0:
            return fit, ()
        moved: list[str] = []
        fair: float | None = None
        for arm in ARMS:
            hands = project(self.camera, model_points(np.asarray(fit.pose), np.asarray(fit.root), self.body))
            shoulder_px = max(float(np.hypot(*(hands[1] - hands[2]))), 10.0)
            target = hand_target(features, arm, hands)
            if target is None or not unexplained(hands, target, cfg.reach_share * shoulder_px):
                continue
            root = np.asarray(fit.root)
            best = self._reach_seed(features, np.asarray(fit.pose), root, arm, target, shoulder_px, index, interval)
            if best is None:
                continue
            found = self._fit(
                features, best, root, "trajectory", (arm,), index, interval, self.config.recovery_window_scale
            )
            if fair is None:
                fair = self._fair_cost(features, np.asarray(fit.pose), root, index, interval)
            found_fair = self._fair_cost(features, np.asarray(found.pose), root, index, interval)
            found_hand = project(self.camera, model_points(np.asarray(found.pose), root, self.body))[HAND_JOINT[arm]]
            if found_fair < fair and np.hypot(*(found_hand - target)) < np.hypot(*(hands[HAND_JOINT[arm]] - target)):
                fit, fair = found, found_fair
                moved.append(arm)
        return fit, tuple(moved)

    def _untangle_hands(
        self, features: FrameFeatures, fit: FitLike, index: int, interval: float
    ) -> tuple[FitLike, FrameFeatures, tuple[str, ...]]:
        """Tries the other labelling of the hands' skin points when the fitted arms cross.

        The matching labels the hand blobs by the prediction, so arms that the prediction carried
        past each other (two hands that met and parted) take each other's blobs and stay
        crossed. When both hands hold blobs of their own and the fitted hands lie crossed in the
        image, both arms are also sought from the swapped points (as `_reach_hands` does) and
        scored against the swapped features; the lower cost wins, labelling included.

        Returns the fit, the features that go with it and the arms it moved.
        """
        right, left = features.right_hand, features.left_hand
        if (
            not self.config.untangle_hands
            or self.config.reach_candidates <= 0
            or right is None
            or left is None
            or right.merged
            or left.merged
            or right.blob == left.blob
        ):
            return fit, features, ()
        pose, root = np.asarray(fit.pose), np.asarray(fit.root)
        points = project(self.camera, model_points(pose, root, self.body))
        # Facing the camera, the right hand lies left of the left hand in the image.
        if not points[HAND_JOINT["right_arm"]][0] > points[HAND_JOINT["left_arm"]][0]:
            return fit, features, ()
        swapped = dataclasses.replace(features, right_hand=left, left_hand=right)
        shoulder_px = max(float(np.hypot(*(points[1] - points[2]))), 10.0)
        candidate = pose.copy()
        for arm, point in (("right_arm", left), ("left_arm", right)):
            seed = self._reach_seed(swapped, candidate, root, arm, point.xy, shoulder_px, index, interval)
            if seed is None:
                return fit, features, ()
            candidate = seed
        found = self._fit(
            swapped, candidate, root, "trajectory", ARMS, index, interval, self.config.recovery_window_scale
        )
        mine = self._fair_cost(features, pose, root, index, interval)
        theirs = self._fair_cost(swapped, np.asarray(found.pose), root, index, interval)
        if theirs < mine:
            return found, swapped, ARMS
        return fit, features, ()

    def _reach_seed(
        self,
        features: FrameFeatures,
        pose: FloatArray,
        root: FloatArray,
        arm: str,
        target: npt.ArrayLike,
        shoulder_px: float,
        index: int,
        interval: float,
    ) -> FloatArray | None:
        """`pose` with `arm` moved to the cheapest tabulated pose that puts its hand near `target`.

        None when no tabulated pose reaches the target. The table is made on first use (per body).
        """
        if self._reach is None:
            self._reach = ArmReach(self.body)
        seeds = self._reach.candidates(
            arm,
            pose,
            root,
            self.camera,
            target,
            self.config.reach_candidates,
            tolerance_px=0.5 * shoulder_px,
            elbow_spread_px=0.15 * shoulder_px,
        )
        if not seeds:
            return None
        costs = [float(self._fit(features, seed, root, "initial", (), index, interval).cost) for seed in seeds]
        return seeds[int(np.argmin(costs))]

    def _fair_cost(
        self, features: FrameFeatures, pose: FloatArray, root: FloatArray, index: int, interval: float
    ) -> float:
        """A pose's cost unsearched, in the full-range search's regions: comparable between poses."""
        return float(self._fit(features, pose, root, "initial", (), index, interval).cost)

    def _arm_scales(self, interval: float) -> FloatArray | None:
        """Per-angle window factors: each arm's windows grow with its last change.

        The windows cap an arm's speed; the prediction follows a steady motion, the wider
        window absorbs a speed-up (a wave starting, an arm thrown up).
        """
        gain = self.config.velocity_window_gain
        if gain <= 0:
            return None
        scales = np.ones(13)
        step = np.abs(self._pose - self._previous_pose) / (0.15 * interval * 30.0)
        for part in ("right_arm", "left_arm"):
            sl = PART_ANGLES[part]
            scales[sl] = 1.0 + gain * float(np.max(step[sl]))
        return scales

    def _fit(
        self,
        features: FrameFeatures,
        prediction: FloatArray,
        root: FloatArray,
        mode: Mode,
        search: tuple[str, ...],
        index: int,
        interval: float,
        window_scale: float = 1.0,
        angle_scales: FloatArray | None = None,
    ) -> FitLike:
        extra = {} if angle_scales is None else {"angle_window_scales": angle_scales}
        return self._fitter(
            features,
            np.ascontiguousarray(prediction, dtype=np.float64),
            np.ascontiguousarray(root, dtype=np.float64),
            self.body,
            self.camera,
            mode=mode,
            window_scale=window_scale,
            frame_interval=interval,
            search=search,
            frame_index=index,
            config=self._search_config,
            **extra,
        )

    def _static_fit(self, pose: FloatArray, root: FloatArray) -> StaticFit:
        joints = forward_kinematics(pose, root, self.body)
        return StaticFit(pose.copy(), root.copy(), joints, project(self.camera, joints), self._last_cost)

    def _accept(
        self,
        fit: FitLike,
        features: FrameFeatures,
        index: int,
        searched: tuple[str, ...],
        timings: dict[str, float],
    ) -> TrackResult:
        """Takes a fit as this frame's pose: presence, lost detection, status, state for next frame."""
        pose = np.array(fit.pose, dtype=np.float64)
        root = np.array(fit.root, dtype=np.float64)
        anatomical_2d = np.array(fit.joints_2d, dtype=np.float64)
        joints_3d = np.array(fit.joints_3d, dtype=np.float64)
        # Presence, lost hands and the next frame's prediction compare the model with the image's
        # head and hand points: those measure the solids (`model_points`); the result reports
        # the anatomical joints.
        joints_2d = project(self.camera, model_points(pose, root, self.body))
        labels = self._render_labels(pose, root)
        model = labels > 0
        area = int(np.count_nonzero(model))
        covered = int(np.count_nonzero(features.sil[model])) if area else 0
        # Present while the silhouette covers the model, or while the head's skin blob is where
        # the model's head is (an estimated background can hold a person who hardly moved, and
        # then the silhouette misses them).
        head = features.head
        head_near = (
            head is not None
            and not head.merged
            and float(np.hypot(*(np.asarray(head.xy) - joints_2d[0]))) < float(np.hypot(*(joints_2d[1] - joints_2d[2])))
        )
        present = area > 0 and (covered >= self.config.presence_share * area or head_near)

        was_lost = dict(self._lost.lost)
        points = features.points_array()
        loose = unexplained_by_side(features.sil, labels, 0.5 * float(joints_2d[1, 0] + joints_2d[2, 0]))
        arm_px = self._arm_area_px(root)
        if len(self._loose_baseline) < 10:  # the body-shape mismatch of the first tracked frames
            self._loose_baseline.append([loose[a] / arm_px for a in ARMS])
        base = np.median(self._loose_baseline, axis=0)
        excess = [loose[arm] / arm_px - base[k] for k, arm in enumerate(ARMS)]
        # More than a few arms' worth on both sides is a global change (light, a moved camera),
        # not a misplaced arm: no evidence.
        global_change = min(excess) > 3.0
        missing = {arm: not global_change and excess[k] > self.config.unexplained_share for k, arm in enumerate(ARMS)}
        distances = hand_distances(joints_2d, features)
        lost = self._lost.update(joints_2d, distances, missing)
        self._doubt.update(joints_2d, distances)
        self._recovered = any(was_lost[a] and not lost[a] for a in ARMS)
        shoulder_px = float(np.hypot(*(joints_2d[1] - joints_2d[2])))
        for arm in ARMS:
            if lost[arm] and arm not in self._follow.windows:
                k = HAND_POINT[arm]
                start = (
                    self._last_points[k] if np.all(np.isfinite(self._last_points[k])) else joints_2d[HAND_JOINT[arm]]
                )
                self._follow.start(arm, start, shoulder_px)
            elif not lost[arm]:
                self._follow.stop(arm)
        self._followed = self._follow.step(features.skin) if self._follow.windows else {}
        for k in (1, 2):
            if np.all(np.isfinite(points[k])):
                self._last_points[k] = points[k]

        status_now = self.state.tracking(present, any(lost.values()))
        lost_parts = tuple(a for a in ARMS if lost[a])
        if status_now == NO_PERSON:
            self._reset_person()
            return TrackResult(index, NO_PERSON, searched=searched, timings=timings)
        previous = self._pose.copy() if self._corrected else self._pose  # last frame's result keeps its own
        for arm in self._corrected:  # a correction is no motion: no velocity to extrapolate
            previous[PART_ANGLES[arm]] = pose[PART_ANGLES[arm]]
        self._previous_pose, self._pose = previous, pose
        self._last_root, self._labels = root, labels
        self._last_joints, self._last_cost = joints_2d, float(fit.cost)
        size = (int(features.sil.shape[0]), int(features.sil.shape[1]))
        excess_by_arm = {arm: float(excess[k]) for k, arm in enumerate(ARMS)}
        confidence = self._confidence.update(
            anatomical_2d, joints_2d, features, distances, lost_parts, self._corrected, excess_by_arm, size
        )
        return TrackResult(
            index,
            status_now,
            pose,
            root,
            anatomical_2d,
            joints_3d,
            float(fit.cost),
            searched,
            lost_parts,
            timings,
            confidence,
            tuple(visibility(anatomical_2d, lost_parts, size)),
        )

    def _arm_area_px(self, root: FloatArray) -> float:
        """Projected area in pixels of one whole arm seen side-on at the root's depth."""
        dims = self.body.as_dict()
        width = float(sum(dims["upper_arm_radii"]) + sum(dims["lower_arm_radii"]))  # two mean diameters
        length = float(dims["upper_arm_length"]) + float(dims["lower_arm_length"])
        scale = pixels_per_metre(self.camera, float(root[2]))
        return float(0.5 * width * length * scale * scale)

    def _render_labels(
        self, pose: FloatArray, root: FloatArray, body: BodyModel | None = None
    ) -> npt.NDArray[np.uint8]:
        """The model's part labels at full size, rasterised at half resolution (4x cheaper).

        They serve the motion flags (counted inside a 9x9 dilation) and the torso region of the
        arm silhouette, where a pixel of rounding does not matter.
        """
        height, width = self.size
        body = body or self.body
        if self._half_camera is None:
            return render_masks(pose, root, self.camera, width, height, body)["labels"]
        small = render_masks(pose, root, self._half_camera, (width + 1) // 2, (height + 1) // 2, body)["labels"]
        return np.asarray(cv2.resize(small, (width, height), interpolation=cv2.INTER_NEAREST), dtype=np.uint8)

    def _reset_person(self) -> None:
        if self._extract is not None:
            self._extract.forget_skin()
        self._body = self._base_body
        self._pose = Pose.a_pose().angles.copy()
        self._previous_pose = self._pose.copy()
        self._root = RootEstimator(self.camera, self._body, [0.0, 0.0, 2.2], None)
        self._last_root = None
        self._labels = None
        self._last_joints = None
        self._last_cost = float("nan")
        self._last_points = np.full((3, 2), np.nan)
        self._followed = {}
        self._recovered = False
        self._loose_baseline = []
        self._face_streak = 0
        self._face_widths = []
        self._last_face = None
        self._lost.reset()
        self._doubt.reset()
        self._corrected = ()
        self._follow.reset()
        self._reach = None
        self._confidence.reset()


__all__ = ["PARTS", "StaticFit", "TrackResult", "Tracker", "TrackerConfig"]
