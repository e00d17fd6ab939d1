"""`upperpose render`: draw the body model at a pose, to see the angle conventions."""

from __future__ import annotations

import argparse

import cv2
import numpy as np

from upperpose.commands.limits import OptionError, check_focal, check_number, check_size
from upperpose.draw import draw_model
from upperpose.io.files import write_image
from upperpose.model import ANGLE_NAMES, Camera, Pose

NAME = "render"
HELP = "draw the body model at a pose over a plain background and write it as an image"

# Poses shown by --sheet: each illustrates one angle convention of docs/body-model.md.
EXAMPLE_POSES = {
    "rest": Pose(),
    "A-pose (start-up)": Pose.a_pose(),
    "right_z_up=1.6 (abduction)": Pose(right_z_up=1.6, left_z_up=0.3),
    "right_x_up=1.5 (flexion, at camera)": Pose(right_x_up=1.5, left_z_up=0.3),
    "x_up=3.0 (arms overhead)": Pose(right_x_up=3.0, left_x_up=3.0),
    "right_x_down=1.6 (elbow bent)": Pose(right_z_up=0.4, right_x_down=1.6),
    "wave": Pose(right_z_up=1.3, right_x_down=1.4, right_y_up=-1.2, left_z_up=0.3),
    "torso_y=0.6 (turn)": Pose(torso_y=0.6, right_z_up=0.5, left_z_up=0.5),
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument("-o", "--output", default="model.png", help="image to write (default: model.png)")
    p.add_argument(
        "--angle",
        action="append",
        default=[],
        metavar="NAME=RAD",
        help=f"set one angle in radians (repeatable); names: {', '.join(ANGLE_NAMES)}",
    )
    p.add_argument("--sheet", action="store_true", help="draw a labelled sheet of example poses instead")
    p.add_argument("--width", type=int, default=640)
    p.add_argument("--height", type=int, default=480)
    p.add_argument("--depth", type=float, default=2.2, help="distance of the body from the camera, metres")
    p.add_argument("--focal", type=float, default=None, help="focal length in pixels (default: image width)")


def parse_angles(items: list[str]) -> Pose:
    """Parses NAME=RAD settings into a pose."""
    named: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep:
            raise OptionError(f"--angle takes NAME=RAD, got {item!r}")
        try:
            named[name.strip()] = float(value)
        except ValueError:
            raise OptionError(f"--angle {name}: {value!r} is not a number") from None
    return Pose(**named)


def render_pose(pose: Pose, width: int, height: int, depth: float, focal: float | None) -> np.ndarray:
    """The model at `pose`, `depth` metres in front of the default camera, on a grey background."""
    check_size(width, height)
    check_number("--depth", depth, 0.3, 100.0, "metres")
    check_focal(focal)
    camera = Camera.for_image(width, height, focal)
    background = np.full((height, width, 3), 70, np.uint8)
    return draw_model(background, pose, [0.0, 0.15, depth], camera)


def run(args: argparse.Namespace) -> int:
    """Renders and writes the image."""
    if args.sheet:
        tiles = []
        for label, pose in EXAMPLE_POSES.items():
            tile = render_pose(pose, args.width, args.height, args.depth, args.focal)
            cv2.putText(tile, label, (8, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1, cv2.LINE_AA)
            tiles.append(tile)
        rows = [np.hstack(tiles[i : i + 4]) for i in range(0, len(tiles), 4)]
        image = np.vstack(rows)
    else:
        image = render_pose(parse_angles(args.angle), args.width, args.height, args.depth, args.focal)
    path = write_image(args.output, image)
    print(f"wrote {path}")
    return 0
