"""Smoothing the tracked poses in angle space, without lag: a fixed-lag local quadratic smoother.

Each frame's 13 angles and root are replaced by the value at that frame of a weighted
least-squares quadratic through the frames up to `lag` before and after it, within the run of
consecutive frames that have a pose; the weights fall off with the distance in frames as the
tricube kernel `(1 - (|k| / (lag + 1))^3)^3` (as in LOESS), which damps the frame-to-frame
jitter more than equal weights do at the same window and still passes quadratic motion
unchanged. The joints are then recomputed from the smoothed angles (forward kinematics and
projection), so bone lengths stay the body's. The quadratic has no lag for any window, so near
the ends of a run the window keeps the frames it has on either side (one-sided at the first and
last frame) rather than shrinking to the shorter side: the ends are smoothed as well. The price
of the centred window is that a frame's smoothed pose is known `lag` frames later, so a live
run's outputs trail the camera by `lag` frames.

Each part (the torso with the root, each arm) is smoothed over its own window, which stops at a
frame where the part's angles jump by more than a search step (`max_step`): a lost arm found
again, or a correction that moved it, often lands in another configuration of the angles that
puts the hand near the same place, and a quadratic through both configurations passes through
poses the arm never took (the hand swung 110 px away and back over three frames on the
validation set).
"""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Iterator
from typing import Generic, TypeVar

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError
from upperpose.model import BodyModel, Camera, forward_kinematics, project, reaching_camera
from upperpose.result import LOST, TRACKED, TrackResult

FloatArray = npt.NDArray[np.float64]
T = TypeVar("T")
DEFAULT_LAG = 7
MAX_LAG = 30
# The angles of each part, in order: the torso (the root moves with it), the right arm, the left arm.
PART_ANGLES = (slice(0, 3), slice(3, 8), slice(8, 13))
# Radians: twice the largest step a search takes between two frames (a trajectory window reaches
# 0.15 rad at 30 frames/s, twice that after a poor fit and twice again at 15 frames/s).
DEFAULT_MAX_STEP = 1.2


def window_weights(before: int, after: int, lag: int) -> FloatArray:
    """Weights giving frame 0's value of a tricube-weighted least-squares fit over `-before..after`.

    The kernel reaches `lag + 1` frames. A quadratic through four or more frames; through three,
    a line (a quadratic would pass through them, keeping the noise); one or two frames keep the
    frame's own value.
    """
    count = before + after + 1
    if count <= 2:
        kept: FloatArray = np.eye(count)[before]
        return kept
    k = np.arange(-before, after + 1, dtype=float)
    kernel = (1.0 - (np.abs(k) / (lag + 1)) ** 3) ** 3
    degree = 2 if count >= 4 else 1
    basis = np.stack([k**d for d in range(degree + 1)], axis=1)
    # The fitted value at k = 0 is the first coefficient of the weighted normal equations' solution.
    weights: FloatArray = np.linalg.solve(basis.T @ (kernel[:, None] * basis), basis.T * kernel)[0]
    return weights


def steady_span(values: FloatArray, before: int, after: int, max_step: float) -> tuple[int, int]:
    """How far the window around row `before` of `values` reaches on each side without a jump.

    A jump is a change between consecutive rows of more than `max_step` in any column.
    """
    steps = np.abs(np.diff(values, axis=0)).max(axis=1) > max_step  # steps[k]: row k to k + 1
    b = next((before - k - 1 for k in range(before - 1, -1, -1) if steps[k]), before)
    a = next((k - before for k in range(before, len(steps)) if steps[k]), after)
    return b, a


def has_pose(result: TrackResult) -> bool:
    """Whether the frame carries a pose to smooth."""
    return result.status in (TRACKED, LOST) and result.pose is not None and result.root is not None


class PoseSmoother(Generic[T]):
    """Smooths a stream of `TrackResult`s; each comes out `lag` frames after it went in.

    Args:
        camera: projects the smoothed joints.
        lag: frames on each side of the window (0 passes the results through).
        max_step: radians; a larger change of any of a part's angles between two frames ends
            that part's window.

    Each result goes in with the body it was fitted with and any payload (a video frame for an
    overlay, say) that should come out with it.
    """

    def __init__(self, camera: Camera, lag: int = DEFAULT_LAG, max_step: float = DEFAULT_MAX_STEP) -> None:
        if isinstance(lag, bool) or not isinstance(lag, int) or not 0 <= lag <= MAX_LAG:
            raise InputError(f"smoothing lag must be an integer within 0..{MAX_LAG} frames, got {lag!r}")
        if not max_step > 0:
            raise InputError(f"the largest smoothed step must be a positive number of radians, got {max_step!r}")
        self.camera, self.lag, self.max_step = camera, lag, max_step
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
        before, after = min(self.lag, len(past)), min(self.lag, len(future))
        window = [*past[len(past) - before :], (result, body), *future[:after]]
        self._past.append((result, body))
        return self._smoothed(window, before, after), payload

    def _smoothed(self, window: list[tuple[TrackResult, BodyModel]], before: int, after: int) -> TrackResult:
        result, body = window[before]
        if before + after < 2:
            return result
        poses = np.array([np.asarray(r.pose, dtype=float) for r, _ in window])
        roots = np.array([np.asarray(r.root, dtype=float) for r, _ in window])
        windows = [self._part_window(poses[:, part], before, after) for part in PART_ANGLES]
        pose = np.concatenate([w @ poses[span, part] for (span, w), part in zip(windows, PART_ANGLES)])
        torso_span, torso_weights = windows[0]
        root = torso_weights @ roots[torso_span]  # the root moves with the torso
        if reaching_camera(pose, root, body, self.camera):
            return result  # the quadratic overshot into the camera: keep the fitted pose
        joints_3d = forward_kinematics(pose, root, body)
        return dataclasses.replace(
            result, pose=pose, root=root, joints_3d=joints_3d, joints_2d=project(self.camera, joints_3d)
        )

    def _part_window(self, angles: FloatArray, before: int, after: int) -> tuple[slice, FloatArray]:
        """The rows of the window one part is smoothed over, and their weights.

        A part re-seeded between two frames (a lost arm found again in another configuration)
        changes its angles by more than a search step can: the angles in between describe no
        motion, so the part's window stops there.
        """
        b, a = steady_span(angles, before, after, self.max_step)
        return slice(before - b, before + a + 1), window_weights(b, a, self.lag)


__all__ = [
    "DEFAULT_LAG",
    "DEFAULT_MAX_STEP",
    "MAX_LAG",
    "PART_ANGLES",
    "PoseSmoother",
    "has_pose",
    "steady_span",
    "window_weights",
]
