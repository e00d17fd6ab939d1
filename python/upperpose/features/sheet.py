"""A labelled contact sheet of every feature image of one frame, to see why tracking fails."""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.background import Background
from upperpose.features.checks import Frame
from upperpose.features.frame import FrameFeatures

TILE_WIDTH = 320
POINT_COLOURS = {
    "head": (0, 255, 255),
    "right_hand": (0, 0, 255),
    "left_hand": (0, 255, 0),
}


def label_tile(image: npt.NDArray[np.uint8], title: str, detail: str = "") -> npt.NDArray[np.uint8]:
    """`image` (grey or BGR) scaled to the tile width with a title bar on top."""
    if image.ndim == 2:
        image = cast(npt.NDArray[np.uint8], cv2.cvtColor(image, cv2.COLOR_GRAY2BGR))
    height = round(image.shape[0] * TILE_WIDTH / image.shape[1])
    tile = cv2.resize(image, (TILE_WIDTH, height), interpolation=cv2.INTER_AREA)
    bar = np.full((22, TILE_WIDTH, 3), 40, np.uint8)
    cv2.putText(
        bar,
        title,
        (5, 16),
        cv2.FONT_HERSHEY_SIMPLEX,
        0.5,
        (255, 255, 255),
        1,
        cv2.LINE_AA,
    )
    if detail:
        room = TILE_WIDTH - cv2.getTextSize(title, cv2.FONT_HERSHEY_SIMPLEX, 0.5, 1)[0][0] - 15
        size = cv2.getTextSize(detail, cv2.FONT_HERSHEY_SIMPLEX, 0.4, 1)[0][0]
        while size > room and len(detail) > 3:  # cut short rather than written over the title
            detail = detail[: max(len(detail) - 4, 0)].rstrip(" ,") + "..."
            size = cv2.getTextSize(detail, cv2.FONT_HERSHEY_SIMPLEX, 0.4, 1)[0][0]
        cv2.putText(
            bar,
            detail,
            (TILE_WIDTH - size - 5, 16),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.4,
            (180, 220, 255),
            1,
            cv2.LINE_AA,
        )
    out = np.vstack([bar, tile])
    cv2.rectangle(out, (0, 0), (out.shape[1] - 1, out.shape[0] - 1), (90, 90, 90), 1)
    return out


def blob_overlay(frame: Frame, features: FrameFeatures) -> npt.NDArray[np.uint8]:
    """The frame with skin blobs outlined (P_SB printed) and head/hand points marked."""
    out: npt.NDArray[np.uint8] = frame.copy()
    for i, blob in enumerate(features.blobs):
        x, y, w, h = blob.bbox
        cv2.rectangle(out, (x, y), (x + w - 1, y + h - 1), (255, 0, 255), 1)
        cv2.putText(
            out,
            f"{i}: P={blob.gradient:.2f}",
            (x, max(y - 4, 10)),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.45,
            (255, 0, 255),
            1,
            cv2.LINE_AA,
        )
    for name, point in zip(POINT_COLOURS, features.points):
        if point is None:
            continue
        centre = (round(point.xy[0]), round(point.xy[1]))
        colour = POINT_COLOURS[name]
        if point.merged:
            cv2.drawMarker(out, centre, colour, cv2.MARKER_TILTED_CROSS, 18, 2)
            cv2.putText(
                out,
                f"{name} merged",
                (centre[0] + 8, centre[1] + 14),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.45,
                colour,
                1,
                cv2.LINE_AA,
            )
        else:
            cv2.circle(out, centre, 6, colour, 2, cv2.LINE_AA)
    return out


def sil_overlay(frame: Frame, features: FrameFeatures) -> npt.NDArray[np.uint8]:
    """The frame with I_sil tinted and the arm silhouette, when known, in another tint."""
    out: npt.NDArray[np.uint8] = frame.copy()
    sil = features.sil > 0
    out[sil] = (0.5 * out[sil] + (0, 90, 0)).astype(np.uint8)
    if features.arm_sil is not None:
        arm = features.arm_sil > 0
        out[arm] = (0.5 * frame[arm] + (110, 0, 110)).astype(np.uint8)
    return out


def contact_sheet(
    frame: Frame,
    features: FrameFeatures,
    background: Background,
    title: str = "",
    room_skin: npt.NDArray[np.uint8] | None = None,
) -> npt.NDArray[np.uint8]:
    """Every feature image of one frame, labelled, four to a row.

    Args:
        frame: the `(H, W, 3)` BGR frame the features were computed from.
        features: its features.
        background: the background model used.
        title: a line written above the tiles (e.g. the video and frame number).
        room_skin: the room's pixels the extractor took for skin-coloured
            (`FeatureExtractor.room_skin`, in the person's learnt colour too); the background's
            own (generic rule) when None.

    Returns:
        A BGR image.
    """
    pixels = frame.shape[0] * frame.shape[1]

    def share(mask: npt.NDArray[np.uint8]) -> str:
        return f"{100.0 * cv2.countNonZero(mask) / pixels:.1f}%"

    how = "estimated: " + background.method if background.estimated else "clean plate"
    room = background.skin if room_skin is None else room_skin
    tiles = [
        label_tile(frame, "frame"),
        label_tile(background.plate, "background", how),
        label_tile(room, "background skin", share(room)),
    ]
    for name, image in features.images().items():
        tiles.append(label_tile(image, name, share(image)))
    tiles.append(label_tile(sil_overlay(frame, features), "I_sil over frame", "purple: arm sil"))
    points = sum(p is not None for p in features.points)
    tiles.append(
        label_tile(
            blob_overlay(frame, features),
            "skin blobs, points",
            f"{len(features.blobs)} blobs, {points} points",
        )
    )
    if features.motion_flags is not None:
        text = "  ".join(
            f"{k}:{'MOVE' if f.moving else 'still'} {f.count}/{f.perimeter}" for k, f in features.motion_flags.items()
        )
    else:
        text = "motion flags: no previous projection given"
    while len(tiles) % 4:
        tiles.append(np.zeros_like(tiles[0]))
    rows = [np.hstack(tiles[i : i + 4]) for i in range(0, len(tiles), 4)]
    header = np.full((48, rows[0].shape[1], 3), 20, np.uint8)
    cv2.putText(
        header,
        title,
        (8, 20),
        cv2.FONT_HERSHEY_SIMPLEX,
        0.55,
        (255, 255, 255),
        1,
        cv2.LINE_AA,
    )
    cv2.putText(
        header,
        text,
        (8, 40),
        cv2.FONT_HERSHEY_SIMPLEX,
        0.5,
        (180, 220, 255),
        1,
        cv2.LINE_AA,
    )
    return np.vstack([header, *rows])
