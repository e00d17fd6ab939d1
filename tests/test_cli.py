"""The command line: in-process runs and one real subprocess."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import cv2
import pytest

import upperpose
from upperpose.cli import main


def test_version_smoke(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"upperpose {upperpose.__version__}"


def test_render_writes_an_image(tmp_path: Path) -> None:
    out = tmp_path / "model.png"
    assert main(["render", "-o", str(out), "--angle", "right_z_up=1.2", "--width", "320", "--height", "240"]) == 0
    image = cv2.imread(str(out))
    assert image.shape == (240, 320, 3)
    assert (image != 70).any()  # something was drawn on the plain background
    assert [p.name for p in tmp_path.iterdir()] == ["model.png"]  # no temporary file left


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["render", "--angle", "elbow=1"], "unknown angle 'elbow'"),
        (["render", "-o", "/nonexistent-folder/x.png"], "does not exist"),
    ],
)
def test_bad_input_is_one_line_and_exit_1(argv: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_usage_error_exits_2() -> None:
    with pytest.raises(SystemExit) as exc:
        main(["render", "--width", "wide"])
    assert exc.value.code == 2


def usage_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Runs a command line that must end in argparse's usage and exit 2; returns its error line."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"usage: upperpose {argv[0]} ") and "Traceback" not in err, err
    last = err.splitlines()[-1]
    assert last.startswith(f"upperpose {argv[0]}: error: "), err
    return last


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["render", "--angle", "right_z_up"], "--angle takes NAME=RAD, got 'right_z_up'"),
        (["render", "--depth", "-1"], "--depth must be within 0.3..100 metres, got -1"),
        (["track", "v.mp4", "-o", "x.json", "--particles", "0"], "--particles must be at least 1, got 0"),
        (["track", "v.mp4", "-o", "x.json", "--seed", "-1"], "--seed must be within 0..2**64-1, got -1"),
        (["track", "-o", "x.json"], "give either a VIDEO or --camera N"),
        (["batch", "v.mp4", "--out-dir", "o", "--jobs", "0"], "--jobs must be at least 1, got 0"),
        (["batch", "v.mp4", "--out-dir", "o", "--iterations", "-3"], "--iterations must be at least 1, got -3"),
        (["config", "--sigma", "0"], "--sigma must be a positive number, got 0.0"),
        (["eval", "p.json", "g.json", "--pck", "0"], "--pck must be positive, got 0.0"),
        (["features", "v.mp4", "--frame", "-2", "-o", "f.png"], "--frame must be >= 0, got -2"),
        (["demo", "--frames", "5"], "--frames must be within 30..3000, got 5"),
    ],
)
def test_bad_option_values_exit_2_with_the_usage(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # where any output named above would go
    assert message in usage_error(argv, capsys)
    assert list(tmp_path.iterdir()) == []


def test_installed_command_runs_in_a_subprocess(tmp_path: Path) -> None:
    out = tmp_path / "sheet.png"
    argv = [sys.executable, "-m", "upperpose", "render", "--sheet", "-o", str(out)]
    proc = subprocess.run(argv, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr
    assert cv2.imread(str(out)).shape == (960, 2560, 3)


def test_written_files_get_the_usual_permissions(tmp_path: Path) -> None:
    out = tmp_path / "model.png"
    assert main(["render", "-o", str(out), "--width", "64", "--height", "48"]) == 0
    assert out.stat().st_mode & 0o777 == 0o666 & ~_current_umask()


def _current_umask() -> int:
    import os

    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["render", "--width", "20000", "--height", "20000"], "--width must be within 32..8192 pixels"),
        (["render", "--depth", "1e-12"], "--depth must be within 0.3..100 metres"),
        (["render", "--focal", "1e-300"], "--focal must be within 1..100000 pixels"),
        (["synth", "OUT", "--fps", "inf"], "--fps must be within 1..240"),
        (["synth", "OUT", "--width", "641", "--height", "479"], "--width must be even"),
        (["synth", "OUT", "--width", "100000"], "--width must be within 32..8192 pixels"),
    ],
)
def test_sizes_and_rates_out_of_range_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    argv = [str(tmp_path / "out") if a == "OUT" else a for a in argv]
    assert message in usage_error([*argv, "-o", str(tmp_path / "m.png")] if argv[0] == "render" else argv, capsys)
    assert list(tmp_path.iterdir()) == []


def test_render_masks_refuses_huge_images_before_allocating() -> None:
    with pytest.raises(upperpose.InputError, match="width must be at most 8192 pixels, got 20000"):
        upperpose.render_masks(upperpose.Pose(), [0.0, 0.1, 2.2], upperpose.Camera.for_image(640, 480), 20000, 20000)
