"""The optimisers of the thesis' comparison (SPEC 7): API, command-line flags, `upperpose compare`."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import upperpose
from tracker_helpers import clip
from upperpose.cli import build_parser, main
from upperpose.commands.track import tracker_config
from upperpose.lab.compare import Method, find_clips, run_all


@pytest.mark.parametrize("optimizer", ["apso", "pso", "simplex", "apsopf"])
def test_search_config_takes_every_optimizer(optimizer: str) -> None:
    c = upperpose.SearchConfig(optimizer=optimizer, sigma=0.3)
    assert (c.optimizer, c.sigma) == (optimizer, 0.3)
    assert upperpose.SearchConfig().optimizer == "apso" and upperpose.SearchConfig().sigma == 1.0


@pytest.mark.parametrize("kwargs", [{"optimizer": "annealing"}, {"sigma": 0.0}, {"sigma": float("nan")}])
def test_search_config_rejects_bad_values(kwargs: dict[str, object]) -> None:
    with pytest.raises(ValueError):
        upperpose.SearchConfig(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize("command", ["track", "bench", "demo"])
def test_flags_reach_the_search(command: str) -> None:
    extra = ["v.mp4", "-o", "x.json"] if command == "track" else []
    args = build_parser().parse_args(
        [command, *extra, "--optimizer", "apsopf", "--sigma", "0.4", "--limits", "thesis", "--seed", "3"]
    )
    search = tracker_config(args).search_config()
    assert (search.optimizer, search.sigma, search.limits, search.seed) == ("apsopf", 0.4, "thesis", 3)


def test_bad_flags_are_one_line_errors(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["track", "v.mp4", "-o", "x.json", "--optimizer", "newton"])
    assert "invalid choice" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["track", "v.mp4", "-o", "x.json", "--sigma", "-1"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.splitlines()[-1] == "upperpose track: error: --sigma must be a positive number, got -1.0"


def dataset(tmp_path: Path) -> Path:
    """Two clips: one with its clean plate, one without (background estimated)."""
    src = clip()
    root = tmp_path / "set"
    for name, files in (
        ("a", ("video.mp4", "background.png", "gt.json", "meta.json")),
        ("b", ("video.mp4", "gt.json", "meta.json")),
    ):
        (root / name).mkdir(parents=True)
        for f in files:
            (root / name / f).symlink_to(src / f)
    return root


def compare(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(["compare", *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_report_has_every_method(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    root = dataset(tmp_path)
    args = [str(root), "--frames", "16", "--sigmas", "0.5", "--jobs", "2", "--quiet", "-o", str(tmp_path / "r.md")]
    code, _, _ = compare(args, capsys)
    assert code == 0
    report = (tmp_path / "r.md").read_text()
    header = "| Body part | APSO | APSO, thesis limits | PSO | Simplex [1] | APSOPF [2] σ=1 |"
    assert header in report
    for row in ("| Right elbow x (px) |", "| **Total average y (px)** |", "| Frame rate (fps) |", "| 2D MPJPE (px) |"):
        assert row in report
    assert "| coverage (%) |" in report and "| σ = 0.5 |" in report
    assert "| a |" in report and "| b |" in report and "b has no clean plate" in report
    assert re.search(r"Fingerprint of all 12 runs' poses: `\w{16}`", report)


def test_same_seed_same_numbers_whatever_jobs_and_threads(tmp_path: Path) -> None:
    clips = find_clips(dataset(tmp_path))[:1]
    methods = [Method("S", "simplex"), Method("P", "apsopf", sigma=0.5)]
    one = run_all(clips, methods, frames=30, seed=4, jobs=1, threads=1)
    two = run_all(clips, methods, frames=30, seed=4, jobs=2, threads=2)
    assert [r["scores"]["coverage"] for r in one] == [r["scores"]["coverage"] for r in two]
    assert all(r["scores"]["coverage"] > 0.3 for r in one)
    for a, b in zip(one, two):
        assert (a["fingerprint"], a["scores"]["joint_error_px"]) == (b["fingerprint"], b["scores"]["joint_error_px"])


@pytest.mark.parametrize(
    ("setup", "args", "message"),
    [
        ("missing", [], "is not a folder"),
        ("empty", [], "no clip in"),
        ("no_gt", [], "clip c has no gt.json"),
        ("bad_meta", [], "clip c: meta.json needs camera.focal"),
    ],
)
def test_bad_input_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], setup: str | None, args: list[str], message: str
) -> None:
    root = tmp_path / "set"
    root.mkdir()
    if setup in ("no_gt", "bad_meta", None):
        (root / "c").mkdir()
        (root / "c" / "video.mp4").write_bytes(b"")
        (root / "c" / "meta.json").write_text('{"camera": {}}')
        if setup == "bad_meta":
            (root / "c" / "gt.json").write_text("{}")
    target = tmp_path / "nowhere" if setup == "missing" else root
    code, _, err = compare([str(target), *args], capsys)
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 1 and len(lines) == 1 and "Traceback" not in err
    assert message in lines[0]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--jobs", "0"], "--jobs must be at least 1, got 0"),
        (["--sigmas", "0"], "--sigmas must be positive numbers, got 0.0"),
    ],
)
def test_bad_values_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["compare", str(tmp_path), *args])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "usage: upperpose compare" in err and err.splitlines()[-1] == f"upperpose compare: error: {message}"


def test_a_failing_run_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    root = tmp_path / "set" / "c"
    root.mkdir(parents=True)
    (root / "video.mp4").write_bytes(b"not a video")
    (root / "gt.json").write_text("{}")
    (root / "meta.json").write_text('{"camera": {"focal": 500}}')
    code, _, err = compare([str(root.parent), "--sigmas", "--quiet"], capsys)
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 1 and len(lines) == 1 and lines[0].startswith("upperpose compare: error: clip c, APSO: ")
