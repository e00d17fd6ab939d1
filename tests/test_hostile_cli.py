"""A generated corpus of malformed files and absurd option values for the command line.

Each case runs `upperpose.cli.main(argv)` in-process and must end in one of three ways:
exit 0 with valid outputs, exit 1 with one line `upperpose CMD: error: ...` (not an internal
error), or exit 2 with argparse's usage. Never a traceback. A few cases run as real
subprocesses to show that nothing else (an abort, OpenCV's logging) reaches the terminal.
"""

from __future__ import annotations

import json
import subprocess
import sys
import zlib

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from test_hostile_why import png_header
from upperpose.cli import main
from upperpose.io.posefile import load_poses, make_poses

W, H = 64, 48  # a small valid video: features and start-up run, no person to find


def video_bytes(tmp: Path, frames: int = 6, size: tuple[int, int] = (W, H), fourcc: str = "mp4v") -> bytes:
    path = tmp / f"v.{'mp4' if fourcc == 'mp4v' else 'avi'}"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*fourcc), 15.0, size)
    rng = np.random.default_rng(frames)
    for _ in range(frames):
        writer.write(rng.integers(0, 255, (size[1], size[0], 3), dtype=np.uint8))
    writer.release()
    data = path.read_bytes()
    path.unlink()
    return data


def image_bytes(width: int, height: int, ext: str = ".png") -> bytes:
    ok, data = cv2.imencode(ext, np.full((height, width, 3), 120, np.uint8))
    assert ok
    return data.tobytes()


# -- the corpus of files ------------------------------------------------------------------------
# name -> function of a scratch folder giving the file's bytes (None: the name is a folder, or
# nothing at all).
Maker = Callable[[Path], "bytes | None"]


def media_corpus() -> dict[str, Maker]:
    rng = np.random.default_rng(23)
    corpus: dict[str, Maker] = {
        "valid.mp4": lambda t: video_bytes(t),
        "one-frame.mp4": lambda t: video_bytes(t, frames=1),
        "zero-bytes.mp4": lambda t: b"",
        "text.mp4": lambda t: b"not a video\n" * 40,
        "text.txt": lambda t: b"hello",
        "json.mp4": lambda t: b'{"format": "upperpose.poses/1"}',
        "nul-bytes.mp4": lambda t: bytes(5000),
        "image.png": lambda t: image_bytes(W, H),
        "image.jpg": lambda t: image_bytes(W, H, ".jpg"),
        "image-1x1.png": lambda t: image_bytes(1, 1),
        "image-31x31.png": lambda t: image_bytes(31, 31),
        "image-33x33.png": lambda t: image_bytes(33, 33),
        "image-8000x8.png": lambda t: image_bytes(8000, 8),
        "image-8193x40.png": lambda t: image_bytes(8193, 40),
        "image-40000x40000-header.png": lambda t: png_header(40_000, 40_000),
        "png-header-only.png": lambda t: png_header(64, 48)[:33],
        "video-2x2.avi": lambda t: video_bytes(t, 3, (2, 2), "MJPG"),
        "video-32x32.mp4": lambda t: video_bytes(t, 3, (32, 32)),
        "video-34x36.mp4": lambda t: video_bytes(t, 3, (34, 36)),
        "video-odd-66x50.avi": lambda t: video_bytes(t, 3, (65, 49), "MJPG"),
        "folder.mp4": lambda t: None,
        "missing.mp4": lambda t: None,
        "compressed-garbage.mp4": lambda t: zlib.compress(bytes(range(256)) * 50),
    }
    for k in range(8):  # truncated at 1/16 .. 15/16 of the file
        corpus[f"truncated-{k}.mp4"] = lambda t, k=k: (lambda d: d[: len(d) * (2 * k + 1) // 16])(video_bytes(t))
    for k in range(6):  # a corrupt middle: a run of random bytes over part of the file

        def corrupt(t: Path, k: int = k) -> bytes:
            data = bytearray(video_bytes(t))
            start = len(data) * (k + 1) // 8
            data[start : start + 400] = np.random.default_rng(k).integers(0, 256, 400, dtype=np.uint8).tobytes()
            return bytes(data)

        corpus[f"corrupt-middle-{k}.mp4"] = corrupt
    for k, n in enumerate([1, 7, 64, 1000, 20000]):
        corpus[f"random-{n}.mp4"] = lambda t, n=n, k=k: rng.integers(0, 256, n, dtype=np.uint8).tobytes()
    return corpus


def json_corpus() -> dict[str, Maker]:
    good = make_poses(W, H, 15.0, [{"frame": 0, "status": "tracked", "joints_2d": [[1.0, 2.0]] * 7, "joints_3d": None}])
    text = json.dumps(good)
    variants = {
        "valid.json": text,
        "empty.json": "",
        "nul.json": "\x00" * 10,
        "truncated.json": text[: len(text) // 2],
        "deep.json": "[" * 50_000 + "]" * 50_000,
        "deep-dict.json": '{"a":' * 50_000 + "1" + "}" * 50_000,
        "nan.json": text.replace("1.0", "NaN"),
        "inf.json": text.replace("1.0", "1e999"),
        "huge.json": text.replace("1.0", "1e300"),
        "negative-width.json": text.replace(f'"width": {W}', '"width": -5'),
        "string-width.json": text.replace(f'"width": {W}', '"width": "64"'),
        "bool-frame.json": text.replace('"frame": 0', '"frame": true'),
        "big-frame.json": text.replace('"frame": 0', '"frame": 100000000000000000000000000000'),
        "list.json": "[1, 2, 3]",
        "number.json": "42",
        "string.json": '"upperpose"',
        "wrong-format.json": text.replace("upperpose.poses/1", "upperpose.poses/2"),
        "no-frames.json": json.dumps({k: v for k, v in good.items() if k != "frames"}),
        "frames-dict.json": json.dumps(good | {"frames": {"0": good["frames"]}}),
        "short-joints.json": text.replace("[[1.0, 2.0], ", "", 1),
        "bad-status.json": text.replace('"tracked"', '"dancing"'),
        "duplicate-frame.json": json.dumps(good | {"frames": good["frames"] * 2}),
        "latin1.json": text.encode("utf-16").decode("latin-1"),
        "bom.json": "\ufeff" + text,
    }
    corpus: dict[str, Maker] = {
        name: (lambda t, v=v: v.encode("utf-8", "surrogatepass")) for name, v in variants.items()
    }
    corpus["binary.json"] = lambda t: bytes(range(256))
    corpus["folder.json"] = lambda t: None
    corpus["missing.json"] = lambda t: None
    return corpus


def toml_corpus() -> dict[str, Maker]:
    variants = {
        "empty.toml": "",
        "garbage.toml": "[[[ not toml",
        "unknown-key.toml": "nonsense = 3\n",
        "bad-type.toml": 'particles = "many"\n',
        "negative.toml": "particles = -4\n",
        "huge.toml": "particles = 100000000000000000000000\n",
        "nan.toml": "presence_share = nan\n",
        "inf.toml": "root_window = inf\n",
        "nested.toml": "[features]\nskin_threshold = -1\n",
        "valid.toml": "particles = 8\n",
    }
    return {name: (lambda t, v=v: v.encode()) for name, v in variants.items()}


MEDIA, JSONS, TOMLS = media_corpus(), json_corpus(), toml_corpus()


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The corpus written to a folder, one file per name (folders for 'folder.*')."""
    root = tmp_path_factory.mktemp("corpus")
    scratch = tmp_path_factory.mktemp("scratch")
    for name, make in {**MEDIA, **JSONS, **TOMLS}.items():
        data = make(scratch)
        if name.startswith("folder"):
            (root / name).mkdir()
        elif data is not None:
            (root / name).write_bytes(data)
    return root


# -- absurd option values -----------------------------------------------------------------------
ABSURD = ["-1", "0", "1e309", "nan", "inf", "-inf", "1e-300", "99999999999999999999999", "abc", "", "0x10"]
OPTIONS = {
    "track": ["--particles", "--iterations", "--threads", "--seed", "--focal", "--sigma", "--camera"],
    "render": ["--width", "--height", "--depth", "--focal", "--angle"],
    "synth": ["--fps", "--frames", "--width", "--height", "--depth", "--noise", "--focal", "--holdout", "--jobs"],
    "eval": ["--pck"],
    "config": ["--particles", "--iterations", "--threads", "--seed", "--sigma"],
}


def option_cases() -> list[tuple[str, str, str]]:
    return [(cmd, opt, v) for cmd, opts in OPTIONS.items() for opt in opts for v in ABSURD]


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    """Runs the command line; checks the exit status and stderr; returns the status and stdout."""
    try:
        code = main(argv)
    except SystemExit as exit_:  # argparse's usage errors
        code = int(exit_.code or 0)
    out, err = capsys.readouterr()
    assert "Traceback" not in err + out
    lines = [line for line in err.splitlines() if not line.startswith(f"upperpose {argv[0]}: warning: ")]
    if code == 1:
        assert len(lines) == 1, err
        assert lines[0].startswith(f"upperpose {argv[0]}: error: "), err
        assert "internal error" not in lines[0]
    elif code == 2:
        assert "usage:" in err and lines[-1].startswith("upperpose"), err
    else:
        assert code == 0 and not lines, (code, err)
    return code, out


def assert_valid_poses(path: Path) -> None:
    assert load_poses(path)["frames"] is not None


# -- the cases ----------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(MEDIA))
@pytest.mark.parametrize("plate", [False, True])
def test_track_any_file(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, plate: bool
) -> None:
    (tmp_path / "plate.png").write_bytes(image_bytes(W, H))
    out = tmp_path / "o.json"
    argv = ["track", str(corpus / name), "-o", str(out), "--csv", str(tmp_path / "o.csv"), "--quiet"]
    argv += ["--particles", "4", "--iterations", "2"] + (["--background", str(tmp_path / "plate.png")] if plate else [])
    code, _ = run(argv, capsys)
    if out.exists():  # written whole or not at all, whatever the exit status
        assert_valid_poses(out)
    assert code != 0  # none of these files shows a person
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary files left


@pytest.mark.parametrize("name", sorted(MEDIA))
def test_any_file_as_the_plate(corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str) -> None:
    video = tmp_path / "v.mp4"
    video.write_bytes(MEDIA["valid.mp4"](tmp_path))
    run(["track", str(video), "--background", str(corpus / name), "-o", str(tmp_path / "o.json"), "--quiet"], capsys)


@pytest.mark.parametrize("name", sorted(MEDIA))
def test_features_of_any_file(corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str) -> None:
    out = tmp_path / "f.png"
    code, _ = run(["features", str(corpus / name), "--frame", "0", "-o", str(out)], capsys)
    assert (code == 0) == out.exists()


@pytest.mark.parametrize("name", sorted(JSONS))
@pytest.mark.parametrize("side", ["prediction", "truth"])
def test_eval_any_json(corpus: Path, capsys: pytest.CaptureFixture[str], name: str, side: str) -> None:
    pair = [str(corpus / name), str(corpus / "valid.json")]
    code, _ = run(["eval", *(pair if side == "prediction" else pair[::-1]), "--json"], capsys)
    assert (code == 0) == (name in ("valid.json", "big-frame.json"))  # frame numbers may be any size


@pytest.mark.parametrize("name", sorted(JSONS))
def test_plot_any_json(corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str) -> None:
    pytest.importorskip("matplotlib")
    out = tmp_path / "p.png"
    code, _ = run(["plot", str(corpus / name), "-o", str(out)], capsys)
    assert (code == 0) == out.exists()


@pytest.mark.parametrize("name", sorted(TOMLS))
def test_any_settings_file(corpus: Path, capsys: pytest.CaptureFixture[str], name: str) -> None:
    code, _ = run(["config", "--config", str(corpus / name)], capsys)
    assert (code == 0) == (name in ("empty.toml", "valid.toml"))


@pytest.mark.parametrize(("command", "option", "value"), option_cases())
def test_absurd_option_values(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, option: str, value: str
) -> None:
    video = tmp_path / "missing.mp4"  # a valid value still ends at the missing video, cheaply
    small = ["--frames", "1", "--width", "32", "--height", "32"]  # a valid value makes a tiny clip
    argv = {
        "track": ["track", str(video), "-o", str(tmp_path / "o.json")],
        "render": ["render", "-o", str(tmp_path / "r.png"), "--width", "32", "--height", "32"],
        "synth": ["synth", str(tmp_path / "clip"), *small],
        "eval": ["eval", str(tmp_path / "a.json"), str(tmp_path / "b.json")],
        "config": ["config"],
    }[command]
    if command == "track" and option == "--camera":
        argv.remove(str(video))
    value_arg = [f"{option}={value}"] if option != "--angle" else ["--angle", f"right_z_up={value}"]
    code, out = run([*argv, *value_arg], capsys)
    made = {"render": tmp_path / "r.png", "synth": tmp_path / "clip"}.get(command)
    if code != 0:
        assert made is None or not made.exists()  # nothing half-written
    elif command == "render":
        assert cv2.imread(str(made)).shape == (32, 32, 3)
    elif command == "synth":
        assert len(load_poses(tmp_path / "clip" / "gt.json")["frames"]) >= 1
    else:
        assert command == "config" and tomllib.loads(out)


# -- real processes -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "args"),
    [
        ("truncated-3.mp4", ["-o", "OUT"]),
        ("zero-bytes.mp4", ["-o", "OUT"]),
        ("image-40000x40000-header.png", ["-o", "OUT"]),
        ("valid.mp4", ["-o", "OUT", "--overlay", "OUT.unknown-extension"]),
        ("valid.mp4", ["-o", "OUT", "--particles", "1000000000"]),
        ("video-2x2.avi", ["-o", "OUT"]),
    ],
)
def test_nothing_but_one_line_reaches_the_terminal(corpus: Path, tmp_path: Path, name: str, args: list[str]) -> None:
    out = str(tmp_path / "o.json")
    argv = [sys.executable, "-m", "upperpose", "track", str(corpus / name), *[a.replace("OUT", out) for a in args]]
    argv += ["--background", str(corpus / "image.png")]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 1, done  # not a signal (negative), not an abort (134)
    assert done.stdout == "" and len(done.stderr.splitlines()) == 1, done.stderr  # FFmpeg's logging too
    assert done.stderr.startswith("upperpose track: error: ") and "Traceback" not in done.stderr
