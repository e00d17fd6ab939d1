"""The examples of the hostile-input issue not covered elsewhere, one test each.

Covered elsewhere: huge particle/iteration counts and seeds (test_track_cli, test_search),
render/synth sizes, rates and depths (test_cli), frames too small or thin and camera indices
(test_track_cli), a plate of another size (test_track_cli), two outputs naming one file
(test_track_cli), TrackerConfig ranges (test_tracker, test_settings), SIGTERM and repeated
Ctrl-C (test_track_cli), memory over long runs (test_long_runs).
"""

from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest

import upperpose
from test_track_cli import fake_search, one_line_error, track, write_video  # noqa: F401 (fixture)
from tracker_helpers import camera_of, clip
from upperpose.cli import main
from upperpose.fit import Tracker, TrackerConfig
from upperpose.fit.pipeline import VideoTracking
from upperpose.io.posefile import load_poses, make_poses, write_poses
from upperpose.model import check_camera_fits

# -- the Python API ------------------------------------------------------------------------------


class Planes:
    """Features of a 64x48 frame: empty bit planes and no skin points, each replaceable."""

    size = (48, 64)

    def __init__(self, plane: np.ndarray | None = None, points: np.ndarray | None = None) -> None:
        self.sil_bits = np.zeros((48, 1), np.uint64) if plane is None else plane
        self.edge_bits = np.zeros((48, 1), np.uint64)
        self.motion_bits = np.zeros((48, 1), np.uint64)
        self.points = np.full((3, 2), np.nan) if points is None else points

    def points_array(self) -> np.ndarray:
        return self.points


def fit(features: object, root: tuple[float, float, float] = (0.0, 0.0, 2.0)) -> upperpose.FrameFit:
    config = upperpose.SearchConfig(particles=4, iterations=2)
    camera = upperpose.Camera.for_image(64, 48)
    return upperpose.fit_frame(features, upperpose.Pose(), root, upperpose.BodyModel(), camera, config=config)  # type: ignore[arg-type]


def test_fit_frame_of_none_is_a_type_error_naming_features() -> None:
    with pytest.raises(TypeError, match="features must be a frame's features .*got NoneType"):
        fit(None)


def test_a_nan_feature_plane_is_refused() -> None:
    with pytest.raises(upperpose.InputError, match="features.sil_bits must be a uint64 bit plane, got dtype float64"):
        fit(Planes(plane=np.full((48, 1), np.nan)))


@pytest.mark.parametrize(
    ("point", "message"),
    [(np.inf, r"skin points must be finite or NaN \(absent\)"), (1e300, "skin point must be within")],
)
def test_infinite_or_absurd_skin_points_are_refused(point: float, message: str) -> None:
    points = np.full((3, 2), np.nan)
    points[1] = [point, 10.0]
    with pytest.raises(upperpose.InputError, match=message):
        fit(Planes(points=points))
    points[1] = [30.0, 20.0]  # the same hand inside the image is scored
    assert np.isfinite(fit(Planes(points=points)).cost)


def test_a_root_at_the_camera_is_an_error_not_a_zero_cost() -> None:
    with pytest.raises(upperpose.InputError, match=r"root\[2\] must be within 0.1..=1000 metres .*got 1e-12"):
        fit(Planes(), root=(0.0, 0.0, 1e-12))
    done = fit(Planes(), root=(0.0, 0.0, 2.0))
    assert done.evaluations > 0 and done.cost > 0


def test_a_string_angle_is_a_type_error() -> None:
    with pytest.raises(TypeError, match="angle right_z_up must be a number, got str"):
        upperpose.Pose(right_z_up="1.0")  # type: ignore[arg-type]
    assert upperpose.Pose(right_z_up=np.float32(1.0))["right_z_up"] == 1.0


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: upperpose.Camera.for_image(-1, 480), "width must be within 1..=8192, got -1"),
        (lambda: upperpose.Camera.for_image(640, 10**40), "height must be within 1..=8192, got 1e40|beyond 2"),
        (lambda: upperpose.SearchConfig(particles=-1), "particles must be within 1..=10000, got -1"),
        (lambda: upperpose.SearchConfig(seed=-1), "seed must be within 0..=18446744073709551615, got -1"),
        (lambda: upperpose.SearchConfig(threads=2**200), "threads must be within 1..=1024, got an integer beyond"),
    ],
)
def test_out_of_range_integers_name_the_argument_and_range(call, message: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(upperpose.InputError, match=message):
        call()


def test_a_camera_for_another_image_size_is_refused() -> None:
    folder = clip()
    plate = cv2.imread(str(folder / "background.png"))
    with pytest.raises(upperpose.InputError, match="a camera for another image size"):
        Tracker(upperpose.Camera.for_image(1280, 720), plate, TrackerConfig())
    with pytest.raises(upperpose.InputError, match="320x240 images"):
        VideoTracking(folder / "video.mp4", plate, camera=upperpose.Camera.for_image(640, 480))
    check_camera_fits(camera_of(folder), 320, 240)  # the clip's own camera fits


# -- upperpose eval ------------------------------------------------------------------------------


def test_eval_of_deeply_nested_json_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    assert main(["eval", str(deep), str(deep)]) == 1
    assert "JSON nested too deeply to be a pose file" in one_line_error(capsys.readouterr().err)


def test_eval_refuses_coordinates_whose_errors_overflow(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def poses(value: float) -> dict[str, object]:
        frame = {"frame": 0, "status": "tracked", "joints_2d": [[value, 1.0]] * 7, "joints_3d": None}
        return make_poses(640, 480, 30.0, [frame])

    write_poses(tmp_path / "pred.json", poses(1e308))
    write_poses(tmp_path / "gt.json", poses(-1e308))
    assert main(["eval", str(tmp_path / "pred.json"), str(tmp_path / "gt.json"), "--json"]) == 1
    line = one_line_error(capsys.readouterr().err)
    assert "prediction frame 0: joints_2d beyond +-1e+09 cannot be scored" in line
    write_poses(tmp_path / "pred.json", poses(3.0))  # ordinary coordinates still score
    write_poses(tmp_path / "gt.json", poses(1.0))
    assert main(["eval", str(tmp_path / "pred.json"), str(tmp_path / "gt.json"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["mpjpe_2d_px"] == pytest.approx(2.0)


# -- short and odd videos ----------------------------------------------------------------------


def person_frames(n: int) -> list[np.ndarray]:
    """`n` frames of the clip with the person standing in view."""
    cap = cv2.VideoCapture(str(clip() / "video.mp4"))
    frames = [cap.read()[1] for _ in range(20 + n)][20:]
    cap.release()
    return frames


@pytest.mark.usefixtures("fake_search")
@pytest.mark.parametrize("count", [1, 2])
def test_one_and_two_frame_videos_write_a_whole_file_and_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], count: int
) -> None:
    video = write_video(tmp_path / "short.mp4", person_frames(count))
    out = tmp_path / "o.json"
    code, _, err = track([str(video), "--background", str(clip() / "background.png"), "-o", str(out)], capsys)
    assert code == 1 and f"tracking never started in {video} ({count} frames)" in one_line_error(err)
    assert [f["frame"] for f in load_poses(out)["frames"]] == list(range(count))


@pytest.mark.usefixtures("fake_search")
def test_a_single_png_as_a_video_is_one_frame(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    image = tmp_path / "still.png"
    cv2.imwrite(str(image), person_frames(1)[0])
    out = tmp_path / "o.json"
    code, _, err = track([str(image), "--background", str(clip() / "background.png"), "-o", str(out)], capsys)
    assert code == 1 and "(1 frames)" in one_line_error(err)
    assert len(load_poses(out)["frames"]) == 1


@pytest.mark.usefixtures("fake_search")
def test_a_5000_fps_clip_is_timed_as_30_fps_with_a_warning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cap = cv2.VideoCapture(str(clip() / "video.mp4"))
    frames = [cap.read()[1] for _ in range(50)]
    cap.release()
    video = write_video(tmp_path / "fast.mp4", frames, fps=5000.0)
    out = tmp_path / "o.json"
    code, _, err = track([str(video), "--background", str(clip() / "background.png"), "-o", str(out)], capsys)
    assert code == 0
    assert err.splitlines() == [f"upperpose track: warning: {video} reports 5000 fps, outside 1..1000: timed as 30 fps"]
    doc = load_poses(out)
    assert doc["fps"] == 30.0 and len(doc["frames"]) == 50


def test_a_1x1_video_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    video = tmp_path / "dot.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 15.0, (1, 1))
    for _ in range(3):
        writer.write(np.zeros((1, 1, 3), np.uint8))
    writer.release()
    code, _, err = track([str(video), "-o", str(tmp_path / "o.json")], capsys)
    assert code == 1 and "is 1x1: upperpose takes 32..8192 pixels a side" in one_line_error(err)


def png_header(width: int, height: int) -> bytes:
    """A PNG that declares `width x height` pixels and holds one row of them."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(bytes(width + 1)))
        + chunk(b"IEND", b"")
    )


def test_a_40000_pixel_plate_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plate = tmp_path / "huge.png"
    plate.write_bytes(png_header(40_000, 40_000))
    code, _, err = track(
        [str(clip() / "video.mp4"), "--background", str(plate), "-o", str(tmp_path / "o.json")], capsys
    )
    assert code == 1 and "too large (over 2^30 pixels) or corrupt" in one_line_error(err)


@pytest.mark.usefixtures("fake_search")
def test_an_unknown_overlay_extension_is_one_line_without_opencv_noise(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "o.json"
    args = [str(clip() / "video.mp4"), "--background", str(clip() / "background.png"), "-o", str(out)]
    assert main(["track", *args, "--overlay", str(tmp_path / "overlay.abc")]) == 1
    line = one_line_error(capfd.readouterr().err)  # file descriptor 2: OpenCV's own logging too
    assert "cannot open an mp4v video writer for" in line and "overlay.abc" in line
