"""Shared fixtures: a fixed camera and body, seeded random poses."""

from __future__ import annotations

import numpy as np
import pytest

import upperpose


@pytest.fixture(scope="session")
def camera() -> upperpose.Camera:
    """The default 640x480 pinhole camera."""
    return upperpose.Camera.for_image(640, 480)


@pytest.fixture(scope="session")
def body() -> upperpose.BodyModel:
    """Adult-average body dimensions."""
    return upperpose.BodyModel()


def random_pose(rng: np.random.Generator) -> upperpose.Pose:
    """A pose uniform in the anatomical ranges."""
    limits = upperpose.joint_limits("anatomical")
    return upperpose.Pose([rng.uniform(r[0][0], r[-1][1]) for r in limits])


@pytest.fixture(autouse=True)
def no_timed_progress_lines(monkeypatch: pytest.MonkeyPatch) -> None:
    """No plain progress lines on a captured stderr: whether one shows would depend on the run's speed."""
    monkeypatch.setenv("UPPERPOSE_PROGRESS_EVERY", "0")


@pytest.fixture(autouse=True)
def pose_files_follow_the_schema(monkeypatch: pytest.MonkeyPatch):  # type: ignore[no-untyped-def]
    """Every pose file any test writes is checked against the shipped JSON Schema."""
    import json

    jsonschema = pytest.importorskip("jsonschema")
    import upperpose.io.output as output
    import upperpose.io.posefile as posefile

    validator = jsonschema.Draft202012Validator(posefile.schema())
    write = posefile.write_pose_lines

    def checked(path, head, lines):  # type: ignore[no-untyped-def]
        written = write(path, head, lines)
        validator.validate(json.loads(written.read_text(encoding="utf-8")))
        return written

    monkeypatch.setattr(posefile, "write_pose_lines", checked)
    monkeypatch.setattr(output, "write_pose_lines", checked)
