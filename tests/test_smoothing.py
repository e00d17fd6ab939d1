"""The fixed-lag angle smoother: exact on quadratics to the ends of a run, no lag, every frame once.

Runs of poses, and a part's angles on either side of a re-seed, are never mixed.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.fit.smoothing import PART_ANGLES, PoseSmoother, steady_span, window_weights
from upperpose.model import BodyModel, Camera, Pose, forward_kinematics, project, reaching_camera
from upperpose.result import NO_PERSON, TRACKED, TrackResult

CAMERA = Camera.for_image(640, 480)
BODY = BodyModel()
ROOT = np.array([0.0, 0.1, 2.2])


def result(i: int, pose: np.ndarray | None, root: np.ndarray = ROOT) -> TrackResult:
    if pose is None:
        return TrackResult(i, NO_PERSON)
    j3 = forward_kinematics(pose, root, BODY)
    return TrackResult(i, TRACKED, pose=pose, root=root, joints_3d=j3, joints_2d=project(CAMERA, j3), cost=1.0)


def run(smoother: PoseSmoother[int], results: list[TrackResult]) -> list[tuple[TrackResult, int]]:
    out = []
    for r in results:
        out += list(smoother.push(r, BODY, r.frame))
    return out + list(smoother.flush())


WINDOWS = [(before, after, lag) for lag in (1, 2, 3, 6) for before in range(lag + 1) for after in range(lag + 1)]


@pytest.mark.parametrize(("before", "after", "lag"), WINDOWS)
def test_weights_sum_to_one_and_keep_lines_and_quadratics(before: int, after: int, lag: int) -> None:
    w = window_weights(before, after, lag)
    assert len(w) == before + after + 1 and w.sum() == pytest.approx(1.0)
    k = np.arange(-before, after + 1, dtype=float)
    if len(k) >= 3:
        assert w @ (3.0 + 2.0 * k) == pytest.approx(3.0)
    if len(k) >= 4:
        assert w @ (3.0 + 2.0 * k - 0.7 * k * k) == pytest.approx(3.0)
    if len(k) <= 2:
        assert w[before] == 1.0  # too few frames to tell noise from motion: the value is kept


@pytest.mark.parametrize(("before", "after", "lag"), [w for w in WINDOWS if sum(w[:2]) >= 2])
def test_weights_are_a_tricube_weighted_polynomial_fit(before: int, after: int, lag: int) -> None:
    # Reference: numpy's weighted polynomial fit (its weights multiply the residuals, hence the root).
    k = np.arange(-before, after + 1, dtype=float)
    kernel = (1.0 - (np.abs(k) / (lag + 1)) ** 3) ** 3
    values = np.random.default_rng(before * 100 + after * 10 + lag).normal(size=k.size)
    fitted = np.polyval(np.polyfit(k, values, 2 if k.size >= 4 else 1, w=np.sqrt(kernel)), 0.0)
    assert window_weights(before, after, lag) @ values == pytest.approx(fitted, abs=1e-12)


def test_centred_weights_damp_noise_more_than_one_sided_ones() -> None:
    # Variance of the smoothed value of white noise, against 1 for the raw value.
    def variance(before: int, after: int) -> float:
        return float(np.sum(window_weights(before, after, 6) ** 2))

    assert variance(6, 6) < variance(3, 6) < variance(0, 6) < 1.0


def test_quadratic_motion_passes_unchanged() -> None:
    base = Pose.a_pose().angles
    t = np.arange(40, dtype=float)
    poses = [base + 0.002 * ti - 0.0001 * ti * ti for ti in t]
    roots = [ROOT + [0.001 * ti, 0.0, 0.0005 * ti * ti / 40] for ti in t]
    out = run(PoseSmoother(CAMERA, 3), [result(i, p, r) for i, (p, r) in enumerate(zip(poses, roots))])
    assert [r.frame for r, _ in out] == list(range(40))
    for (r, payload), p, root in zip(out, poses, roots):  # the ends of the run too
        assert payload == r.frame
        np.testing.assert_allclose(r.pose, p, atol=1e-12)
        np.testing.assert_allclose(r.root, root, atol=1e-12)
        np.testing.assert_allclose(r.joints_3d, forward_kinematics(p, root, BODY), atol=1e-9)
        np.testing.assert_allclose(r.joints_2d, project(CAMERA, forward_kinematics(p, root, BODY)), atol=1e-6)


def test_jitter_is_reduced_without_moving_the_mean() -> None:
    rng = np.random.default_rng(3)
    base = Pose.a_pose().angles
    noisy = [base + rng.normal(0, 0.02, 13) for _ in range(200)]
    out = run(PoseSmoother(CAMERA, 3), [result(i, p) for i, p in enumerate(noisy)])
    raw = np.array(noisy)
    smooth = np.array([r.pose for r, _ in out])
    assert np.diff(smooth, 2, axis=0).std() < 0.5 * np.diff(raw, 2, axis=0).std()
    np.testing.assert_allclose(smooth.mean(axis=0), raw.mean(axis=0), atol=2e-3)


@settings(max_examples=40, deadline=None)
@given(
    gaps=st.lists(st.booleans(), min_size=1, max_size=40),
    lag=st.integers(0, 5),
)
def test_every_frame_once_in_order_and_runs_never_mix(gaps: list[bool], lag: int) -> None:
    # Each run of poses has its own constant angles: smoothing must give back exactly those.
    results, value, previous = [], 0.0, False
    for i, posed in enumerate(gaps):
        if posed and not previous:
            value += 0.05
        results.append(result(i, Pose.a_pose().angles + value if posed else None))
        previous = posed
    out = run(PoseSmoother(CAMERA, lag), results)
    assert [r.frame for r, _ in out] == list(range(len(gaps)))
    for (r, _), given_result in zip(out, results):
        assert r.status == given_result.status
        if given_result.pose is None:
            assert r.pose is None
        else:
            np.testing.assert_allclose(r.pose, given_result.pose, atol=1e-12)


def test_lag_zero_passes_results_through_and_bad_lags_are_refused() -> None:
    results = [result(i, Pose.a_pose().angles + 0.01 * i * i) for i in range(6)]
    out = run(PoseSmoother(CAMERA, 0), results)
    assert [r for r, _ in out] == results
    with pytest.raises(ValueError, match="smoothing lag must be an integer within 0..30"):
        PoseSmoother(CAMERA, -1)


def test_a_smoothed_arm_never_reaches_through_the_camera() -> None:
    # A person 0.62 m away swinging an arm towards the camera: fitted poses with the arm at
    # x_up 0.8 and 2.3 rad keep every joint clear of the camera, their average (pointing at it)
    # puts the hand behind it. Such frames keep the fitted pose.
    root = np.array([0.0, 0.1, 0.62])
    swings = [np.zeros(13) for _ in range(15)]
    for i, pose in enumerate(swings):
        pose[4] = 0.8 if i % 2 else 2.3
    assert all(not reaching_camera(p, root, BODY, CAMERA) for p in swings)
    middle = np.zeros(13)
    middle[4] = 1.55
    assert reaching_camera(middle, root, BODY, CAMERA) == ("right_arm",)
    # Steps of 1.5 rad are a re-seeded arm to the default smoother, which then keeps each frame's
    # own arm: without that split the fallback must still hold.
    out = run(PoseSmoother(CAMERA, lag=6, max_step=np.inf), [result(i, p, root) for i, p in enumerate(swings)])
    kept = 0
    for r, _ in out:
        assert reaching_camera(r.pose, r.root, BODY, CAMERA) == ()
        assert np.all(np.isfinite(r.joints_2d))
        kept += int(np.array_equal(r.pose, swings[r.frame]))
    assert kept > 0


@settings(max_examples=200, deadline=None)
@given(
    steps=st.lists(st.floats(-2.0, 2.0), min_size=0, max_size=14),
    centre=st.integers(0, 14),
    max_step=st.floats(0.1, 1.5),
)
def test_steady_span_is_the_widest_window_without_a_jump(steps: list[float], centre: int, max_step: float) -> None:
    values = np.cumsum([0.0, *steps])[:, None] * np.array([1.0, -0.5])  # the second column never jumps alone
    centre = min(centre, len(steps))
    before, after = steady_span(values, centre, len(steps) - centre, max_step)

    def jump(k: int) -> bool:  # from row k to k + 1
        return bool(np.abs(values[k + 1] - values[k]).max() > max_step)

    assert 0 <= before <= centre and 0 <= after <= len(steps) - centre
    assert not any(jump(k) for k in range(centre - before, centre + after))
    assert before == centre or jump(centre - before - 1)
    assert after == len(steps) - centre or jump(centre + after)


def test_a_reseeded_arm_is_smoothed_on_each_side_of_its_jump_alone() -> None:
    # The right arm is found again in another configuration at frame 20 (its shoulder angles
    # jump by 1.5 rad). Averaged across the jump, its angles would pass through poses it never
    # took; each side's own quadratic motion must come out unchanged instead, while the noisy
    # torso, root and left arm are smoothed across the jump exactly as without it.
    rng = np.random.default_rng(5)
    t = np.arange(40, dtype=float)
    right = PART_ANGLES[1]
    steady, jumping = [], []
    for ti in t:
        pose = Pose.a_pose().angles + rng.normal(0, 0.02, 13)
        pose[right] = Pose.a_pose().angles[right] + 0.01 * ti - 0.0004 * ti * ti
        steady.append(pose.copy())
        if ti >= 20:
            pose[4] += 1.5  # x_up: the arm swung forwards
            pose[5] -= 0.004 * ti  # z_up: another motion after the jump, a line
        jumping.append(pose)
    roots = [ROOT + rng.normal(0, 0.005, 3) for _ in t]
    out = run(PoseSmoother(CAMERA, 6), [result(i, p, r) for i, (p, r) in enumerate(zip(jumping, roots))])
    without = run(PoseSmoother(CAMERA, 6), [result(i, p, r) for i, (p, r) in enumerate(zip(steady, roots))])
    for (r, _), (w, _), fitted in zip(out, without, jumping):
        np.testing.assert_allclose(r.pose[right], fitted[right], atol=1e-12)
        for part in (PART_ANGLES[0], PART_ANGLES[2]):
            np.testing.assert_allclose(r.pose[part], w.pose[part], atol=1e-12)
        np.testing.assert_allclose(r.root, w.root, atol=1e-12)
    smoothed_left = np.array([r.pose[PART_ANGLES[2]] for r, _ in out])
    raw_left = np.array([p[PART_ANGLES[2]] for p in jumping])
    assert np.diff(smoothed_left, 2, axis=0).std() < 0.5 * np.diff(raw_left, 2, axis=0).std()
