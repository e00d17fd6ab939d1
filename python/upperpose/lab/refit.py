"""Measures the search alone on clips with ground truth (issue 5's acceptance check).

Each frame is fitted from the previous frame's true pose plus Gaussian noise, with the true
root, against the frame's real features (clean plate). The fit's 2D joints are compared with
the truth. Run: `python -m upperpose.lab.refit DEV_SET_DIR [--noise RAD] [--frames N]`.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any, cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features import Background, FeatureExtractor
from upperpose.fit.search import SearchConfig, fit_frame
from upperpose.model import BodyModel, Camera


def refit_clip(folder: Path, noise: float, limit: int | None, config: SearchConfig, seed: int = 0) -> dict[str, float]:
    """Mean and 90th-percentile joint error (px) of per-frame fits from noisy true poses."""
    meta = json.loads((folder / "meta.json").read_text())
    gt = json.loads((folder / "gt.json").read_text())["frames"]
    cam = meta["camera"]
    camera = Camera.perspective(cam["focal"], cam["cx"], cam["cy"])
    body = BodyModel(**meta["body"])
    plate = cv2.imread(str(folder / "background.png"))
    extractor = FeatureExtractor(Background.from_plate(cast(npt.NDArray[np.uint8], plate)), reuse_buffers=True)
    rng = np.random.default_rng(seed)
    video = cv2.VideoCapture(str(folder / "video.mp4"))
    errors, before, seconds = [], [], []
    previous: Any = None  # the previous gt.json frame (JSON)
    for i, truth in enumerate(gt):
        ok, frame = video.read()
        if not ok or (limit is not None and i >= limit):
            break
        have = truth["status"] == "tracked" and previous is not None and previous["status"] == "tracked"
        features = extractor(
            cast(npt.NDArray[np.uint8], frame), predicted_joints=np.array(previous["joints_2d"]) if have else None
        )
        if have:
            prediction = np.array(previous["angles"]) + rng.normal(0.0, noise, 13)
            start = time.perf_counter()
            fit = fit_frame(features, prediction, truth["root"], body, camera, frame_index=i, config=config)
            seconds.append(time.perf_counter() - start)
            target = np.array(truth["joints_2d"])
            errors.append(np.linalg.norm(fit.joints_2d - target, axis=1).mean())
            before.append(np.linalg.norm(np.array(previous["joints_2d"]) - target, axis=1).mean())
        previous = truth
    e = np.array(errors)
    return {
        "frames": float(len(e)),
        "mean_px": float(e.mean()),
        "p90_px": float(np.percentile(e, 90)),
        "previous_truth_px": float(np.mean(before)),
        "ms_per_frame": 1000.0 * float(np.median(seconds)),
    }


def main() -> None:
    """Command line."""
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("dataset")
    p.add_argument("--noise", type=float, default=0.05, help="std of the noise on the previous true angles, rad")
    p.add_argument("--frames", type=int, default=None, help="at most this many frames per clip")
    p.add_argument("--particles", type=int, default=None)
    p.add_argument("--iterations", type=int, default=None)
    args = p.parse_args()
    config = SearchConfig(particles=args.particles, iterations=args.iterations)
    rows = []
    for folder in sorted(Path(args.dataset).iterdir()):
        if (folder / "gt.json").exists():
            r = refit_clip(folder, args.noise, args.frames, config)
            rows.append(r)
            print(
                f"{folder.name:32s} frames {r['frames']:4.0f}  mean {r['mean_px']:5.2f} px  p90 {r['p90_px']:5.2f} px"
                f"  (prediction {r['previous_truth_px']:5.2f} px)  {r['ms_per_frame']:5.1f} ms/frame",
                flush=True,
            )
    print(f"all clips: mean {np.mean([r['mean_px'] for r in rows]):.2f} px")


if __name__ == "__main__":
    main()
