"""`lab.plate_estimate`: an estimated plate's wrong pixels, by how often the samples show the room."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from upperpose.features import FeatureConfig
from upperpose.lab.feature_scene import textured_background
from upperpose.lab.plate_estimate import classify_errors, estimate_clip, main

H, W = 40, 60


def test_wrong_pixels_are_split_by_the_share_of_samples_that_show_the_room() -> None:
    truth = textured_background(H, W, seed=1)
    samples = np.repeat(truth[None], 10, axis=0)
    samples[:3, 0:10, 0:10] = (0, 0, 255)  # the room shows in 7 of 10 samples
    samples[:8, 0:10, 20:30] = (0, 255, 0)  # in 2 of 10
    samples[:, 0:10, 40:50] = (255, 0, 0)  # never
    plate = truth.copy()
    plate[0:5, 0:10] = (0, 0, 255)  # 50 wrong where most samples show the room
    plate[0:10, 20:30] = (0, 255, 0)  # 100 where some do
    plate[0:2, 40:50] = (255, 0, 0)  # 20 where none does
    plate[30:32, 0:5] = np.clip(truth[30:32, 0:5].astype(int) + 25, 0, 255)  # within the threshold
    errors = classify_errors(plate, truth, samples, threshold=30)
    area = H * W
    assert errors.most == pytest.approx(50 / area)
    assert errors.some == pytest.approx(100 / area)
    assert errors.never == pytest.approx(20 / area)
    assert errors.wrong == pytest.approx(170 / area)


def test_a_clip_folder_is_estimated_and_printed(tmp_path, capsys) -> None:
    # A square crossing the room: the estimate finds the room everywhere the square left.
    truth = textured_background(96, 128, seed=2)
    folder = tmp_path / "clip"
    folder.mkdir()
    cv2.imwrite(str(folder / "background.png"), truth)
    writer = cv2.VideoWriter(str(folder / "video.mp4"), cv2.VideoWriter_fourcc(*"mp4v"), 30, (128, 96))
    for i in range(40):
        frame = truth.copy()
        frame[30:60, 3 * i : 3 * i + 20] = (90, 200, 60)
        writer.write(frame)
    writer.release()
    method, seconds, errors = estimate_clip(folder, FeatureConfig(), 30)
    assert method == "masked median" and seconds > 0
    assert errors.wrong < 0.01 and errors.most == 0.0  # (mp4v leaves a few pixels off in every frame)
    main([str(folder)])
    out = capsys.readouterr().out
    assert "clip" in out and "masked median" in out and out.strip().splitlines()[-1].startswith("MEAN")
