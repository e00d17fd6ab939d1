"""Benchmark of the per-frame features: median milliseconds per stage on synthetic frames.

Not a test: wall-clock numbers depend on the machine. `upperpose bench` can call
`benchmark_features()`; `python -m upperpose.lab.features_bench` prints a table.
"""

from __future__ import annotations

import argparse
import statistics
import time

import cv2

from upperpose.features.background import Background
from upperpose.features.config import SKIN_SPACES, FeatureConfig
from upperpose.features.extractor import FeatureExtractor
from upperpose.lab.feature_scene import render_scene, textured_background
from upperpose.model import Pose


def benchmark_features(
    width: int = 640,
    height: int = 480,
    frames: int = 300,
    config: FeatureConfig | None = None,
    reuse_buffers: bool = True,
    threads: int = 1,
) -> dict[str, float]:
    """Median milliseconds per frame for all features, and per stage.

    Runs a full call per frame (previous frame, predicted joints and part labels given, so
    motion flags and arm silhouette are included) on two alternating synthetic frames.

    Args:
        width: frame width in pixels.
        height: frame height in pixels.
        frames: timed frames (after 20 warm-up frames).
        config: feature thresholds; defaults when None.
        reuse_buffers: see `FeatureExtractor`.
        threads: OpenCV threads during the run (restored afterwards); 1 = one core.

    Returns:
        {"total wall": median wall-clock ms per frame, "total cpu": median CPU ms of the
        calling thread per frame, then one entry per stage: median CPU ms}. On a busy
        machine the wall time includes waiting for a core; the CPU time does not.
    """
    config = config or FeatureConfig()
    plate = textured_background(height, width, seed=11)
    depth = 2.2 * 640 / width
    poses = [
        Pose.a_pose(),
        Pose.a_pose().replace(right_z_up=0.9, right_x_down=0.4, left_z_up=0.5),
    ]
    scenes = [render_scene(p, plate, root=(0.0, 0.15, depth), seed=i, short_sleeves=True) for i, p in enumerate(poses)]
    extract = FeatureExtractor(Background.from_plate(plate, config), config, reuse_buffers=reuse_buffers)
    saved = cv2.getNumThreads()
    cv2.setNumThreads(threads)
    try:
        walls: list[float] = []
        cpus: list[float] = []
        stages: dict[str, list[float]] = {}
        for i in range(frames + 20):
            scene, previous = scenes[i % 2], scenes[(i + 1) % 2]
            wall, cpu = time.perf_counter(), time.thread_time()
            extract(scene.frame, previous.joints, previous.labels)
            cpu, wall = time.thread_time() - cpu, time.perf_counter() - wall
            features = extract(scene.frame, previous.joints, previous.labels, timed=True)
            if i < 20:
                continue
            walls.append(wall)
            cpus.append(cpu)
            for name, seconds in features.timings.items():
                stages.setdefault(name, []).append(seconds)
    finally:
        cv2.setNumThreads(saved)
    result = {
        "total wall": 1e3 * statistics.median(walls),
        "total cpu": 1e3 * statistics.median(cpus),
    }
    result.update({name: 1e3 * statistics.median(values) for name, values in stages.items()})
    return result


def main() -> None:
    """Prints the benchmark table."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--skin", default="rgb+ycrcb", choices=SKIN_SPACES)
    parser.add_argument("--fresh-buffers", action="store_true", help="allocate new images every frame")
    args = parser.parse_args()
    result = benchmark_features(
        args.width,
        args.height,
        args.frames,
        FeatureConfig(skin_space=args.skin),
        reuse_buffers=not args.fresh_buffers,
    )
    print(f"features of one {args.width}x{args.height} frame, one thread, median of {args.frames} frames:")
    for name, ms in result.items():
        print(f"  {name:14s} {ms:7.3f} ms")


if __name__ == "__main__":
    main()
