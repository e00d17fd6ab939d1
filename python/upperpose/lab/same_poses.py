"""Checks that a change left the tracker's output unchanged, bit for bit, on a set of clips.

    python -m upperpose.lab.same_poses RECORD_DIR --devset dev-set [--seed 0] [--record]

With `--record`, tracks every clip of the dev set (`upperpose track`, clean plates) and keeps
each pose file in RECORD_DIR; without it, tracks them again and compares every frame's status,
joints, angles, cost and root with the recorded ones (exact float equality: the pose file
writes Python's shortest round-trip repr). Exits 1 and names the first differing frame of each
clip that changed.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

FIELDS = ("frame", "status", "joints_2d", "joints_3d", "angles", "cost", "root")


def track(clip: Path, out: Path, seed: int) -> None:
    """Runs `upperpose track` on one clip with its clean plate and focal length."""
    meta = json.loads((clip / "meta.json").read_text())
    cmd = [sys.executable, "-m", "upperpose", "track", str(clip / "video.mp4"), "--quiet"]
    cmd += ["--background", str(clip / "background.png"), "--focal", str(meta["camera"]["focal"])]
    cmd += ["--seed", str(seed), "-o", str(out)]
    run = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        raise RuntimeError(f"tracking {clip.name} failed: {run.stderr.strip()[-500:]}")


def first_difference(a: dict[str, Any], b: dict[str, Any]) -> str | None:
    """Where two pose documents' frames first differ, or None."""
    fa, fb = a["frames"], b["frames"]
    if len(fa) != len(fb):
        return f"{len(fa)} frames against {len(fb)}"
    for x, y in zip(fa, fb):
        for key in FIELDS:
            if x.get(key) != y.get(key):
                return f"frame {x['frame']}: {key} differs"
    return None


def main() -> int:
    """Command line; returns the exit status."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("record_dir")
    p.add_argument("--devset", default="dev-set")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--record", action="store_true", help="record the reference pose files")
    a = p.parse_args()
    clips = sorted(c for c in Path(a.devset).iterdir() if (c / "gt.json").exists())
    if not clips:
        p.error(f"no clips in {a.devset} (make them with: upperpose synth {a.devset} --devset)")
    record = Path(a.record_dir)
    record.mkdir(parents=True, exist_ok=True)
    changed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for clip in clips:
            name = f"{clip.name}-s{a.seed}.json"
            out = record / name if a.record else Path(tmp) / name
            track(clip, out, a.seed)
            if a.record:
                print(f"{clip.name}: recorded")
                continue
            diff = first_difference(json.loads((record / name).read_text()), json.loads(out.read_text()))
            changed += diff is not None
            print(f"{clip.name}: {'same' if diff is None else 'CHANGED, ' + diff}")
    if not a.record:
        print(f"{len(clips) - changed} of {len(clips)} clips identical")
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main())
