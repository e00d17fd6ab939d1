"""The root's 3D position per frame (SPEC 2), in place of the thesis' pixel scale matrix (§3.4.7).

Depth: start-up's, held until the head's skin blob says the person stepped closer or back. The
blob's reference size (w0, h0) is the median of its first `reference_frames` measurements, the
start-up frame's included: a single frame's blob can be a head's width off (the skin colour
learnt from the face at start-up grows it on the next frames; a turn of the head shrinks it),
and every later depth is measured against it. Then each frame the blob's width and its height
each give a depth (Z = Z0 * w0 / w); the held depth moves only when the medians of the last five
of both lie more than `depth_deadband` from it on the same side, and then follows them until it
is within `SETTLED` of them. The blob's size wobbles by far more than a person's depth changes
while they stand (a head turning widens it and shortens it; hair, a hand near the face,
lighting), so following it frame by frame is further from the truth than holding. A subject who
steps closer therefore changes depth, never body size. Measurements are rejected when the head
blob is merged with a hand, its width changes by more than `max_jump` from last frame's, or its
shape (width over height) differs from the reference's by more than `max_shape_change`: a step
keeps the blob's shape, a bowed head or a hand joining it does not. X and Y: the head
point (only when its blob is about a head's size: a hand on the head that the matching did not
see would drag it, and a scrap of skin taken for the head while a hand covers the face would
drop it) back-projected at that depth, minus the head's offset from the root at the predicted
pose, blended with last frame's fitted root (whose x, y the torso search refines). A measurement
farther from last frame's root (moved on at its velocity) than a head moves in one frame is held
back, and does not move the depth either, until a few in a row agree with each other (then the
person did move). Frames without a usable head point blend with the last measurement instead, so
that the search cannot walk the body away frame after frame. When a frontal face is found away
from the model's head (`move_to_face`: the head point followed a hand down the chest), the root
is put back under the face at once.
"""

from __future__ import annotations

from collections import deque
from typing import cast

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.fit.startup import pixels_per_metre, root_from_head
from upperpose.model import BodyModel, Camera

# Relative distance between the held depth and the measured one at which following stops.
SETTLED = 0.03


class RootEstimator:
    """Estimates the root position frame by frame.

    Args:
        camera: the camera.
        body: the person's body model.
        root: the root at start-up (metres, camera frame).
        head_blob_width: width in pixels of the head's skin blob at start-up (None: not seen).
        head_blob_height: its height in pixels (None: not seen).
        head_bias: the head point's offset in pixels from the true head centre at start-up.
        head_size_px: the head's width in pixels at start-up (the face box), to reject head
            blobs that hold more than a head; `head_blob_width` when None.
        depth_gain: weight of a new depth measurement while the depth follows them.
        depth_deadband: relative distance of the measured depth (both the width's and the
            height's) from the held one beyond which the depth follows them.
        xy_gain: weight of the head measurement against last frame's fitted root.
        max_jump: largest accepted relative change of the head blob's width from last frame's.
        min_head_share: smallest head blob accepted, as a share of the expected head size in
            width and in height.
        xy_gate: largest accepted distance of the measured root from the one expected at last
            frame's velocity, in head widths (a head moving 2 m/s at 2 m and 30 fps moves about
            0.4 of its width a frame).
        confirm_jumps: measurements in a row, each within `xy_gate` of the one before, after
            which they are accepted however far from the expected root.
        reference_frames: head blob measurements (start-up's first) whose median is the
            reference size; the depth holds until there are that many. Without a head size
            (`head_size_px` and `head_blob_width` None) the depth always holds.
        max_shape_change: largest accepted relative change of the head blob's width over height
            from the reference's.
    """

    def __init__(
        self,
        camera: Camera,
        body: BodyModel,
        root: npt.ArrayLike,
        head_blob_width: float | None,
        head_blob_height: float | None,
        head_bias: npt.ArrayLike = (0.0, 0.0),
        head_size_px: float | None = None,
        depth_gain: float = 0.15,
        depth_deadband: float = 0.2,
        xy_gain: float = 0.5,
        max_jump: float = 0.25,
        min_head_share: float = 0.5,
        xy_gate: float = 0.5,
        confirm_jumps: int = 3,
        reference_frames: int = 5,
        max_shape_change: float = 0.25,
    ) -> None:
        self.camera, self.body = camera, body
        self.root = np.array(root, dtype=np.float64)
        self._z0 = float(self.root[2])
        self._size0 = head_blob_width if head_size_px is None else head_size_px
        # The head blob's first sizes, until their median becomes the reference (w0, h0).
        self._first: list[tuple[float, float]] = []
        if head_blob_width is not None and head_blob_height is not None:
            self._first.append((float(head_blob_width), float(head_blob_height)))
        self._reference_frames = max(reference_frames, 1)
        self._reference: tuple[float, float] | None = None
        self._take_reference()
        self._bias = np.asarray(head_bias, dtype=np.float64)
        self._depth_gain, self._xy_gain, self._max_jump = depth_gain, xy_gain, max_jump
        self._deadband, self._max_shape_change = depth_deadband, max_shape_change
        self._min_head_share, self._confirm_jumps = min_head_share, confirm_jumps
        # The gate in metres: the head's width at start-up times `xy_gate`.
        self._gate_m = xy_gate * (self._size0 or 0.0) / pixels_per_metre(camera, self._z0)
        # The last measurements, each near the one before; only whether there are confirm_jumps
        # of them is asked, so no more are kept (a list grew by one a frame while tracking).
        self._run: deque[npt.NDArray[np.float64]] = deque(maxlen=max(confirm_jumps, 1))
        self._previous_fit: npt.NDArray[np.float64] | None = None  # last frame's fitted X, Y
        self._expected = self.root[:2].copy()  # this frame's X, Y at last frame's velocity
        self._velocity_known = False
        # Depths from the head blob's width and from its height, the last five accepted.
        self._by_width: deque[float] = deque(maxlen=5)
        self._by_height: deque[float] = deque(maxlen=5)
        self._following = False  # the held depth is moving towards the measured one
        self._last_width: float | None = None  # the head blob's width last frame
        self._anchor = self.root[:2].copy()  # the last root X, Y measured from the head

    @property
    def depth(self) -> float:
        """The current root depth, metres."""
        return float(self.root[2])

    @property
    def face_px(self) -> float | None:
        """The start-up face's width in pixels at the current depth (None: not known)."""
        return None if self._size0 is None else self._at_depth(self._size0)

    def move_to_face(self, face_px: npt.ArrayLike, pose: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Puts the root's X, Y under a face's centre (pixels) at the predicted `pose`, as start-up did.

        The jump is no velocity, and the head points measured before it no longer count.
        """
        self.root[:2] = root_from_head(self.camera, face_px, self.depth, pose, self.body)[:2]
        self._anchor = self.root[:2].copy()
        self._previous_fit = None
        self._run.clear()
        return cast(npt.NDArray[np.float64], self.root.copy())

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
        face = self._at_depth(self._size0)
        # Hair that passes the skin rule widens the head's blob past the face: the widest
        # allowed is the blob's own width at start-up, if wider than the face.
        widest = self._at_depth(max(self._size0, self._reference_width()))
        # The held depth may be up to the deadband off before it moves.
        slack = 1.0 + self._deadband
        small = self._min_head_share * face / slack
        largest = (1.0 + self._max_jump) * widest * slack
        return small <= width <= largest and small <= height <= 2.2 * face * slack

    def _at_depth(self, start_px: float) -> float:
        """A head measure in pixels at the current depth, from its pixels at start-up."""
        return float(start_px) * self._z0 / self.depth

    def _accept_xy(self, measured: npt.NDArray[np.float64]) -> bool:
        """Whether a root X, Y measured from the head point is taken (see the module docs).

        Taken when it lies within the gate of this frame's expected X, Y, or when it continues
        a run of `confirm_jumps` measurements each within the gate of the one before (the
        person did move, or the estimate had drifted).
        """
        if self._size0 is None or not self._velocity_known:
            return True  # right after start-up the person may still be walking in
        if self._run and float(np.hypot(*(measured - self._run[-1]))) > self._gate_m:
            self._run.clear()
        self._run.append(measured)
        near = float(np.hypot(*(measured - self._expected))) <= self._gate_m
        return near or len(self._run) >= self._confirm_jumps

    def _reference_width(self) -> float:
        """The head blob's reference width, or the median of its first widths while they are taken (0: none)."""
        if self._reference is not None:
            return self._reference[0]
        return float(np.median([w for w, _ in self._first])) if self._first else 0.0

    def _take_reference(self) -> None:
        """Fixes the reference size once enough first sizes are in."""
        if self._reference is None and len(self._first) >= self._reference_frames:
            w0, h0 = np.median(self._first, axis=0)
            self._reference = (float(w0), float(h0))

    def _update_depth(self, features: FrameFeatures) -> None:
        head = features.head
        if self._size0 is None or head is None:
            return
        _, _, width, height = features.blobs[head.blob].bbox
        last, self._last_width = self._last_width, float(width)
        if last is not None and not abs(width / last - 1.0) <= self._max_jump:
            return
        if self._reference is None:
            self._first.append((float(width), float(height)))
            self._take_reference()
            return
        w0, h0 = self._reference
        if not abs((width / height) / (w0 / h0) - 1.0) <= self._max_shape_change:
            return
        self._by_width.append(self._z0 * w0 / width)
        self._by_height.append(self._z0 * h0 / height)
        z_width, z_height = float(np.median(self._by_width)), float(np.median(self._by_height))
        if not self._following:
            # Both beyond the deadband, on the same side: the person stepped closer or back.
            off_width, off_height = z_width / self.depth - 1.0, z_height / self.depth - 1.0
            beyond = min(abs(off_width), abs(off_height)) > self._deadband
            self._following = beyond and off_width * off_height > 0
        if self._following:
            measured = float(np.sqrt(z_width * z_height))
            self.root[2] += self._depth_gain * (measured - self.root[2])
            self._following = abs(measured / self.depth - 1.0) > SETTLED

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
        self._expected = self.root[:2].copy()
        self._velocity_known = False
        if fitted_root is not None:
            fitted = np.asarray(fitted_root, dtype=np.float64)[:2]
            self._velocity_known = self._previous_fit is not None
            step = fitted - self._previous_fit if self._previous_fit is not None else np.zeros(2)
            self.root[:2], self._previous_fit = fitted, fitted.copy()
            self._expected = fitted + step
        head = features.head
        if head is not None and self._head_blob_ok(features):
            point = np.asarray(head.xy) - self._bias
            # A head point held back as a jump is not the head: its width must not move the depth.
            if self._accept_xy(root_from_head(self.camera, point, self.depth, pose, self.body)[:2]):
                self._update_depth(features)
                self._anchor = root_from_head(self.camera, point, self.depth, pose, self.body)[:2].copy()
        else:
            self._run.clear()
        # Without a head measurement the last one still anchors X, Y: the search's root window
        # must not be able to walk the body away frame after frame.
        self.root[:2] += self._xy_gain * (self._anchor - self.root[:2])
        return cast(npt.NDArray[np.float64], self.root.copy())


__all__ = ["RootEstimator"]
