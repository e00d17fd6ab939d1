"""The shipped JSON Schema: printed by `upperpose schema`, valid itself, and it catches bad files."""

from __future__ import annotations

import json
from typing import Any

import pytest

from upperpose.cli import main
from upperpose.io.posefile import make_poses, schema, validate_poses

jsonschema = pytest.importorskip("jsonschema")


def good() -> dict[str, Any]:
    frames = [
        {"frame": 0, "status": "no_person", "joints_2d": None, "joints_3d": None, "angles": None, "cost": None},
        {
            "frame": 1,
            "status": "tracked",
            "joints_2d": [[1.0, 2.0]] * 7,
            "joints_3d": [[0.0, 0.0, 2.0]] * 7,
            "angles": [0.0] * 13,
            "cost": 1.5,
            "root": [0.0, 0.1, 2.0],
            "confidence": [0.97, 0.34, 0.34, 0.45, 0.23, 0.87, 0.07],
            "visibility": ["observed"] * 4 + ["unobserved", "observed", "unobserved"],
        },
    ]
    return make_poses(
        640,
        480,
        30.0,
        frames,
        smoothing=None,
        camera={"model": "perspective", "focal": 600.0, "cx": 319.5, "cy": 239.5},
    )


def test_schema_command_prints_a_valid_schema(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["schema"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == schema()
    jsonschema.Draft202012Validator.check_schema(printed)
    jsonschema.validate(good(), printed)


@pytest.mark.parametrize(
    "spoil",
    [
        lambda d: d.update(format="other/1"),
        lambda d: d.update(width=0),
        lambda d: d["frames"][1].update(status="maybe"),
        lambda d: d["frames"][1].update(joints_2d=[[1.0, 2.0]] * 6),
        lambda d: d["frames"][0].update(joints_2d=[[1.0, 2.0]] * 7),  # a no_person frame with joints
        lambda d: d["frames"][1].update(joints_2d=None),  # a tracked frame without them
        lambda d: d["camera"].update(focal=-1.0),
    ],
)
def test_schema_rejects_what_the_reader_rejects(spoil) -> None:  # type: ignore[no-untyped-def]
    doc = good()
    spoil(doc)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, schema())


@pytest.mark.parametrize(
    "spoil",
    [
        lambda d: d["frames"][1].update(visibility=["observed"] * 6 + ["hidden"]),
        lambda d: d["frames"][1].update(visibility=["observed"] * 6),
        lambda d: d["frames"][1].update(confidence=[0.5] * 6 + [1.5]),
        lambda d: d["frames"][1].update(confidence=[0.5] * 6 + ["high"]),
        lambda d: d["frames"][0].update(visibility=["observed"] * 7),  # a no_person frame with visibility
        lambda d: d["frames"][0].update(confidence=[0.5] * 7),
    ],
)
def test_per_joint_fields_are_checked_by_schema_and_reader(spoil) -> None:  # type: ignore[no-untyped-def]
    validate_poses(good())
    doc = good()
    spoil(doc)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, schema())
    with pytest.raises(ValueError, match="confidence|visibility"):
        validate_poses(doc)
