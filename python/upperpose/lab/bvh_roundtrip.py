"""Does the BVH export say what the pose file says? Issue 21's round trip on whole clips.

Each clip of a development set is tracked with `--bvh`; the BVH is read back with bvhio (an
independent reader and forward kinematics from PyPI, a development dependency) and its seven
joints are compared with the pose file's `joints_3d` on every frame that has a pose.

    python -m upperpose.lab.bvh_roundtrip DEV_SET_DIR [--seed 0] [--clips 01,05]

prints the largest and mean distance per clip in millimetres and exits 1 when any clip's
largest distance exceeds `--limit-mm` (1 mm).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import numpy.typing as npt

from upperpose.io.bvh import FLIP
from upperpose.io.posefile import load_poses

FloatArray = npt.NDArray[np.float64]
# The BVH skeleton's joints that stand for the seven reported joints (JOINT_NAMES order).
BVH_JOINTS = ("Head", "RightShoulder", "LeftShoulder", "RightForearm", "LeftForearm", "RightHand", "LeftHand")


def bvh_joints(path: Path) -> list[FloatArray]:
    """World positions of the seven reported joints per frame, read by bvhio, in the camera frame."""
    import bvhio  # a development dependency: only this lab tool and the tests need it

    root = bvhio.readAsHierarchy(str(path))
    frames = int(next(line for line in path.read_text().splitlines() if line.startswith("Frames:")).split()[1])
    out = []
    for f in range(frames):
        root.loadPose(f)
        where = {j.Name: np.array(list(j.PositionWorld)) for j, _, _ in root.layout()}
        out.append(np.array([where[n] for n in BVH_JOINTS]) @ FLIP)
    return out


def round_trip_mm(poses: Path, bvh: Path) -> tuple[float, float, int]:
    """Largest and mean joint distance (mm) between a pose file and its BVH, and the frames compared."""
    frames = load_poses(poses)["frames"]
    read = bvh_joints(bvh)
    if len(read) != len(frames):
        raise ValueError(f"{bvh}: {len(read)} frames against the pose file's {len(frames)}")
    gaps = [
        1000.0 * np.linalg.norm(got - np.asarray(f["joints_3d"], dtype=np.float64), axis=1)
        for got, f in zip(read, frames)
        if f.get("joints_3d") is not None
    ]
    if not gaps:
        return 0.0, 0.0, 0
    every = np.concatenate(gaps)
    return float(every.max()), float(every.mean()), len(gaps)


def main(argv: list[str] | None = None) -> int:
    """The command line (see the module's docstring)."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("devset", type=Path, help="a folder of clips (video.mp4, background.png, meta.json)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--clips", default="", help="comma-separated clip name prefixes (default: all)")
    parser.add_argument("--limit-mm", type=float, default=1.0)
    args = parser.parse_args(argv)
    wanted = [c for c in args.clips.split(",") if c]
    clips = sorted(d for d in args.devset.glob("*") if (d / "video.mp4").is_file())
    clips = [d for d in clips if not wanted or any(d.name.startswith(w) for w in wanted)]
    if not clips:
        print(f"upperpose.lab.bvh_roundtrip: no clips in {args.devset}", file=sys.stderr)
        return 2
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for clip in clips:
            focal = json.loads((clip / "meta.json").read_text())["camera"]["focal"]
            poses, bvh = Path(tmp) / f"{clip.name}.json", Path(tmp) / f"{clip.name}.bvh"
            command = [sys.executable, "-m", "upperpose", "track", str(clip / "video.mp4"), "-o", str(poses)]
            command += ["--bvh", str(bvh), "--quiet", "--background", str(clip / "background.png")]
            command += ["--focal", str(focal), "--seed", str(args.seed)]
            run = subprocess.run(command, check=False, capture_output=True, text=True)
            if run.returncode != 0:
                print(f"{clip.name}: tracking failed: {run.stderr.strip()}", file=sys.stderr)
                return 1
            largest, mean, frames = round_trip_mm(poses, bvh)
            worst = max(worst, largest)
            print(f"{clip.name:32s} frames {frames:4d}   largest {largest:.6f} mm   mean {mean:.6f} mm")
    print(f"largest over {len(clips)} clips: {worst:.6f} mm (limit {args.limit_mm} mm)")
    return 0 if worst <= args.limit_mm else 1


if __name__ == "__main__":
    sys.exit(main())
