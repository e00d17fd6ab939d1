"""The search as the tracker calls it: what a fitter returns, and one frame's fits for one person.

`Fitter` is `upperpose.fit_frame` or a test double; `FrameSearch` binds it to the person's body,
the camera, the search settings and the frame, so the per-frame loop, start-up and the arm
corrections all call it the same way.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.fit.search import Mode, SearchConfig
from upperpose.model import BodyModel, Camera, penetrates, reaching_camera

FloatArray = npt.NDArray[np.float64]
PARTS = ("torso", "right_arm", "left_arm")
# Angle indices per searched part (ANGLE_NAMES order).
PART_ANGLES = {"torso": slice(0, 3), "right_arm": slice(3, 8), "left_arm": slice(8, 13)}


class FitLike(Protocol):
    """What a fitter returns (`upperpose.FrameFit` or a test double)."""

    @property
    def pose(self) -> Any:
        """The 13 joint angles, radians."""

    @property
    def root(self) -> Any:
        """The root position, metres."""

    @property
    def joints_3d(self) -> Any:
        """The anatomical joints in the camera frame, metres."""

    @property
    def joints_2d(self) -> Any:
        """The anatomical joints in the image, pixels."""

    @property
    def cost(self) -> float:
        """The fit's cost."""

    @property
    def stage_costs(self) -> dict[str, float]:
        """The cost of each searched stage."""


Fitter = Callable[..., FitLike]


@dataclass(frozen=True)
class StaticFit:
    """A fit made without searching (nothing moved, or a test double)."""

    pose: FloatArray
    root: FloatArray
    joints_3d: FloatArray
    joints_2d: FloatArray
    cost: float
    stage_costs: dict[str, float] = field(default_factory=dict)
    terms: dict[str, Any] = field(default_factory=dict)
    evaluations: int = 0


@dataclass(frozen=True)
class FrameSearch:
    """The fitter bound to one person's body, the camera, the search settings and one frame."""

    fitter: Fitter
    body: BodyModel
    camera: Camera
    config: SearchConfig
    index: int
    interval: float

    def run(
        self,
        features: FrameFeatures,
        prediction: FloatArray,
        root: FloatArray,
        mode: Mode,
        parts: tuple[str, ...],
        window_scale: float = 1.0,
        angle_scales: FloatArray | None = None,
    ) -> FitLike:
        """Searches `parts` around `prediction` (none: scores the prediction as it is)."""
        extra = {} if angle_scales is None else {"angle_window_scales": angle_scales}
        return self.fitter(
            features,
            np.ascontiguousarray(prediction, dtype=np.float64),
            np.ascontiguousarray(root, dtype=np.float64),
            self.body,
            self.camera,
            mode=mode,
            window_scale=window_scale,
            frame_interval=self.interval,
            search=parts,
            frame_index=self.index,
            config=self.config,
            **extra,
        )

    def fair_cost(self, features: FrameFeatures, pose: FloatArray, root: FloatArray) -> float:
        """A pose's cost unsearched, in the full-range search's regions: comparable between poses.

        Infinite for a pose the search rejects (an arm through the torso or the other arm, a
        part reaching the camera), whose stage the fitter scores 0.
        """
        if self.config.non_penetration and penetrates(pose, root, self.body):
            return math.inf
        if reaching_camera(pose, root, self.body, self.camera):
            return math.inf
        return float(self.run(features, pose, root, "initial", ()).cost)


__all__ = ["PARTS", "PART_ANGLES", "FitLike", "Fitter", "FrameSearch", "StaticFit"]
