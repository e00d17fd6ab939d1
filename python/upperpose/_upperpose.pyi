"""Type stubs for the Rust extension `upperpose._upperpose` (hand-written; see STYLE.md)."""

from typing import Literal, final

import numpy as np
import numpy.typing as npt
from typing_extensions import Self

__all__ = [
    "ANGLE_NAMES",
    "BodyModel",
    "Camera",
    "JOINT_NAMES",
    "PART_NAMES",
    "UpperposeError",
    "__version__",
    "forward_kinematics",
    "joint_limits",
    "render_masks",
    "skeleton",
    "solids",
]

__version__: str
ANGLE_NAMES: list[str]
JOINT_NAMES: list[str]
PART_NAMES: list[str]

class UpperposeError(Exception): ...

@final
class BodyModel:
    def __new__(
        cls,
        *,
        shoulder_width: float | None = None,
        shoulder_height: float | None = None,
        head_offset: float | None = None,
        head_radii: list[float] | None = None,
        neck_length: float | None = None,
        neck_radius: float | None = None,
        torso_top: float | None = None,
        torso_bottom: float | None = None,
        torso_half_width: float | None = None,
        torso_half_depth: float | None = None,
        upper_arm_length: float | None = None,
        upper_arm_radii: list[float] | None = None,
        lower_arm_length: float | None = None,
        lower_arm_radii: list[float] | None = None,
    ) -> Self: ...
    @property
    def shoulder_width(self) -> float: ...
    @property
    def shoulder_height(self) -> float: ...
    @property
    def head_offset(self) -> float: ...
    @property
    def head_radii(self) -> list[float]: ...
    @property
    def neck_length(self) -> float: ...
    @property
    def neck_radius(self) -> float: ...
    @property
    def torso_top(self) -> float: ...
    @property
    def torso_bottom(self) -> float: ...
    @property
    def torso_half_width(self) -> float: ...
    @property
    def torso_half_depth(self) -> float: ...
    @property
    def upper_arm_length(self) -> float: ...
    @property
    def upper_arm_radii(self) -> list[float]: ...
    @property
    def lower_arm_length(self) -> float: ...
    @property
    def lower_arm_radii(self) -> list[float]: ...
    def as_dict(self) -> dict[str, float | list[float]]: ...
    def __eq__(self, value: object, /) -> bool: ...

@final
class Camera:
    @staticmethod
    def perspective(focal: float, cx: float, cy: float) -> Camera: ...
    @staticmethod
    def orthographic(scale: float, cx: float, cy: float) -> Camera: ...
    @staticmethod
    def weak_perspective(focal: float, cx: float, cy: float, reference_depth: float) -> Camera: ...
    @staticmethod
    def for_image(width: int, height: int, focal: float | None = None) -> Camera: ...
    @property
    def kind(self) -> Literal["perspective", "orthographic", "weak_perspective"]: ...
    @property
    def focal(self) -> float: ...
    @property
    def cx(self) -> float: ...
    @property
    def cy(self) -> float: ...
    @property
    def reference_depth(self) -> float | None: ...
    def project(self, points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def __eq__(self, value: object, /) -> bool: ...

def forward_kinematics(
    pose: npt.NDArray[np.float64], root: npt.NDArray[np.float64], body: BodyModel
) -> npt.NDArray[np.float64]: ...
def skeleton(
    pose: npt.NDArray[np.float64], root: npt.NDArray[np.float64], body: BodyModel
) -> dict[str, npt.NDArray[np.float64]]: ...
def solids(
    pose: npt.NDArray[np.float64], root: npt.NDArray[np.float64], body: BodyModel
) -> list[dict[str, object]]: ...
def joint_limits(preset: str = "anatomical") -> list[list[tuple[float, float]]]: ...
def render_masks(
    pose: npt.NDArray[np.float64],
    root: npt.NDArray[np.float64],
    body: BodyModel,
    camera: Camera,
    width: int,
    height: int,
    roi: tuple[int, int, int, int] | None = None,
) -> dict[str, npt.NDArray[np.uint8]]: ...
