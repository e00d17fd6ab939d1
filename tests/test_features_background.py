"""Background estimation without a clean plate: recovers the plate, warns, and what it cannot do."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from upperpose.features import (
    CleanPlateWarning,
    FeatureConfig,
    background_from_video,
    estimate_background,
)
from upperpose.features.background import iterative_masked_median
from upperpose.features.scene import textured_background

H, W = 96, 128


def moving_square_frames(plate: np.ndarray, count: int, start: int = 0, size: int = 40) -> list[np.ndarray]:
    """A grey square that moves across the plate from frame `start` on, with camera noise."""
    rng = np.random.default_rng(3)
    frames = []
    for i in range(count):
        frame = plate.astype(np.float64)
        if i >= start:
            x = 5 + (i - start) * (W - size - 10) // max(count - start - 1, 1)
            frame[30 : 30 + size, x : x + size] = (90, 200, 60)
        frames.append(np.clip(frame + rng.normal(0, 2, frame.shape), 0, 255).astype(np.uint8))
    return frames


def error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a.astype(int) - b.astype(int)).max(axis=2)


def test_masked_median_recovers_plate_behind_a_moving_object() -> None:
    plate = textured_background(H, W, seed=2)
    frames = moving_square_frames(plate, 30, size=24)
    plain = np.median(np.stack(frames), axis=0).astype(np.uint8)
    estimated = iterative_masked_median(frames, FeatureConfig(bg_mask_dilate=5))
    # The plain median is pulled towards the object where it passed; the masked one is not.
    assert error(estimated, plate).mean() < error(plain, plate).mean()
    assert (error(estimated, plate) > 12).sum() < 0.005 * H * W
    assert error(estimated, plate).mean() < 2.5


def test_masked_median_keeps_an_object_that_hardly_moves() -> None:
    # The documented limit: where the object sits in most samples, no median can see behind it.
    plate = textured_background(H, W, seed=3)
    frames = moving_square_frames(plate, 30)
    frames += [frames[15]] * 30
    estimated = iterative_masked_median(frames, FeatureConfig(bg_mask_dilate=5))
    assert (error(estimated, plate) > 30).sum() > 0.5 * 40 * 40


def test_empty_lead_in_gives_the_plate_and_warns() -> None:
    plate = textured_background(H, W, seed=4)
    frames = moving_square_frames(plate, 60, start=30)
    # The object then stays put for the rest of the clip: only the lead-in shows the plate there.
    frames += [frames[-1]] * 60
    with pytest.warns(CleanPlateWarning, match="clean plate"):
        background = estimate_background(frames[:30], frames[::3])
    assert background.estimated and background.method == "lead-in median"
    assert error(background.plate, plate).max() <= 6


def test_person_from_first_frame_falls_back_to_masked_median() -> None:
    plate = textured_background(H, W, seed=5)
    frames = moving_square_frames(plate, 40, start=0)
    with pytest.warns(CleanPlateWarning):
        background = estimate_background(frames[:30], frames)
    assert background.method == "masked median"
    assert (error(background.plate, plate) > 12).sum() < 0.02 * H * W


def test_background_from_video(tmp_path) -> None:
    plate = textured_background(H, W, seed=6)
    frames = moving_square_frames(plate, 50, start=30)
    path = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30, (W, H))
    for frame in frames:
        writer.write(frame)
    writer.release()
    with pytest.warns(CleanPlateWarning):
        background = background_from_video(path)
    assert background.size == (H, W)
    assert np.median(error(background.plate, plate)) < 8  # MJPG loses a little
    given = background_from_video(path, plate=plate)
    assert not given.estimated and np.array_equal(given.plate, plate)
