"""Large frames tracked at a working size: the size, the camera, the mapping back, the pipeline."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import upperpose
from tracker_helpers import TruthFitter, clip, clip_frames, truth, write_video
from upperpose.fit import TrackerConfig
from upperpose.fit.pipeline import VideoTracking
from upperpose.fit.work_size import WorkSize


def test_small_frames_keep_their_size_and_large_ones_shrink_to_about_the_budget() -> None:
    assert not WorkSize.of(640, 480, 640 * 480).reduced
    assert not WorkSize.of(4000, 3000, 0).reduced  # 0: no limit
    assert WorkSize.of(1280, 960, 640 * 480).work == (640, 480)
    hd = WorkSize.of(1920, 1080, 640 * 480)
    assert hd.work == (739, 416)
    assert abs(hd.work[0] * hd.work[1] - 640 * 480) < 0.01 * 640 * 480
    assert abs(hd.scales[0] - hd.scales[1]) < 1e-3  # the shape is kept
    frame = np.zeros((1080, 1920, 3), np.uint8)
    assert hd.frame(frame).shape == (416, 739, 3)
    assert WorkSize.of(640, 480, 640 * 480).frame(frame) is frame


@settings(max_examples=60, deadline=None)
@given(
    st.integers(320, 4000),
    st.integers(240, 3000),
    st.sampled_from(["perspective", "weak_perspective", "orthographic"]),
    st.floats(-0.8, 0.8),
    st.floats(-0.6, 0.6),
    st.floats(1.0, 6.0),
)
def test_a_point_seen_by_the_working_camera_maps_back_to_the_video_camera_pixel(
    width: int, height: int, kind: str, x: float, y: float, z: float
) -> None:
    work = WorkSize.of(width, height, 640 * 480)
    if kind == "perspective":
        camera = upperpose.Camera.for_image(width, height)
    elif kind == "weak_perspective":
        camera = upperpose.Camera.weak_perspective(width, (width - 1) / 2, (height - 1) / 2, 2.5)
    else:
        camera = upperpose.Camera.orthographic(width / 2.5, (width - 1) / 2, (height - 1) / 2)
    point = np.array([[x, y, z]])
    in_video = upperpose.project(camera, point)
    via_work = work.to_video(upperpose.project(work.camera(camera), point))
    # Exact but for the working height's rounding, which the single focal length ignores.
    sx, sy = work.scales
    allowed = 1e-6 + abs(sy / sx - 1.0) * np.abs(in_video[0, 1] - camera.cy)
    assert np.allclose(work.to_work(via_work), upperpose.project(work.camera(camera), point))
    assert abs(via_work[0, 0] - in_video[0, 0]) < 1e-6
    assert abs(via_work[0, 1] - in_video[0, 1]) <= allowed * 1.01 + 1e-6


@pytest.fixture(scope="module")
def doubled(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The test clip and its plate at twice their size."""
    folder = tmp_path_factory.mktemp("doubled")
    frames = [cv2.resize(f, None, fx=2, fy=2, interpolation=cv2.INTER_CUBIC) for f in clip_frames(clip())]
    plate = cv2.resize(cv2.imread(str(clip() / "background.png")), None, fx=2, fy=2, interpolation=cv2.INTER_CUBIC)
    cv2.imwrite(str(folder / "plate.png"), plate)
    return write_video(folder / "video.mp4", frames), folder / "plate.png"


def tracked(video: Path, plate: Path, work_pixels: int) -> tuple[VideoTracking, list[upperpose.TrackResult]]:
    config = TrackerConfig(work_pixels=work_pixels)
    with VideoTracking(video, str(plate), config=config, fitter=TruthFitter(truth(clip()))) as run:
        return run, [r for _, r in run.frames()]


def test_a_doubled_video_is_tracked_at_its_working_size_and_reported_in_its_own_pixels(
    doubled: tuple[Path, Path],
) -> None:
    video, plate = doubled
    small = clip()
    _, native = tracked(small / "video.mp4", small / "background.png", 320 * 240)
    run, results = tracked(video, plate, 320 * 240)
    assert run.work.video == (640, 480) and run.work.work == (320, 240)
    assert run.background is not None and run.background.size == (240, 320)
    assert run.tracker.camera.focal == pytest.approx(run.camera.focal / 2)
    both = [(a, b) for a, b in zip(native, results) if a.joints_2d is not None and b.joints_2d is not None]
    assert len(both) >= sum(a.joints_2d is not None for a in native) - 2 > 20
    # The same angles (the search double's truth); the root from the shrunk frames' face and
    # skin, within a pixel or two of the native clip's.
    gap = np.median([np.abs(b.joints_2d - (2 * (a.joints_2d + 0.5) - 0.5)).max() for a, b in both])
    assert gap < 4.0
    # Without the working size the same video is tracked at its own size.
    run_full, _ = tracked(video, plate, 0)
    assert not run_full.work.reduced and run_full.tracker.camera.focal == run_full.camera.focal
