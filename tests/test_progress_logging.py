"""The command line's progress (tqdm, or plain lines off a terminal) and its -v/-q logging."""

from __future__ import annotations

import io
import logging
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import upperpose.fit.tracker as tracker_module
import upperpose.io.progress as progress_module
from tracker_helpers import TruthFitter, clip, truth
from upperpose.cli import main
from upperpose.exceptions import InputError
from upperpose.io.progress import Progress


class Clock:
    """Stands in for time.monotonic: the tests say when time passes."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch) -> Clock:
    fake = Clock()
    monkeypatch.setattr(progress_module.time, "monotonic", fake)
    return fake


@pytest.fixture
def fake_search(monkeypatch: pytest.MonkeyPatch) -> TruthFitter:
    fitter = TruthFitter(truth(clip()), wrong=range(36, 48))  # wrong right arm: a real loss and recovery
    monkeypatch.setattr(tracker_module, "fit_frame", fitter)
    return fitter


def test_off_a_terminal_one_plain_line_per_interval(clock: Clock, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("UPPERPOSE_PROGRESS_EVERY", "10")
    out = io.StringIO()
    meter = Progress("upperpose track", stream=out)
    for done in range(1, 61):  # 60 frames at 3 a second: lines at 10 s and at 20 s only
        clock.now = done / 3
        meter.update(done, 100, "tracked")
    meter.close()
    lines = out.getvalue().splitlines()
    assert len(lines) == 2 and "\r" not in out.getvalue()
    assert lines[0].startswith("upperpose track: 30/100 frames (30 %),")
    assert lines[0].endswith("3.00 frames/s, ETA 00:23, tracked")  # 70 frames left at 3 a second
    assert lines[1].startswith("upperpose track: 60/100 frames (60 %)")


def test_a_live_source_has_no_total_and_no_time_left(clock: Clock, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("UPPERPOSE_PROGRESS_EVERY", "5")
    out = io.StringIO()
    meter = Progress("upperpose track", stream=out)
    clock.now = 5.0
    meter.update(45, None, "lost")
    assert out.getvalue() == "upperpose track: 45 frames, 9.00 frames/s, lost\n"


def test_zero_turns_the_plain_lines_off_and_a_bad_interval_is_refused(
    clock: Clock, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("UPPERPOSE_PROGRESS_EVERY", "0")
    out = io.StringIO()
    meter = Progress("upperpose track", stream=out)
    clock.now = 1000.0
    meter.update(10, 20)
    assert out.getvalue() == ""
    for bad in ("-1", "soon", "nan"):
        monkeypatch.setenv("UPPERPOSE_PROGRESS_EVERY", bad)
        with pytest.raises(InputError, match="UPPERPOSE_PROGRESS_EVERY must be a number of seconds >= 0"):
            Progress("upperpose track", stream=out)


def test_on_a_terminal_a_bar_with_lines_above_it(clock: Clock) -> None:
    screen = Terminal()
    meter = Progress("upperpose batch", stream=screen)
    meter.update(40, 80, "videos 1/2")
    meter.write("[1/2] a.mp4: done")
    meter.close()
    shown = screen.getvalue()
    assert "\r" in shown and "40/80" in shown and "videos 1/2" in shown and "[1/2] a.mp4: done\n" in shown


def test_disabled_shows_nothing(clock: Clock) -> None:
    screen = Terminal()
    meter = Progress("upperpose track", enabled=False, stream=screen)
    clock.now = 100.0
    meter.update(5, 10)
    meter.close()
    assert screen.getvalue() == ""


def run_track(
    argv: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str], before: list[str] | None = None
) -> tuple[str, str]:
    """Tracks the test clip without its clean plate (a warning) into tmp_path; returns stdout, stderr."""
    args = [*(before or []), "track", str(clip() / "video.mp4"), "-o", str(tmp_path / "o.json"), *argv]
    assert main(args) == 0
    return capsys.readouterr()


@pytest.mark.usefixtures("fake_search")
def test_warnings_show_by_default_and_go_with_quiet(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out, err = run_track([], tmp_path, capsys)
    lines = err.splitlines()
    assert lines and all(line.startswith("upperpose track: warning: ") for line in lines)
    assert "background" in err and out.startswith("Tracked ")
    assert run_track(["--quiet"], tmp_path, capsys) == ("", "")
    assert run_track([], tmp_path, capsys, before=["-q"]) == ("", "")


@pytest.mark.usefixtures("fake_search")
def test_verbose_tells_start_up_losses_and_outputs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    _, err = run_track(["-v"], tmp_path, capsys)
    info = [line for line in err.splitlines() if line.startswith("upperpose track: info: ")]
    assert any("start-up found the person: tracking from frame" in line for line in info), err
    assert any("lost the right arm" in line for line in info) and any(
        "recovered the right arm" in line for line in info
    )
    assert info[-1].endswith(f"wrote {tmp_path / 'o.json'}")
    assert "debug:" not in err
    assert len(info) < 10  # events, not one line per frame
    # -vv before the subcommand: also the details, as log records of the package's logger.
    with caplog.at_level(logging.DEBUG, logger="upperpose"):
        _, err = run_track([], tmp_path, capsys, before=["-vv"])
    assert "upperpose track: debug: video.mp4: 320x240 at 15 fps, 50 frames" in err
    assert any(r.levelno == logging.DEBUG and r.name == "upperpose.fit.outputs" for r in caplog.records)


def test_the_logger_is_left_as_it_was(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = logging.getLogger("upperpose")
    before = (log.level, list(log.handlers))
    with pytest.raises(SystemExit):
        main(["-vv", "track", "-o", str(tmp_path / "o.json")])  # a usage error: neither video nor camera
    assert (log.level, list(log.handlers)) == before


def test_quiet_batch_and_plain_batch_lines(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fake_search: object
) -> None:
    video = str(clip() / "video.mp4")
    assert main(["batch", video, "--out-dir", str(tmp_path / "q"), "--quiet"]) == 0
    assert capsys.readouterr() == ("", "")
    assert main(["batch", video, "--out-dir", str(tmp_path / "v")]) == 0
    err = capsys.readouterr().err
    assert err.startswith(f"[1/1] {video}: done, 50 frames") and "\r" not in err
    assert "  |  50/50 frames (100 %), " in err and "ETA 00:00, videos 1/1" in err


def test_off_a_terminal_a_real_run_prints_plain_progress_lines(tmp_path: Path) -> None:
    # A real process with stderr to a pipe, as under a job scheduler, with a very short interval.
    env = {**os.environ, "UPPERPOSE_PROGRESS_EVERY": "0.000001"}
    argv = [sys.executable, "-m", "upperpose", "track", str(clip() / "video.mp4"), "-o", str(tmp_path / "o.json")]
    argv += ["--background", str(clip() / "background.png"), "--particles", "8", "--iterations", "2"]
    done = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode in (0, 1), done.stderr  # a search this small may never start tracking
    lines = [line for line in done.stderr.splitlines() if re.match(r"upperpose track: \d+/50 frames \(\d+ %\), ", line)]
    assert len(lines) >= 2 and "\r" not in done.stderr, done.stderr
    counts = [int(line.split()[2].split("/")[0]) for line in lines]
    assert counts == sorted(counts) and counts[-1] > counts[0] and all("ETA" in line for line in lines)
