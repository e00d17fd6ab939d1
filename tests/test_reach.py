"""Arm poses that put a hand on an image point (upperpose.fit.reach)."""

from __future__ import annotations

from types import SimpleNamespace

import cv2
import numpy as np
import pytest

import upperpose
from upperpose.features import FeatureConfig, SkinPoint, find_skin_blobs
from upperpose.fit import StaticFit, TrackerConfig
from upperpose.fit.arm_corrections import ArmCorrections
from upperpose.fit.fitter import FrameSearch
from upperpose.fit.reach import ARM_ANGLES, ARM_JOINTS, ArmReach, hand_target, shared_blob_ends, unexplained
from upperpose.fit.search import SearchConfig
from upperpose.model import model_points, penetrates

BODY = upperpose.BodyModel()
CAMERA = upperpose.Camera.for_image(640, 480)
REACH = ArmReach(BODY)


def test_the_table_holds_for_any_torso_pose_and_root() -> None:
    # Hands and elbows tabulated with the torso upright at the origin, rotated and moved by the
    # torso's frame, are where forward kinematics puts them for the full pose.
    rng = np.random.default_rng(4)
    for _ in range(20):
        pose = np.zeros(13)
        pose[:3] = rng.uniform([-0.8, -0.3, -0.3], [0.8, 0.5, 0.3])
        root = rng.uniform([-0.3, -0.2, 1.5], [0.3, 0.2, 3.5])
        i = int(rng.integers(len(REACH.angles)))
        rotation = upperpose.skeleton(pose, root, BODY)["torso"]
        for arm, (elbow, hand) in ARM_JOINTS.items():
            full = pose.copy()
            full[ARM_ANGLES[arm]] = REACH.angles[i]
            points = model_points(full, root, BODY)
            assert np.allclose(root + rotation @ REACH.hands[arm][i], points[hand], atol=1e-12)
            assert np.allclose(root + rotation @ REACH.elbows[arm][i], points[elbow], atol=1e-12)


def test_no_tabulated_arm_passes_through_the_torso() -> None:
    alone = np.zeros(13)
    alone[ARM_ANGLES["left_arm"]] = (0.0, 0.0, 1.57, 0.0)
    for angles in REACH.angles[::7]:
        alone[ARM_ANGLES["right_arm"]] = angles
        assert not penetrates(alone, np.zeros(3), BODY)
    assert 1000 < len(REACH.angles) < 2700  # the grid, less the poses through the torso


@pytest.mark.parametrize("arm", ["right_arm", "left_arm"])
def test_candidates_put_the_hand_near_the_target(arm: str) -> None:
    rng = np.random.default_rng(7 if arm == "right_arm" else 8)
    root = np.array([0.05, 0.1, 2.2])
    for _ in range(10):
        pose = np.zeros(13)
        pose[:3] = rng.uniform(-0.2, 0.2, 3)
        pose[ARM_ANGLES[arm]] = rng.uniform([-1.0, -0.3, 0.0, 0.0], [1.0, 2.5, 2.5, 2.2])
        elbow, hand = ARM_JOINTS[arm]
        target = upperpose.project(CAMERA, model_points(pose, root, BODY))[hand]
        start = pose.copy()
        start[ARM_ANGLES[arm]] = 0.0
        found = REACH.candidates(arm, start, root, CAMERA, target, 6, tolerance_px=30.0, elbow_spread_px=10.0)
        assert 1 <= len(found) <= 6
        elbows = []
        for candidate in found:
            points = upperpose.project(CAMERA, model_points(candidate, root, BODY))
            assert np.hypot(*(points[hand] - target)) <= 30.0
            # Only the arm's searched angles change.
            keep = np.ones(13, bool)
            keep[ARM_ANGLES[arm]] = False
            assert np.array_equal(candidate[keep], start[keep])
            elbows.append(points[elbow])
        for a in range(len(elbows)):
            for b in range(a):
                assert np.hypot(*(elbows[a] - elbows[b])) >= 10.0
    # A point no arm can reach gives nothing.
    assert REACH.candidates(arm, np.zeros(13), root, CAMERA, (5000.0, 5000.0), 6, 30.0, 10.0) == []


@pytest.mark.parametrize("arm", ["right_arm", "left_arm"])
def test_the_candidate_keeping_the_elbow_comes_first(arm: str) -> None:
    # Untangling asks for the pose that keeps the arm's elbow where it is and moves the hand:
    # it comes first, its hand within the tolerance, and no candidate's elbow lies nearer.
    rng = np.random.default_rng(9 if arm == "right_arm" else 10)
    root = np.array([0.05, 0.1, 2.2])
    elbow, hand = ARM_JOINTS[arm]
    for _ in range(10):
        pose = np.zeros(13)
        pose[ARM_ANGLES[arm]] = rng.uniform([-1.0, -0.3, 0.0, 0.0], [1.0, 2.5, 2.5, 2.2])
        points = upperpose.project(CAMERA, model_points(pose, root, BODY))
        start = pose.copy()
        start[ARM_ANGLES[arm]] = 0.0
        kept = REACH.candidates(arm, start, root, CAMERA, points[hand], 6, 30.0, 10.0, near_elbow=points[elbow])
        plain = REACH.candidates(arm, start, root, CAMERA, points[hand], 6, 30.0, 10.0)
        assert 1 <= len(kept) <= 6

        def at(candidate: np.ndarray, joint: int) -> np.ndarray:
            return upperpose.project(CAMERA, model_points(candidate, root, BODY))[joint]

        first = float(np.hypot(*(at(kept[0], elbow) - points[elbow])))
        assert np.hypot(*(at(kept[0], hand) - points[hand])) <= 30.0
        assert all(first <= np.hypot(*(at(c, elbow) - points[elbow])) + 1e-9 for c in kept + plain)


def _features(shapes, points) -> SimpleNamespace:
    skin = np.zeros((480, 640), np.uint8)
    for draw in shapes:
        draw(skin)
    edge = cv2.morphologyEx(skin, cv2.MORPH_GRADIENT, np.ones((3, 3), np.uint8))
    blobs = find_skin_blobs(skin, edge, FeatureConfig())
    sil = np.zeros_like(skin)
    cv2.rectangle(sil, (150, 40), (500, 479), 255, -1)
    return SimpleNamespace(blobs=blobs, points=points(blobs), sil=sil)


def _blob_at(blobs, x, y) -> int:
    return min(range(len(blobs)), key=lambda i: np.hypot(blobs[i].centroid[0] - x, blobs[i].centroid[1] - y))


MODEL = np.array([[320, 100], [270, 170], [370, 170], [260, 230], [380, 230], [255, 290], [385, 290]], float)


def face(skin):
    cv2.ellipse(skin, (320, 100), (28, 36), 0, 0, 360, 255, -1)


def test_a_matched_hand_point_is_the_target_and_a_merged_one_none() -> None:
    hand = lambda skin: cv2.circle(skin, (250, 300), 18, 255, -1)  # noqa: E731
    features = _features(
        [face, hand],
        lambda b: (
            SkinPoint(b[_blob_at(b, 320, 100)].centroid, False, _blob_at(b, 320, 100)),
            SkinPoint((250.0, 300.0), False, _blob_at(b, 250, 300)),
            SkinPoint(b[_blob_at(b, 320, 100)].centroid, True, _blob_at(b, 320, 100)),
        ),
    )
    assert np.allclose(hand_target(features, "right_arm", MODEL), (250.0, 300.0))  # type: ignore[arg-type]
    assert hand_target(features, "left_arm", MODEL) is None  # type: ignore[arg-type]


def test_a_hand_without_a_blob_takes_the_nearest_free_blob_on_the_person() -> None:
    hand = lambda skin: cv2.circle(skin, (420, 380), 18, 255, -1)  # noqa: E731
    off_person = lambda skin: cv2.circle(skin, (560, 300), 20, 255, -1)  # noqa: E731
    scrap = lambda skin: cv2.circle(skin, (400, 250), 5, 255, -1)  # noqa: E731
    features = _features(
        [face, hand, off_person, scrap],
        lambda b: (SkinPoint(b[_blob_at(b, 320, 100)].centroid, False, _blob_at(b, 320, 100)), None, None),
    )
    target = hand_target(features, "left_arm", MODEL)  # type: ignore[arg-type]
    assert target is not None and np.hypot(target[0] - 420, target[1] - 380) < 10
    # Without the person's blob only the room's skin-coloured object and a scrap remain: no hand.
    features.blobs = [b for b in features.blobs if np.hypot(b.centroid[0] - 420, b.centroid[1] - 380) > 5]
    assert hand_target(features, "left_arm", MODEL) is None  # type: ignore[arg-type]


def test_a_hand_sharing_the_face_blob_takes_a_free_blob_when_there_is_one() -> None:
    # The matching put the left hand on the face (merged), while the real hand shows elsewhere.
    hand = lambda skin: cv2.circle(skin, (420, 380), 18, 255, -1)  # noqa: E731
    head = lambda b: SkinPoint(b[_blob_at(b, 320, 100)].centroid, True, _blob_at(b, 320, 100))  # noqa: E731
    features = _features([face, hand], lambda b: (head(b), None, head(b)))
    target = hand_target(features, "left_arm", MODEL)  # type: ignore[arg-type]
    assert target is not None and np.hypot(target[0] - 420, target[1] - 380) < 10


def test_a_target_either_fitted_hand_explains_is_not_reached_for() -> None:
    # MODEL's hands are at (255, 290) and (385, 290).
    assert not unexplained(MODEL, (260.0, 295.0), 20.0)  # the arm's own hand is there
    assert not unexplained(MODEL, (380.0, 300.0), 20.0)  # the other hand is there: maybe its point
    assert unexplained(MODEL, (320.0, 380.0), 20.0)
    assert not unexplained(MODEL, (320.0, 380.0), 120.0)  # 111 px from either hand


def _both_hands_on(blobs, x: float, y: float) -> tuple:  # type: ignore[no-untyped-def]
    """Skin points: the head on the face's blob, both hands merged on the blob nearest (x, y)."""
    head, hands = _blob_at(blobs, 320, 100), _blob_at(blobs, x, y)
    return (SkinPoint(blobs[head].centroid, False, head),) + (SkinPoint(blobs[hands].centroid, True, hands),) * 2


def test_a_blob_both_hands_share_gives_its_two_ends() -> None:
    # Forearms crossed in front of the belly: one bar of skin from (230, 300) to (410, 320), 24 px
    # thick, both hands' points merged at its centre. MODEL's shoulders are 100 px apart, so each
    # end is the centroid of the last 50 px of the bar: 25 px in from its tip along the bar.
    def bar(skin):
        cv2.line(skin, (230, 300), (410, 320), 255, 24)

    def shared(b):
        return _both_hands_on(b, 320, 310)

    features = _features([face, bar], shared)
    ends = shared_blob_ends(features, MODEL)  # type: ignore[arg-type]
    along = np.array([180.0, 20.0]) / np.hypot(180.0, 20.0)
    tips = sorted(ends, key=lambda e: e[0])
    assert len(ends) == 2
    assert np.hypot(*(tips[0] - (np.array([230.0, 300.0]) + 13.0 * along))) < 5.0
    assert np.hypot(*(tips[1] - (np.array([410.0, 320.0]) - 13.0 * along))) < 5.0
    # Not for hands on blobs of their own, a blob the head shares, or a blob with no long axis.
    separate = _features(
        [face, bar, lambda skin: cv2.circle(skin, (420, 400), 18, 255, -1)],
        lambda b: (
            None,
            SkinPoint((0.0, 0.0), False, _blob_at(b, 320, 310)),
            SkinPoint((0.0, 0.0), False, _blob_at(b, 420, 400)),
        ),
    )
    assert shared_blob_ends(separate, MODEL) == []  # type: ignore[arg-type]
    with_head = _features([face, bar], lambda b: (SkinPoint((0.0, 0.0), True, _blob_at(b, 320, 310)),) + shared(b)[1:])
    assert shared_blob_ends(with_head, MODEL) == []  # type: ignore[arg-type]
    round_blob = _features([face, lambda skin: cv2.circle(skin, (320, 310), 40, 255, -1)], shared)
    assert shared_blob_ends(round_blob, MODEL) == []  # type: ignore[arg-type]


class _HandTargetFitter:
    """A search double: a pose costs 0.5 plus each model hand's pixel distance from its target,
    over 100; a search returns the prediction unchanged (the seed is the result), or with the
    searched arms' angles taken from `found` when given."""

    def __init__(self, targets: np.ndarray, found: np.ndarray | None = None) -> None:
        self.targets, self.found = targets, found

    def __call__(self, features, prediction, root, body, camera, **kw):  # type: ignore[no-untyped-def]
        pose, r = np.array(prediction, dtype=np.float64), np.array(root, dtype=np.float64)
        for arm in kw["search"] if self.found is not None else ():
            pose[ARM_ANGLES[arm]] = self.found[ARM_ANGLES[arm]]
        hands = upperpose.project(camera, model_points(pose, r, body))[[5, 6]]
        cost = 0.5 + float(np.hypot(*(hands - self.targets).T).sum()) / 100.0
        joints = upperpose.forward_kinematics(pose, r, body)
        return StaticFit(pose, r, joints, upperpose.project(camera, joints), cost)


@pytest.mark.parametrize("case", ["crossed", "as_fitted", "elbow_moved"])
def test_the_free_end_of_a_blob_both_hands_share_is_reached_when_that_costs_less(case: str) -> None:
    # Both fitted hands lie at the right end of a bar of skin that both hands' points share (the
    # matching gave both hands the bar). "crossed": the cost puts the left hand at the free left
    # end, across the body, and that arm is sought there, its elbow kept. "as_fitted": the cost
    # prefers the hands where they are: nothing moves. "elbow_moved": the search ends with the
    # hand at the free end but the elbow more than half a shoulder width from the fit's (as a
    # hand put at the far end of forearms lying side by side, at their elbows, would): refused
    # however much less it costs.
    root = np.array([0.0, 0.1, 2.2])
    hands_end, free_end = np.array([350.0, 300.0]), np.array([270.0, 300.0])
    start = np.zeros(13)
    for arm in ("right_arm", "left_arm"):
        start = REACH.candidates(arm, start, root, CAMERA, hands_end, 1, 15.0, 1.0)[0]
    assert not penetrates(start, root, BODY)
    fitted = upperpose.project(CAMERA, model_points(start, root, BODY))
    sw = float(np.hypot(*(fitted[1] - fitted[2])))
    # The bar's ends' centroids lie a quarter shoulder width in from its tips
    # (`shared_blob_ends`, half a shoulder width long).
    tip = 0.25 * sw - 10.0

    def bar(skin):
        cv2.line(skin, (round(free_end[0] - tip), 300), (round(hands_end[0] + tip), 300), 255, 20)

    features = _features([face, bar], lambda b: _both_hands_on(b, 310, 300))
    ends = sorted(shared_blob_ends(features, fitted), key=lambda e: e[0])  # type: ignore[arg-type]
    assert np.hypot(*(ends[0] - free_end)) < 4.0 and np.hypot(*(ends[1] - hands_end)) < 4.0
    found = None
    if case == "elbow_moved":  # the hand at the free end, the elbow raised a shoulder width
        away = fitted[4] + np.array([0.0, -sw])
        found = REACH.candidates("left_arm", start, root, CAMERA, free_end, 1, 15.0, 1.0, near_elbow=away)[0]
        moved_elbow = upperpose.project(CAMERA, model_points(found, root, BODY))[4] - fitted[4]
        assert np.hypot(*moved_elbow) > 0.5 * sw
    targets = np.array([hands_end, hands_end if case == "as_fitted" else free_end])
    search = FrameSearch(_HandTargetFitter(targets, found), BODY, CAMERA, SearchConfig(), 0, 1 / 30)  # type: ignore[arg-type]
    fit = search.run(features, start, root, "initial", ())  # type: ignore[arg-type]
    if found is not None:  # cheaper, so only the elbow's move refuses it
        assert search.fair_cost(features, found, root) < fit.cost  # type: ignore[arg-type]
    kept, moved = ArmCorrections(TrackerConfig())._reach_free_end(features, fit, search)  # type: ignore[arg-type]
    joints = upperpose.project(CAMERA, model_points(np.asarray(kept.pose), root, BODY))
    if case == "crossed":
        assert moved == ["left_arm"]
        assert np.hypot(*(joints[6] - free_end)) < 0.5 * sw
        assert np.hypot(*(joints[4] - fitted[4])) <= 0.5 * sw
        assert np.allclose(np.asarray(kept.pose)[:8], start[:8])  # torso and right arm kept
    else:
        assert moved == [] and kept is fit
