"""Pose files paired with their truth: `PRED_DIR/NAME.json` with `TRUTH_DIR/NAME/gt.json`.

The layout `run.py` of the external validation set writes (`--out PRED_DIR`) next to the clip
folders it reads; the lab tools that compare a folder of predictions with the truth share it.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from upperpose.io.posefile import load_poses


def pairs_parser(prog: str, description: str) -> argparse.ArgumentParser:
    """A parser taking the folder of pose files and the folder of clips, in that order."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument("predictions", type=Path, help="folder of pose files NAME.json")
    parser.add_argument("truth", type=Path, help="folder of clips NAME/gt.json")
    return parser


def pose_pairs(predictions: Path, truth: Path) -> Iterator[tuple[str, dict[str, Any], dict[str, Any]]]:
    """Each pose file of `predictions` that has a truth in `truth`, loaded: (name, prediction, truth)."""
    for path in sorted(predictions.glob("*.json")):
        gt = truth / path.stem / "gt.json"
        if gt.is_file():
            yield path.stem, load_poses(path), load_poses(gt)


__all__ = ["pairs_parser", "pose_pairs"]
