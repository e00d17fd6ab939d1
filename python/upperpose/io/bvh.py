"""BVH export: the tracked angles on the person's own skeleton, for Blender and other tools.

The skeleton (docs/guide.md, "BVH"): the root `Torso` at the upper-body root moves and turns
with the torso; `Head`, `RightShoulder` and `LeftShoulder` are fixed to it at the reported
joints; `RightUpperArm` turns about the arm's hinge, `RightForearm` about the elbow, and
`RightHand` is fixed to the forearm at the reported hand (the palm's centre); the left arm is
the same. The rest pose (every rotation zero) is the body model's: upright, arms hanging
straight down, facing the camera. Lengths are metres, angles degrees, channels `Zrotation
Yrotation Xrotation` (rotation = Rz Ry Rx). The world frame is Y up, Z towards the camera and X
to the image's right: the camera frame (Y down, Z away) turned half a turn about X. Frames
without a pose repeat the nearest pose before them (the first pose, before it).
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError
from upperpose.io.files import write_atomic
from upperpose.model import BodyModel, skeleton

FloatArray = npt.NDArray[np.float64]
# Camera frame -> BVH world (Y up, Z towards the camera): half a turn about X.
FLIP = np.diag([1.0, -1.0, -1.0])
ROTATION_CHANNELS = "Zrotation Yrotation Xrotation"
# Tips of the leaf bones (BVH needs an end to each chain), in the bone's own frame, metres.
HEAD_TIP = (0.0, 0.12, 0.0)
SHOULDER_TIP = (0.0, 0.02, 0.0)
HAND_TIP = (0.0, -0.05, 0.0)


def euler_zyx_degrees(rotation: FloatArray) -> tuple[float, float, float]:
    """Angles (z, y, x) in degrees with `rotation = Rz(z) @ Ry(y) @ Rx(x)`."""
    r = rotation
    y = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    if math.cos(y) > 1e-9:
        z = math.atan2(r[1, 0], r[0, 0])
        x = math.atan2(r[2, 1], r[2, 2])
    else:  # gimbal lock: only z - x (or z + x) is defined; put it all in z
        z = math.atan2(-r[0, 1], r[1, 1])
        x = 0.0
    return math.degrees(z), math.degrees(y), math.degrees(x)


def _flip(m: FloatArray) -> FloatArray:
    return FLIP @ m @ FLIP


def _vector(v: Iterable[float]) -> str:
    return " ".join(f"{float(c):.6f}" for c in v)


def hierarchy(body: BodyModel) -> str:
    """The HIERARCHY section for `body`'s dimensions."""
    rest = skeleton(np.zeros(13), np.zeros(3), body)
    joints, hinges = rest["joints"] @ FLIP, rest["model_points"] @ FLIP

    def fixed(name: str, offset: FloatArray, tip: tuple[float, ...], indent: str) -> list[str]:
        return [
            f"{indent}JOINT {name}",
            f"{indent}{{",
            f"{indent}\tOFFSET {_vector(offset)}",
            f"{indent}\tCHANNELS 3 {ROTATION_CHANNELS}",
            f"{indent}\tEnd Site",
            f"{indent}\t{{",
            f"{indent}\t\tOFFSET {_vector(tip)}",
            f"{indent}\t}}",
            f"{indent}}}",
        ]

    lines = ["HIERARCHY", "ROOT Torso", "{", "\tOFFSET 0.000000 0.000000 0.000000"]
    lines.append(f"\tCHANNELS 6 Xposition Yposition Zposition {ROTATION_CHANNELS}")
    lines += fixed("Head", joints[0], HEAD_TIP, "\t")
    for side, k in (("Right", 0), ("Left", 1)):
        shoulder, hinge, elbow, hand = joints[1 + k], hinges[1 + k], hinges[3 + k], joints[5 + k]
        lines += fixed(f"{side}Shoulder", shoulder, SHOULDER_TIP, "\t")
        lines += [
            f"\tJOINT {side}UpperArm",
            "\t{",
            f"\t\tOFFSET {_vector(hinge)}",
            f"\t\tCHANNELS 3 {ROTATION_CHANNELS}",
            f"\t\tJOINT {side}Forearm",
            "\t\t{",
            f"\t\t\tOFFSET {_vector(elbow - hinge)}",
            f"\t\t\tCHANNELS 3 {ROTATION_CHANNELS}",
            *fixed(f"{side}Hand", hand - elbow, HAND_TIP, "\t\t\t"),
            "\t\t}",
            "\t}",
        ]
    return "\n".join([*lines, "}"]) + "\n"


def motion_row(angles: npt.ArrayLike, root: npt.ArrayLike, body: BodyModel) -> str:
    """One MOTION line: the root's position and every joint's rotation, in hierarchy order."""
    s = skeleton(np.asarray(angles, dtype=float), np.asarray(root, dtype=float), body)
    torso = s["torso"]
    values = [*(FLIP @ s["root"]), *euler_zyx_degrees(_flip(torso))]
    still = (0.0, 0.0, 0.0)
    values += still  # Head
    for side in ("right", "left"):
        upper, lower = s[f"{side}_upper"], s[f"{side}_lower"]
        values += still  # Shoulder
        values += euler_zyx_degrees(_flip(torso.T @ upper))
        values += euler_zyx_degrees(_flip(upper.T @ lower))
        values += still  # Hand
    return " ".join(f"{v:.6f}" for v in values)


def write_bvh(path: str | os.PathLike[str], frames: Iterable[dict[str, Any]], body: BodyModel, fps: float) -> Path:
    """Writes the pose-file frames (each with "angles" and "root", or null for no pose) as BVH.

    Raises:
        InputError: no frame has a pose, or fps is not positive.
        OSError: the file cannot be written.
    """
    if not (math.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be a positive number, got {fps}")
    rows: list[str | None] = []
    for f in frames:
        posed = f.get("angles") is not None and f.get("root") is not None
        rows.append(motion_row(f["angles"], f["root"], body) if posed else None)
    if not any(rows):
        raise InputError("no frame has a pose: nothing to write as BVH")
    first = next(r for r in rows if r)
    held: list[str] = []
    for r in rows:
        held.append(r or (held[-1] if held else first))
    text = hierarchy(body) + f"MOTION\nFrames: {len(held)}\nFrame Time: {1.0 / fps:.8f}\n" + "\n".join(held) + "\n"

    def write(tmp: Path) -> None:
        tmp.write_text(text, encoding="utf-8")

    return write_atomic(path, write)


__all__ = ["euler_zyx_degrees", "hierarchy", "motion_row", "write_bvh"]
