"""Light changes against the clean plate: gains measured, features compensated; faces in lead-ins."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.features import Background, FeatureConfig, FeatureExtractor
from upperpose.features.background import shows_a_face
from upperpose.features.exposure import channel_gains, needs_compensation
from upperpose.lab.feature_scene import textured_background
from upperpose.lab.synth import ClipConfig, plan_clip, render_frame

H, W = 120, 160


def lit(plate: np.ndarray, gains: tuple[float, float, float]) -> np.ndarray:
    return np.clip(plate.astype(np.float64) * np.array(gains), 0, 255).round().astype(np.uint8)


@settings(max_examples=30, deadline=None)
@given(
    st.tuples(*[st.floats(0.5, 1.4)] * 3),
    st.integers(0, 2**31 - 1),
)
def test_gains_are_measured_with_a_person_in_the_frame(gains: tuple[float, float, float], seed: int) -> None:
    plate = textured_background(H, W, seed=seed % 1000)
    frame = lit(plate, gains)
    frame[20:90, 50:100] = (40, 160, 230)  # a third of the frame is "person"
    measured = channel_gains(frame, plate, step=4)
    # Rounding to integers moves a ratio by at most 0.5 / level; levels are >= 24.
    np.testing.assert_allclose(measured, gains, atol=0.03)


def test_unchanged_light_needs_no_compensation() -> None:
    plate = textured_background(H, W, seed=1)
    noisy = np.clip(plate + np.random.default_rng(0).normal(0, 3, plate.shape), 0, 255).astype(np.uint8)
    gains = channel_gains(noisy, plate, step=4)
    assert not needs_compensation(gains, FeatureConfig().exposure_tolerance)
    assert needs_compensation(np.array([1.0, 1.0, 0.9]), 0.04)


def test_dimmed_frame_is_not_foreground() -> None:
    plate = textured_background(H, W, seed=2)
    frame = lit(plate, (0.7, 0.7, 0.7))
    frame[30:80, 60:100] = (40, 160, 230)
    person = np.zeros((H, W), bool)
    person[30:80, 60:100] = True
    on = FeatureExtractor(Background.from_plate(plate))(frame)
    off = FeatureExtractor(Background.from_plate(plate, FeatureConfig(exposure_tolerance=10.0)))(frame)
    iou = np.logical_and(on.sil > 0, person).sum() / np.logical_or(on.sil > 0, person).sum()
    assert iou > 0.9
    # Without compensation most of the dimmed room counts as foreground.
    assert (off.sub > 0).mean() > 0.5 > (on.sub > 0).mean()


def test_a_face_is_seen_in_a_person_not_in_an_empty_room() -> None:
    plan = plan_clip(ClipConfig("wave_right", 40, seed=101, empty_start=True, fps=20))
    empty, person, _ = render_frame(plan, 0)
    assert not person.any()
    config = FeatureConfig()
    assert not shows_a_face([empty], config)
    frame, person, _ = render_frame(plan, 39)
    assert person.any()
    assert shows_a_face([frame], config)


def test_dimmed_skin_is_still_skin() -> None:
    # Skin (B, G, R) = (100, 130, 180) in the plate's light, R - G = 50; the lamp dims to 35 %:
    # (35, 46, 63), R - G = 17, below the rule's 20. Scaled back to the plate's light it is skin.
    plate = textured_background(H, W, seed=3)
    frame = lit(plate, (0.35, 0.35, 0.35))
    frame[30:80, 60:100] = (35, 46, 63)
    on = FeatureExtractor(Background.from_plate(plate))(frame)
    off = FeatureExtractor(Background.from_plate(plate, FeatureConfig(exposure_tolerance=10.0)))(frame)
    assert on.skin0[30:80, 60:100].all()
    assert not off.skin0[30:80, 60:100].any()
