"""Resident memory of a long stream tracked without a clean plate (the online background).

    python -m upperpose.lab.memory_stream [--minutes 10] [--search]

Renders a short synthetic clip (640x480, 30 fps, `wave_right`, the room empty for its first
second) and feeds its frames to one `Tracker` over and over, like a live camera, for `--minutes`
of video; prints the process's resident set size (VmRSS) every 30 s of video. Without
`--search` the fits are the prediction itself (no swarm: the loop then costs the features, the
background model and the tracker's bookkeeping, which is what could grow); with it, the real
search. Linux only (reads /proc/self/status). Not a test: a measurement.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from upperpose.fit.tracker import PARTS, StaticFit, Tracker
from upperpose.io.video import VideoReader
from upperpose.lab.synth import ClipConfig, write_clip
from upperpose.model import Camera, forward_kinematics, project


def rss_mb() -> float:
    """This process's resident set size in MiB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


class Prediction:
    """A fitter that returns the prediction (no search); the search's memory is not measured."""

    def __call__(self, features: Any, prediction: Any, root: Any, body: Any, camera: Camera, **kw: Any) -> StaticFit:
        """The prediction as the fit."""
        pose, r = np.array(prediction, dtype=np.float64), np.array(root, dtype=np.float64)
        joints = forward_kinematics(pose, r, body)
        return StaticFit(pose, r, joints, project(camera, joints), 1.0, {part: 1.0 / 3 for part in PARTS})


def main(argv: list[str] | None = None) -> None:
    """Prints the resident memory every 30 s of video."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0, help="minutes of video at 30 fps")
    parser.add_argument("--search", action="store_true", help="fit with the real search (slow)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="upperpose-memory-") as tmp:
        folder = Path(tmp) / "clip"
        write_clip(ClipConfig(motion="wave_right", frames=120, empty_start=True, seed=3), folder)
        with VideoReader(folder / "video.mp4") as reader:
            frames = list(reader)
        cam = json.loads((folder / "meta.json").read_text())["camera"]
    camera = Camera.perspective(cam["focal"], cam["cx"], cam["cy"])
    tracker = Tracker(camera, None, fps=30.0, fitter=None if args.search else Prediction())
    total = round(args.minutes * 60 * 30)
    print(f"{'video s':>8} {'frames':>7} {'RSS MiB':>8}  status")
    for index in range(total):
        # Ping-pong through the clip: no cut, so the person stays and the background keeps learning.
        k = index % (2 * len(frames) - 2)
        result = tracker.update(frames[k if k < len(frames) else 2 * len(frames) - 2 - k])
        if index % 900 == 0 or index == total - 1:
            print(f"{index / 30:8.0f} {index + 1:7d} {rss_mb():8.1f}  {result.status}", flush=True)


if __name__ == "__main__":
    main()
