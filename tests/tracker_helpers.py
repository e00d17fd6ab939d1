"""Helpers shared by the tracker tests: one small synthetic clip and a search double.

The clip (320x240, 15 fps, 50 frames): an empty room for one second, the person walks in,
stands in the A-pose for a second, then waves with the right hand. Rendered once per test
process (about 8 s).
"""

from __future__ import annotations

import functools
import json
import tempfile
from pathlib import Path
from typing import Any

import cv2
import numpy as np

import upperpose
from upperpose.fit import PARTS, StaticFit
from upperpose.io.video import VideoReader
from upperpose.lab.synth import ClipConfig, write_clip

CLIP = ClipConfig(motion="wave_right", frames=50, fps=15.0, width=320, height=240, depth=2.0, empty_start=True, seed=5)


@functools.lru_cache(maxsize=1)
def clip() -> Path:
    """The rendered clip folder (video.mp4, background.png, gt.json, meta.json)."""
    folder = Path(tempfile.mkdtemp(prefix="upperpose-tracker-test-")) / "clip"
    write_clip(CLIP, folder)
    return folder


def camera_of(folder: Path) -> upperpose.Camera:
    """The clip's camera."""
    cam = json.loads((folder / "meta.json").read_text())["camera"]
    return upperpose.Camera.perspective(cam["focal"], cam["cx"], cam["cy"])


PART_ANGLES = {"torso": slice(0, 3), "right_arm": slice(3, 8), "left_arm": slice(8, 13)}


class TruthFitter:
    """Stands in for `fit_frame`: searched parts take the true angles of the frame.

    Args:
        gt: the clip's ground truth document.
        wrong: frame numbers on which a trajectory search of the right arm returns a wrong arm
            (raised overhead), to force a real loss; an "initial" search always finds the truth.
    """

    def __init__(self, gt: dict[str, Any], wrong: range | None = None) -> None:
        self.frames = gt["frames"]
        self.wrong = wrong or range(0)
        self.calls: list[tuple[int, str, tuple[str, ...]]] = []

    def __call__(self, features: Any, prediction: Any, root: Any, body: Any, camera: Any, **kw: Any) -> StaticFit:
        index, mode, search = kw["frame_index"], kw["mode"], tuple(kw["search"])
        assert set(search) <= set(PARTS)
        self.calls.append((index, mode, search))
        pose = np.array(prediction, dtype=np.float64)
        truth = self.frames[min(index, len(self.frames) - 1)]["angles"]
        if truth is not None:
            for part in search:
                pose[PART_ANGLES[part]] = np.asarray(truth)[PART_ANGLES[part]]
        if mode == "trajectory" and index in self.wrong and "right_arm" in search:
            pose[PART_ANGLES["right_arm"]] = [0.0, 0.0, 2.8, 0.0, 0.0]
        r = np.array(root, dtype=np.float64)
        joints = upperpose.forward_kinematics(pose, r, body)
        return StaticFit(pose, r, joints, upperpose.project(camera, joints), 0.5, {part: 0.5 / 3 for part in PARTS})


def truth(folder: Path) -> dict[str, Any]:
    """The clip's gt.json."""
    return json.loads((folder / "gt.json").read_text())  # type: ignore[no-any-return]


def clip_frames(folder: Path) -> list[np.ndarray]:
    """The clip's decoded frames."""
    with VideoReader(folder / "video.mp4") as reader:
        return list(reader)


def write_video(path: Path, frames: list[np.ndarray], fps: float = 15.0) -> Path:
    """Writes BGR frames as an mp4v video."""
    h, w = frames[0].shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), fps, (w, h))
    for f in frames:
        writer.write(f)
    writer.release()
    return path


def one_line_error(err: str) -> str:
    """The only line of a command's stderr, which must hold no traceback."""
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]
