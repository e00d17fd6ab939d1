"""The overlay: the fitted model drawn over each frame with status and cost (thesis Ch. 4 figures)."""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.draw import draw_model
from upperpose.exceptions import InputError, VideoError
from upperpose.model import BodyModel, Camera
from upperpose.result import TrackResult

STATUS_COLOURS = {
    "no_person": (160, 160, 160),
    "initialising": (0, 200, 255),
    "tracked": (80, 220, 80),
    "lost": (60, 60, 255),
}


def draw_overlay(
    frame: npt.NDArray[np.uint8], result: TrackResult, camera: Camera, body: BodyModel
) -> npt.NDArray[np.uint8]:
    """The frame with the fitted cones, contours and joints, and a status line.

    Args:
        frame: `(H, W, 3)` uint8 BGR.
        result: the tracker's result for this frame.
        camera: the camera.
        body: the body model used for the fit.
    """
    if result.pose is not None and result.root is not None:
        out = draw_model(frame, result.pose, result.root, camera, body)
    else:
        out = frame.copy()
    text = f"#{result.frame}  {result.status}"
    if result.cost is not None and result.pose is not None:
        text += f"  cost {result.cost:.3f}"
    if result.root is not None and result.pose is not None:
        text += f"  depth {result.root[2]:.2f} m"
    if result.lost_parts:
        text += "  lost: " + ", ".join(result.lost_parts)
    colour = STATUS_COLOURS.get(result.status, (255, 255, 255))
    cv2.rectangle(out, (0, 0), (out.shape[1], 24), (0, 0, 0), -1)
    cv2.putText(out, text, (6, 17), cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv2.LINE_AA)
    return out


class OverlayWriter:
    """Writes overlay frames to a temporary mp4v video, renamed onto `path` by `close()`.

    A reader never sees half a video; after Ctrl-C `close()` still finishes the frames so far.

    Raises:
        OSError: the folder does not exist.
        VideoError: no mp4v encoder.
    """

    def __init__(self, path: str | os.PathLike[str], width: int, height: int, fps: float) -> None:
        self.path = Path(path)
        folder = self.path.parent if str(self.path.parent) else Path(".")
        if not folder.is_dir():
            raise OSError(f"cannot write {self.path}: folder {folder} does not exist")
        self._tmp = folder / f".{self.path.name}.partial{self.path.suffix or '.mp4'}"
        self._writer = cv2.VideoWriter(str(self._tmp), cv2.VideoWriter_fourcc(*"mp4v"), fps, (width, height))  # type: ignore[attr-defined]
        if not self._writer.isOpened():
            self._tmp.unlink(missing_ok=True)
            raise VideoError(f"cannot open an mp4v video writer for {self.path}")
        self.frames = 0

    def write(self, image: npt.NDArray[np.uint8]) -> None:
        """Appends one frame."""
        self._writer.write(image)
        self.frames += 1

    def close(self, keep: bool = True) -> Path | None:
        """Finishes the video and renames it onto `path` (or deletes it when `keep` is False)."""
        self._writer.release()
        if keep and self.frames:
            os.replace(self._tmp, self.path)
            return self.path
        self._tmp.unlink(missing_ok=True)
        return None


def contact_sheet(images: list[npt.NDArray[np.uint8]], columns: int = 4, width: int = 320) -> npt.NDArray[np.uint8]:
    """Tiles images (scaled to `width` pixels wide) into one sheet, row by row."""
    if not images:
        raise InputError("a contact sheet needs at least one image")
    tiles = []
    for image in images:
        h, w = image.shape[:2]
        tiles.append(cv2.resize(image, (width, max(1, round(h * width / w))), interpolation=cv2.INTER_AREA))
    blank = np.zeros_like(tiles[0])
    while len(tiles) % columns:
        tiles.append(blank)
    rows = [np.hstack(tiles[i : i + columns]) for i in range(0, len(tiles), columns)]
    return np.vstack(rows)


__all__ = ["OverlayWriter", "contact_sheet", "draw_overlay"]
