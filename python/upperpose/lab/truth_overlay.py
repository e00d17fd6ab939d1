"""The truth's joints and a pose file's drawn together on chosen frames, to look at a failure.

    python -m upperpose.lab.truth_overlay CLIP_DIR POSES.json --frames 78,84,90 [-o sheet.png]

CLIP_DIR holds `video.mp4` and `gt.json` (as the external validation set's clips do). Green: the
truth's joints and bones; red: the pose file's. Every tile is the same crop around both
skeletons over all the chosen frames (so that tiles line up), with the frame number and that
frame's mean absolute x / y error. Also prints each chosen frame's signed error per joint
(pose file minus truth, pixels).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.draw import BONES as STICK_FIGURE
from upperpose.exceptions import UpperposeError
from upperpose.io.files import write_image
from upperpose.io.overlay import contact_sheet
from upperpose.io.posefile import load_poses
from upperpose.io.video import VideoReader

FloatArray = npt.NDArray[np.float64]
Image = npt.NDArray[np.uint8]
# Joint pairs drawn as bones: the head to each shoulder, then the model's stick figure.
BONES = ((0, 1), (0, 2), *STICK_FIGURE)
SHORT_NAMES = ("h", "rs", "ls", "re", "le", "rh", "lh")
TRUTH_COLOUR, MINE_COLOUR = (0, 220, 0), (0, 0, 255)


def joints_by_frame(document: dict[str, object]) -> dict[int, FloatArray]:
    """Frame number -> `(7, 2)` joints of a loaded pose file's posed frames."""
    frames = document["frames"]
    assert isinstance(frames, list)
    return {f["frame"]: np.asarray(f["joints_2d"], dtype=np.float64)[:7] for f in frames if f.get("joints_2d")}


def draw_skeleton(image: Image, joints: FloatArray, colour: tuple[int, int, int]) -> None:
    """Draws the bones and joints in place (joints outside the image are clipped by OpenCV)."""
    points = [tuple(int(round(v)) for v in p) for p in joints]
    for a, b in BONES:
        cv2.line(image, points[a], points[b], colour, 1, cv2.LINE_AA)
    for p in points:
        cv2.circle(image, p, 3, colour, -1, cv2.LINE_AA)


def crop_box(skeletons: list[FloatArray], size: tuple[int, int], margin: float = 40.0) -> tuple[int, int, int, int]:
    """`(x0, y0, x1, y1)`: the box around all `skeletons` plus `margin` px, inside an image of `size` (h, w)."""
    points = np.vstack(skeletons)
    h, w = size
    x0, y0 = np.floor(points.min(axis=0) - margin).astype(int)
    x1, y1 = np.ceil(points.max(axis=0) + margin).astype(int)
    x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
    if x1 - x0 < 2 or y1 - y0 < 2:  # everything off the image: show it whole
        return 0, 0, w, h
    return int(x0), int(y0), int(x1), int(y1)


def main(argv: list[str] | None = None) -> int:
    """Writes the sheet and prints the errors; 1 when no chosen frame has both poses."""
    parser = argparse.ArgumentParser(prog="python -m upperpose.lab.truth_overlay", description=__doc__.split("\n")[0])
    parser.add_argument("clip", type=Path, help="clip folder with video.mp4 and gt.json")
    parser.add_argument("poses", type=Path, help="pose file of the same video")
    parser.add_argument("--frames", required=True, help="comma-separated frame numbers, e.g. 78,84,90")
    parser.add_argument("-o", "--output", type=Path, default=Path("truth_overlay.png"), help="image to write")
    args = parser.parse_args(argv)
    try:
        wanted = sorted({int(v) for v in args.frames.split(",") if v.strip()})
    except ValueError:
        parser.error(f"--frames must be comma-separated frame numbers, got {args.frames!r}")
    try:
        truth = joints_by_frame(load_poses(args.clip / "gt.json"))
        mine = joints_by_frame(load_poses(args.poses))
        shown = [k for k in wanted if k in truth and k in mine]
        if not shown:
            print("no chosen frame has a pose in both the truth and the pose file", file=sys.stderr)
            return 1
        images: dict[int, Image] = {}
        with VideoReader(args.clip / "video.mp4") as reader:
            for k, frame in enumerate(reader):
                if k in shown:
                    images[k] = frame
                if k >= shown[-1]:
                    break
    except (UpperposeError, OSError) as problem:
        print(f"error: {problem}", file=sys.stderr)
        return 1
    shown = [k for k in shown if k in images]
    if not shown:
        print("the video ends before the chosen frames", file=sys.stderr)
        return 1
    size = images[shown[0]].shape[:2]
    x0, y0, x1, y1 = crop_box([s[k] for k in shown for s in (truth, mine)], size)
    tiles = []
    print("frame  " + " ".join(f"{n:>9s}" for n in SHORT_NAMES) + "   mean |x| |y|")
    for k in shown:
        image = images[k].copy()
        draw_skeleton(image, truth[k], TRUTH_COLOUR)
        draw_skeleton(image, mine[k], MINE_COLOUR)
        offset = mine[k] - truth[k]
        x, y = np.abs(offset).mean(axis=0)
        tile = np.ascontiguousarray(image[y0:y1, x0:x1])
        cv2.putText(tile, f"{k}  {x:.0f}/{y:.0f} px", (4, 16), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1)
        tiles.append(tile)
        print(f"{k:5d}  " + " ".join(f"{dx:+4.0f},{dy:+4.0f}" for dx, dy in offset) + f"   {x:5.1f} {y:5.1f}")
    try:
        write_image(args.output, contact_sheet(tiles, columns=min(4, len(tiles)), width=min(x1 - x0, 480)))
    except (UpperposeError, OSError) as problem:
        print(f"error: {problem}", file=sys.stderr)
        return 1
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
