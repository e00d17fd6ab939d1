"""Fitting one frame: the hierarchical annealed particle swarm of the Rust core (SPEC 5).

See docs/cost.md for the cost terms and docs/search.md for the search.
"""

from __future__ import annotations

import inspect
from collections.abc import Iterable
from typing import Literal, Protocol

import numpy as np
import numpy.typing as npt

import upperpose._upperpose as _upperpose
from upperpose._upperpose import BodyModel, Camera, FrameFit, SearchConfig
from upperpose.exceptions import InputError
from upperpose.model import PoseLike, as_float_array, pose_array

STAGES = ("torso", "right_arm", "left_arm")
# The core's string options (`SearchConfig(limits=..., optimizer=...)`, `fit_frame(mode=...)`).
Limits = Literal["anatomical", "thesis"]
Optimizer = Literal["apso", "pso", "simplex", "apsopf"]
Mode = Literal["trajectory", "initial"]


class BitFeatures(Protocol):
    """What the search reads from a frame's features (`upperpose.features.FrameFeatures`)."""

    @property
    def sil_bits(self) -> npt.NDArray[np.uint64]: ...
    @property
    def edge_bits(self) -> npt.NDArray[np.uint64]: ...
    @property
    def motion_bits(self) -> npt.NDArray[np.uint64]: ...

    def points_array(self) -> npt.NDArray[np.float64]:
        """`(3, 2)` head, right-hand and left-hand points in pixels; NaN when absent or merged."""
        ...


def fit_frame(
    features: BitFeatures,
    prediction: PoseLike,
    root: npt.ArrayLike,
    body: BodyModel,
    camera: Camera,
    *,
    width: int | None = None,
    mode: Mode = "trajectory",
    window_scale: float = 1.0,
    frame_interval: float = 1.0 / 30.0,
    search: Iterable[str] = STAGES,
    frame_index: int = 0,
    config: SearchConfig | None = None,
    angle_window_scales: npt.ArrayLike | None = None,
) -> FrameFit:
    """Fits the body model to one frame: torso, then right arm, then left arm.

    Args:
        features: the frame's features (bit planes and skin points).
        prediction: the predicted pose; centre of the trajectory windows and pose of every
            stage not searched.
        root: `(3,)` root position in metres estimated for this frame.
        body: body dimensions.
        camera: the camera.
        width: image width in pixels; defaults to the features' (`features.size` is
            (height, width)), else 64 x words per row.
        mode: "trajectory" (windows around the prediction) or "initial" (anatomical ranges).
        window_scale: multiplies the trajectory windows (> 1 after a poor fit).
        frame_interval: seconds since the previous frame; windows scale with it.
        search: the stages to search (from the motion flags); others keep the prediction.
        frame_index: keys the random streams: the same seed, frame and inputs give the same fit
            whatever the thread count.
        config: search settings; defaults when None.
        angle_window_scales: `(13,)` multipliers of each angle's trajectory window on top of
            `window_scale` (>= 0; 0 pins the angle at the prediction); all 1 when None.

    Returns:
        The `FrameFit` (pose, root, joints, cost and its terms, evaluations).

    Raises:
        TypeError: `features` is not a frame's features.
        ValueError: inconsistent shapes, bad values or unknown stage names.
    """
    sil, edge, motion = (bit_plane(features, name) for name in ("sil_bits", "edge_bits", "motion_bits"))
    if width is None:
        size = getattr(features, "size", None)
        width = int(size[1]) if size is not None else 64 * int(np.shape(features.sil_bits)[1])
    return _upperpose.fit_frame_bits(
        sil,
        edge,
        motion,
        skin_points(features),
        width,
        pose_array(prediction),
        as_float_array(root, "root", (3,)),
        body,
        camera,
        mode,
        window_scale,
        frame_interval,
        list(search),
        frame_index,
        config or SearchConfig(),
        None if angle_window_scales is None else as_float_array(angle_window_scales, "angle_window_scales", (13,)),
        merged_boxes(features),
        cover_bits(features),
    )


# SearchConfig's keyword options, which are also its attributes (read once: `inspect` parses
# the core's text signature each time).
_OPTIONS = tuple(name for name in inspect.signature(SearchConfig).parameters if name != "seed")


def reseeded(config: SearchConfig, seed: int) -> SearchConfig:
    """A copy of `config` with another seed (the core's settings cannot be changed in place)."""
    return SearchConfig(**{name: getattr(config, name) for name in _OPTIONS}, seed=seed)


def bit_plane(features: BitFeatures, name: str) -> npt.NDArray[np.uint64]:
    """The bit plane `features.<name>`, refused unless it holds unsigned integers.

    A float plane would otherwise be cast to bits silently, NaN included.
    """
    if not hasattr(features, name):
        raise TypeError(
            f"features must be a frame's features (upperpose.features.FrameFeatures), "
            f"got {type(features).__name__} without {name}"
        )
    plane = np.asarray(getattr(features, name))
    if plane.dtype.kind != "u":
        raise InputError(f"features.{name} must be a uint64 bit plane, got dtype {plane.dtype}")
    return np.ascontiguousarray(plane, dtype=np.uint64)


def skin_points(features: BitFeatures) -> npt.NDArray[np.float64]:
    """`(3, 2)` skin points in pixels; NaN marks an absent or merged point.

    An infinite point (a broken detector) is refused: the core would take it for an absent one.
    The core refuses points beyond its range.
    """
    points = np.asarray(features.points_array())
    if points.dtype.kind not in "iuf" or points.shape != (3, 2):
        raise InputError(f"features.points_array() must be (3, 2) numbers, got {points.dtype} {points.shape}")
    points = np.ascontiguousarray(points, dtype=np.float64)
    if np.isinf(points).any():
        raise InputError(f"skin points must be finite or NaN (absent), got {points.tolist()}")
    return points


def cover_bits(features: BitFeatures) -> npt.NDArray[np.uint64] | None:
    """The skin the arms should cover (`FrameFeatures.cover_bits`), or None (no Cover term).

    Features without `cover_bits` (test doubles) have no such skin.
    """
    bits = getattr(features, "cover_bits", None)
    return None if bits is None else np.ascontiguousarray(bits, dtype=np.uint64)


def merged_boxes(features: BitFeatures) -> npt.NDArray[np.float64] | None:
    """`(3, 4)` box of the merged blob holding each part (NaN rows: not merged), or None.

    Features without `merged_boxes_array` (test doubles) have no merged blobs.
    """
    boxes = getattr(features, "merged_boxes_array", None)
    return None if boxes is None else np.ascontiguousarray(boxes(), dtype=np.float64)


__all__ = ["STAGES", "FrameFit", "Limits", "Mode", "Optimizer", "SearchConfig", "fit_frame", "reseeded"]
