"""The SPEC 9 pose file: round trip and clear errors for every kind of malformed input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from upperpose.io.posefile import load_poses, make_poses, write_poses


def frame(i: int, status: str = "tracked", offset: float = 0.0) -> dict[str, object]:
    """A valid frame; joints at simple known places."""
    if status in ("no_person", "initialising"):
        return {"frame": i, "status": status, "joints_2d": None, "joints_3d": None, "angles": None, "cost": None}
    return {
        "frame": i,
        "status": status,
        "joints_2d": [[100.0 + 10 * j + offset, 50.0 + 5 * j] for j in range(7)],
        "joints_3d": [[0.1 * j, -0.05 * j, 2.0] for j in range(7)],
        "angles": [0.0] * 13,
        "cost": 1.5,
    }


def write_raw(path: Path, data: object) -> Path:
    path.write_text(json.dumps(data))
    return path


def test_round_trip(tmp_path: Path) -> None:
    data = make_poses(640, 480, 30.0, [frame(0, "no_person"), frame(1), frame(2, "lost")], run_time_s=1.25)
    write_poses(tmp_path / "p.json", data)
    loaded = load_poses(tmp_path / "p.json")
    assert loaded["frames"] == data["frames"]
    assert loaded["run_time_s"] == 1.25
    assert (loaded["width"], loaded["height"], loaded["fps"]) == (640, 480, 30.0)


def test_frames_are_sorted_and_extra_fields_kept(tmp_path: Path) -> None:
    f2, f1 = frame(2), frame(1)
    f1["root"] = [0.0, 0.1, 2.2]
    data = make_poses(640, 480, 30.0, [f2, f1], source="test")
    loaded = load_poses(write_raw(tmp_path / "p.json", data))
    assert [f["frame"] for f in loaded["frames"]] == [1, 2]
    assert loaded["frames"][0]["root"] == [0.0, 0.1, 2.2]
    assert loaded["source"] == "test"


def bad(**changes: object) -> dict[str, object]:
    data = make_poses(640, 480, 30.0, [frame(0), frame(1)])
    for key, value in changes.items():
        if key.startswith("f1_"):
            data["frames"][1][key[3:]] = value  # type: ignore[index]
        else:
            data[key] = value
    return data


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (bad(format="poses/0"), "format must be"),
        (bad(width=0), "width must be a positive integer"),
        (bad(fps="30"), "fps must be a finite number"),
        (bad(joints=["head"]), "joints must be"),
        (bad(frames={}), "frames must be a list"),
        (bad(f1_status="found"), r"frames\[1\].status must be one of"),
        (bad(f1_frame=-1), r"frames\[1\].frame must be a non-negative integer"),
        (bad(f1_frame=0), "frame 0 appears more than once"),
        (bad(f1_joints_2d=[[1.0, 2.0]] * 6), r"frames\[1\].joints_2d must list 7 joints"),
        (bad(f1_joints_2d=[[1.0, 2.0]] * 6 + [[1.0]]), r"frames\[1\].joints_2d\[6\] \(left_hand\) must be 2 numbers"),
        (bad(f1_joints_3d=[[1.0, 2.0, float("nan")]] * 7), "must be a finite number"),
        (bad(f1_angles=[0.0] * 12), r"frames\[1\].angles must be 13 numbers"),
        (bad(f1_status="no_person"), "'no_person' frame carries no joints_2d"),
        (bad(f1_joints_2d=None), "'tracked' frame needs joints_2d"),
        (bad(f1_cost="low"), "cost must be a finite number"),
        ([1, 2], "expected a JSON object"),
    ],
)
def test_malformed_files_name_the_problem(tmp_path: Path, data: object, message: str) -> None:
    path = write_raw(tmp_path / "p.json", data)
    with pytest.raises(ValueError, match=message) as info:
        load_poses(path)
    assert str(path) in str(info.value)


def test_not_json_and_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "p.json"
    path.write_text("{not json")
    with pytest.raises(ValueError, match="not valid JSON"):
        load_poses(path)
    with pytest.raises(OSError, match="no such file"):
        load_poses(tmp_path / "absent.json")


def test_writer_refuses_invalid_data(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="status"):
        write_poses(tmp_path / "p.json", bad(f1_status="maybe"))
    assert not (tmp_path / "p.json").exists()
