"""The pre-pass's estimated plate against the true one, and which of its errors could be avoided.

    python -m upperpose.lab.plate_estimate CLIP [CLIP ...] [--threshold 30]

Each CLIP is a folder with `video.mp4` and `background.png` (the true clean plate), as the
external validation set has. Per clip: how the plate was made, the seconds the estimate took,
and its wrong pixels (some channel more than `--threshold` from the true plate) in three
classes, by the share of the estimate's own samples that show the room there (within the
threshold of the true plate):

- `most`: the room shows in at least half the samples. A plain temporal median has these
  right; an estimate that has them wrong masked the room's samples out (a person cut that
  overreaches into the room, whose samples then count as the person still there);
- `some`: the room shows in some samples but fewer than half: the person covered it most of the
  time, and only masking them out can find it;
- `never`: no sample shows the room: only the inpainting can guess it.

Quick (under 2 s a clip, no tracking), so a change to the estimate can be screened before
the tracker is run on it; the plate is only a means, and a plate with fewer wrong pixels has
tracked worse (docs/RESULTS.md, The estimated plates' wrong pixels).
Not a test: the numbers depend on the clips; times on the machine.
"""

from __future__ import annotations

import argparse
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features import CleanPlateWarning, FeatureConfig
from upperpose.features.background import estimate_plate, median_samples, sample_video
from upperpose.features.change import colour_change
from upperpose.features.checks import Frame

CLASSES = ("most", "some", "never")


@dataclass(frozen=True)
class PlateErrors:
    """Wrong pixels of an estimated plate, as shares of the image, by how often the room shows."""

    wrong: float
    most: float
    some: float
    never: float


def classify_errors(plate: Frame, truth: Frame, samples: npt.NDArray[np.uint8], threshold: int) -> PlateErrors:
    """The plate's wrong pixels against `truth`, split by the share of `samples` showing the room.

    Args:
        plate: `(H, W, 3)` uint8 estimate.
        truth: `(H, W, 3)` uint8 true plate.
        samples: `(N, H, W, 3)` uint8 frames the estimate was made from.
        threshold: a pixel differs when some channel differs by more than this.
    """
    wrong = colour_change(plate, truth, threshold) > 0
    room_share = np.mean([colour_change(sample, truth, threshold) == 0 for sample in samples], axis=0)
    area = wrong.size
    return PlateErrors(
        wrong=float(wrong.sum()) / area,
        most=float((wrong & (room_share >= 0.5)).sum()) / area,
        some=float((wrong & (room_share > 0) & (room_share < 0.5)).sum()) / area,
        never=float((wrong & (room_share == 0)).sum()) / area,
    )


def estimate_clip(folder: Path, config: FeatureConfig, threshold: int) -> tuple[str, float, PlateErrors]:
    """(method, seconds, errors) of the pre-pass estimate for one clip folder."""
    truth = cast(Frame | None, cv2.imread(str(folder / "background.png"), cv2.IMREAD_COLOR))
    if truth is None:
        raise SystemExit(f"{folder}: no readable background.png")
    start = time.perf_counter()
    lead, samples, _ = sample_video(folder / "video.mp4", config)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CleanPlateWarning)
        plate, method, _ = estimate_plate(lead, samples, config)
    seconds = time.perf_counter() - start
    # The frames the masked median used (a lead-in median used its own).
    used = np.stack(median_samples(lead, samples, config))
    return method, seconds, classify_errors(plate, truth, used, threshold)


def main(argv: list[str] | None = None) -> None:
    """Prints one row per clip and the mean over them."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("clips", nargs="+", type=Path)
    parser.add_argument("--threshold", type=int, default=30, help="channel difference that counts as wrong")
    args = parser.parse_args(argv)
    config = FeatureConfig()
    rows = []
    print(f"{'clip':30s} {'method':31s} {'s':>5s} {'wrong %':>8s} " + " ".join(f"{c:>6s}" for c in CLASSES))
    for folder in args.clips:
        method, seconds, errors = estimate_clip(folder, config, args.threshold)
        rows.append((seconds, errors))
        shares = " ".join(f"{100 * getattr(errors, c):6.2f}" for c in CLASSES)
        print(f"{folder.name:30s} {method:31s} {seconds:5.2f} {100 * errors.wrong:8.2f} {shares}")
    mean = {c: 100 * float(np.mean([getattr(e, c) for _, e in rows])) for c in ("wrong", *CLASSES)}
    total = sum(s for s, _ in rows)
    print(
        f"{'MEAN':30s} {'':31s} {total / len(rows):5.2f} {mean['wrong']:8.2f} "
        + " ".join(f"{mean[c]:6.2f}" for c in CLASSES)
    )


if __name__ == "__main__":
    main()
