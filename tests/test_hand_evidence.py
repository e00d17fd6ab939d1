"""Far-off hands by their skin evidence (upperpose.lab.hand_evidence)."""

from __future__ import annotations

import dataclasses
from collections import Counter
from types import SimpleNamespace

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import upperpose
from tracker_helpers import camera_of, clip, truth
from upperpose.features import SkinPoint
from upperpose.lab.hand_evidence import CLASSES, beyond_reach, classify, main, ray_distance, report, survey_clip
from upperpose.model import Pose, model_points, project

FloatArray = npt.NDArray[np.float64]
CAMERA = upperpose.Camera.for_image(640, 480, 600.0)
ROOT = np.array([0.0, 0.0, 2.4])
RIGHT_ARM = (1, 3, 5)


def unit(v: FloatArray) -> FloatArray:
    return np.asarray(v / np.linalg.norm(v), dtype=np.float64)


@settings(max_examples=200, deadline=None)
@given(st.floats(-300, 300), st.floats(-220, 220), st.floats(0.5, 6.0), st.floats(0.0, 0.8), st.floats(0.0, 2 * np.pi))
def test_ray_distance_is_the_distance_to_the_closest_point_of_the_ray(
    dx: float, dy: float, depth: float, gap: float, turn: float
) -> None:
    # A point `gap` metres off the ray, built from the ray's closest point and a perpendicular.
    pixel = np.array([CAMERA.cx + dx, CAMERA.cy + dy])
    d = unit(np.array([dx / CAMERA.focal, dy / CAMERA.focal, 1.0]))
    a = unit(np.cross(d, [0.0, 1.0, 0.0]))
    b = np.cross(d, a)
    point = depth * d + gap * (np.cos(turn) * a + np.sin(turn) * b)
    assert ray_distance(CAMERA, pixel, point) == pytest.approx(gap, abs=1e-9)


def arm_out(bend: float) -> tuple[FloatArray, FloatArray]:
    """Model points and projections with the right arm raised sideways in the image plane."""
    pose = Pose.a_pose().angles.copy()
    pose[5], pose[6] = 1.5, bend  # right z_up (sideways), x_down (elbow)
    points = model_points(pose, ROOT, upperpose.BodyModel())
    return points, project(CAMERA, points)


def along(projected: FloatArray, share: float) -> FloatArray:
    return np.asarray(projected[1] + share * (projected[5] - projected[1]), dtype=np.float64)


def test_a_point_beyond_a_straight_arm_is_out_of_its_reach() -> None:
    model, projected = arm_out(0.0)
    # The shortest arm reaching the ray through a point 1.12 lengths out at the shoulder's depth:
    # |(S - Q) x Q| / |Q| (the arm may turn towards the camera).
    q = model[1] + 1.12 * (model[5] - model[1])
    asked = np.linalg.norm(np.cross(model[1] - q, q)) / np.linalg.norm(q) / np.linalg.norm(model[5] - model[1])
    assert 1.05 < asked < 1.12
    assert beyond_reach(CAMERA, model, RIGHT_ARM, along(projected, 1.12))
    assert not beyond_reach(CAMERA, model, RIGHT_ARM, along(projected, 1.0))
    assert not beyond_reach(CAMERA, model, RIGHT_ARM, along(projected, 1.03))  # asks less than 5 % more
    bent, bent_2d = arm_out(1.2)
    assert not beyond_reach(CAMERA, bent, RIGHT_ARM, along(bent_2d, 1.5))  # a bent arm could straighten


def test_each_far_off_hand_gets_the_class_of_its_evidence() -> None:
    body = upperpose.BodyModel()
    model, fitted = arm_out(0.0)
    pose = Pose.a_pose().angles.copy()
    pose[5], pose[6] = 1.5, 0.0
    result = upperpose.TrackResult(0, "tracked", pose, ROOT, fitted.copy())
    true = fitted.copy()
    true[5] = along(fitted, 1.2)  # the right hand 1.2 arm lengths out: the fit falls short
    true[6] = fitted[6] + (0.0, 40.0)  # the left hand 40 px below the fitted one
    gap = float(np.hypot(*(true[5] - fitted[5])))
    assert 25 < gap < 40, gap
    head = SkinPoint((320.0, 100.0), False, 0)

    def kinds(right: SkinPoint | None, left: SkinPoint | None, h: SkinPoint | None = head) -> list[tuple[str, bool]]:
        return classify(result, SimpleNamespace(points=[h, right, left]), true, body, CAMERA, 25.0)  # type: ignore[arg-type]

    at = (float(true[5, 0]), float(true[5, 1]))
    left_at = (float(true[6, 0]), float(true[6, 1]))
    # The right hand's own point on the true hand, beyond the straight arm's reach.
    assert kinds(SkinPoint(at, False, 1), SkinPoint(left_at, False, 2)) == [
        ("skin point right, fit far", True),
        ("skin point right, fit far", True),  # the left arm hangs straight: 40 px below its hand is out of reach too
    ]
    assert kinds(None, None) == [("no skin", False), ("no skin", False)]
    merged_head = SkinPoint((320.0, 100.0), True, 0)
    assert kinds(SkinPoint(at, True, 0), None, merged_head)[0] == ("on the head's blob", False)
    assert kinds(SkinPoint(at, True, 3), SkinPoint(left_at, True, 3))[:2] == [
        ("on the other hand's blob", False),
        ("on the other hand's blob", False),
    ]
    assert kinds(SkinPoint(at, True, 1, (0.0, 0.0, 5.0, 5.0)), None)[0] == ("cut by the border", False)
    assert kinds(SkinPoint((0.0, 0.0), False, 1), None)[0] == ("skin point off", False)
    # A point on the model's hand but far from the truth: the evidence itself misled.
    near_fit = (float(fitted[5, 0]) + 5.0, float(fitted[5, 1]))
    assert kinds(SkinPoint(near_fit, False, 1), None)[0] == ("skin point off", False)
    # The model's hand on a point that is on the true hand, and still the reported palm far off.
    palm_off = dataclasses.replace(result, joints_2d=fitted - (30.0, 0.0))
    on_hand = true.copy()
    on_hand[5] = fitted[5] + (15.0, 0.0)
    point = SkinPoint((float(fitted[5, 0]) + 10.0, float(fitted[5, 1])), False, 1)
    found = classify(palm_off, SimpleNamespace(points=[head, point, None]), on_hand, body, CAMERA, 25.0)  # type: ignore[arg-type]
    assert found[0] == ("skin point right, fit near it", False)
    # Hands within 25 px of the truth are not counted at all.
    assert classify(result, SimpleNamespace(points=[head, None, None]), fitted, body, CAMERA, 25.0) == []  # type: ignore[arg-type]


def test_the_survey_counts_every_far_off_hand_once() -> None:
    folder = clip()
    counts, compared = survey_clip(folder, seed=0)
    gt = {f["frame"]: f["joints_2d"] for f in truth(folder)["frames"] if f.get("joints_2d")}
    far = posed = 0
    meta = camera_of(folder)
    for result in upperpose.track_video(folder / "video.mp4", folder / "background.png", camera=meta):
        if result.joints_2d is None or result.frame not in gt:
            continue
        posed += 1
        far += int(
            np.sum(np.hypot(*(np.asarray(result.joints_2d)[[5, 6]] - np.asarray(gt[result.frame])[[5, 6]]).T) > 25)
        )
    assert compared == 2 * posed > 40
    assert sum(counts[k] for k in CLASSES) == far
    assert counts["beyond reach"] <= counts["skin point right, fit far"]


def test_report_lists_the_classes_in_order_with_the_reach_count() -> None:
    counts = Counter({"skin point off": 2, "no skin": 1, "skin point right, fit far": 4, "beyond reach": 3})
    assert report("v", counts, 100) == (
        "v: 7 of 100 hands far off: no skin 1, skin point off 2, skin point right, fit far 4 "
        "(3 of them beyond the straight arm's reach)"
    )
    assert report("v", Counter(), 10) == "v: 0 of 10 hands far off"


def test_the_command_prints_one_line_per_clip(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(clip())]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 1 and out[0].startswith("clip: ") and "hands far off" in out[0]
