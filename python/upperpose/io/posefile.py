"""The pose file of SPEC 9 ("upperpose.poses/1"): validated reading and atomic writing.

Tracker output and ground truth share this schema. `load_poses` checks every field and raises
one `ValueError` that names the file and the first thing wrong; `write_poses` validates and
writes atomically. Fields may be added to the format, never renamed: unknown top-level and
per-frame fields are kept as they are.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable
from importlib import resources
from pathlib import Path
from typing import Any

from upperpose.exceptions import InputError
from upperpose.io.files import write_atomic
from upperpose.model import ANGLE_NAMES, JOINT_NAMES
from upperpose.result import VISIBILITIES

FORMAT = "upperpose.poses/1"
STATUSES = ("no_person", "initialising", "tracked", "lost")
_EMPTY_STATUSES = ("no_person", "initialising")  # these carry no pose


def _number(value: object, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _points(value: object, dims: int, where: str) -> list[list[float]]:
    if not isinstance(value, list) or len(value) != len(JOINT_NAMES):
        got = f"{len(value)} entries" if isinstance(value, list) else repr(type(value).__name__)
        raise InputError(f"{where} must list {len(JOINT_NAMES)} joints ({', '.join(JOINT_NAMES)}), got {got}")
    out = []
    for j, point in enumerate(value):
        if not isinstance(point, list) or len(point) != dims:
            raise InputError(f"{where}[{j}] ({JOINT_NAMES[j]}) must be {dims} numbers, got {point!r}")
        out.append([_number(v, f"{where}[{j}]") for v in point])
    return out


def validate_frame(frame: object, index: int) -> dict[str, Any]:
    """Checks one entry of "frames" and returns it with numbers as floats.

    Raises:
        ValueError: naming the entry and the field that is wrong.
    """
    where = f"frames[{index}]"
    if not isinstance(frame, dict):
        raise InputError(f"{where} must be an object, got {type(frame).__name__}")
    number = frame.get("frame")
    if isinstance(number, bool) or not isinstance(number, int) or number < 0:
        raise InputError(f"{where}.frame must be a non-negative integer, got {number!r}")
    status = frame.get("status")
    if status not in STATUSES:
        raise InputError(f"{where}.status must be one of {', '.join(STATUSES)}, got {status!r}")
    out = dict(frame)
    for key, dims in (("joints_2d", 2), ("joints_3d", 3)):
        value = frame.get(key)
        if value is None:
            out[key] = None
        elif status in _EMPTY_STATUSES:
            raise InputError(f"{where}: a {status!r} frame carries no {key} (must be null)")
        else:
            out[key] = _points(value, dims, f"{where}.{key}")
    if status == "tracked" and out["joints_2d"] is None:
        raise InputError(f"{where}: a 'tracked' frame needs joints_2d")
    angles = frame.get("angles")
    if angles is not None:
        if not isinstance(angles, list) or len(angles) != len(ANGLE_NAMES):
            raise InputError(f"{where}.angles must be {len(ANGLE_NAMES)} numbers ({', '.join(ANGLE_NAMES)}) or null")
        out["angles"] = [_number(v, f"{where}.angles") for v in angles]
    cost = frame.get("cost")
    out["cost"] = None if cost is None else _number(cost, f"{where}.cost")
    _per_joint(frame, where, status)
    return out


def _per_joint(frame: dict[str, Any], where: str, status: str) -> None:
    """Checks the optional per-joint "confidence" (numbers in [0, 1]) and "visibility" (VISIBILITIES)."""
    for key, ok, wanted in (
        ("confidence", lambda v: _is_number(v) and 0.0 <= v <= 1.0, "numbers in [0, 1]"),
        ("visibility", lambda v: v in VISIBILITIES, f"one of {', '.join(map(repr, VISIBILITIES))}"),
    ):
        value = frame.get(key)
        if value is None:
            continue
        if status in _EMPTY_STATUSES:
            raise InputError(f"{where}: a {status!r} frame carries no {key} (must be null)")
        if not isinstance(value, list) or len(value) != len(JOINT_NAMES) or not all(ok(v) for v in value):
            raise InputError(f"{where}.{key} must be {len(JOINT_NAMES)} entries, each {wanted}, or null; got {value!r}")


def _is_number(value: object) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def validate_poses(data: object) -> dict[str, Any]:
    """Checks a whole pose document (already parsed from JSON).

    Returns:
        The document with validated frames, sorted by frame number.

    Raises:
        ValueError: the first problem found.
    """
    if not isinstance(data, dict):
        raise InputError(f"expected a JSON object, got {type(data).__name__}")
    if data.get("format") != FORMAT:
        raise InputError(f"format must be {FORMAT!r}, got {data.get('format')!r}")
    if data.get("joints", list(JOINT_NAMES)) != list(JOINT_NAMES):
        raise InputError(f"joints must be {list(JOINT_NAMES)}, got {data.get('joints')!r}")
    if data.get("angles", list(ANGLE_NAMES)) != list(ANGLE_NAMES):
        raise InputError(f"angles must be {list(ANGLE_NAMES)}, got {data.get('angles')!r}")
    for key in ("width", "height"):
        v = data.get(key)
        if isinstance(v, bool) or not isinstance(v, int) or v <= 0:
            raise InputError(f"{key} must be a positive integer, got {v!r}")
    out = dict(data)
    out["fps"] = _number(data.get("fps"), "fps")
    if out["fps"] <= 0:
        raise InputError(f"fps must be positive, got {out['fps']}")
    if data.get("run_time_s") is not None:
        out["run_time_s"] = _number(data["run_time_s"], "run_time_s")
        if out["run_time_s"] < 0:
            raise InputError(f"run_time_s must not be negative, got {out['run_time_s']}")
    frames = data.get("frames")
    if not isinstance(frames, list):
        raise InputError(f"frames must be a list, got {type(frames).__name__}")
    checked = [validate_frame(f, i) for i, f in enumerate(frames)]
    seen: set[int] = set()
    for f in checked:
        if f["frame"] in seen:
            raise InputError(f"frame {f['frame']} appears more than once")
        seen.add(f["frame"])
    out["frames"] = sorted(checked, key=lambda f: f["frame"])
    return out


def schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of the pose file, shipped in the package."""
    text = resources.files("upperpose.io").joinpath("schemas/poses-1.schema.json").read_text(encoding="utf-8")
    loaded: dict[str, Any] = json.loads(text)
    return loaded


def load_poses(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Reads and validates a pose file.

    Raises:
        OSError: the file cannot be read.
        ValueError: not JSON, or not the SPEC 9 schema (the message names the file).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise OSError(f"no such file: {p}") from None
    except UnicodeDecodeError:
        raise InputError(f"{p}: not a text file") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise InputError(f"{p}: not valid JSON ({err.msg} at line {err.lineno} column {err.colno})") from None
    except RecursionError:  # the parser recurses per level; no pose file nests more than 4 deep
        raise InputError(f"{p}: JSON nested too deeply to be a pose file") from None
    try:
        return validate_poses(data)
    except ValueError as err:
        raise InputError(f"{p}: {err}") from None


def make_poses(width: int, height: int, fps: float, frames: list[dict[str, Any]], **extra: Any) -> dict[str, Any]:
    """A pose document with the fixed header fields filled in."""
    return {
        "format": FORMAT,
        "width": width,
        "height": height,
        "fps": fps,
        "joints": list(JOINT_NAMES),
        "angles": list(ANGLE_NAMES),
        **extra,
        "frames": frames,
    }


def write_poses(path: str | os.PathLike[str], data: dict[str, Any]) -> Path:
    """Validates `data` and writes it atomically as JSON (one line per frame).

    Raises:
        ValueError: `data` does not follow the schema.
        OSError: the file cannot be written.
    """
    validate_poses(data)
    head = {k: v for k, v in data.items() if k != "frames"}
    return write_pose_lines(path, head, (frame_line(f) for f in data["frames"]))


def frame_line(frame: dict[str, Any]) -> str:
    """One frame as the pose file writes it: compact JSON on one line."""
    return json.dumps(frame, separators=(",", ":"))


def write_pose_lines(path: str | os.PathLike[str], head: dict[str, Any], lines: Iterable[str]) -> Path:
    """Writes a pose file atomically from its header fields and its frames' lines, streamed.

    The caller has validated both (`validate_poses`, `validate_frame`).
    """

    def write(tmp: Path) -> None:
        with tmp.open("w", encoding="utf-8") as f:
            f.write(json.dumps(head, indent=1)[:-2] + ',\n "frames": [\n')
            for k, line in enumerate(lines):
                f.write(line if k == 0 else ",\n" + line)
            f.write("\n ]\n}\n")

    return write_atomic(path, write)
