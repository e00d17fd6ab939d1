"""`upperpose plot`: a figure of every joint against time, with the truth when given."""

from __future__ import annotations

from pathlib import Path

import cv2
import pytest

from tracker_helpers import clip
from upperpose.cli import main

pytest.importorskip("matplotlib")


def test_plot_with_truth_writes_a_figure(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    truth = clip() / "gt.json"
    out = tmp_path / "fig.png"
    assert main(["plot", str(truth), "--truth", str(truth), "-o", str(out)]) == 0
    image = cv2.imread(str(out))
    assert image is not None and image.shape[0] > image.shape[1] > 1000  # seven rows of three panels
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig.png"]


def test_plot_refuses_an_unknown_format_and_a_bad_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    truth = clip() / "gt.json"
    assert main(["plot", str(truth), "-o", str(tmp_path / "fig.bmp")]) == 1
    assert "must be .png, .pdf or .svg" in capsys.readouterr().err
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    assert main(["plot", str(bad), "-o", str(tmp_path / "fig.png")]) == 1
    assert "format must be" in capsys.readouterr().err
    assert not (tmp_path / "fig.png").exists()
