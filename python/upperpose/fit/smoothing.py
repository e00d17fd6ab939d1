"""Smoothing the tracked poses in angle space, without lag: a centred fixed-lag smoother.

Each frame's 13 angles and root are replaced by the value at that frame of a weighted
least-squares quadratic through the frames up to `lag` before and after it, within the run of
consecutive frames that have a pose; the weights fall off with the distance in frames as the
tricube kernel `(1 - (|k| / (lag + 1))^3)^3` (as in LOESS), which damps the frame-to-frame
jitter more than equal weights do at the same window and still passes quadratic motion
unchanged. The joints are then recomputed from the smoothed angles (forward kinematics and
projection), so bone lengths stay the body's. A centred window has no lag; the price is that a
frame's smoothed pose is known `lag` frames later, so a live run's outputs trail the camera by
`lag` frames. Near the ends of a run the window shrinks symmetrically (at the very first and
last frame of a run the pose is kept as it is).
"""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Iterator
from typing import Generic, TypeVar

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError
from upperpose.model import BodyModel, Camera, forward_kinematics, project
from upperpose.result import LOST, TRACKED, TrackResult

FloatArray = npt.NDArray[np.float64]
T = TypeVar("T")
DEFAULT_LAG = 6
MAX_LAG = 30


def centre_weights(half: int) -> FloatArray:
    """Weights of the centre value of a tricube-weighted least-squares quadratic over 2 * half + 1 points.

    half 0 keeps the value; half 1 is the plain mean of three (a quadratic through three points
    would fit them exactly, so a line is fitted instead).
    """
    if half == 0:
        return np.ones(1)
    if half == 1:
        return np.full(3, 1.0 / 3.0)
    k = np.arange(-half, half + 1, dtype=float)
    kernel = (1.0 - (np.abs(k) / (half + 1)) ** 3) ** 3
    basis = np.stack([np.ones_like(k), k, k * k], axis=1)
    # The fitted value at k = 0 is the first coefficient of the weighted normal equations' solution.
    weights: FloatArray = np.linalg.solve(basis.T @ (kernel[:, None] * basis), basis.T * kernel)[0]
    return weights


def has_pose(result: TrackResult) -> bool:
    """Whether the frame carries a pose to smooth."""
    return result.status in (TRACKED, LOST) and result.pose is not None and result.root is not None


class PoseSmoother(Generic[T]):
    """Smooths a stream of `TrackResult`s; each comes out `lag` frames after it went in.

    Args:
        camera: projects the smoothed joints.
        lag: frames on each side of the window (0 passes the results through).

    Each result goes in with the body it was fitted with and any payload (a video frame for an
    overlay, say) that should come out with it.
    """

    def __init__(self, camera: Camera, lag: int = DEFAULT_LAG) -> None:
        if isinstance(lag, bool) or not isinstance(lag, int) or not 0 <= lag <= MAX_LAG:
            raise InputError(f"smoothing lag must be an integer within 0..{MAX_LAG} frames, got {lag!r}")
        self.camera, self.lag = camera, lag
        self._past: deque[tuple[TrackResult, BodyModel]] = deque(maxlen=max(lag, 1))
        self._pending: deque[tuple[TrackResult, BodyModel, T]] = deque()

    def push(self, result: TrackResult, body: BodyModel, payload: T) -> Iterator[tuple[TrackResult, T]]:
        """Adds one frame; yields the frames whose window is now complete, oldest first."""
        if not has_pose(result):
            yield from self.flush()
            yield result, payload
            return
        self._pending.append((result, body, payload))
        while len(self._pending) > self.lag:
            yield self._emit()

    def flush(self) -> Iterator[tuple[TrackResult, T]]:
        """Yields every frame still held (at the end of the video or of a run of poses)."""
        while self._pending:
            yield self._emit()
        self._past.clear()

    def _emit(self) -> tuple[TrackResult, T]:
        result, body, payload = self._pending.popleft()
        past = list(self._past)
        future = [(r, b) for r, b, _ in self._pending]
        half = min(self.lag, len(past), len(future))
        window = [*past[len(past) - half :], (result, body), *future[:half]]
        self._past.append((result, body))
        return self._smoothed(window, half), payload

    def _smoothed(self, window: list[tuple[TrackResult, BodyModel]], half: int) -> TrackResult:
        result, body = window[half]
        if half == 0:
            return result
        w = centre_weights(half)
        pose = w @ np.array([np.asarray(r.pose, dtype=float) for r, _ in window])
        root = w @ np.array([np.asarray(r.root, dtype=float) for r, _ in window])
        joints_3d = forward_kinematics(pose, root, body)
        return dataclasses.replace(
            result, pose=pose, root=root, joints_3d=joints_3d, joints_2d=project(self.camera, joints_3d)
        )


__all__ = ["DEFAULT_LAG", "MAX_LAG", "PoseSmoother", "centre_weights", "has_pose"]
