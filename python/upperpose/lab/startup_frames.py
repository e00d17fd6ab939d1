"""When did tracking start? One row per pose file: first face, first stable face, first pose.

Issue 25's acceptance: tracking starts within 15 frames of the first frame with a stable face,
and clips that start mid-motion get a pose within 15 frames of the first frame. A pose file
does not record the face itself; a frame that is not `no_person` had one (the tracker's
`initialising` status, or a pose). The first *stable* face is taken as the second of the first
two such frames in a row (the tracker's own stability test also bounds the face's movement).

    python -m upperpose.lab.startup_frames PRED_DIR [--within 15]

reads every `PRED_DIR/*.json` pose file and prints the frames and the delay from the stable
face to the first pose; rows over `--within` are marked.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from upperpose.io.posefile import load_poses


def startup_frames(poses: dict[str, Any]) -> dict[str, int | None]:
    """First frame with a face, with a stable face and with a pose (None: never)."""
    frames = sorted(poses["frames"], key=lambda f: f["frame"])
    face = [f["status"] != "no_person" for f in frames]
    posed = [f.get("joints_2d") is not None for f in frames]
    first_face = next((i for i, seen in enumerate(face) if seen), None)
    stable = next((i for i in range(1, len(face)) if face[i] and face[i - 1]), None)
    first_pose = next((i for i, p in enumerate(posed) if p), None)
    return {"face": first_face, "stable": stable, "pose": first_pose}


def main(argv: list[str] | None = None) -> int:
    """The command line (see the module's docstring)."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", type=Path, help="folder of pose files")
    parser.add_argument("--within", type=int, default=15, help="frames allowed from the stable face to a pose")
    args = parser.parse_args(argv)
    files = sorted(args.folder.glob("*.json"))
    if not files:
        print(f"no pose files in {args.folder}", file=sys.stderr)
        return 1
    print(f"{'clip':32s} {'face':>5s} {'stable':>6s} {'pose':>5s} {'delay':>5s}")
    late = 0
    for path in files:
        row = startup_frames(load_poses(path))
        delay = None if row["pose"] is None or row["stable"] is None else row["pose"] - row["stable"]
        over = delay is None or delay > args.within
        late += over

        def cell(value: int | None, width: int) -> str:
            return f"{value:{width}d}" if value is not None else " " * (width - 1) + "-"

        mark = "  late" if over else ""
        cells = f"{cell(row['face'], 5)} {cell(row['stable'], 6)} {cell(row['pose'], 5)} {cell(delay, 5)}"
        print(f"{path.stem:32s} {cells}{mark}")
    print(f"{late} of {len(files)} late (more than {args.within} frames from the stable face, or never)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
