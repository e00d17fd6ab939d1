"""`Tracker`: video frames in, 3D upper-body poses out, one `update(frame)` at a time.

The loop of the thesis' flowchart (Fig. 3.6-1): while nobody is tracked, look for a frontal face
and the A-pose (start-up, §3.3), or fit any pose around the face (`fit/person_finder.py`); then
per frame predict the pose (constant velocity), extract the features around the prediction,
estimate the root, search the moving parts (motion flags, §3.4.3) inside trajectory windows,
and check for lost hands (§3.4.9), which are searched over their anatomical ranges until
found (`fit/arm_corrections.py`); every few frames a frontal face away from the model's head
puts the body back under it. Without a clean plate the background is learnt here too, away
from the person. See docs/tracker.md.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose._upperpose import joint_limits
from upperpose.exceptions import InputError
from upperpose.features import Background, FeatureConfig, FeatureExtractor, FrameFeatures, skin_mask
from upperpose.features.background import NOT_THE_ROOM
from upperpose.features.checks import check_frame
from upperpose.features.faces import face_centre, faces_near
from upperpose.features.online import OnlineBackground, body_region
from upperpose.fit.arm_corrections import ArmCorrections
from upperpose.fit.confidence import JointConfidence, shares
from upperpose.fit.fitter import PART_ANGLES, PARTS, FitLike, Fitter, FrameSearch, StaticFit
from upperpose.fit.person_finder import PersonFinder, Start, starting_root
from upperpose.fit.recovery import (
    ARMS,
    HAND_JOINT,
    HAND_POINT,
    DoubtDetector,
    HandFollower,
    LostDetector,
    hand_distances,
    hands_on_followed_points,
    unexplained_by_side,
)
from upperpose.fit.root import RootEstimator
from upperpose.fit.search import Limits, SearchConfig, fit_frame
from upperpose.fit.startup import FaceBox, FaceDetector, choose_face, pixels_per_metre
from upperpose.fit.state import StateMachine
from upperpose.fit.tracker_config import TrackerConfig
from upperpose.fit.visibility import visibility
from upperpose.model import (
    BodyModel,
    Camera,
    Pose,
    check_camera_fits,
    forward_kinematics,
    model_points,
    project,
    reaching_camera,
    render_labels,
)
from upperpose.result import NO_PERSON, TrackResult

FloatArray = npt.NDArray[np.float64]
# Without a plate, the body around a detected face is not learnt for this many frames after the
# face was last detected: the cascade misses a face now and then, and a pixel never seen would be
# learnt at once (half a second at 30 fps).
FACE_HOLD_FRAMES = 15
# The face check looks this many face widths around the model's head: the head point slides
# about a shoulder width (two face widths) down a hand held to the chest.
FACE_CHECK_REACH = 3.0


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
            An estimated `Background` (`background_from_video` without a plate) goes on
            learning while tracking when `bg_refine_estimate` is on.
        config: tracker settings.
        fps: frame rate, for the search's trajectory windows when `update` gets no timestamps.
        body: dimensions to start the start-up measurement from (adult averages when None).
        fitter: the search; `upperpose.fit_frame` when None (injectable for tests).
        face_detector: callable frame -> face boxes; OpenCV's Haar cascade when None.

    One Tracker per thread and per video.
    """

    # Per-person state, set by _reset_person() and _begin().
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
    _corrected: tuple[str, ...]  # arms a correction moved this frame (no velocity to extrapolate)
    _face_away: FloatArray | None  # a face found away from the model's head at the last check

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
        self._refines_estimate = False  # the online model started from an estimated plate
        self._first_faces: list[FaceBox] | None = None
        self._features: FrameFeatures | None = None
        self._held_faces: tuple[list[FaceBox], int] = ([], 0)  # last detected faces, frames left
        self._extract: FeatureExtractor | None = None
        self.background: Background | None = None
        self.size = (0, 0)  # (height, width), known from the background or the first frame
        if background is not None:
            self._set_background(background)
            estimate = self._extractor.background
            if estimate.estimated and estimate.config.bg_refine_estimate:
                self._online = OnlineBackground.from_estimate(estimate)
                self._refines_estimate = True
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
        self._finder = PersonFinder(
            camera, cfg, self.state, self._fitter, self._search_config, self._base_body, self.fps, self._render_labels
        )
        self._corrections = ArmCorrections(cfg)
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
    def features(self) -> FrameFeatures | None:
        """The last frame's image features, skin points included (None before the first frame)."""
        return self._features

    @property
    def room_skin(self) -> npt.NDArray[np.uint8] | None:
        """The room's pixels the features take for skin-coloured (None before the first frame).

        See `FeatureExtractor.room_skin`.
        """
        return None if self._extract is None else self._extract.room_skin

    @property
    def learns_background(self) -> bool:
        """Whether the background is learnt from the frames alone (no clean plate, no estimate).

        Until the first fit such a background shows the inpainted guess behind the person.
        """
        return self._extract is None or (self._online is not None and not self._refines_estimate)

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
        """Starts the online background from the first frame, the body around its face left out.

        The face is the box most skin; when none passes the skin rule (a real face under a bluish
        webcam's light), the largest box: a person learnt into the plate stays invisible while
        they keep still, room held by mistake is learnt once seen beside the person.
        """
        config = self.config.features or FeatureConfig()
        frame = check_frame(frame, "frame")
        self._first_faces = self._detect_faces(frame)
        face = choose_face(self._first_faces, skin_mask(frame, config))
        if face is None and self._first_faces:
            face = max(self._first_faces, key=lambda box: box[2])
        self._online = OnlineBackground(frame, [face] if face is not None else [], config)
        self._set_background(self._online.background)

    def _learn_background(self, frame: npt.NDArray[np.uint8]) -> None:
        """Teaches the online background this frame away from the person.

        The person: the model's projection once tracked, else the body region around the faces
        detected in the last `FACE_HOLD_FRAMES` frames; skin and motion are held too where the
        model has seen the room.
        """
        online, features = cast(OnlineBackground, self._online), self._features
        if features is not None and not self.state.has_person and not self._refines_estimate:
            if cv2.countNonZero(features.sub) >= NOT_THE_ROOM * features.sub.size:
                # Nobody tracked and most of the frame is not the model's room: a webcam's black
                # first frames, a fade, a cut. Start again from this frame.
                self._start_background(frame)
                return
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
        t0 = time.perf_counter()
        features = self._features = self._extractor(frame)
        t1 = time.perf_counter()
        boxes = self._first_faces if self._first_faces is not None else self._detect_faces(frame)
        self._first_faces = None
        if boxes:
            self._held_faces = (boxes, FACE_HOLD_FRAMES)
        seen = self._finder.see(frame, features, boxes, self._extractor)
        t2 = time.perf_counter()
        timings = {"features": t1 - t0, "startup": t2 - t1}
        attempt = self._finder.attempt(features, seen, self._extractor.config, index, self.face_only_frames)
        if attempt.searched:
            timings.update(search=time.perf_counter() - t2)
        if attempt.start is None:
            return TrackResult(index, self.state.status, timings=timings)
        fit = self._begin(attempt.start)
        t3 = time.perf_counter()
        result = self._accept(fit, attempt.start.features, index, PARTS, timings)
        timings["other"] = time.perf_counter() - t3
        return result

    def _begin(self, start: Start) -> FitLike:
        """Sets up the per-person state from the start-up fit; `start.pose` is last frame's pose."""
        self._body = start.chosen.body
        self._root = starting_root(self.camera, start)
        self._pose = np.array(start.pose, dtype=np.float64)
        self._previous_pose = self._pose.copy()
        self._lost.reset()
        self._doubt.reset()
        self._corrected = ()
        self._face_away = None
        self._follow.reset()
        self._corrections.reset()
        self._confidence.reset()
        return cast(FitLike, start.chosen.fit)

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
        features = self._extractor(frame, predicted_joints, self._labels)
        features = self._features = hands_on_followed_points(features, self._followed)
        root = self._root.update(features, prediction, self._last_root)
        root = self._keep_head_on_face(frame, index, prediction, root)
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
        search = self._frame_search(index, interval)
        if trajectory:
            fit: FitLike = search.run(
                features, prediction, root, "trajectory", trajectory, scale, self._arm_scales(interval)
            )
        else:
            fit = self._static_fit(prediction, root)
        doubted = self._doubt.take_doubted(lost)
        fit, features, self._corrected = self._corrections.correct(features, fit, lost, doubted, search)
        fit = self._clear_of_camera(features, fit, search)
        t2 = time.perf_counter()
        searched = tuple(p for p in PARTS if p in trajectory or p in doubted)
        result = self._accept(fit, features, index, searched, {"features": t1 - t0, "search": t2 - t1})
        result.timings["other"] = time.perf_counter() - t2
        return result

    def _keep_head_on_face(
        self, frame: npt.NDArray[np.uint8], index: int, pose: FloatArray, root: FloatArray
    ) -> FloatArray:
        """Every `face_check_frames` frames, the root put back under the face if the head left it.

        The root follows the head's skin point, which a hand touching the face or held to the
        chest can carry away; the whole body then slides after it. A frontal face of the
        person's size within `FACE_CHECK_REACH` face widths of the model's head, more than
        `face_drift_share` face widths from it, on two checks in a row at the same place, moves
        the root under it; not when the face lies below the head (a bow).
        """
        every = self.config.face_check_frames
        width = self._root.face_px
        if every <= 0 or index % every or width is None:
            return root
        head = project(self.camera, model_points(pose, root, self.body))[0]
        boxes = self._faces_around_head(frame, head, width)
        if not boxes:
            self._face_away = None
            return root
        centre = face_centre(boxes[0])
        # A face well below the model's head is a person bowing, which the torso's range may
        # not reach: the head is left where the fit put it.
        if np.hypot(*(centre - head)) <= self.config.face_drift_share * width or centre[1] > head[1] + 0.5 * width:
            self._face_away = None
            return root
        confirmed = self._face_away is not None and np.hypot(*(centre - self._face_away)) <= 0.5 * width
        self._face_away = None if confirmed else centre
        return self._root.move_to_face(centre, pose) if confirmed else root

    def _faces_around_head(self, frame: npt.NDArray[np.uint8], head: FloatArray, width: float) -> list[FaceBox]:
        """The faces of the person's size within `FACE_CHECK_REACH` face widths of `head`, nearest first.

        Most checks find the face where the head is. A square just large enough to hold that
        face (its centre within the drift share, its half-width at the largest size, a margin)
        is searched first, at about 40 % of the whole square's cost; the whole square only when
        no face lies within the drift share.
        """
        near = getattr(self._detect_faces, "near", None)
        if near is None:  # an injected detector: the whole frame, then the same choice
            return faces_near(self._detect_faces(frame), head, width, FACE_CHECK_REACH)
        drift = self.config.face_drift_share
        if drift + 1.0 >= FACE_CHECK_REACH:  # the small square would be the whole one
            return cast(list[FaceBox], near(frame, head, width, FACE_CHECK_REACH))
        on_head = near(frame, head, width, drift + 1.0)
        if on_head and np.hypot(*(face_centre(on_head[0]) - head)) <= drift * width:
            return cast(list[FaceBox], on_head)
        return cast(list[FaceBox], near(frame, head, width, FACE_CHECK_REACH))

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

    def _frame_search(self, index: int, interval: float) -> FrameSearch:
        """This frame's fits of the person's body."""
        return FrameSearch(self._fitter, self.body, self.camera, self._search_config, index, interval)

    def _clear_of_camera(self, features: FrameFeatures, fit: FitLike, search: FrameSearch) -> FitLike:
        """The fit with each arm that reaches the camera searched again over its whole range.

        A stage whose every candidate the search rejects keeps its prediction, and a person
        filming themselves at arm's length can have an arm predicted and leant (with the
        torso) through the camera; its joints would then project to infinity.
        """
        for arm in reaching_camera(np.asarray(fit.pose), np.asarray(fit.root), self.body, self.camera):
            if arm == "torso":
                continue
            refit = search.run(features, np.asarray(fit.pose), np.asarray(fit.root), "initial", (arm,))
            if arm not in reaching_camera(np.asarray(refit.pose), np.asarray(refit.root), self.body, self.camera):
                fit = refit
        return fit

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
        if self._follow.windows:
            face_radius_px = self.body.head_radii[0] * pixels_per_metre(self.camera, float(root[2]))
            self._followed = self._follow.step(features.skin, (joints_2d[0], face_radius_px))
        else:
            self._followed = {}
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
        confidence = shares(
            self._confidence.groups(
                anatomical_2d, joints_2d, features, distances, lost_parts, self._corrected, excess_by_arm, size
            )
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
            return render_labels(pose, root, self.camera, width, height, body)
        small = render_labels(pose, root, self._half_camera, (width + 1) // 2, (height + 1) // 2, body)
        return np.asarray(cv2.resize(small, (width, height), interpolation=cv2.INTER_NEAREST), dtype=np.uint8)

    def _reset_person(self) -> None:
        if self._extract is not None:
            self._extract.forget_skin()
        self._body = self._base_body
        self._pose = Pose.a_pose().angles.copy()
        self._previous_pose = self._pose.copy()
        self._root = RootEstimator(self.camera, self._body, [0.0, 0.0, 2.2], None, None)
        self._last_root = None
        self._labels = None
        self._last_joints = None
        self._last_cost = float("nan")
        self._last_points = np.full((3, 2), np.nan)
        self._followed = {}
        self._recovered = False
        self._loose_baseline = []
        self._finder.reset()
        self._lost.reset()
        self._doubt.reset()
        self._corrected = ()
        self._face_away = None
        self._follow.reset()
        self._corrections.reset()
        self._confidence.reset()


__all__ = ["PARTS", "Fitter", "StaticFit", "TrackResult", "Tracker", "TrackerConfig"]
