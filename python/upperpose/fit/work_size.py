"""Large frames tracked at a reduced working size (docs/tracker.md, Working size).

The features' pixel sizes (morphology, margins, blob areas, the face detector's smallest face)
and the cost's balance were set and measured on 640x480 video, and a 1920x1080 frame has 6.75
times its pixels to process. Frames with more than `TrackerConfig.work_pixels` pixels are
therefore shrunk, keeping their shape, to about that many pixels (OpenCV's area
interpolation); the tracker sees those frames, the plate shrunk the same way and the camera
scaled to match, and the results' 2D joints are mapped back to the video's pixels. Angles, the
root and the 3D joints are metric and the same for both.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.checks import Frame
from upperpose.model import Camera
from upperpose.result import TrackResult

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class WorkSize:
    """A video's frame size and the working size its frames are tracked at.

    Attributes:
        video: the video's (width, height).
        work: the working (width, height); the video's when its frames are small enough.
    """

    video: tuple[int, int]
    work: tuple[int, int]

    @classmethod
    def of(cls, width: int, height: int, work_pixels: int) -> WorkSize:
        """The working size of `width` x `height` frames: at most about `work_pixels` pixels (0: no limit)."""
        if work_pixels <= 0 or width * height <= work_pixels:
            return cls((width, height), (width, height))
        scale = math.sqrt(work_pixels / (width * height))
        return cls((width, height), (max(round(width * scale), 1), max(round(height * scale), 1)))

    @property
    def reduced(self) -> bool:
        """Whether frames are shrunk."""
        return self.work != self.video

    @property
    def scales(self) -> tuple[float, float]:
        """Working pixels per video pixel, in x and in y (equal but for rounding)."""
        return self.work[0] / self.video[0], self.work[1] / self.video[1]

    def frame(self, image: Frame) -> Frame:
        """A video-sized image (frame or plate) at the working size."""
        if not self.reduced:
            return image
        return np.ascontiguousarray(cv2.resize(image, self.work, interpolation=cv2.INTER_AREA))

    def camera(self, camera: Camera) -> Camera:
        """The video's camera for working-size frames: pixel sizes and the principal point scaled.

        A pixel's centre `u` maps to `(u + 0.5) * s - 0.5`, as OpenCV's resize samples; the
        focal length takes the x scale (the y scale differs from it only by the rounding of
        the working height).
        """
        if not self.reduced:
            return camera
        sx, sy = self.scales
        cx, cy = (camera.cx + 0.5) * sx - 0.5, (camera.cy + 0.5) * sy - 0.5
        if camera.kind == "perspective":
            return Camera.perspective(camera.focal * sx, cx, cy)
        if camera.kind == "weak_perspective":
            return Camera.weak_perspective(camera.focal * sx, cx, cy, camera.reference_depth or 1.0)
        return Camera.orthographic(camera.focal * sx, cx, cy)

    def to_video(self, points: FloatArray) -> FloatArray:
        """`(N, 2)` working-size pixels as video pixels."""
        sx, sy = self.scales
        mapped: FloatArray = (np.asarray(points, dtype=np.float64) + 0.5) / np.array([sx, sy]) - 0.5
        return mapped

    def to_work(self, points: FloatArray) -> FloatArray:
        """`(N, 2)` video pixels as working-size pixels."""
        sx, sy = self.scales
        mapped: FloatArray = (np.asarray(points, dtype=np.float64) + 0.5) * np.array([sx, sy]) - 0.5
        return mapped

    def result(self, result: TrackResult) -> TrackResult:
        """A result of the working-size tracker with its 2D joints in video pixels."""
        if not self.reduced or result.joints_2d is None:
            return result
        return dataclasses.replace(result, joints_2d=self.to_video(result.joints_2d))


__all__ = ["WorkSize"]
