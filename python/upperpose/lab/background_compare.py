"""The learnt background against the true plate: ours (`features.online`), OpenCV's MOG2 and KNN.

    python -m upperpose.lab.background_compare CLIP [CLIP ...] [--every 30]

Each CLIP is a folder with `video.mp4`, `background.png` (the true clean plate) and
`meta.json` (`camera.focal`). The tracker runs without the plate, once with the online
background and once with the default for a file (the pre-pass estimate, refined while tracking:
"refined"); MOG2 and KNN (`cv2.createBackgroundSubtractor*`, default settings, no shadows) are
fed the same frames and their `getBackgroundImage()` is read at the same frames. Reported per
clip and model: the share of pixels whose background differs from the true plate by more than
`sub_threshold` in some channel (each such pixel is a false I_sub), at chosen frames and as a
mean over them, and the milliseconds per frame (median, CPU of this thread) of learning, and of
producing the image.
The estimate of the pre-pass over the whole video (`features.background`) is given once.

Not a test: the numbers depend on the clips; times on the machine.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
import warnings
from pathlib import Path
from typing import Any, cast

import cv2
import numpy as np

from upperpose.features import CleanPlateWarning, FeatureConfig
from upperpose.features.change import colour_change
from upperpose.features.checks import Frame
from upperpose.fit import TrackerConfig
from upperpose.fit.pipeline import VideoTracking


def wrong_share(background: Frame, plate: Frame, threshold: int) -> float:
    """Share of pixels where `background` differs from the true `plate` by more than `threshold`."""
    changed = colour_change(background, plate, threshold)
    return cv2.countNonZero(changed) / changed.size


def compare_clip(folder: Path, every: int = 30) -> dict[str, Any]:
    """The models' errors against the clip's plate every `every` frames, and their times."""
    meta = json.loads((folder / "meta.json").read_text())
    plate = cast(Frame, cv2.imread(str(folder / "background.png"), cv2.IMREAD_COLOR))
    threshold = FeatureConfig().sub_threshold
    subtractors = {
        "mog2": cv2.createBackgroundSubtractorMOG2(detectShadows=False),
        "knn": cv2.createBackgroundSubtractorKNN(detectShadows=False),
    }
    errors: dict[str, list[float]] = {"online": [], "refined": [], "mog2": [], "knn": []}
    learn: dict[str, list[float]] = {"online": [], "refined": [], "mog2": [], "knn": []}
    image_ms: dict[str, list[float]] = {"mog2": [], "knn": []}
    frames: list[int] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CleanPlateWarning)
        online_config = TrackerConfig(features=FeatureConfig(bg_model="online"))
        run = VideoTracking(folder / "video.mp4", None, focal=float(meta["camera"]["focal"]), config=online_config)
        with run:
            for index, (frame, _) in enumerate(run.frames()):
                online = run.tracker._online  # noqa: SLF001 (lab tooling reads the model)
                if online is not None:
                    learn["online"].append(online.last_learn_ms)
                for name, subtractor in subtractors.items():
                    t0 = time.thread_time()
                    subtractor.apply(frame)
                    learn[name].append(1000 * (time.thread_time() - t0))
                if index % every:
                    continue
                frames.append(index)
                background = run.tracker.background
                if background is not None:
                    errors["online"].append(wrong_share(background.plate, plate, threshold))
                for name, subtractor in subtractors.items():
                    t0 = time.thread_time()
                    image = cast(Frame, subtractor.getBackgroundImage())
                    image_ms[name].append(1000 * (time.thread_time() - t0))
                    errors[name].append(wrong_share(image, plate, threshold))
        # The default for a file: the pre-pass estimate, learning on while tracking.
        run = VideoTracking(folder / "video.mp4", None, focal=float(meta["camera"]["focal"]))
        with run:
            for index, _ in enumerate(run.frames()):
                refined = run.tracker._online  # noqa: SLF001 (lab tooling reads the model)
                if refined is not None:
                    learn["refined"].append(refined.last_learn_ms)
                if index % every == 0 and run.tracker.background is not None:
                    errors["refined"].append(wrong_share(run.tracker.background.plate, plate, threshold))
    estimated = run.background  # the pre-pass estimate the refinement started from, unchanged
    assert estimated is not None
    return {
        "clip": folder.name,
        "frames": frames,
        "errors": errors,
        "prepass": wrong_share(estimated.plate, plate, threshold),
        "learn_ms": {k: statistics.median(v) if v else float("nan") for k, v in learn.items()},
        "image_ms": {k: statistics.median(v) for k, v in image_ms.items()},
    }


def main(argv: list[str] | None = None) -> None:
    """Prints the comparison for the clips on the command line."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("clips", nargs="+", type=Path)
    parser.add_argument("--every", type=int, default=30, help="compare every this many frames")
    args = parser.parse_args(argv)
    cv2.setNumThreads(1)
    means: dict[str, list[float]] = {"online": [], "refined": [], "mog2": [], "knn": [], "prepass": []}
    print("clip: model wrong % at frames ... | mean | learn ms/frame | image ms")
    for folder in args.clips:
        r = compare_clip(folder, args.every)
        print(f"{r['clip']} (frames {' '.join(map(str, r['frames']))})")
        for name, values in r["errors"].items():
            mean = float(np.mean(values))
            means[name].append(mean)
            shares = " ".join(f"{100 * v:4.1f}" for v in values)
            image = f" | {r['image_ms'][name]:.2f}" if name in r["image_ms"] else ""
            print(f"  {name:7s} {shares} | {100 * mean:4.1f} | {r['learn_ms'][name]:.2f}{image}")
        means["prepass"].append(r["prepass"])
        print(f"  prepass {100 * r['prepass']:4.1f} (one plate for the whole clip)")
    print("MEAN wrong %: " + ", ".join(f"{k} {100 * float(np.mean(v)):.1f}" for k, v in means.items()))


if __name__ == "__main__":
    main()
