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
