"""`upperpose batch` and `upperpose.batch.run`: pose files, summary, skipping, failures, Ctrl-C, Ray.

The corpus: six clip folders made from the tracker tests' clip (320x240, 15 fps): four with a
person (50, 44, 38 and 32 frames), one corrupt, one with nobody in it (the empty room). The
real search runs (it takes well under a second per clip), so that worker processes and Ray
tasks track exactly as this process does.
"""

from __future__ import annotations

import csv
import functools
import json
import shutil
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import cv2
import pytest

import upperpose.batch
from tracker_helpers import clip, clip_frames, one_line_error, write_video
from upperpose.batch.inputs import find_videos
from upperpose.cli import main
from upperpose.io.posefile import load_poses
from upperpose.lab.compare import fingerprint

PERSON = {"a": 50, "b": 44, "d": 38, "f": 32}  # clip folder -> frames
EMPTY_FRAMES = 20
POSE_FILES = sorted(f"{name}/video.json" for name in [*PERSON, "e"])
FIRST_RUN = {"a": "done", "b": "done", "c": "failed", "d": "done", "e": "no_pose", "f": "done"}


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("corpus")
    source = clip()
    frames = clip_frames(source)
    plate = source / "background.png"
    for name, n in PERSON.items():
        (root / name).mkdir()
        write_video(root / name / "video.mp4", frames[:n])
        shutil.copy(plate, root / name / "background.png")
    (root / "c").mkdir()
    data = (source / "video.mp4").read_bytes()
    (root / "c" / "video.mp4").write_bytes(data[:40] + bytes(len(data) // 3))  # header start, then zeros
    (root / "e").mkdir()
    write_video(root / "e" / "video.mp4", [cv2.imread(str(plate))] * EMPTY_FRAMES)
    shutil.copy(plate, root / "e" / "background.png")
    return root


def batch(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = main(["batch", *args])
    return code, capsys.readouterr().err


def summary(out: Path) -> dict[str, dict[str, str]]:
    with (out / "summary.csv").open() as f:
        return {Path(r["video"]).parent.name: r for r in csv.DictReader(f)}


def files_in(out: Path) -> list[str]:
    return sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())


def poses_of(out: Path) -> dict[str, str]:
    """Pose file -> hash of its poses (statuses, joints, angles; not its run time)."""
    return {name: fingerprint(load_poses(out / name)) for name in POSE_FILES}


@pytest.fixture(scope="module")
def local_run(corpus: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int, str]:
    """The corpus through the local backend with two processes: (out dir, exit code, stderr)."""
    out = tmp_path_factory.mktemp("local") / "out"
    argv = [sys.executable, "-m", "upperpose", "batch", str(corpus), "--out-dir", str(out), "--jobs", "2"]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    return out, done.returncode, done.stderr


def check_first_run(out: Path) -> None:
    """Five pose files and a summary naming the one failure."""
    assert files_in(out) == sorted([*POSE_FILES, "summary.csv", "summary.json"])  # nothing partial, no temp files
    rows = summary(out)
    assert list(rows) == ["a", "b", "c", "d", "e", "f"]
    assert {k: r["status"] for k, r in rows.items()} == FIRST_RUN
    assert "c/video.mp4" in rows["c"]["error"] and "corrupt" in rows["c"]["error"]
    assert rows["c"]["frames"] == "" and rows["c"]["output"] == "c/video.json"
    for name, n in PERSON.items():
        doc = load_poses(out / name / "video.json")
        assert len(doc["frames"]) == n and int(rows[name]["frames"]) == n
        posed = sum(f["status"] in ("tracked", "lost") for f in doc["frames"])
        assert int(rows[name]["frames_with_pose"]) == posed >= n - 25  # the person walks in, then is tracked
        assert float(rows[name]["frames_per_s"]) > 0
        assert doc["settings"]["threads"] == 1 and doc["seed"] == 0 and doc["clean_plate"] is True
    empty = load_poses(out / "e" / "video.json")
    assert [f["status"] for f in empty["frames"]] == ["no_person"] * EMPTY_FRAMES
    assert rows["e"]["frames_with_pose"] == "0" and rows["e"]["error"] == "no person found"
    totals = json.loads((out / "summary.json").read_text())["totals"]
    assert totals["failed"] == 1 and totals["videos"] == 6
    assert totals["frames"] == sum(PERSON.values()) + EMPTY_FRAMES


def test_local_batch_records_the_failure_and_a_rerun_skips_all(
    corpus: Path, local_run: tuple[Path, int, str], capsys: pytest.CaptureFixture[str]
) -> None:
    out, code, err = local_run
    assert code == 1, err  # a video failed
    assert "Traceback" not in err and "failed: " in err and "[6/6]" in err and "ETA" in err
    check_first_run(out)
    before = {name: (out / name).read_bytes() for name in POSE_FILES}
    code, err = batch([str(corpus), "--out-dir", str(out), "--quiet"], capsys)
    assert code == 1 and "Traceback" not in err
    assert {k: r["status"] for k, r in summary(out).items()} == {
        "a": "skipped", "b": "skipped", "c": "failed", "d": "skipped", "e": "skipped", "f": "skipped"
    }  # fmt: skip
    assert {name: (out / name).read_bytes() for name in POSE_FILES} == before  # not rewritten
    assert summary(out)["a"]["frames"] == str(PERSON["a"])  # skipped rows still carry their counts


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_interrupted_batch_leaves_no_partial_file_and_a_rerun_completes_it(
    jobs: str, corpus: Path, tmp_path: Path, local_run: tuple[Path, int, str]
) -> None:
    out = tmp_path / "out"
    argv = [sys.executable, "-m", "upperpose", "batch", str(corpus), "--out-dir", str(out), "--jobs", jobs]
    # Ctrl-C as in a terminal, even when this test runs in the background (where the shell
    # starts it with SIGINT ignored, which a child would inherit).
    default_sigint = functools.partial(signal.signal, signal.SIGINT, signal.SIG_DFL)
    with subprocess.Popen(argv, stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint) as run:
        assert run.stderr is not None
        seen, done_lines = [], 0
        for line in run.stderr:
            seen.append(line)
            # Ctrl-C once two videos are done. Not simply at "[2/6]": with two jobs the corrupt
            # clip can fail before the first clip ends, and then only one pose file exists.
            done_lines += line.startswith("[") and ": done" in line
            if done_lines == 2:
                run.send_signal(signal.SIGINT)
                break
        rest = run.stderr.read()
        code = run.wait(timeout=120)
    assert code == 130, "".join(seen) + rest
    assert "interrupted" in rest and "Traceback" not in rest
    done = [name for name in POSE_FILES if (out / name).exists()]
    assert 2 <= len(done) < 5
    assert files_in(out) == sorted([*done, "summary.csv", "summary.json"])  # no partial or temporary file
    for name in done:
        load_poses(out / name)  # whole and valid
    first = summary(out)
    assert json.loads((out / "summary.json").read_text())["interrupted"] is True
    assert sum(r["status"] == "not_run" for r in first.values()) >= 1

    again = subprocess.run(argv[:-2] + ["--quiet"], capture_output=True, text=True, timeout=300)
    assert again.returncode == 1, again.stderr  # the corrupt clip still fails
    skipped = {name.split("/")[0] for name in done}
    assert {k: r["status"] for k, r in summary(out).items()} == {
        k: "skipped" if k in skipped else status for k, status in FIRST_RUN.items()
    }
    assert poses_of(out) == poses_of(local_run[0])  # the same poses as the uninterrupted run with two jobs


def test_a_rerun_redoes_a_video_whose_settings_changed(corpus: Path, tmp_path: Path) -> None:
    video = [str(corpus / "f" / "video.mp4")]
    out = tmp_path / "out"

    def status(**kw: Any) -> str:
        result = upperpose.batch.run(video, out, **kw)
        assert len(result.rows) == 1 and result.summary == [out / "summary.csv", out / "summary.json"]
        return str(result.rows[0]["status"])

    assert status() == "done"
    assert status() == "skipped"
    seed_0 = load_poses(out / "video.json")
    assert status(config=upperpose.TrackerConfig(threads=2)) == "skipped"  # threads do not change the poses
    assert status(config=upperpose.TrackerConfig(seed=1)) == "done"
    assert load_poses(out / "video.json")["seed"] == 1
    assert status(smooth=False) == "done"
    assert status(smooth=False) == "skipped"
    assert status(smooth=False, csv=True, bvh=True, overlay=True) == "done"  # files it did not have yet
    frames = len(seed_0["frames"])
    with (out / "video.csv").open() as f:
        assert len(list(csv.reader(f))) == frames + 1
    assert (out / "video.bvh").read_text().count("\n") > frames
    assert (out / "video.overlay.mp4").stat().st_size > 0
    (out / "video.csv").unlink()
    assert status(smooth=False, csv=True, bvh=True, overlay=True) == "done"
    (out / "video.json").write_text((out / "video.json").read_text()[:-20])  # cut short: not finished
    assert status(smooth=False, csv=True, bvh=True, overlay=True) == "done"


def test_inputs_folders_globs_and_lists(corpus: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    folder = find_videos([str(corpus)])
    assert [v.place.as_posix() for v in folder] == [f"{k}/video" for k in "abcdef"]
    globbed = find_videos([f"{corpus}/[ab]/*.mp4", str(corpus / "a" / "video.mp4")])  # the repeat is dropped
    assert [(v.place.as_posix(), Path(v.source).parent.name) for v in globbed] == [("a/video", "a"), ("b/video", "b")]
    listing = tmp_path / "videos.txt"
    listing.write_text(f"# session 1\n{corpus / 'd' / 'video.mp4'}\n\nrtsp://camera.local/live/cam2\n")
    (tmp_path / "local").mkdir()
    shutil.copy(corpus / "f" / "video.mp4", tmp_path / "local" / "take.mp4")
    with listing.open("a") as f:
        f.write("local/take.mp4\n")
    listed = find_videos([str(listing)])
    assert [(v.source, v.place.as_posix()) for v in listed] == [
        (str(corpus / "d" / "video.mp4"), "video"),
        ("rtsp://camera.local/live/cam2", "cam2"),
        (str(tmp_path / "local" / "take.mp4"), "local/take"),
    ]
    with pytest.raises(ValueError, match="would both write video.json"):
        find_videos([str(corpus / "a" / "video.mp4"), str(corpus / "b" / "video.mp4")])
    with pytest.raises(ValueError, match="no video matches"):
        find_videos([f"{corpus}/*/*.avi"])


def test_bad_batch_input_is_one_line(corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = str(tmp_path / "out")
    cases = [
        (["nope.mp4", "--out-dir", out], "no such video, folder or list file: nope.mp4"),
        ([str(tmp_path), "--out-dir", out], "no video in the folder"),
        ([str(corpus), "--out-dir", out, "--collect"], "address and collect are for the ray backend"),
        ([str(corpus), "--out-dir", str(corpus / "a" / "video.mp4")], "is a file"),
    ]
    for argv, message in cases:
        code, err = batch(argv, capsys)
        assert code == 1 and message in one_line_error(err), (argv, err)
    assert not (tmp_path / "out").exists()


def test_ray_backend_gives_the_local_backends_pose_files(
    corpus: Path, tmp_path: Path, local_run: tuple[Path, int, str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # Every Ray process this test starts listens on the loopback interface only (set before Ray loads).
    monkeypatch.setenv("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
    ray = pytest.importorskip("ray")
    sigterm = signal.getsignal(signal.SIGTERM)
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    signal.signal(signal.SIGTERM, sigterm)  # ray.init takes SIGTERM over for good
    try:
        assert {n["NodeManagerAddress"] for n in ray.nodes()} == {"127.0.0.1"}
        shared, collected = tmp_path / "shared", tmp_path / "collected"
        for out, collect in ((shared, False), (collected, True)):
            result = upperpose.batch.run([corpus], out, backend="ray", collect=collect)
            assert result.failed == 1
            check_first_run(out)
            assert poses_of(out) == poses_of(local_run[0])
        again = upperpose.batch.run([corpus], shared, backend="ray")
        assert [r["status"] for r in again.rows] == ["skipped"] * 2 + ["failed"] + ["skipped"] * 3
        assert ray.is_initialized()  # the batch leaves a Ray it did not start running
    finally:
        ray.shutdown()
