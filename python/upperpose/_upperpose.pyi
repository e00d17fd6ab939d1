"""Type stubs for the Rust extension `upperpose._upperpose` (hand-written; see STYLE.md)."""

from typing import Literal, TypedDict, final

import numpy as np
import numpy.typing as npt
from typing_extensions import Self

__all__ = [
    "ANGLE_NAMES",
    "BodyModel",
    "Camera",
    "FrameFit",
    "SearchConfig",
    "JOINT_NAMES",
    "MIN_JOINT_DEPTH",
    "PART_NAMES",
    "InputError",
    "SearchError",
    "UpperposeError",
    "__version__",
    "fit_frame_bits",
    "forward_kinematics",
    "joint_limits",
    "penetrates",
    "reaching_camera",
    "render_labels",
    "render_masks",
    "skeleton",
    "solids",
]

__version__: str
ANGLE_NAMES: list[str]
JOINT_NAMES: list[str]
PART_NAMES: list[str]
MIN_JOINT_DEPTH: float

_Limits = Literal["anatomical", "thesis"]
_Optimizer = Literal["apso", "pso", "simplex", "apsopf"]
_Mode = Literal["trajectory", "initial"]

class _BodyDims(TypedDict):
    """`BodyModel.as_dict()`: every dimension, the keyword arguments of `BodyModel`."""

    shoulder_width: float
    shoulder_height: float
    head_offset: float
    head_radii: list[float]
    neck_length: float
    neck_radius: float
    torso_top: float
    torso_bottom: float
    torso_half_width: float
    torso_half_depth: float
    upper_arm_length: float
    upper_arm_radii: list[float]
    lower_arm_length: float
    lower_arm_radii: list[float]

class UpperposeError(Exception): ...
class InputError(UpperposeError, ValueError): ...
class SearchError(UpperposeError): ...

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
    def as_dict(self) -> _BodyDims: ...
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
def penetrates(pose: npt.NDArray[np.float64], root: npt.NDArray[np.float64], body: BodyModel) -> bool: ...
def reaching_camera(
    pose: npt.NDArray[np.float64], root: npt.NDArray[np.float64], body: BodyModel, camera: Camera
) -> list[str]: ...
def joint_limits(preset: _Limits = "anatomical") -> list[list[tuple[float, float]]]: ...
def render_masks(
    pose: npt.NDArray[np.float64],
    root: npt.NDArray[np.float64],
    body: BodyModel,
    camera: Camera,
    width: int,
    height: int,
    roi: tuple[int, int, int, int] | None = None,
) -> dict[str, npt.NDArray[np.uint8]]: ...
def render_labels(
    pose: npt.NDArray[np.float64],
    root: npt.NDArray[np.float64],
    body: BodyModel,
    camera: Camera,
    width: int,
    height: int,
    roi: tuple[int, int, int, int] | None = None,
) -> npt.NDArray[np.uint8]: ...

@final
class SearchConfig:
    def __new__(
        cls,
        *,
        particles: int | None = None,
        iterations: int | None = None,
        c0: float | None = None,
        annealing: bool | None = None,
        max_speed: float | None = None,
        weights: dict[str, float] | None = None,
        limits: _Limits = "anatomical",
        non_penetration: bool = True,
        threads: int | None = None,
        seed: int | None = None,
        root_window: float | None = None,
        initial_root_window: float | None = None,
        row_steps: tuple[int, int, int] | None = None,
        optimizer: _Optimizer = "apso",
        sigma: float | None = None,
        behind_weight: float | None = None,
        behind_margin: float | None = None,
        turn_weight: float | None = None,
        lean_weight: float | None = None,
        rotation_weight: float | None = None,
        mask_other_arm_edges: bool = True,
        sil_by_part_area: bool = True,
        merged_skin: bool = True,
    ) -> Self: ...
    @property
    def particles(self) -> int: ...
    @property
    def iterations(self) -> int: ...
    @property
    def c0(self) -> float: ...
    @property
    def annealing(self) -> bool: ...
    @property
    def max_speed(self) -> float: ...
    @property
    def limits(self) -> _Limits: ...
    @property
    def non_penetration(self) -> bool: ...
    @property
    def threads(self) -> int | None: ...
    @property
    def seed(self) -> int: ...
    @property
    def root_window(self) -> float: ...
    @property
    def initial_root_window(self) -> float: ...
    @property
    def behind_weight(self) -> float: ...
    @property
    def behind_margin(self) -> float: ...
    @property
    def turn_weight(self) -> float: ...
    @property
    def lean_weight(self) -> float: ...
    @property
    def rotation_weight(self) -> float: ...
    @property
    def mask_other_arm_edges(self) -> bool: ...
    @property
    def sil_by_part_area(self) -> bool: ...
    @property
    def merged_skin(self) -> bool: ...
    @property
    def row_steps(self) -> tuple[int, int, int]: ...
    @property
    def optimizer(self) -> _Optimizer: ...
    @property
    def sigma(self) -> float: ...
    @property
    def weights(self) -> dict[str, float]: ...

@final
class FrameFit:
    @property
    def pose(self) -> npt.NDArray[np.float64]: ...
    @property
    def root(self) -> npt.NDArray[np.float64]: ...
    @property
    def joints_3d(self) -> npt.NDArray[np.float64]: ...
    @property
    def joints_2d(self) -> npt.NDArray[np.float64]: ...
    @property
    def cost(self) -> float: ...
    @property
    def stage_costs(self) -> dict[str, float]: ...
    @property
    def terms(self) -> dict[str, dict[str, float]]: ...
    @property
    def evaluations(self) -> int: ...

def fit_frame_bits(
    sil: npt.NDArray[np.uint64],
    edge: npt.NDArray[np.uint64],
    motion: npt.NDArray[np.uint64],
    points: npt.NDArray[np.float64],
    width: int,
    prediction: npt.NDArray[np.float64],
    root: npt.NDArray[np.float64],
    body: BodyModel,
    camera: Camera,
    mode: _Mode,
    window_scale: float,
    frame_interval: float,
    search: list[str],
    frame_index: int,
    config: SearchConfig,
    angle_window_scales: npt.NDArray[np.float64] | None = None,
    merged_boxes: npt.NDArray[np.float64] | None = None,
    skin_mask: npt.NDArray[np.uint64] | None = None,
) -> FrameFit: ...
