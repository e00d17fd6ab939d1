"""The tracker: state machine, start-up check, root, lost detection and recovery."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace
from typing import Any

import cv2
import numpy as np
import pytest

import upperpose
from tracker_helpers import PART_ANGLES, TruthFitter, camera_of, clip, truth
from upperpose.features import Background, FeatureExtractor, SkinBlob
from upperpose.features.blobs import blob_from_pixels
from upperpose.features.faces import FaceDetector
from upperpose.features.packing import pack_rows
from upperpose.features.points import SkinPoint
from upperpose.fit import INITIALISING, LOST, NO_PERSON, PARTS, TRACKED, StateMachine, StaticFit, Tracker, TrackerConfig
from upperpose.fit.reach import ArmReach
from upperpose.fit.recovery import (
    DoubtDetector,
    HandFollower,
    LostDetector,
    hands_on_followed_points,
    unexplained_by_side,
)
from upperpose.fit.root import SETTLED, RootEstimator
from upperpose.fit.startup import (
    HAND_REACH_FACES,
    StartupFit,
    check_apose,
    depth_from_face,
    face_centre,
    fit_bodies,
    hand_candidates,
    head_raised,
    root_from_head,
    widened,
)
from upperpose.fit.tracker import FACE_CHECK_REACH
from upperpose.io.video import VideoReader
from upperpose.model import MIN_JOINT_DEPTH, model_points, penetrates, reaching_camera

# -- pure units -------------------------------------------------------------------------------


def test_state_machine_start_up_needs_consecutive_passes() -> None:
    sm = StateMachine(confirm_frames=3, leave_frames=2)
    assert not sm.startup(face_found=False, passed=False) and sm.status == NO_PERSON
    assert not sm.startup(True, False) and sm.status == INITIALISING
    assert not sm.startup(True, True) and sm.status == INITIALISING
    assert not sm.startup(True, False) and sm.status == INITIALISING  # a failed check restarts the count
    assert not sm.startup(True, True)
    assert not sm.startup(True, True)
    assert sm.startup(True, True) and sm.status == TRACKED
    with pytest.raises(RuntimeError):
        sm.startup(True, True)


def test_state_machine_lost_and_leaving() -> None:
    sm = StateMachine(confirm_frames=1, leave_frames=2)
    assert sm.startup(True, True)
    assert sm.tracking(present=True, lost=True) == LOST
    assert sm.tracking(present=True, lost=False) == TRACKED
    assert sm.tracking(present=False, lost=False) == TRACKED  # one absent frame is not enough
    assert sm.tracking(present=True, lost=False) == TRACKED  # and the count restarts
    assert sm.tracking(present=False, lost=False) == TRACKED
    assert sm.tracking(present=False, lost=False) == NO_PERSON
    assert not sm.has_person


def test_hands_of_a_large_body_seen_with_a_small_face_box_are_hand_candidates() -> None:
    # The default body's A-pose hands hang 5.6 face widths from its face; 20 % larger (start-up's
    # clamp) and seen with a face box 8 % small, 7.3: still hands. A skin blob much further off
    # (a lamp across the room) is not.
    face = (284, 85, 32, 32)
    centre = face_centre(face)

    def disc_at(distance_faces: float, angle: float) -> SkinBlob:
        x, y = centre + distance_faces * face[2] * np.array([np.sin(angle), np.cos(angle)])
        pixels = np.zeros((480, 640), np.uint8)
        cv2.circle(pixels, (round(x), round(y)), 12, 255, -1)
        return blob_from_pixels(pixels, (0, 0), 0.5)

    blobs = [disc_at(7.3, -0.6), disc_at(7.3, 0.6), disc_at(HAND_REACH_FACES + 1.0, 0.3)]
    assert hand_candidates(face, blobs) == [0, 1]


def test_apose_check_thresholds() -> None:
    face = 40.0
    good = np.array([[320.0, 100.0], [200.0, 300.0], [440.0, 300.0]])
    check = check_apose(good, face)
    assert check.passed and check.r_d == pytest.approx(1.0) and check.d3_faces == pytest.approx(6.0)
    lopsided = np.array([[320.0, 100.0], [300.0, 140.0], [440.0, 400.0]])
    assert not check_apose(lopsided, face).passed and "r_d" in check_apose(lopsided, face).reason
    together = np.array([[320.0, 100.0], [310.0, 300.0], [330.0, 300.0]])
    assert not check_apose(together, face).passed and "d3" in check_apose(together, face).reason
    raised = np.array([[320.0, 100.0], [200.0, 50.0], [440.0, 50.0]])
    assert not check_apose(raised, face).passed
    missing = good.copy()
    missing[2] = np.nan
    assert not check_apose(missing, face).passed


def test_root_from_head_reprojects_the_head() -> None:
    camera = upperpose.Camera.for_image(640, 480)
    body = upperpose.BodyModel()
    pose = upperpose.Pose(torso_x=0.2, torso_z=0.1)
    root = root_from_head(camera, [300.0, 150.0], 2.3, pose, body)
    head = upperpose.project(camera, upperpose.model.model_points(pose, root, body))[0]
    assert root[2] == 2.3
    np.testing.assert_allclose(head, [300.0, 150.0], atol=1e-6)
    # Twice the face width in pixels means half the depth.
    assert depth_from_face(camera, 100.0) == pytest.approx(2 * depth_from_face(camera, 200.0))


class _HeadOnly:
    """The two things RootEstimator reads of FrameFeatures: the head point and its blob's box."""

    def __init__(self, xy: tuple[float, float], size: tuple[int, int]) -> None:
        self.head = SkinPoint(xy, merged=False, blob=0)
        self.blobs = [SimpleNamespace(bbox=(int(xy[0] - size[0] / 2), int(xy[1] - size[1] / 2), *size))]


def _root_estimator() -> tuple[RootEstimator, upperpose.Camera, upperpose.BodyModel, np.ndarray]:
    camera = upperpose.Camera.for_image(640, 480)
    body = upperpose.BodyModel()
    pose = upperpose.Pose().angles
    root = root_from_head(camera, [320.0, 150.0], 2.0, pose, body)
    # Head 50 px wide at start-up; the head blob's width is that of the face box, its height 60 px.
    return RootEstimator(camera, body, root, 50.0, 60.0, head_size_px=50.0), camera, body, pose


def _head_px(estimator: RootEstimator, camera: upperpose.Camera, body: upperpose.BodyModel, pose: np.ndarray) -> float:
    return float(upperpose.project(camera, upperpose.model.model_points(pose, estimator.root, body))[0][0])


def test_root_follows_a_steady_sideways_walk() -> None:
    estimator, camera, body, pose = _root_estimator()
    fitted = None
    for k in range(1, 31):  # 20 px a frame: 0.4 head widths, a brisk walk at 2 m
        fitted = estimator.update(_HeadOnly((320.0 + 20.0 * k, 150.0), (50, 60)), pose, fitted)
    # The half-and-half blend with the fit lags a steady motion by one step (20 px).
    assert abs(_head_px(estimator, camera, body, pose) - (320.0 + 20.0 * 30)) <= 21.0


def test_root_ignores_a_head_point_that_jumps_for_a_frame_or_two() -> None:
    estimator, camera, body, pose = _root_estimator()
    fitted = None
    for _ in range(3):  # tracking, with a velocity (zero)
        fitted = estimator.update(_HeadOnly((320.0, 150.0), (50, 60)), pose, fitted)
    for _ in range(2):  # a hand's blob taken for the head, 100 px (two head widths) below it
        fitted = estimator.update(_HeadOnly((320.0, 250.0), (45, 45)), pose, fitted)
        np.testing.assert_allclose(fitted[:2], estimator.root[:2])
        assert abs(upperpose.project(camera, upperpose.model.model_points(pose, fitted, body))[0][1] - 150.0) < 0.5
    # A third measurement in a row that agrees with the last two is believed: the person moved.
    fitted = estimator.update(_HeadOnly((320.0, 252.0), (45, 45)), pose, fitted)
    head_y = upperpose.project(camera, upperpose.model.model_points(pose, fitted, body))[0][1]
    assert head_y == pytest.approx(150.0 + 0.5 * 102.0, abs=0.5)


def test_root_ignores_a_scrap_of_skin_taken_for_the_head() -> None:
    estimator, camera, body, pose = _root_estimator()
    fitted = None
    for _ in range(3):
        fitted = estimator.update(_HeadOnly((320.0, 150.0), (50, 60)), pose, fitted)
    for _ in range(5):  # a 10 x 8 px blob (under half a head) 30 px below the head, frame after frame
        fitted = estimator.update(_HeadOnly((320.0, 180.0), (10, 8)), pose, fitted)
    assert _head_px(estimator, camera, body, pose) == pytest.approx(320.0, abs=0.5)
    head_y = upperpose.project(camera, upperpose.model.model_points(pose, fitted, body))[0][1]
    assert head_y == pytest.approx(150.0, abs=0.5)


def _walk(estimator: RootEstimator, pose: np.ndarray, sizes: list[tuple[float, float]]) -> list[float]:
    """Feeds head blobs of the given (width, height) at one place; the depth after each."""
    fitted, depths = None, []
    for width, height in sizes:
        fitted = estimator.update(_HeadOnly((320.0, 150.0), (round(width), round(height))), pose, fitted)
        depths.append(estimator.depth)
    return depths


def _estimator_for_blob(width: float, height: float, **settings: Any) -> RootEstimator:
    """A root estimator started at 2 m with a 50 px face and a head blob of `width` x `height` px."""
    camera = upperpose.Camera.for_image(640, 480)
    body = upperpose.BodyModel()
    root = root_from_head(camera, [320.0, 150.0], 2.0, upperpose.Pose().angles, body)
    return RootEstimator(camera, body, root, width, height, head_size_px=50.0, **settings)


def _ramp(frame: int, frames: int) -> float:
    """0 over the first ten frames after start-up (the head blob's reference is taken), then up to 1 over `frames`."""
    return min(max(frame - 10, 0), frames) / frames


def test_a_head_blob_widened_by_hair_still_measures_depth() -> None:
    # Blond hair passes the skin rule: the head's blob is 1.3 face widths wide at start-up.
    estimator, pose = _estimator_for_blob(65.0, 70.0), upperpose.Pose().angles
    # Steps from 2.0 m to 1.5 m over a second: the blob grows from 65 x 70 to 87 x 93 px.
    scales = [2.0 / (2.0 - 0.5 * _ramp(k, 30)) for k in range(100)]
    _walk(estimator, pose, [(65.0 * f, 70.0 * f) for f in scales])
    assert estimator.depth == pytest.approx(1.5, rel=SETTLED + 0.01)


@pytest.mark.parametrize("wobble", [0.0, 0.1, 0.18])
def test_depth_holds_while_the_head_blob_wobbles(wobble: float) -> None:
    # A person standing still: the depth the blob's size gives swings by up to `wobble` either way.
    estimator, _, _, pose = _root_estimator()
    swing = [1.0 / (1.0 + wobble * np.sin(2 * np.pi * k / 40)) for k in range(120)]
    depths = _walk(estimator, pose, [(50.0 * f, 60.0 * f) for f in swing])
    assert depths == [2.0] * 120


def test_depth_holds_while_the_head_turns() -> None:
    # A head turned to profile: its blob a third wider and a third shorter, the person in place.
    estimator, _, _, pose = _root_estimator()
    turn = [min(k, 10) / 10 for k in range(60)]
    depths = _walk(estimator, pose, [(50.0 * (1 + t / 3), 60.0 * (1 - t / 3)) for t in turn])
    assert depths == [2.0] * 60


def test_depth_holds_when_the_start_up_blob_was_not_the_heads_usual_size() -> None:
    # The start-up frame's head blob is 34 x 52 px; from the next frame on (the skin colour learnt
    # from the face) it is 56 x 78 px, with the person in place: the reference is the blobs' median.
    pose = upperpose.Pose().angles
    depths = _walk(_estimator_for_blob(34.0, 52.0), pose, [(56.0, 78.0)] * 60)
    assert depths == [2.0] * 60
    # Taken from that one frame, the reference would have brought the person 40 % nearer.
    single = _estimator_for_blob(34.0, 52.0, reference_frames=1)
    assert _walk(single, pose, [(56.0, 78.0)] * 60)[-1] < 1.4


def test_depth_holds_when_the_head_blob_changes_shape() -> None:
    # A head bowed towards the camera: its skin blob shrinks to 30 x 22 px from 50 x 60, both
    # measures saying "farther", but a step back would keep the blob's shape and this one is
    # squat; taken as a depth, the person would be put 1.5 times farther away or more.
    pose = upperpose.Pose().angles
    sizes = [(50.0, 60.0)] * 5 + [(30.0, 22.0)] * 60
    assert _walk(_estimator_for_blob(50.0, 60.0), pose, sizes) == [2.0] * 65
    any_shape = _estimator_for_blob(50.0, 60.0, max_shape_change=10.0)
    assert _walk(any_shape, pose, sizes)[-1] > 3.0


def test_depth_follows_a_quick_step_closer_through_noise() -> None:
    # From 2.0 m to 1.5 m in three frames, the blob's size noisy by up to 6 % either way.
    estimator, _, _, pose = _root_estimator()
    rng = np.random.default_rng(3)
    scales = [2.0 / (2.0 - 0.5 * _ramp(k, 3)) for k in range(100)]
    noisy = [(50.0 * f * rng.uniform(0.94, 1.06), 60.0 * f * rng.uniform(0.94, 1.06)) for f in scales]
    depths = _walk(estimator, pose, noisy)
    assert depths[12] == 2.0  # not within a frame or two: the median of five must agree first
    assert depths[-1] == pytest.approx(1.5, rel=SETTLED + 0.03)


def test_depth_follows_a_step_back_then_holds() -> None:
    estimator, _, _, pose = _root_estimator()
    scales = [2.0 / (2.0 + 0.6 * _ramp(k, 15)) for k in range(160)]
    depths = _walk(estimator, pose, [(50.0 * f, 60.0 * f) for f in scales])
    assert depths[-1] == pytest.approx(2.6, rel=SETTLED + 0.01)
    assert len(set(depths[-20:])) == 1  # settled: no creeping after


def test_lost_detector_counts_misses_and_pauses_without_evidence() -> None:
    detector = LostDetector(threshold=1.0, frames=3)
    joints = np.array([[320, 100], [270, 170], [370, 170], [250, 250], [390, 250], [240, 330], [400, 330]], float)
    far = {"right_arm": 140.0, "left_arm": 5.0}  # shoulder width is 100 px
    assert not detector.update(joints, far)["right_arm"]
    assert not detector.update(joints, far)["right_arm"]
    for _ in range(5):  # merged blob: no evidence, the count neither grows nor restarts
        assert not detector.update(joints, {"right_arm": None, "left_arm": 5.0})["right_arm"]
    assert detector.update(joints, far)["right_arm"]
    assert not detector.lost["left_arm"]
    assert not detector.update(joints, {"right_arm": 20.0, "left_arm": 5.0})["right_arm"]
    # unexplained silhouette on an arm's side counts as a miss even without a skin point
    for _ in range(3):
        lost = detector.update(joints, {"right_arm": None, "left_arm": None}, {"right_arm": False, "left_arm": True})
    assert lost == {"right_arm": False, "left_arm": True}


def test_doubt_detector_needs_a_run_of_frames_off_the_evidence() -> None:
    doubt = DoubtDetector(share=0.35, frames=3)
    joints = np.array([[320, 100], [270, 170], [370, 170], [250, 250], [390, 250], [240, 330], [400, 330]], float)
    off = {"right_arm": 50.0, "left_arm": 20.0}  # shoulder width 100 px: 0.5 and 0.2 of it
    for _ in range(2):
        doubt.update(joints, off)
    assert doubt.take_doubted([]) == []
    doubt.update(joints, {"right_arm": None, "left_arm": 20.0})  # no evidence breaks the run
    for _ in range(2):
        doubt.update(joints, off)
    assert doubt.take_doubted([]) == []
    doubt.update(joints, off)
    assert doubt.take_doubted(["right_arm"]) == []  # lost: searched over its ranges anyway
    assert doubt.take_doubted([]) == ["right_arm"]
    assert doubt.take_doubted([]) == []  # one search, then the count starts again
    for _ in range(3):
        doubt.update(joints, {"right_arm": 50.0, "left_arm": 50.0})
    assert DoubtDetector(frames=0).take_doubted([]) == [] and doubt.take_doubted([]) == ["right_arm", "left_arm"]


def test_unexplained_silhouette_by_side() -> None:
    labels = np.zeros((240, 320), np.uint8)
    labels[60:200, 130:190] = 1  # the model: a torso
    sil = (labels > 0).astype(np.uint8) * 255
    sil[20:60, 60:80] = 255  # a raised arm on the image's left, not modelled
    sil[230:240, 100:220] = 255  # legs below the model: ignored
    loose = unexplained_by_side(sil, labels, neck_x=160.0)
    assert loose == {"right_arm": 40 * 20, "left_arm": 0}


def test_mean_shift_follows_a_skin_blob() -> None:
    skin = np.zeros((240, 320), np.uint8)
    cv2.circle(skin, (200, 150), 12, 255, -1)
    follower = HandFollower(window_side=0.5)
    follower.start("right_arm", (185.0, 140.0), shoulder_px=60.0)
    centre = follower.step(skin)["right_arm"]
    assert np.hypot(*(centre - [200.0, 150.0])) < 3.0
    follower.stop("right_arm")
    assert follower.step(skin) == {}


def test_mean_shift_kept_off_the_face_stays_on_the_hand_beside_it() -> None:
    # A hand at the ear touches the face; the window starts between them. On the whole skin
    # image it climbs onto the face and stays there; with the face's disc left out it sits on
    # the hand and goes with it when the hand moves off.
    face, hand, moved = (160, 100), (186, 118), (194, 132)

    def skin_with_hand_at(xy: tuple[int, int]) -> np.ndarray:
        skin = np.zeros((240, 320), np.uint8)
        cv2.circle(skin, face, 20, 255, -1)
        cv2.circle(skin, xy, 9, 255, -1)
        return skin

    ends = {}
    for kept_off in (False, True):
        follower = HandFollower(window_side=0.5)
        follower.start("right_arm", (178.0, 110.0), shoulder_px=80.0)
        disc = (face, 20.0) if kept_off else None
        at_ear = follower.step(skin_with_hand_at(hand), disc)["right_arm"]
        ends[kept_off] = (at_ear, follower.step(skin_with_hand_at(moved), disc)["right_arm"])
    assert np.hypot(*(ends[False][0] - face)) < 1.0 and np.hypot(*(ends[False][1] - face)) < 1.0
    assert np.hypot(*(ends[True][0] - hand)) < 1.0 and np.hypot(*(ends[True][1] - moved)) < 1.0


def test_a_followed_hand_merged_with_the_head_is_put_at_its_followed_point() -> None:
    plate = np.zeros((48, 64, 3), np.uint8)
    features = FeatureExtractor(Background.from_plate(plate))(plate)
    head = SkinPoint((30.0, 12.0), True, 0)
    on_face = SkinPoint((30.0, 12.0), True, 0, (36.0, 10.0, 44.0, 20.0))
    together = SkinPoint((20.0, 40.0), True, 1)  # merged with the other hand, not the head
    features = dataclasses.replace(features, head=head, right_hand=on_face, left_hand=together)
    followed = {"right_arm": np.array([41.0, 15.0]), "left_arm": np.array([18.0, 38.0])}
    out = hands_on_followed_points(features, followed)
    assert out.right_hand == SkinPoint((41.0, 15.0), False, 0)
    assert out.left_hand is together and out.head is head
    assert hands_on_followed_points(features, {}) is features
    assert hands_on_followed_points(dataclasses.replace(features, head=None), followed).right_hand is on_face


class _Rendered:
    """Ideal features of a rendered pose (silhouette, contours as edges, joints as skin points)."""

    def __init__(self, pose: upperpose.Pose, root: np.ndarray, body: upperpose.BodyModel, camera: upperpose.Camera):
        m = upperpose.render_masks(pose, root, camera, 640, 480, body)
        self.sil_bits = pack_rows(m["silhouette"])
        self.edge_bits = pack_rows((m["contour"] > 0).astype(np.uint8))
        self.motion_bits = pack_rows(np.zeros_like(m["contour"]))
        self.points = upperpose.project(camera, upperpose.model.model_points(pose, root, body))[[0, 5, 6]].copy()
        self.size = (480, 640)

    def points_array(self) -> np.ndarray:
        return self.points


def _fit_rendered_person(
    person: upperpose.BodyModel, candidates: list[upperpose.BodyModel], camera: upperpose.Camera, **kw: object
) -> StartupFit:
    """Fits candidates to a rendered A-pose `person`, each placed with its head on the person's."""
    root = np.array([0.02, 0.12, 2.2])
    pose = upperpose.Pose.a_pose()
    head_px = upperpose.project(camera, upperpose.model.model_points(pose, root, person))[0]
    frontal = np.ones(13)
    frontal[0] = 0.0
    return fit_bodies(
        upperpose.fit_frame,
        _Rendered(pose, root, person, camera),
        pose.angles,
        candidates,
        camera,
        lambda c: (c, root_from_head(camera, head_px, 2.2, pose, c)),
        window_scale=3.0,
        angle_window_scales=frontal,
        **kw,
    )


@pytest.mark.parametrize("true_scale", [0.85, 1.1])
def test_start_up_width_is_chosen_by_the_cost(true_scale: float, camera: upperpose.Camera) -> None:
    # A person in the A-pose, narrower or wider than the measured width: the fit with the
    # true width has the lowest cost, frontal (turn held at zero).
    base = upperpose.BodyModel()
    person = widened(base, true_scale)
    candidates = [widened(base, k) for k in (0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15)]
    chosen = _fit_rendered_person(person, candidates, camera)
    assert chosen.body.shoulder_width == pytest.approx(person.shoulder_width)
    assert chosen.candidate == chosen.body
    assert chosen.fit.pose[0] == 0.0


@pytest.mark.parametrize("true_scale", [0.88, 1.12])
def test_start_up_head_height_is_chosen_by_the_torso_cost(true_scale: float, camera: upperpose.Camera) -> None:
    # The head a little lower or higher above the shoulders than the averages: with the head
    # put on the face, only the candidate of the true height has its shoulders on the person's.
    base = upperpose.BodyModel()
    person = head_raised(base, true_scale)
    assert person.head_offset - person.neck_length == pytest.approx(base.head_offset - base.neck_length)
    candidates = [head_raised(base, k) for k in (0.8, 0.88, 0.94, 1.0, 1.06, 1.12, 1.2)]
    chosen = _fit_rendered_person(person, candidates, camera, score=lambda fit: fit.stage_costs["torso"])
    assert chosen.body.head_offset == pytest.approx(person.head_offset)


def test_fit_bodies_keeps_a_better_incumbent(camera: upperpose.Camera) -> None:
    base = upperpose.BodyModel()
    first = _fit_rendered_person(base, [base], camera)
    again = _fit_rendered_person(base, [head_raised(base, 1.2), widened(base, 1.2)], camera, best=first)
    assert again is first
    with pytest.raises(ValueError, match="candidates"):
        _fit_rendered_person(base, [], camera)


# -- on a rendered clip, with a search double -------------------------------------------------


def run_clip(fitter: TruthFitter, extra_empty: int = 0, force_lost_at: int | None = None) -> list[str]:
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    tracker = Tracker(camera_of(folder), plate, TrackerConfig(), fps=15.0, fitter=fitter)
    statuses = []
    with VideoReader(folder / "video.mp4") as reader:
        for i, frame in enumerate(reader):
            if i == force_lost_at:
                tracker.force_lost("right_arm")
            statuses.append(tracker.update(frame).status)
    rng = np.random.default_rng(0)
    for _ in range(extra_empty):  # the person leaves: the empty room, with sensor noise
        noisy = np.clip(plate.astype(np.int16) + rng.integers(-3, 4, plate.shape), 0, 255).astype(np.uint8)
        statuses.append(tracker.update(noisy).status)
    return statuses


@pytest.fixture(scope="module")
def gt() -> dict:
    return truth(clip())


def test_search_options_reach_the_search_config() -> None:
    config = TrackerConfig(particles=12, search_options={"mask_other_arm_edges": False, "weights": {"edge": 1.0}})
    search = config.search_config()
    assert (search.particles, search.mask_other_arm_edges, search.weights["edge"]) == (12, False, 1.0)
    assert TrackerConfig(seed=1, search_options={"seed": 3}).search_config().seed == 3
    with pytest.raises(TypeError, match="passes"):
        TrackerConfig(search_options={"passes": 1}).search_config()


def test_states_from_empty_room_to_tracked_and_back(gt: dict) -> None:
    fitter = TruthFitter(gt)
    statuses = run_clip(fitter, extra_empty=12)
    first_person = next(i for i, f in enumerate(gt["frames"]) if f["status"] == "tracked")
    assert all(s == NO_PERSON for s in statuses[:first_person])  # empty room
    assert INITIALISING in statuses
    start = statuses.index(TRACKED)
    assert statuses.index(INITIALISING) < start < 50
    assert statuses[start:50].count(TRACKED) >= 0.9 * (50 - start)
    assert statuses[-1] == NO_PERSON and statuses[50:].count(NO_PERSON) >= 4  # the person left
    # the start-up frame searches every part, around the A-pose
    assert (start, "trajectory", ("torso", "right_arm", "left_arm")) in fitter.calls


def test_recovery_after_a_forced_loss(gt: dict) -> None:
    fitter = TruthFitter(gt)
    statuses = run_clip(fitter, force_lost_at=40)
    assert (40, "initial", ("right_arm",)) in fitter.calls  # the lost arm searches its full ranges
    assert (40, "trajectory", ("torso", "right_arm", "left_arm")) not in fitter.calls
    # the full-range search found the hand on its skin point: tracked again at once
    assert statuses[40:].count(TRACKED) >= len(statuses[40:]) - 1


def test_real_loss_is_detected_and_recovered(gt: dict) -> None:
    # The search double puts the right arm overhead whenever it is searched on frames 36-47
    # (the motion flags decide which those are) while the hand is down: the lost detector must
    # fire, the arm be searched over its ranges and found again.
    fitter = TruthFitter(gt, wrong=range(36, 48))
    statuses = run_clip(fitter)
    assert LOST in statuses[36:48]
    lost_at = statuses.index(LOST, 36)
    assert any(c[0] >= lost_at and c[1] == "initial" and c[2] == ("right_arm",) for c in fitter.calls)
    assert statuses[-1] == TRACKED


class ThroughCameraFitter(TruthFitter):
    """The search double, for a person filming themselves at arm's length: on `near` frames
    the trajectory search returns the right arm pointing straight at a camera 0.5 m away (the
    hand 0.1 m behind it); the full-range search finds the true arm."""

    def __init__(self, gt: dict[str, Any], near: range) -> None:
        super().__init__(gt)
        self.near = near

    def __call__(self, features: object, prediction: object, root: object, body: object, camera: object, **kw: object):  # type: ignore[no-untyped-def]
        index = kw["frame_index"]
        if index in self.near:
            root = np.array([*np.asarray(root)[:2], 0.5])
        fit = super().__call__(features, prediction, root, body, camera, **kw)
        if kw["mode"] != "trajectory" or index not in self.near or "right_arm" not in kw["search"]:  # type: ignore[operator]
            return fit
        pose = np.array(fit.pose)
        pose[3:8] = [0.0, np.pi / 2, 0.0, 0.0, 0.0]
        joints = upperpose.forward_kinematics(pose, fit.root, body)
        return StaticFit(pose, fit.root, joints, upperpose.project(camera, joints), fit.cost, fit.stage_costs)


def test_an_arm_through_the_camera_is_searched_again_over_its_ranges(gt: dict) -> None:
    # A stage whose every candidate reaches the camera keeps its prediction; the tracker must
    # not take such an arm, whose joints project to infinity (and would make the pose file
    # unwritable), but search it over its whole range.
    near = range(41, 47)  # the wave: the right arm is searched
    fitter = ThroughCameraFitter(gt, near)
    folder = clip()
    camera = camera_of(folder)
    tracker = Tracker(camera, cv2.imread(str(folder / "background.png")), TrackerConfig(), fps=15.0, fitter=fitter)
    results = []
    with VideoReader(folder / "video.mp4") as reader:
        for frame in reader:
            results.append(tracker.update(frame))
    pointing = upperpose.forward_kinematics([0, 0, 0, 0, np.pi / 2, 0, 0, 0, 0, 0, 0, 0, 0], [0, 0, 0.5], tracker.body)
    assert pointing[5, 2] < 0  # the double's arm does reach through the camera
    assert any(i in near and mode == "trajectory" and "right_arm" in parts for i, mode, parts in fitter.calls)
    assert any(i in near and (mode, parts) == ("initial", ("right_arm",)) for i, mode, parts in fitter.calls)
    for r in results:
        if r.pose is not None:
            assert np.all(np.isfinite(r.joints_2d)), r.frame
            assert reaching_camera(r.pose, r.root, tracker.body, camera) == (), r.frame
            assert r.joints_3d[:, 2].min() >= MIN_JOINT_DEPTH or r.frame not in near


class RegionBiasedFitter(TruthFitter):
    """The search double, with the full-range search's bias: its larger regions lower the cost
    of any pose (here by 0.1), and it returns a wrong right arm (raised overhead)."""

    def __call__(self, features: object, prediction: object, root: object, body: object, camera: object, **kw: object):  # type: ignore[no-untyped-def]
        fit = super().__call__(features, prediction, root, body, camera, **kw)
        if kw["mode"] != "initial":
            return fit
        pose = np.array(fit.pose)
        if "right_arm" in kw["search"]:  # type: ignore[operator]
            pose[3:8] = [0.0, 0.0, 2.8, 0.0, 0.0]
        joints = upperpose.forward_kinematics(pose, fit.root, body)
        return StaticFit(pose, fit.root, joints, upperpose.project(camera, joints), fit.cost - 0.1, fit.stage_costs)


@pytest.mark.parametrize("fair", [True, False])
def test_a_lost_arm_compares_both_fits_in_the_same_regions(gt: dict, fair: bool) -> None:
    # Scored in its own (larger) regions the wrong full-range fit wins; scored against the
    # trajectory fit in the same regions it does not. (Re-seeking the arm from its hand, which
    # rescores fits too, is off so that only the recovery's comparison is seen.)
    fitter = RegionBiasedFitter(gt)
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    config = TrackerConfig(fair_recovery=fair, reach_candidates=0)
    tracker = Tracker(camera_of(folder), plate, config, fps=15.0, fitter=fitter)
    raised = []
    with VideoReader(folder / "video.mp4") as reader:
        for i, frame in enumerate(reader):
            if i == 40:
                tracker.force_lost("right_arm")
            pose = tracker.update(frame).pose
            raised.append(pose is not None and pose[5] == 2.8)
    assert ((40, "initial", ()) in fitter.calls) == fair  # the trajectory fit rescored
    assert any(raised[40:]) != fair


class StuckElbowFitter(TruthFitter):
    """The search double with a stuck right elbow: on `wrong` frames its trajectory search
    bends the right elbow 0.7 rad more than the truth (the hand off its blob by less than the
    lost threshold). Every pose costs 0.5 plus its distance from the truth, so a full-range
    search, which finds the truth, wins a comparison. Keeps each call's prediction."""

    def __init__(self, gt: dict, wrong: range) -> None:
        super().__init__(gt, wrong)
        self.predictions: dict[int, np.ndarray] = {}

    def __call__(self, features: object, prediction: object, root: object, body: object, camera: object, **kw: object):  # type: ignore[no-untyped-def]
        index, mode = kw["frame_index"], kw["mode"]
        if mode == "trajectory":
            self.predictions[index] = np.array(prediction)  # type: ignore[arg-type]
        fit = super().__call__(features, prediction, root, body, camera, **kw)
        pose = np.array(fit.pose)
        true = self.frames[index]["angles"]  # type: ignore[index]
        if mode == "trajectory" and index in self.wrong and "right_arm" in kw["search"]:  # type: ignore[operator]
            pose[PART_ANGLES["right_arm"]] = true[3:8]
            pose[6] += 0.7  # right_x_down
        cost = 0.5 + (float(np.abs(pose - true).sum()) if true is not None else 0.0)
        joints = upperpose.forward_kinematics(pose, fit.root, body)
        return StaticFit(pose, fit.root, joints, upperpose.project(camera, joints), cost, fit.stage_costs)


@pytest.mark.parametrize("doubt_frames", [3, 0])
def test_an_arm_that_stays_off_its_hand_blob_is_searched_over_its_ranges(gt: dict, doubt_frames: int) -> None:
    fitter = StuckElbowFitter(gt, wrong=range(30, 50))
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    # Every part searched every frame: the stuck elbow, not a motion flag, keeps the hand off.
    # At the truth the left hand's skin point sits 0.25-0.27 shoulder widths from the model's in
    # this small clip, about the default limit: 0.3 keeps the left arm out of doubt. Re-seeking
    # the arm from its hand is off: this is the doubt's test.
    config = TrackerConfig(doubt_frames=doubt_frames, doubt_share=0.3, skip_static=False, reach_candidates=0)
    tracker = Tracker(camera_of(folder), plate, config, fps=15.0, fitter=fitter)
    results, poses = [], []
    with VideoReader(folder / "video.mp4") as reader:
        for frame in reader:
            results.append(tracker.update(frame))
            poses.append(None if results[-1].pose is None else results[-1].pose.copy())
    assert all(p is None or np.array_equal(p, r.pose) for p, r in zip(poses, results))  # results stay as given
    assert LOST not in [r.status for r in results]  # off its blob, but not lost
    wide = [c[0] for c in fitter.calls if c[1] == "initial" and c[2] == ("right_arm",)]
    assert bool(wide) == (doubt_frames > 0)
    for k in wide:
        # the full-range fit is taken, and the next frame does not extrapolate the correction
        assert np.allclose(results[k].pose[3:8], gt["frames"][k]["angles"][3:8])
        assert "right_arm" in results[k].searched
        if k + 1 in fitter.predictions:
            assert np.allclose(fitter.predictions[k + 1][3:8], results[k].pose[3:8])


def test_start_up_waits_while_the_face_moves() -> None:
    # The clip's person stands in the A-pose; a face box that jumps 0.6 of its width every
    # frame is a person still walking: no start-up.
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    detect = FaceDetector()
    count = [0]

    def jumping(frame: np.ndarray) -> list:
        count[0] += 1
        shift = 0.3 if count[0] % 2 else -0.3
        return [(int(x + shift * w), y, w, h) for x, y, w, h in detect(frame)]

    fitter = TruthFitter(truth(folder))
    tracker = Tracker(camera_of(folder), plate, TrackerConfig(), fps=15.0, fitter=fitter, face_detector=jumping)
    with VideoReader(folder / "video.mp4") as reader:
        statuses = [tracker.update(frame).status for frame in reader]
    assert INITIALISING in statuses and TRACKED not in statuses


@pytest.mark.parametrize("steady_face_frames", [8, 0])
def test_a_face_too_cool_for_the_skin_rule_starts_tracking_once_steady(steady_face_frames: int) -> None:
    # Bluish light leaves the face no generic skin; the cascade still finds it in one place.
    def cool(image: np.ndarray) -> np.ndarray:
        return np.clip(image * np.array([1.25, 1.0, 0.7]), 0, 255).astype(np.uint8)

    folder = clip()
    plate = cool(cv2.imread(str(folder / "background.png")))
    config = TrackerConfig(steady_face_frames=steady_face_frames)
    tracker = Tracker(camera_of(folder), plate, config, fps=15.0, fitter=TruthFitter(truth(folder)))
    with VideoReader(folder / "video.mp4") as reader:
        statuses = [tracker.update(cool(frame)).status for frame in reader]
    assert (TRACKED in statuses) == (steady_face_frames > 0)


def test_track_video_streams_one_result_per_frame(gt: dict) -> None:
    folder = clip()
    stream = upperpose.track_video(
        folder / "video.mp4", folder / "background.png", camera=camera_of(folder), fitter=TruthFitter(gt)
    )
    assert iter(stream) is stream  # a generator: nothing is kept between frames
    results = list(stream)
    assert [r.frame for r in results] == list(range(50))
    assert results[0].status == NO_PERSON and results[-1].status == TRACKED
    assert results[-1].joints_3d.shape == (7, 3) and results[-1].pose.shape == (13,)


class LocalSearchFitter(TruthFitter):
    """A search double that is local: every pose costs 0.5 plus its distance from the truth, and
    a search finds a part's true angles only when the prediction lies within 0.3 rad of them
    per angle, times the window scale (otherwise the part stays where predicted). On frame
    `knock` the right arm's trajectory search returns it swung out to the side, far from its
    hand's blob."""

    def __init__(self, gt: dict, knock: int) -> None:
        super().__init__(gt)
        self.knock = knock

    def __call__(self, features: object, prediction: object, root: object, body: object, camera: object, **kw: object):  # type: ignore[no-untyped-def]
        index, mode, search = kw["frame_index"], kw["mode"], tuple(kw["search"])  # type: ignore[arg-type]
        self.calls.append((index, mode, search))  # type: ignore[arg-type]
        pose = np.array(prediction, dtype=np.float64)
        true = self.frames[min(index, len(self.frames) - 1)]["angles"]  # type: ignore[call-overload]
        if true is not None:
            for part in search:
                near = np.abs(pose[PART_ANGLES[part]] - np.asarray(true)[PART_ANGLES[part]]).max()
                if near <= 0.3 * float(kw["window_scale"]):  # type: ignore[arg-type]
                    pose[PART_ANGLES[part]] = np.asarray(true)[PART_ANGLES[part]]
        if mode == "trajectory" and index == self.knock and "right_arm" in search:
            pose[PART_ANGLES["right_arm"]] = [0.0, 0.0, 1.6, 0.0, 0.0]
        cost = 0.5 + (float(np.abs(pose - np.asarray(true)).sum()) if true is not None else 0.0)
        r = np.array(root, dtype=np.float64)
        joints = upperpose.forward_kinematics(pose, r, body)
        return StaticFit(pose, r, joints, upperpose.project(camera, joints), cost, {part: cost / 3 for part in PARTS})


@pytest.mark.parametrize("reach", [6, 0])
def test_an_arm_knocked_off_its_hand_is_sought_again_from_the_hand(gt: dict, reach: int) -> None:
    # The arm swung out (the hand a shoulder width from its blob) lies beyond the local search's
    # windows: only re-seeking it from the hand's skin point brings it back. The lost and doubt
    # detectors are off so that only the reach acts.
    knock = 32
    fitter = LocalSearchFitter(gt, knock)
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    config = TrackerConfig(reach_candidates=reach, doubt_frames=0, lost_threshold=100.0, skip_static=False)
    tracker = Tracker(camera_of(folder), plate, config, fps=15.0, fitter=fitter)
    arms = []
    with VideoReader(folder / "video.mp4") as reader:
        for i, frame in enumerate(reader):
            result = tracker.update(frame)
            if i >= knock and result.pose is not None:
                true = np.asarray(gt["frames"][i]["angles"])[PART_ANGLES["right_arm"]]
                arms.append(float(np.abs(result.pose[PART_ANGLES["right_arm"]] - true).max()))
    assert arms[0] >= 1.0  # knocked off
    assert (min(arms[1:4]) < 1e-9) == (reach > 0)  # found again within three frames, or never
    assert (arms[-1] < 1e-9) == (reach > 0)


class LabelledFitter(TruthFitter):
    """A search double for the hands' labelling: a pose costs 0.5 plus its angle distance from
    `prefer` (the shape terms, which do not care about labels) plus the pixel distance of each
    model hand from the skin point labelled with it, over 100 (the Skin term). A search finds
    `prefer`'s arm angles when the prediction lies within 0.3 rad of them per angle, times the
    window scale."""

    def __init__(self, gt: dict, prefer: np.ndarray) -> None:
        super().__init__(gt)
        self.prefer = prefer

    def __call__(self, features, prediction, root, body, camera, **kw):  # type: ignore[no-untyped-def]
        pose = np.array(prediction, dtype=np.float64)
        for part in kw["search"]:
            sl = PART_ANGLES[part]
            if np.abs(pose[sl] - self.prefer[sl]).max() <= 0.3 * float(kw["window_scale"]):
                pose[sl] = self.prefer[sl]
        r = np.array(root, dtype=np.float64)
        joints = upperpose.forward_kinematics(pose, r, body)
        hands = upperpose.project(camera, model_points(pose, r, body))[[5, 6]]
        labelled = [features.right_hand, features.left_hand]
        skin = sum(float(np.hypot(*(h - p.xy))) / 100.0 for h, p in zip(hands, labelled) if p is not None)
        cost = 0.5 + float(np.abs(pose - self.prefer).sum()) + skin
        return StaticFit(pose, r, joints, upperpose.project(camera, joints), cost)


class FeatureKeeper(Tracker):
    """A tracker that keeps the features of the frames it accepts."""

    kept: dict[int, object] = {}

    def _accept(self, fit, features, index, searched, timings):  # type: ignore[no-untyped-def]
        self.kept[index] = features
        return super()._accept(fit, features, index, searched, timings)


@pytest.mark.parametrize("truth_cheaper", [True, False])
def test_crossed_arms_on_swapped_hand_points_are_untangled_when_that_costs_less(gt: dict, truth_cheaper: bool) -> None:
    # Frame 40: the truth's hands hold their own blobs. The fit crosses the arms (each hand on the
    # other's blob) and the features carry the labels swapped to match, as the matching does when
    # the prediction carried the hands past each other. Relabelled, the uncrossed truth costs less.
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    tracker = FeatureKeeper(
        camera_of(folder), plate, TrackerConfig(skip_static=False), fps=15.0, fitter=TruthFitter(gt)
    )
    with VideoReader(folder / "video.mp4") as reader:
        for i, frame in enumerate(reader):
            tracker.update(frame)
            if i == 40:
                break
    features = tracker.kept[40]
    assert features.right_hand is not None and features.left_hand is not None  # type: ignore[attr-defined]
    truth_pose = np.asarray(gt["frames"][40]["angles"], dtype=np.float64)
    root = np.asarray(tracker._last_root)
    reach = ArmReach(tracker.body)
    crossed = truth_pose.copy()
    for arm, point in (("right_arm", features.left_hand), ("left_arm", features.right_hand)):  # type: ignore[attr-defined]
        # A fit never has an arm through the other (the search rejects it): the first candidate
        # that has not.
        options = reach.candidates(arm, crossed, root, tracker.camera, point.xy, 12, 60.0, 1.0)
        crossed = next(c for c in options if not penetrates(c, root, tracker.body))
    swapped = dataclasses.replace(features, right_hand=features.left_hand, left_hand=features.right_hand)  # type: ignore[arg-type,attr-defined]
    tracker._fitter = LabelledFitter(gt, truth_pose if truth_cheaper else crossed)
    joints = upperpose.forward_kinematics(crossed, root, tracker.body)
    fit = StaticFit(crossed, root, joints, upperpose.project(tracker.camera, joints), 1.0)
    kept, labels, moved = tracker._corrections.untangle_hands(swapped, fit, tracker._frame_search(40, 1 / 15))
    if truth_cheaper:
        assert np.allclose(kept.pose, truth_pose) and moved == ("right_arm", "left_arm")
        assert labels.right_hand is features.right_hand  # type: ignore[attr-defined]
    else:
        assert kept is fit and labels is swapped and moved == ()


def test_a_pose_the_search_rejects_is_never_the_cheaper_by_fair_cost(gt: dict) -> None:
    # The fitter scores an unsearched arm stage whose arm goes through the torso or the other arm
    # as 0 (the stage has no terms): compared as it is, such a pose would beat every real one.
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    tracker = FeatureKeeper(camera_of(folder), plate, TrackerConfig(skip_static=False), fps=15.0)
    with VideoReader(folder / "video.mp4") as reader:
        for i, frame in enumerate(reader):
            tracker.update(frame)
            if i == 40:
                break
    features, root = tracker.kept[40], np.asarray(tracker._last_root)
    search = tracker._frame_search(40, 1 / 15)
    truth_pose = np.asarray(gt["frames"][40]["angles"], dtype=np.float64)
    assert not penetrates(truth_pose, root, tracker.body)
    rng = np.random.default_rng(0)
    low, high = np.array([ranges[0] for ranges in upperpose.joint_limits()]).T
    arm = PART_ANGLES["left_arm"]
    through = truth_pose.copy()
    for _ in range(1000):  # random left arms until one passes through the body
        through[arm] = rng.uniform(low[arm], high[arm])
        if penetrates(through, root, tracker.body):
            break
    assert penetrates(through, root, tracker.body)
    raw = search.run(features, through, root, "initial", ())  # type: ignore[arg-type]
    assert raw.stage_costs["left_arm"] == 0.0
    assert search.fair_cost(features, through, root) == np.inf  # type: ignore[arg-type]
    scored = float(search.run(features, truth_pose, root, "initial", ()).cost)  # type: ignore[arg-type]
    assert np.isfinite(scored) and search.fair_cost(features, truth_pose, root) == scored  # type: ignore[arg-type]


def test_move_to_face_puts_the_model_head_on_the_face_and_forgets_the_velocity() -> None:
    estimator, camera, body, pose = _root_estimator()
    fitted = None
    for k in range(4):  # a head point sliding down 10 px a frame (a hand down the chest)
        fitted = estimator.update(_HeadOnly((320.0, 150.0 + 10.0 * k), (50, 60)), pose, fitted)
    root = estimator.move_to_face([320.0, 150.0], pose)
    head = upperpose.project(camera, model_points(pose, root, body))[0]
    np.testing.assert_allclose(head, [320.0, 150.0], atol=1e-6)
    assert estimator.face_px == pytest.approx(50.0)
    # The next frame starts from the face, not from the slide's velocity.
    fitted = estimator.update(_HeadOnly((320.0, 150.0), (50, 60)), pose, root)
    head = upperpose.project(camera, model_points(pose, fitted, body))[0]
    np.testing.assert_allclose(head, [320.0, 150.0], atol=0.5)


@pytest.mark.parametrize(("slide", "check", "moved"), [(2.0, 5, True), (2.0, 0, False), (-2.0, 5, False)])
def test_a_model_head_carried_off_the_face_is_put_back_under_it(
    monkeypatch: pytest.MonkeyPatch, gt: dict, slide: float, check: int, moved: bool
) -> None:
    # From frame 26 (tracked from about 21) the head's skin point slides `slide` pixels a frame
    # (down: a hand held to the chest carries it; up: the check leaves a face below the head
    # alone, a bow), until the face check moves the root.
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    update, move = RootEstimator.update, RootEstimator.move_to_face
    moves: list[np.ndarray] = []
    frame_index = [0]

    def sliding(self: RootEstimator, features: object, pose: object, fitted_root: object = None) -> np.ndarray:
        head = features.head  # type: ignore[attr-defined]
        if not moves and frame_index[0] >= 26 and head is not None:
            x, y = head.xy
            carried = dataclasses.replace(head, xy=(x, y + slide * (frame_index[0] - 25)))
            features = dataclasses.replace(features, head=carried)  # type: ignore[type-var]
        return update(self, features, pose, fitted_root)  # type: ignore[arg-type]

    def moving(self: RootEstimator, face_px: object, pose: object) -> np.ndarray:
        moves.append(np.asarray(face_px, dtype=np.float64))
        return move(self, face_px, pose)  # type: ignore[arg-type]

    monkeypatch.setattr(RootEstimator, "update", sliding)
    monkeypatch.setattr(RootEstimator, "move_to_face", moving)
    camera = camera_of(folder)
    tracker = Tracker(camera, plate, TrackerConfig(face_check_frames=check), fps=15.0, fitter=TruthFitter(gt))
    results = []
    with VideoReader(folder / "video.mp4") as reader:
        for k, frame in enumerate(reader):
            frame_index[0] = k
            results.append(tracker.update(frame))
            last_frame = frame
    assert bool(moves) == moved
    last = results[-1]
    head = upperpose.project(camera, model_points(last.pose, last.root, tracker.body))[0]
    box = FaceDetector()(last_frame)[0]
    face, width = face_centre(box), box[2]
    if moved:
        # Moved on the second check in a row (every 5 frames) that found the face away.
        assert len(moves) == 1
        np.testing.assert_allclose(moves[0], face, atol=0.25 * width)
        assert np.hypot(*(head - face)) < 0.25 * width
    else:
        assert np.hypot(*(head - face)) > width


class _SquareCountingDetector(FaceDetector):
    """The real detector, keeping the reach of every square searched around the head."""

    def __init__(self) -> None:
        super().__init__()
        self.reaches: list[float] = []

    def near(self, frame: np.ndarray, centre: object, width_px: float, reach: float) -> list:
        self.reaches.append(reach)
        return super().near(frame, centre, width_px, reach)


@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.3, -0.2), (0.0, 1.2), (-2.0, 0.5)])
def test_the_face_check_finds_the_face_the_whole_square_finds(offset: tuple[float, float]) -> None:
    # The model's head `offset` face widths from the face: on it (within the drift share, 0.5)
    # only the small square around the head is searched; off it, the whole reach finds it.
    folder = clip()
    detector = _SquareCountingDetector()
    with VideoReader(folder / "video.mp4") as reader:
        frame = next(f for f in reader if detector(f))
    box = detector(frame)[0]
    face, width = face_centre(box), float(box[2])
    head = face + width * np.asarray(offset)
    plate = cv2.imread(str(folder / "background.png"))
    tracker = Tracker(camera_of(folder), plate, fps=15.0, face_detector=detector)
    found = tracker._faces_around_head(frame, head, width)
    whole = FaceDetector().near(frame, head, width, FACE_CHECK_REACH)
    assert found and whole
    np.testing.assert_allclose(face_centre(found[0]), face, atol=0.15 * width)
    np.testing.assert_allclose(face_centre(found[0]), face_centre(whole[0]), atol=0.15 * width)
    on_head = bool(np.hypot(*offset) <= 0.5)
    assert detector.reaches == ([1.5] if on_head else [1.5, FACE_CHECK_REACH])


@pytest.mark.parametrize("bad", [{"face_check_frames": -1}, {"face_check_frames": 2.5}, {"face_drift_share": 0.0}])
def test_bad_face_check_settings_are_refused(bad: dict) -> None:
    with pytest.raises(upperpose.InputError, match=next(iter(bad))):
        TrackerConfig(**bad)
