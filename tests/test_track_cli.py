"""`upperpose track` (and demo, bench): output schema, atomic writing, Ctrl-C, bad input, determinism."""

from __future__ import annotations

import csv
import dataclasses
import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

import upperpose
import upperpose.fit.tracker as tracker_module
from tracker_helpers import TruthFitter, clip, clip_frames, one_line_error, truth, write_video
from upperpose.cli import main
from upperpose.fit.outputs import BodyHistory
from upperpose.io.output import PoseRecorder, csv_header
from upperpose.io.posefile import load_poses
from upperpose.io.video import VideoReader
from upperpose.model import ANGLE_NAMES, JOINT_NAMES
from upperpose.result import TrackResult


@pytest.fixture
def fake_search(monkeypatch: pytest.MonkeyPatch) -> TruthFitter:
    """Replaces the Rust search with the truth double for the whole command."""
    fitter = TruthFitter(truth(clip()))
    monkeypatch.setattr(tracker_module, "fit_frame", fitter)
    return fitter


def track(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(["track", *args])
    out, err = capsys.readouterr()
    return code, out, err


# -- output -----------------------------------------------------------------------------------


def test_output_follows_spec_9(tmp_path: Path, capsys: pytest.CaptureFixture[str], fake_search: TruthFitter) -> None:
    folder = clip()
    out, table, overlay = tmp_path / "poses.json", tmp_path / "poses.csv", tmp_path / "overlay.mp4"
    code, stdout, _ = track(
        [str(folder / "video.mp4"), "--background", str(folder / "background.png"), "-o", str(out)]
        + ["--csv", str(table), "--overlay", str(overlay)],
        capsys,
    )
    assert code == 0
    doc = load_poses(out)  # validates the whole schema
    raw = json.loads(out.read_text())
    assert raw["format"] == "upperpose.poses/1"
    assert raw["joints"] == list(JOINT_NAMES) and raw["angles"] == list(ANGLE_NAMES)
    assert (raw["width"], raw["height"], raw["fps"]) == (320, 240, 15.0)
    assert raw["run_time_s"] > 0
    frames = doc["frames"]
    assert [f["frame"] for f in frames] == list(range(50))
    for f in frames:
        if f["status"] in ("no_person", "initialising"):
            assert f["joints_2d"] is None and f["joints_3d"] is None and f["angles"] is None
        else:
            assert len(f["angles"]) == 13 and len(f["joints_3d"]) == 7 and f["cost"] is not None
            assert all(z > 0.5 for _, _, z in f["joints_3d"])  # metres in front of the camera
    assert frames[0]["status"] == "no_person" and frames[-1]["status"] == "tracked"
    # pixels and metres agree: the 2D joints are the projections of the 3D ones
    f = frames[-1]
    X, Y, Z = np.array(f["joints_3d"]).T
    np.testing.assert_allclose(np.array(f["joints_2d"])[:, 0], 320 * X / Z + 159.5, atol=1e-3)
    with table.open() as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == csv_header() and len(rows) == 51
    assert rows[-1][1] == "tracked" and rows[1][1] == "no_person" and rows[1][3] == ""
    assert VideoReader(overlay).frame_count == 50
    assert "50 frames" in stdout and "tracked" in stdout


def test_interrupted_run_leaves_a_valid_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fake_search: TruthFitter, monkeypatch: pytest.MonkeyPatch
) -> None:
    original = VideoReader.__iter__

    def interrupted(self: VideoReader):  # type: ignore[no-untyped-def]
        for i, frame in enumerate(original(self)):
            if i == 30:
                raise KeyboardInterrupt
            yield frame

    monkeypatch.setattr(VideoReader, "__iter__", interrupted)
    out = tmp_path / "poses.json"
    folder = clip()
    code, _, err = track(
        [str(folder / "video.mp4"), "--background", str(folder / "background.png"), "-o", str(out)], capsys
    )
    assert code == 130
    assert "interrupted after 30 frames" in one_line_error(err)
    assert [f["frame"] for f in load_poses(out)["frames"]] == list(range(30))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["poses.json"]  # no temporary files left


def test_writing_is_atomic(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "poses.json"
    out.write_text("previous")
    recorder = PoseRecorder(320, 240, 15.0)
    recorder.add(TrackResult(0, "no_person"))
    with pytest.raises(ValueError, match="joints_2d"):
        recorder.add_record({"frame": 1, "status": "tracked", "joints_2d": [[1.0, 2.0]]})  # broken: refused at once
    with pytest.raises(ValueError, match="frames must increase"):
        recorder.add(TrackResult(0, "no_person"))
    recorder.add(TrackResult(1, "initialising"))

    def failing_lines():  # type: ignore[no-untyped-def]
        yield '{"frame":0,"status":"no_person"}'
        raise OSError("disk full")

    monkeypatch.setattr(recorder, "_lines", failing_lines)
    with pytest.raises(OSError, match="disk full"):
        recorder.write_json(out, 1.0)
    assert out.read_text() == "previous"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["poses.json"]
    monkeypatch.undo()
    with recorder:
        recorder.write_json(out, 1.0)
    assert [f["status"] for f in load_poses(out)["frames"]] == ["no_person", "initialising"]


def test_body_history_records_each_body_from_its_first_posed_frame() -> None:
    history = BodyHistory()
    assert history.last() is None and history.records() == []
    first, second = upperpose.BodyModel(), upperpose.BodyModel(shoulder_width=0.42, upper_arm_length=0.31)
    posed = TrackResult(0, "tracked", np.zeros(13), np.array([0.0, 0.0, 2.0]))
    history.see(TrackResult(0, "initialising"), upperpose.BodyModel(shoulder_width=0.5))  # no pose: no body
    for frame, body in ((3, first), (4, first), (5, second), (6, second), (9, first)):
        history.see(dataclasses.replace(posed, frame=frame), body)
    assert history.records() == [
        {"frame": 3, "body": dict(first.as_dict())},
        {"frame": 5, "body": dict(second.as_dict())},
        {"frame": 9, "body": dict(first.as_dict())},
    ]
    assert history.last() is first


def test_recorder_memory_does_not_hold_the_frames() -> None:
    import tracemalloc

    pose = np.zeros(13)
    joints = np.zeros((7, 2)) + 100.0
    joints3 = np.zeros((7, 3)) + 2.0
    recorder = PoseRecorder(640, 480, 30.0)

    def add(n: int, start: int) -> None:
        for i in range(start, start + n):
            recorder.add(TrackResult(i, "tracked", pose, pose[:3], joints, joints3, 1.0))

    add(200, 0)
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    add(5000, 200)
    grown = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    recorder.close()
    assert recorder.frames == 5200 and recorder.first_posed == 0
    assert grown < 200_000  # kept in memory, 5,000 records would take over 20 MB


# -- bad input --------------------------------------------------------------------------------


@pytest.fixture
def plate_path(tmp_path: Path) -> Path:
    return Path(shutil.copy(clip() / "background.png", tmp_path / "plate.png"))


def test_missing_video(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = track([str(tmp_path / "nope.mp4"), "-o", str(tmp_path / "o.json")], capsys)
    assert code == 1 and "no such video" in one_line_error(err)
    assert not (tmp_path / "o.json").exists()


def test_not_a_video(tmp_path: Path, capsys: pytest.CaptureFixture[str], plate_path: Path) -> None:
    text = tmp_path / "notes.mp4"
    text.write_text("this is not a video\n" * 50)
    code, _, err = track([str(text), "--background", str(plate_path), "-o", str(tmp_path / "o.json")], capsys)
    assert code == 1 and str(text) in one_line_error(err)


def test_empty_video(tmp_path: Path, capsys: pytest.CaptureFixture[str], plate_path: Path) -> None:
    empty = tmp_path / "empty.mp4"
    empty.write_bytes(b"")
    code, _, err = track([str(empty), "--background", str(plate_path), "-o", str(tmp_path / "o.json")], capsys)
    assert code == 1 and "empty" in one_line_error(err)


def test_corrupt_video(tmp_path: Path, capsys: pytest.CaptureFixture[str], plate_path: Path) -> None:
    corrupt = tmp_path / "corrupt.mp4"
    data = (clip() / "video.mp4").read_bytes()
    corrupt.write_bytes(data[:40] + bytes(len(data) // 3))  # header start, then zeros
    code, _, err = track([str(corrupt), "--background", str(plate_path), "-o", str(tmp_path / "o.json")], capsys)
    assert code == 1 and "corrupt.mp4" in one_line_error(err)


def test_background_of_another_size(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    small = tmp_path / "small.png"
    cv2.imwrite(str(small), np.zeros((100, 120, 3), np.uint8))
    code, _, err = track(
        [str(clip() / "video.mp4"), "--background", str(small), "-o", str(tmp_path / "o.json")], capsys
    )
    line = one_line_error(err)
    assert code == 1 and "120x100" in line and "320x240" in line


def test_unwritable_output(tmp_path: Path, capsys: pytest.CaptureFixture[str], plate_path: Path) -> None:
    out = tmp_path / "missing-folder" / "o.json"
    code, _, err = track([str(clip() / "video.mp4"), "--background", str(plate_path), "-o", str(out)], capsys)
    assert code == 1 and "does not exist" in one_line_error(err)
    code, _, err = track([str(clip() / "video.mp4"), "-o", str(tmp_path)], capsys)
    assert code == 1 and "is a folder" in one_line_error(err)


def test_bad_option_value(tmp_path: Path, capsys: pytest.CaptureFixture[str], plate_path: Path) -> None:
    with pytest.raises(SystemExit) as exc:
        track(
            [
                str(clip() / "video.mp4"),
                "--background",
                str(plate_path),
                "-o",
                str(tmp_path / "o.json"),
                "--particles",
                "0",
            ],
            capsys,
        )
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: upperpose track") and err.splitlines()[-1].startswith(
        "upperpose track: error: --particles"
    )
    assert not (tmp_path / "o.json").exists()


def test_video_without_a_person(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], plate_path: Path, fake_search: TruthFitter
) -> None:
    plate = cv2.imread(str(plate_path))
    rng = np.random.default_rng(1)
    frames = [np.clip(plate + rng.integers(-2, 3, plate.shape), 0, 255).astype(np.uint8) for _ in range(20)]
    video = write_video(tmp_path / "empty_room.mp4", frames)
    out = tmp_path / "o.json"
    code, _, err = track([str(video), "--background", str(plate_path), "-o", str(out)], capsys)
    assert code == 1 and "no person found" in one_line_error(err)
    doc = load_poses(out)  # still a valid file: every frame "no_person"
    assert len(doc["frames"]) == 20 and {f["status"] for f in doc["frames"]} == {"no_person"}


def test_a_grey_video_without_a_person_says_it_has_no_colour(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], plate_path: Path, fake_search: TruthFitter
) -> None:
    # An infrared or black-and-white camera: no face and no skin can be found, and the error
    # says why.
    plate = cv2.cvtColor(cv2.cvtColor(cv2.imread(str(plate_path)), cv2.COLOR_BGR2GRAY), cv2.COLOR_GRAY2BGR)
    video = write_video(tmp_path / "grey_room.mp4", [plate] * 20)
    code, _, err = track([str(video), "-o", str(tmp_path / "o.json"), "--quiet"], capsys)
    assert code == 1
    assert "no person found" in one_line_error(err) and "the video has no colour" in one_line_error(err)


# -- determinism, with the real search ------------------------------------------------------------


def test_same_seed_same_poses(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = clip()
    docs = []
    for k, threads in enumerate(("1", "2")):
        out = tmp_path / f"p{k}.json"
        args = [str(folder / "video.mp4"), "--background", str(folder / "background.png"), "-o", str(out)]
        code, _, _ = track(args + ["--particles", "8", "--iterations", "4", "--threads", threads, "--quiet"], capsys)
        assert code == 0
        doc = json.loads(out.read_text())
        doc.pop("run_time_s")
        assert doc["settings"].pop("threads") == int(threads)
        docs.append(doc)
    assert docs[0] == docs[1]
    assert any(f["status"] == "tracked" for f in docs[0]["frames"])


def test_start_up_that_never_passes_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fake_search: TruthFitter
) -> None:
    folder = clip()
    settings = tmp_path / "never.toml"
    settings.write_text("confirm_frames = 100000\n")
    out = tmp_path / "o.json"
    args = [str(folder / "video.mp4"), "--background", str(folder / "background.png"), "-o", str(out)]
    code, _, err = track(args + ["--config", str(settings)], capsys)
    assert code == 1 and "tracking never started" in one_line_error(err)
    doc = load_poses(out)
    assert "initialising" in {f["status"] for f in doc["frames"]}
    assert doc["settings"]["confirm_frames"] == 100000


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--particles", "1000000000"], "particles must be within 1..=10000"),
        (["--iterations", "1000000000"], "iterations must be within 1..=10000"),
    ],
)
def test_out_of_range_options_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    folder = clip()
    out = tmp_path / "o.json"
    code, _, err = track([str(folder / "video.mp4"), "-o", str(out), *extra], capsys)
    assert code == 1 and message in one_line_error(err)
    assert not out.exists()


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--seed", "-1"], "--seed must be within 0..2**64-1"),
        (["--seed", str(2**64)], "--seed must be within 0..2**64-1"),
        (["--focal", "1e-300"], "--focal must be within 1..100000 pixels"),
        (["--focal", "nan"], "--focal must be within"),
    ],
)
def test_out_of_range_option_values_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    out = tmp_path / "o.json"
    with pytest.raises(SystemExit) as exc:
        track([str(clip() / "video.mp4"), "-o", str(out), *extra], capsys)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "usage: upperpose track" in err and message in err.splitlines()[-1]
    assert not out.exists()


def test_two_outputs_naming_one_file_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = clip()
    out = tmp_path / "o.json"
    code, _, err = track([str(folder / "video.mp4"), "-o", str(out), "--csv", str(tmp_path / "." / "o.json")], capsys)
    assert code == 1 and "two outputs name the same file" in one_line_error(err)
    assert not out.exists()


@pytest.mark.parametrize(("width", "height"), [(16, 16), (8000, 8)])
def test_frames_too_small_or_thin_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], width: int, height: int
) -> None:
    video = write_video(tmp_path / "tiny.mp4", [np.zeros((height, width, 3), np.uint8)] * 3)
    code, _, err = track([str(video), "-o", str(tmp_path / "o.json")], capsys)
    line = one_line_error(err)
    assert code == 1 and f"is {width}x{height}" in line and "32..8192 pixels a side" in line


@pytest.mark.parametrize(("source", "error"), [(-1, "camera index must be within 0..1023"), (True, "video must be")])
def test_bad_camera_index_is_refused_before_opening(source: object, error: str) -> None:
    with pytest.raises((ValueError, TypeError), match=error):
        VideoReader(source)  # type: ignore[arg-type]


class FakeCamera:
    """Behaves like cv2.VideoCapture on a camera index: frames of a clip, no frame count."""

    def __init__(self, frames: list[np.ndarray] | None) -> None:
        self.frames, self.at = frames, 0

    def isOpened(self) -> bool:  # noqa: N802 - OpenCV's name
        return self.frames is not None

    def read(self) -> tuple[bool, np.ndarray | None]:
        if self.frames is None or self.at >= len(self.frames):
            return False, None
        self.at += 1
        return True, self.frames[self.at - 1]

    def get(self, prop: int) -> float:
        return 30.0 if prop == cv2.CAP_PROP_FPS else 0.0

    def release(self) -> None:
        pass


@pytest.mark.parametrize(("how", "plate"), [(["0"], True), (["--camera", "0"], True), (["0"], False)])
def test_live_camera_is_tracked(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    fake_search: TruthFitter,
    how: list[str],
    plate: bool,
) -> None:
    import upperpose.io.video as video_module

    folder = clip()
    frames = clip_frames(folder)
    opened: list[object] = []

    def capture(source: object) -> FakeCamera:
        opened.append(source)
        return FakeCamera(frames if source == 0 else None)

    monkeypatch.setattr(video_module.cv2, "VideoCapture", capture)
    out = tmp_path / "live.json"
    background = ["--background", str(folder / "background.png")] if plate else []
    code, _, err = track([*how, *background, "-o", str(out), "--quiet"], capsys)
    assert code == 0, err
    assert opened == [0]
    doc = load_poses(out)
    assert doc["source"] == "camera 0" and len(doc["frames"]) == len(frames)
    assert doc["clean_plate"] is plate
    # Without a plate the background is learnt while tracking: a live camera works the same way.
    assert sum(f["status"] == "tracked" for f in doc["frames"]) >= 0.5 * len(frames)


def test_missing_camera_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import upperpose.io.video as video_module

    monkeypatch.setattr(video_module.cv2, "VideoCapture", lambda source: FakeCamera(None))
    code, _, err = track(["3", "-o", str(tmp_path / "o.json")], capsys)
    assert code == 1 and "no camera 3" in one_line_error(err)
    with pytest.raises(SystemExit) as exc:  # a usage error
        track(["-o", str(tmp_path / "o.json")], capsys)
    assert exc.value.code == 2 and "give either a VIDEO or --camera N" in capsys.readouterr().err


def test_sigterm_and_a_second_interrupt_while_writing_keep_a_whole_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fake_search: TruthFitter, monkeypatch: pytest.MonkeyPatch
) -> None:
    import os
    import signal

    import upperpose.io.output as output_module

    original = VideoReader.__iter__

    def terminated(self: VideoReader):  # type: ignore[no-untyped-def]
        for i, frame in enumerate(original(self)):
            if i == 20:
                os.kill(os.getpid(), signal.SIGTERM)  # as a job scheduler would
            yield frame

    write = output_module.write_pose_lines

    def impatient(path, head, lines):  # type: ignore[no-untyped-def]
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C again while the file is being written
        return write(path, head, lines)

    monkeypatch.setattr(VideoReader, "__iter__", terminated)
    monkeypatch.setattr(output_module, "write_pose_lines", impatient)
    out = tmp_path / "poses.json"
    folder = clip()
    code, _, err = track(
        [str(folder / "video.mp4"), "--background", str(folder / "background.png"), "-o", str(out)], capsys
    )
    assert code == 130 and "interrupted" in err and "Traceback" not in err
    frames = [f["frame"] for f in load_poses(out)["frames"]]
    assert frames == list(range(len(frames))) and 20 <= len(frames) <= 22
    assert sorted(p.name for p in tmp_path.iterdir()) == ["poses.json"]
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


@pytest.mark.parametrize("model", ["online", "prepass"])
def test_a_file_without_a_plate_takes_the_chosen_background_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fake_search: TruthFitter, model: str
) -> None:
    out = tmp_path / "poses.json"
    code, _, err = track([str(clip() / "video.mp4"), "--bg-model", model, "-o", str(out), "--quiet"], capsys)
    assert code == 0, err
    doc = load_poses(out)
    assert doc["clean_plate"] is False and doc["settings"]["features"]["bg_model"] == model
    assert sum(f["status"] == "tracked" for f in doc["frames"]) >= 0.5 * len(doc["frames"])
