"""VideoLooks: grey and very dark videos are named as such, ordinary ones are not."""

from __future__ import annotations

import numpy as np
import pytest

from tracker_helpers import clip, clip_frames
from upperpose.io.looks import DARK_LEVEL, GREY_SPREAD, VideoLooks


def looks_of(frames: list[np.ndarray], every: int = 15) -> VideoLooks:
    looks = VideoLooks(every)
    for i, frame in enumerate(frames):
        looks.see(i, frame)
    return looks


def test_the_rendered_clip_looks_usable() -> None:
    assert looks_of(clip_frames(clip())).hint() is None


def test_a_grey_video_is_named() -> None:
    grey = [np.repeat(f.mean(axis=2, keepdims=True), 3, axis=2).astype(np.uint8) for f in clip_frames(clip())]
    hint = looks_of(grey).hint()
    assert hint is not None and "no colour" in hint


@pytest.mark.parametrize("gain", [0.1, 0.2])
def test_a_dark_video_is_named_with_its_level(gain: float) -> None:
    frames = [(f * gain).astype(np.uint8) for f in clip_frames(clip())]
    level = float(np.mean([f[::4, ::4].mean() for f in frames[::15]]))
    assert level < DARK_LEVEL
    hint = looks_of(frames).hint()
    assert hint is not None and f"mean level {level:.0f} of 255" in hint


def test_only_every_nth_frame_is_sampled() -> None:
    # A video whose sampled frames are grey and whose others are coloured counts as grey.
    rng = np.random.default_rng(0)
    coloured = rng.integers(0, 256, (48, 64, 3), dtype=np.uint8)
    grey = np.full((48, 64, 3), 120, np.uint8)
    frames = [grey if i % 5 == 0 else coloured for i in range(20)]
    assert looks_of(frames, every=5).hint() is not None
    assert looks_of(frames, every=1).hint() is None
    assert looks_of([]).hint() is None
    assert GREY_SPREAD * coloured.mean() < np.ptp(coloured.astype(int), axis=2).mean()
