"""The body model in Python: poses, argument checks, and thin wrappers over the Rust core.

Units and frames (SPEC 2, 9): angles in radians; metres in OpenCV's camera frame (X to image
right, Y down, Z away from the camera); pixels with the origin top-left and integer
coordinates at pixel centres.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable, Mapping
from typing import Union

import numpy as np
import numpy.typing as npt

import upperpose._upperpose as _upperpose
from upperpose._upperpose import ANGLE_NAMES, JOINT_NAMES, MIN_JOINT_DEPTH, PART_NAMES, BodyModel, Camera
from upperpose.exceptions import InputError

FloatArray = npt.NDArray[np.float64]
_ANGLE_INDEX = {name: i for i, name in enumerate(ANGLE_NAMES)}

# Start-up pose of SPEC 6: arms straight, hanging about 35 degrees out from the body.
A_POSE_ABDUCTION = 0.6


def as_float_array(value: object, name: str, shape: tuple[int | None, ...]) -> FloatArray:
    """Converts `value` to a C-contiguous float64 array of `shape` (None: any length).

    Raises:
        TypeError: `value` is not numeric.
        ValueError: wrong shape, or NaN or infinite values.
    """
    array = np.asarray(value)
    if array.dtype.kind not in "biuf":
        raise TypeError(f"{name} must be a numeric array, got dtype {array.dtype}")
    if array.ndim != len(shape) or any(n is not None and n != s for n, s in zip(shape, array.shape)):
        want = "(" + ", ".join("N" if n is None else str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"
        raise InputError(f"{name} must have shape {want}, got {array.shape}")
    array = np.ascontiguousarray(array, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be finite, got NaN or infinite values")
    return array


class Pose:
    """The 13 joint angles of SPEC 2 in radians, in `ANGLE_NAMES` order.

    `Pose()` is the rest pose (torso upright facing the camera, arms hanging straight down).
    Angles may be given as one sequence of 13 numbers or by name:
    `Pose(right_z_up=1.2, right_x_down=0.5)`.
    """

    __slots__ = ("_angles",)

    def __init__(self, angles: Iterable[float] | npt.ArrayLike | None = None, **named: float) -> None:
        values = np.zeros(13) if angles is None else as_float_array(angles, "angles", (13,)).copy()
        for key, v in named.items():
            if key not in _ANGLE_INDEX:
                raise InputError(f"unknown angle {key!r}; angles are {', '.join(ANGLE_NAMES)}")
            if not isinstance(v, numbers.Real):  # float('1.0') would take a string silently
                raise TypeError(f"angle {key} must be a number, got {type(v).__name__}")
            values[_ANGLE_INDEX[key]] = float(v)
        values = as_float_array(values, "angles", (13,))
        values.setflags(write=False)
        self._angles = values

    @classmethod
    def a_pose(cls) -> Pose:
        """The start-up A-pose (SPEC 6): arms straight, about 35 degrees out from the body."""
        return cls(right_z_up=A_POSE_ABDUCTION, left_z_up=A_POSE_ABDUCTION)

    @property
    def angles(self) -> FloatArray:
        """`(13,)` float64, read-only."""
        return self._angles

    def __getitem__(self, name: str) -> float:
        """The angle called `name` (one of `ANGLE_NAMES`)."""
        if name not in _ANGLE_INDEX:
            raise KeyError(name)
        return float(self._angles[_ANGLE_INDEX[name]])

    def replace(self, **named: float) -> Pose:
        """A copy with the named angles changed."""
        return Pose(self._angles, **named)

    def to_dict(self) -> dict[str, float]:
        """Angle name to value."""
        return {n: float(v) for n, v in zip(ANGLE_NAMES, self._angles)}

    def __array__(self, dtype: object = None, copy: object = None) -> FloatArray:
        return self._angles if dtype is None else self._angles.astype(dtype)  # type: ignore[call-overload]

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Pose) and bool(np.array_equal(self._angles, other._angles))

    def __hash__(self) -> int:
        return hash(self._angles.tobytes())

    def __repr__(self) -> str:
        nonzero = ", ".join(f"{n}={v:.4g}" for n, v in self.to_dict().items() if v != 0.0)
        return f"Pose({nonzero})"


PoseLike = Union[Pose, npt.ArrayLike, Mapping[str, float]]  # noqa: UP007 (a runtime alias on 3.10)


def pose_array(pose: PoseLike) -> FloatArray:
    """A `(13,)` float64 array from a `Pose`, a sequence of 13 angles, or a name-to-angle dict."""
    if isinstance(pose, Pose):
        return pose.angles
    if isinstance(pose, Mapping):
        return Pose(**pose).angles
    return as_float_array(pose, "pose", (13,))


def forward_kinematics(pose: PoseLike, root: npt.ArrayLike, body: BodyModel | None = None) -> FloatArray:
    """The seven anatomical joints of a posed body, metres in the camera frame.

    Head = centre of the head, shoulders = glenohumeral centres, elbows = elbow centres,
    hands = centres of the palms (docs/body-model.md, "Joints").

    Args:
        pose: the 13 angles (a `Pose`, a sequence, or a name-to-angle dict).
        root: `(3,)` position of the root (centroid of the upper body), metres.
        body: body dimensions; adult averages when None.

    Returns:
        `(7, 3)` float64 joint positions in `JOINT_NAMES` order.
    """
    return _upperpose.forward_kinematics(pose_array(pose), as_float_array(root, "root", (3,)), body or BodyModel())


def model_points(pose: PoseLike, root: npt.ArrayLike, body: BodyModel | None = None) -> FloatArray:
    """The points the model's solids hang from, `(7, 3)` metres in `JOINT_NAMES` order.

    The head ellipsoid's centre (the centre of the face), the upper-arm cones' tops, the
    elbows and the forearm cones' ends (the middle of the hand): what the image's head and hand
    points measure, unlike the anatomical joints of `forward_kinematics`.
    """
    return skeleton(pose, root, body)["model_points"]


def skeleton(pose: PoseLike, root: npt.ArrayLike, body: BodyModel | None = None) -> dict[str, FloatArray]:
    """Joints and the frames of torso and limbs for a pose (see `_upperpose.skeleton`)."""
    return _upperpose.skeleton(pose_array(pose), as_float_array(root, "root", (3,)), body or BodyModel())


def solids(pose: PoseLike, root: npt.ArrayLike, body: BodyModel | None = None) -> list[dict[str, object]]:
    """The body model's solids for a pose, one dict per part (see `_upperpose.solids`)."""
    return _upperpose.solids(pose_array(pose), as_float_array(root, "root", (3,)), body or BodyModel())


def penetrates(pose: PoseLike, root: npt.ArrayLike, body: BodyModel | None = None) -> bool:
    """Whether the pose breaks the search's non-penetration rule (see `_upperpose.penetrates`)."""
    return _upperpose.penetrates(pose_array(pose), as_float_array(root, "root", (3,)), body or BodyModel())


def reaching_camera(pose: PoseLike, root: npt.ArrayLike, body: BodyModel, camera: Camera) -> tuple[str, ...]:
    """The parts ("torso", "right_arm", "left_arm") too near a perspective camera.

    A part is too near when a model point or joint lies nearer than `MIN_JOINT_DEPTH` metres;
    the search rejects such candidates (the joint projects far outside the image, or not at
    all). Empty for the other cameras, whose projection does not depend on the depth.
    """
    return tuple(_upperpose.reaching_camera(pose_array(pose), as_float_array(root, "root", (3,)), body, camera))


def check_camera_fits(camera: Camera, width: int, height: int) -> None:
    """Refuses a camera made for another image size: its principal point off the middle half.

    A calibrated camera's principal point lies near the image centre; one far from it means
    the camera belongs to another resolution, and every pose would be off by the difference.

    Raises:
        InputError: naming both sizes.
    """
    if abs(camera.cx - (width - 1) / 2) > width / 4 or abs(camera.cy - (height - 1) / 2) > height / 4:
        raise InputError(
            f"the camera's principal point ({camera.cx:g}, {camera.cy:g}) is far from the centre of the "
            f"{width}x{height} images: a camera for another image size (make it with Camera.for_image)"
        )


def project(camera: Camera, points: npt.ArrayLike) -> FloatArray:
    """Projects `(N, 3)` points in metres to `(N, 2)` pixels (NaN where a pinhole cannot see)."""
    return camera.project(as_float_array(points, "points", (None, 3)))


def render_masks(
    pose: PoseLike,
    root: npt.ArrayLike,
    camera: Camera,
    width: int,
    height: int,
    body: BodyModel | None = None,
    roi: tuple[int, int, int, int] | None = None,
) -> dict[str, npt.NDArray[np.uint8]]:
    """Rasterises the body model into uint8 masks (see `_upperpose.render_masks`).

    Args:
        pose: the 13 angles.
        root: `(3,)` root position, metres.
        camera: the camera.
        width: image width in pixels.
        height: image height in pixels.
        body: body dimensions; adult averages when None.
        roi: `(x, y, w, h)` inside the image; the whole image when None.

    Returns:
        dict of `(h, w)` uint8 arrays: `silhouette`, `labels`, `contour`, and per part its
        silhouette (`name`) and visible contour (`name + "_contour"`).

    Raises:
        ValueError: bad shapes or values, or a region outside the image.
        TypeError: non-numeric pose or root.
    """
    return _upperpose.render_masks(*_render_args(pose, root, camera, width, height, body), roi)


def render_labels(
    pose: PoseLike,
    root: npt.ArrayLike,
    camera: Camera,
    width: int,
    height: int,
    body: BodyModel | None = None,
    roi: tuple[int, int, int, int] | None = None,
) -> npt.NDArray[np.uint8]:
    """`render_masks(...)["labels"]` alone, several times cheaper: the tracker's per-frame need.

    Returns:
        `(h, w)` uint8: 0 for no part, `k + 1` where part `k` of `PART_NAMES` is the nearest.

    Raises:
        ValueError: bad shapes or values, or a region outside the image.
        TypeError: non-numeric pose or root.
    """
    return _upperpose.render_labels(*_render_args(pose, root, camera, width, height, body), roi)


def _render_args(
    pose: PoseLike, root: npt.ArrayLike, camera: Camera, width: int, height: int, body: BodyModel | None
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], BodyModel, Camera, int, int]:
    for name, v in (("width", width), ("height", height)):
        if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or v <= 0:
            raise InputError(f"{name} must be a positive integer, got {v!r}")
    return pose_array(pose), as_float_array(root, "root", (3,)), body or BodyModel(), camera, int(width), int(height)


__all__ = [
    "ANGLE_NAMES",
    "JOINT_NAMES",
    "MIN_JOINT_DEPTH",
    "PART_NAMES",
    "BodyModel",
    "Camera",
    "Pose",
    "as_float_array",
    "check_camera_fits",
    "forward_kinematics",
    "model_points",
    "penetrates",
    "pose_array",
    "project",
    "reaching_camera",
    "render_labels",
    "render_masks",
    "skeleton",
    "solids",
]
