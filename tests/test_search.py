"""The search from Python: recovery on rendered features, argument checks, threads, the GIL."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest

import upperpose
from upperpose.exceptions import InputError
from upperpose.features.packing import pack_rows

ROOT = np.array([0.02, 0.12, 2.2])


@dataclass
class IdealFeatures:
    """Features of a rendered pose: its silhouette, contours as edges, skin points at the joints."""

    sil_bits: np.ndarray
    edge_bits: np.ndarray
    motion_bits: np.ndarray
    points: np.ndarray
    size: tuple[int, int] = (480, 640)

    def points_array(self) -> np.ndarray:
        return self.points


def ideal(pose: upperpose.Pose, camera: upperpose.Camera) -> IdealFeatures:
    m = upperpose.render_masks(pose, ROOT, camera, 640, 480)
    j = upperpose.project(camera, upperpose.model.model_points(pose, ROOT))
    edge = np.zeros_like(m["contour"])
    edge[m["contour"] > 0] = 1
    return IdealFeatures(
        pack_rows(m["silhouette"]), pack_rows(edge), pack_rows(np.zeros_like(edge)), j[[0, 5, 6]].copy()
    )


WAVE = upperpose.Pose(right_z_up=1.3, right_x_down=1.4, right_y_up=-1.0, left_z_up=0.6)


def joint_error(fit: upperpose.FrameFit, truth: upperpose.Pose, camera: upperpose.Camera) -> float:
    target = upperpose.project(camera, upperpose.forward_kinematics(truth, ROOT))
    return float(np.linalg.norm(fit.joints_2d - target, axis=1).mean())


def test_fit_recovers_a_pose_from_a_noisy_prediction(camera: upperpose.Camera, body: upperpose.BodyModel) -> None:
    rng = np.random.default_rng(0)
    noisy = WAVE.angles + rng.normal(0.0, 0.05, 13)
    fit = upperpose.fit_frame(ideal(WAVE, camera), noisy, ROOT, body, camera)
    start = float(
        np.linalg.norm(
            upperpose.project(camera, upperpose.forward_kinematics(noisy, ROOT, body))
            - upperpose.project(camera, upperpose.forward_kinematics(WAVE, ROOT, body)),
            axis=1,
        ).mean()
    )
    assert joint_error(fit, WAVE, camera) < 1.5 < start
    assert fit.evaluations == 3 * 24 * 17
    assert set(fit.terms) == {"torso", "right_arm", "left_arm"}
    assert fit.cost == pytest.approx(sum(fit.stage_costs.values()))


@dataclass
class MergedHand(IdealFeatures):
    """Ideal features whose right hand is in a merged blob: no point, only the blob's box."""

    box: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)

    def merged_boxes_array(self) -> np.ndarray:
        out = np.full((3, 4), np.nan)
        out[1] = self.box
        return out


def test_merged_hand_pays_its_distance_to_the_blob_box(camera: upperpose.Camera, body: upperpose.BodyModel) -> None:
    f = ideal(WAVE, camera)
    hand = f.points[1].copy()
    f.points[1] = np.nan
    shoulder_px = body.shoulder_width * camera.focal / ROOT[2]

    def skin(box: tuple[float, float, float, float], merged_skin: bool = True) -> float:
        features = MergedHand(f.sil_bits, f.edge_bits, f.motion_bits, f.points, box=box)
        config = upperpose.SearchConfig(merged_skin=merged_skin)
        fit = upperpose.fit_frame(features, WAVE, ROOT, body, camera, search=(), config=config)
        return float(fit.terms["right_arm"]["skin"])

    x, y = hand
    assert skin((x - 20, y - 10, x + 20, y + 10)) == 0.0
    assert skin((x + 30, y - 10, x + 60, y + 10)) == pytest.approx(30 / shoulder_px)
    assert skin((x + 30, y - 10, x + 60, y + 10), merged_skin=False) == 0.0


@dataclass
class BareForearm(IdealFeatures):
    """Ideal features with a skin mask for the Cover term (`FrameFeatures.cover_bits`)."""

    cover_bits: np.ndarray | None = None


# The right forearm folded across the chest (the synthetic cross_arms keyframe), left arm out.
ACROSS = upperpose.Pose(right_y_up=1.04, right_x_up=0.92, right_z_up=0.93, right_x_down=1.72, left_z_up=0.6)


def test_skin_over_the_torso_left_uncovered_costs_the_arm(camera: upperpose.Camera, body: upperpose.BodyModel) -> None:
    m = upperpose.render_masks(ACROSS, ROOT, camera, 640, 480, body)
    forearm = m["right_lower_arm"] > 0
    front = forearm & (m["torso"] > 0)
    assert front.sum() > 500, "pose must put the forearm in front of the torso"
    f = ideal(ACROSS, camera)
    features = BareForearm(f.sil_bits, f.edge_bits, f.motion_bits, f.points, cover_bits=pack_rows(forearm))

    def cover(pose: upperpose.Pose, weight: float = 12.0, feats: IdealFeatures = features) -> float:
        config = upperpose.SearchConfig(weights={"cover": weight})
        fit = upperpose.fit_frame(feats, pose, ROOT, body, camera, search=(), config=config)
        assert fit.terms["torso"]["cover"] == 0.0
        return float(fit.terms["right_arm"]["cover"])

    assert cover(ACROSS) == 0.0
    # The forearm hanging instead: the skin it left over the torso, over the arm's nominal area.
    hanging = ACROSS.replace(right_x_down=0.3)
    moved = upperpose.render_masks(hanging, ROOT, camera, 640, 480, body)
    left = front & (moved["right_lower_arm"] == 0) & (moved["right_upper_arm"] == 0)
    ppm = camera.focal / ROOT[2]
    area = body.upper_arm_length * sum(body.upper_arm_radii) + body.lower_arm_length * sum(body.lower_arm_radii)
    assert cover(hanging) == pytest.approx(left.sum() / (area * ppm**2), rel=0.05)
    assert cover(hanging) > 0.3
    # Unweighed, or without a skin mask, the term is not counted.
    assert cover(hanging, weight=0.0) == 0.0
    assert cover(hanging, feats=f) == 0.0
    wrong = BareForearm(f.sil_bits, f.edge_bits, f.motion_bits, f.points, cover_bits=pack_rows(forearm[:-1]))
    with pytest.raises(ValueError, match="skin_mask must have shape"):
        cover(hanging, feats=wrong)


def test_unsearched_stages_keep_the_prediction(camera: upperpose.Camera, body: upperpose.BodyModel) -> None:
    prediction = WAVE.replace(right_x_down=1.3, left_z_up=0.5)
    fit = upperpose.fit_frame(ideal(WAVE, camera), prediction, ROOT, body, camera, search=["right_arm"])
    np.testing.assert_array_equal(fit.pose[:3], prediction.angles[:3])
    np.testing.assert_array_equal(fit.pose[8:], prediction.angles[8:])
    assert abs(fit.pose[6] - 1.4) < abs(1.3 - 1.4)


def test_same_seed_same_fit_for_1_and_2_threads(camera: upperpose.Camera, body: upperpose.BodyModel) -> None:
    f = ideal(WAVE, camera)
    prediction = WAVE.replace(right_x_down=1.3)
    fits = [
        upperpose.fit_frame(f, prediction, ROOT, body, camera, config=upperpose.SearchConfig(threads=t, seed=5))
        for t in (1, 2, 1)
    ]
    for other in fits[1:]:
        np.testing.assert_array_equal(other.pose, fits[0].pose)
        assert other.cost == fits[0].cost


@pytest.mark.parametrize("value", ["0", "two", "-1"])
def test_a_bad_thread_count_in_the_environment_is_named(
    value: str, camera: upperpose.Camera, body: upperpose.BodyModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("UPPERPOSE_NUM_THREADS", value)
    message = rf"^UPPERPOSE_NUM_THREADS must be a positive whole number, got \"{value}\"$"
    with pytest.raises(InputError, match=message):
        upperpose.fit_frame(ideal(WAVE, camera), WAVE, ROOT, body, camera)


def test_fit_releases_the_gil(camera: upperpose.Camera, body: upperpose.BodyModel) -> None:
    f = ideal(WAVE, camera)
    config = upperpose.SearchConfig(particles=64, iterations=60, threads=1)

    def ticks_while(work: Callable[[], object], seconds: float = 0.3) -> int:
        """How often a second Python thread gets to run while `work` is repeated."""
        ticks = 0
        done = threading.Event()

        def count() -> None:
            nonlocal ticks
            while not done.is_set():
                ticks += 1
                time.sleep(0)

        t = threading.Thread(target=count)
        t.start()
        start = time.perf_counter()
        while time.perf_counter() - start < seconds:
            work()
        done.set()
        t.join()
        return ticks

    def python_busy() -> None:  # holds the GIL except at the interpreter's switch interval
        sum(range(20000))

    during_fits = ticks_while(lambda: upperpose.fit_frame(f, WAVE, ROOT, body, camera, mode="initial", config=config))
    during_python = ticks_while(python_busy)
    # Holding the GIL, the counter runs about once per switch interval (5 ms); released, it spins.
    assert during_fits > 5 * max(during_python, 1)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"mode": "fast"}, "mode must be 'trajectory' or 'initial'"),
        ({"search": ["head"]}, 'unknown stage "head"'),
        ({"window_scale": 0.0}, "window_scale must be > 0"),
        ({"frame_interval": float("nan")}, "frame_interval must be finite"),
        ({"root": [0.0, 0.0, -1.0]}, r"root\[2\] must be within 0.1..=1000 metres in front of the camera"),
        ({"root": [0.0, 0.0, 1e-12]}, r"root\[2\] must be within 0.1..=1000 metres .*, got 1e-12"),
        ({"width": 512}, r"sil must have shape \(480, 8\)"),
    ],
)
def test_bad_arguments_are_named(
    kwargs: dict, message: str, camera: upperpose.Camera, body: upperpose.BodyModel
) -> None:
    args = {"root": ROOT}
    args.update(kwargs)
    root = args.pop("root")
    with pytest.raises(ValueError, match=message):
        upperpose.fit_frame(ideal(WAVE, camera), WAVE, root, body, camera, **args)


def test_search_config_checks_and_reports_its_settings() -> None:
    c = upperpose.SearchConfig(particles=10, weights={"edge": 3.0}, limits="thesis", row_steps=(1, 1, 1))
    assert (c.particles, c.limits, c.row_steps) == (10, "thesis", (1, 1, 1))
    assert c.weights["edge"] == 3.0 and c.weights["sil"] == upperpose.SearchConfig().weights["sil"]
    assert upperpose.SearchConfig(behind_weight=0.0, behind_margin=0.3).behind_margin == 0.3
    assert (upperpose.SearchConfig().turn_weight, upperpose.SearchConfig(turn_weight=0.5).turn_weight) == (2.0, 0.5)
    assert (upperpose.SearchConfig().lean_weight, upperpose.SearchConfig(lean_weight=0.0).lean_weight) == (40.0, 0.0)
    assert (upperpose.SearchConfig().rotation_weight, upperpose.SearchConfig(rotation_weight=0.0).rotation_weight) == (
        1.0,
        0.0,
    )
    default = upperpose.SearchConfig()
    assert (default.mask_other_arm_edges, default.sil_by_part_area) == (True, True)
    spec = upperpose.SearchConfig(mask_other_arm_edges=False, sil_by_part_area=False)
    assert (spec.mask_other_arm_edges, spec.sil_by_part_area) == (False, False)
    for bad, message in [
        ({"particles": 0}, r"particles must be within 1\.\.=10000, got 0"),
        ({"particles": 10**9}, r"particles must be within 1\.\.=10000"),
        ({"iterations": 10**9}, r"iterations must be within 1\.\.=10000"),
        ({"weights": {"elbow": 1.0}}, 'unknown weight "elbow"'),
        ({"limits": "loose"}, "limits must be"),
        ({"threads": 0}, r"threads must be within 1\.\.=1024"),
        ({"row_steps": (0, 1, 1)}, r"row_steps\[0\] must be >= 1"),
        ({"c0": -1.0}, "c0 must be > 0"),
        ({"behind_weight": -1.0}, "behind_weight must be >= 0"),
        ({"turn_weight": float("nan")}, "turn_weight must be >= 0"),
        ({"lean_weight": -1.0}, "lean_weight must be >= 0"),
        ({"rotation_weight": -0.5}, "rotation_weight must be >= 0"),
    ]:
        with pytest.raises(ValueError, match=message):
            upperpose.SearchConfig(**bad)
