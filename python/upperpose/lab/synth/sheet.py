"""Contact sheets: a few frames of each clip folder, labelled, in one image."""

from __future__ import annotations

import os
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import VideoError


def clip_frames(video: str | os.PathLike[str], picks: tuple[float, ...]) -> list[npt.NDArray[np.uint8]]:
    """Frames at the given fractions of a video's length (decoded, as a viewer sees them).

    Raises:
        VideoError: the video cannot be read.
    """
    cap = cv2.VideoCapture(str(video))
    frames = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(cast(npt.NDArray[np.uint8], frame))
    cap.release()
    if not frames:
        raise VideoError(f"cannot read any frame from {video}")
    return [frames[min(int(p * len(frames)), len(frames) - 1)] for p in picks]


def contact_sheet(
    folders: list[Path], picks: tuple[float, ...] = (0.12, 0.5, 0.85), scale: float = 1 / 3, per_row: int = 6
) -> npt.NDArray[np.uint8]:
    """Tiles `picks` frames of each clip folder's video.mp4, labelled with the folder name."""
    tiles = []
    for folder in folders:
        for k, frame in enumerate(clip_frames(folder / "video.mp4", picks)):
            tile = cv2.resize(frame, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
            if k == 0:
                cv2.putText(tile, folder.name, (4, 14), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 3, cv2.LINE_AA)
                cv2.putText(tile, folder.name, (4, 14), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 255, 255), 1, cv2.LINE_AA)
            tiles.append(tile)
    blank = np.zeros_like(tiles[0])
    tiles += [blank] * (-len(tiles) % per_row)
    return np.vstack([np.hstack(tiles[i : i + per_row]) for i in range(0, len(tiles), per_row)])
