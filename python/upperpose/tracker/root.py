"""The root's 3D position per frame (SPEC 2), in place of the thesis' pixel scale matrix (§3.4.7).

Depth: the width of the head's skin blob, compared with its width at start-up when the depth was
known from the face box: Z = Z0 * w0 / w. A subject who steps closer therefore changes depth,
never body size. Measurements are rejected when the head blob is merged with a hand or its
width jumps by more than `max_jump`; accepted ones pass a median of the last five and an
exponential filter. X and Y: the head point (only when its blob is about a head's size: a
hand on the head that the matching did not see would drag it) back-projected at that depth, minus the head's
offset from the root at the predicted pose, blended with last frame's fitted root (whose x, y
the torso search refines). Frames without a usable head point blend with the last measurement
instead, so that the search cannot walk the body away frame after frame.
"""

from __future__ import annotations

from collections import deque

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.model import BodyModel, Camera
from upperpose.tracker.startup import root_from_head


class RootEstimator:
    """Estimates the root position frame by frame.

    Args:
        camera: the camera.
        body: the person's body model.
        root: the root at start-up (metres, camera frame).
        head_blob_width: width in pixels of the head's skin blob at start-up (None: depth stays).
        head_bias: the head point's offset in pixels from the true head centre at start-up.
        head_size_px: the head's width in pixels at start-up (the face box), to reject head
            blobs that hold more than a head; `head_blob_width` when None.
        depth_gain: weight of a new depth measurement (exponential filter).
        xy_gain: weight of the head measurement against last frame's fitted root.
        max_jump: largest accepted relative change of the head blob's width in one frame.
    """

    def __init__(
        self,
        camera: Camera,
        body: BodyModel,
        root: npt.ArrayLike,
        head_blob_width: float | None,
        head_bias: npt.ArrayLike = (0.0, 0.0),
        head_size_px: float | None = None,
        depth_gain: float = 0.15,
        xy_gain: float = 0.5,
        max_jump: float = 0.25,
    ) -> None:
        self.camera, self.body = camera, body
        self.root = np.array(root, dtype=np.float64)
        self._z0 = float(self.root[2])
        self._w0 = head_blob_width
        self._size0 = head_blob_width if head_size_px is None else head_size_px
        self._bias = np.asarray(head_bias, dtype=np.float64)
        self._depth_gain, self._xy_gain, self._max_jump = depth_gain, xy_gain, max_jump
        self._recent: deque[float] = deque(maxlen=5)
        self._anchor = self.root[:2].copy()  # the last root X, Y measured from the head

    @property
    def depth(self) -> float:
        """The current root depth, metres."""
        return float(self.root[2])

    def _head_blob_ok(self, features: FrameFeatures) -> bool:
        """The head point is a measurement: not merged, and its blob about a head's size.

        A hand or forearm touching the head joins its blob without being matched to it when the
        model's arm is elsewhere; the head point would then sit on the hands.
        """
        head = features.head
        if head is None or head.merged:
            return False
        if self._size0 is None:
            return True
        _, _, width, height = features.blobs[head.blob].bbox
        expected = self._size0 * self._z0 / self.depth
        return width <= (1.0 + self._max_jump) * expected and height <= 2.2 * expected

    def _measure_depth(self, features: FrameFeatures) -> float | None:
        head = features.head
        if self._w0 is None or head is None or not self._head_blob_ok(features):
            return None
        width = float(features.blobs[head.blob].bbox[2])
        expected = self._w0 * self._z0 / self.depth
        if not abs(width / expected - 1.0) <= self._max_jump:
            return None
        return self._z0 * self._w0 / width

    def update(
        self, features: FrameFeatures, pose: npt.ArrayLike, fitted_root: npt.ArrayLike | None = None
    ) -> npt.NDArray[np.float64]:
        """The root for this frame from its features, the predicted pose and last frame's fit.

        Args:
            features: this frame's features (head point and blob).
            pose: the predicted pose for this frame.
            fitted_root: last frame's fitted root (x, y refined by the search), if any.

        Returns:
            `(3,)` root, metres.
        """
        if fitted_root is not None:
            self.root[:2] = np.asarray(fitted_root, dtype=np.float64)[:2]
        z = self._measure_depth(features)
        if z is not None:
            self._recent.append(z)
            self.root[2] += self._depth_gain * (float(np.median(self._recent)) - self.root[2])
        head = features.head
        if head is not None and self._head_blob_ok(features):
            measured = root_from_head(self.camera, np.asarray(head.xy) - self._bias, self.depth, pose, self.body)
            self._anchor = measured[:2].copy()
        # Without a head measurement the last one still anchors X, Y: the search's root window
        # must not be able to walk the body away frame after frame.
        self.root[:2] += self._xy_gain * (self._anchor - self.root[:2])
        return self.root.copy()


__all__ = ["RootEstimator"]
