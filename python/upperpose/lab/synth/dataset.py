"""The clip folder: one folder per clip, shared by synthetic and real recordings.

    CLIP/video.mp4       the frames (mp4v)
    CLIP/gt.json         ground truth, SPEC 9 schema ("upperpose.poses/1")
    CLIP/meta.json       camera, description, and how the clip was made
    CLIP/background.png  clean plate (optional: real recordings may have none)
    CLIP/masks.npz       true person and skin masks (optional; synthetic clips have them)

See docs/dataset.md for every field.
"""

from __future__ import annotations

import io
import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import VideoError
from upperpose.io.files import write_atomic, write_image
from upperpose.io.posefile import make_poses, write_poses
from upperpose.lab.synth.scene import ClipConfig, clean_plate, config_dict, plan_clip, render_frame
from upperpose.model import Pose

META_FORMAT = "upperpose.clip/1"
VIDEO, GT, META, BACKGROUND, MASKS = "video.mp4", "gt.json", "meta.json", "background.png", "masks.npz"


def pack_masks(masks: list[npt.NDArray[np.bool_]]) -> npt.NDArray[np.uint8]:
    """`(N, H, W)` bool masks packed 8 pixels a byte along rows: `(N, H, ceil(W / 8))` uint8."""
    return np.packbits(np.asarray(masks, bool), axis=-1)


def load_masks(path: str | os.PathLike[str]) -> dict[str, npt.NDArray[np.bool_]]:
    """Reads masks.npz: name ("person", "skin") -> `(N, H, W)` bool.

    Raises:
        OSError: the file cannot be read.
        ValueError: not a masks file.
    """
    try:
        with np.load(path) as data:
            n, h, w = (int(v) for v in data["shape"])
            return {
                k: np.unpackbits(data[k], axis=-1, count=w).astype(bool).reshape(n, h, w)
                for k in data.files
                if k != "shape"
            }
    except (KeyError, ValueError) as err:
        raise ValueError(f"{path}: not a masks file ({err})") from None


def load_meta(folder: str | os.PathLike[str]) -> dict[str, Any]:
    """Reads and checks CLIP/meta.json: at least a camera with focal, cx, cy in pixels.

    Raises:
        OSError: no meta.json.
        ValueError: malformed.
    """
    path = Path(folder) / META
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise OSError(f"no such file: {path}") from None
    except json.JSONDecodeError as err:
        raise ValueError(f"{path}: not valid JSON ({err.msg} at line {err.lineno})") from None
    cam = meta.get("camera") if isinstance(meta, dict) else None
    if not isinstance(cam, dict) or not all(
        isinstance(cam.get(k), (int, float)) and not isinstance(cam.get(k), bool) for k in ("focal", "cx", "cy")
    ):
        raise ValueError(f'{path}: needs "camera": {{"focal": PX, "cx": PX, "cy": PX}}')
    if not cam["focal"] > 0:
        raise ValueError(f"{path}: camera focal must be positive, got {cam['focal']}")
    return cast(dict[str, Any], meta)


def _write_json(path: Path, data: dict[str, Any]) -> None:
    write_atomic(path, lambda tmp: tmp.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8"))


def write_clip(
    config: ClipConfig, folder: str | os.PathLike[str], progress: Callable[[int, int], None] | None = None
) -> Path:
    """Renders a clip into `folder` (created if needed) in the clip-folder layout.

    Args:
        config: the clip.
        folder: output folder.
        progress: called with (frames done, frames total) now and then.

    Returns:
        The folder.

    Raises:
        VideoError: the video cannot be written.
        OSError: the folder cannot be created or written.
    """
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    plan = plan_clip(config)
    cam, c = plan.camera, plan.config
    person_masks, skin_masks, frames = [], [], []

    def write_video(tmp: Path) -> None:
        writer = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*"mp4v"), c.fps, (c.width, c.height))  # type: ignore[attr-defined]
        if not writer.isOpened():
            raise VideoError(f"cannot open an mp4v video writer for {out / VIDEO}")
        try:
            for i in range(c.frames):
                image, person, skin = render_frame(plan, i)
                writer.write(image)
                person_masks.append(person)
                skin_masks.append(skin)
                frames.append(_truth_frame(plan, i))
                if progress and (i % 30 == 29 or i == c.frames - 1):
                    progress(i + 1, c.frames)
        finally:
            writer.release()

    write_atomic(out / VIDEO, write_video)
    write_image(out / BACKGROUND, clean_plate(plan))

    def write_masks(tmp: Path) -> None:
        buffer = io.BytesIO()
        shape = np.array([c.frames, c.height, c.width])
        np.savez_compressed(buffer, person=pack_masks(person_masks), skin=pack_masks(skin_masks), shape=shape)
        tmp.write_bytes(buffer.getvalue())

    write_atomic(out / MASKS, write_masks)
    write_poses(out / GT, make_poses(c.width, c.height, c.fps, frames, source="upperpose synth"))
    meta = {
        "format": META_FORMAT,
        "description": plan.description(),
        "camera": {"focal": cam.focal, "cx": cam.cx, "cy": cam.cy},
        "width": c.width,
        "height": c.height,
        "fps": c.fps,
        "frames": c.frames,
        "synthetic": True,
        "motion": c.motion,
        "seed": c.seed,
        "appearance": plan.appearance.to_dict(),
        "body": plan.body.as_dict(),
        "options": {
            "empty_start": c.empty_start,
            "lighting_ramp": c.lighting_ramp,
            "step_closer": c.step_closer,
            "noise": c.noise,
        },
        "first_pose_frame": int(np.argmax(plan.present)),
        "config": config_dict(c),
        "files": {"video": VIDEO, "ground_truth": GT, "background": BACKGROUND, "masks": MASKS},
    }
    _write_json(out / META, meta)
    return out


def _truth_frame(plan: Any, i: int) -> dict[str, Any]:
    if not plan.present[i]:
        return {
            "frame": i,
            "status": "no_person",
            "joints_2d": None,
            "joints_3d": None,
            "angles": None,
            "cost": None,
            "root": None,
        }
    joints = plan.joints_3d(i)
    pixels = plan.camera.project(joints)
    return {
        "frame": i,
        "status": "tracked",
        "joints_2d": [[round(float(v), 4) for v in p] for p in pixels],
        "joints_3d": [[round(float(v), 6) for v in p] for p in joints],
        "angles": [round(float(v), 6) for v in Pose(plan.angles[i]).angles],
        "cost": None,
        "root": [round(float(v), 6) for v in plan.roots[i]],
    }
