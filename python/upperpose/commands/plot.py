"""`upperpose plot`: each joint's x, y and depth against time (the thesis' Fig. 4.2-15)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

NAME = "plot"
HELP = "plot each joint's x, y (pixels) and depth (metres) against time, with the truth when given"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand."""
    p.add_argument("poses", help="pose file (SPEC 9) to plot")
    p.add_argument("--truth", metavar="GT.json", help="ground truth to draw beside it")
    p.add_argument("-o", "--output", required=True, metavar="FIG.png", help="image to write (.png, .pdf, .svg)")


def run(args: argparse.Namespace) -> int:
    """Reads the files and writes the figure."""
    from upperpose.commands.track import check_writable
    from upperpose.io.posefile import load_poses

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise OSError("upperpose plot needs matplotlib: pip install 'upperpose[plot]'") from None
    check_writable(args.output)
    poses = load_poses(args.poses)
    truth = load_poses(args.truth) if args.truth else None
    figure = draw(plt, poses, truth)
    write_figure(figure, Path(args.output))
    plt.close(figure)
    print(f"wrote {args.output}")
    return 0


def series(doc: dict[str, Any], key: str, axis: int) -> tuple[list[float], list[list[float]]]:
    """Time in seconds and, per joint, the coordinate `axis` of `key` (NaN where unposed)."""
    frames = doc["frames"]
    times = [f["frame"] / float(doc["fps"]) for f in frames]
    per_joint: list[list[float]] = [[] for _ in range(7)]
    for f in frames:
        points = f.get(key)
        for j in range(7):
            per_joint[j].append(float("nan") if points is None else float(points[j][axis]))
    return times, per_joint


def draw(plt: Any, poses: dict[str, Any], truth: dict[str, Any] | None) -> Any:
    """One row per joint, columns x, y (pixels) and depth (metres)."""
    from upperpose.model import JOINT_NAMES

    columns = [("joints_2d", 0, "x (px)"), ("joints_2d", 1, "y (px)"), ("joints_3d", 2, "depth (m)")]
    figure, axes = plt.subplots(len(JOINT_NAMES), 3, figsize=(13, 2.0 * len(JOINT_NAMES)), sharex=True)
    for c, (key, axis, label) in enumerate(columns):
        t, predicted = series(poses, key, axis)
        if truth is not None:
            tt, true = series(truth, key, axis)
        for j, name in enumerate(JOINT_NAMES):
            ax = axes[j][c]
            if truth is not None:
                ax.plot(tt, true[j], color="0.55", lw=1.6, label="truth")
            ax.plot(t, predicted[j], color="C3", lw=1.0, label="upperpose")
            if key == "joints_2d" and axis == 1:
                ax.invert_yaxis()  # image rows grow downwards
            ax.set_ylabel(f"{name.replace('_', ' ')}\n{label}" if c == 0 else label, fontsize=8)
            ax.tick_params(labelsize=7)
    for c in range(3):
        axes[-1][c].set_xlabel("time (s)", fontsize=8)
    axes[0][0].legend(fontsize=7, loc="upper right")
    figure.tight_layout()
    return figure


def write_figure(figure: Any, path: Path) -> None:
    """Saves the figure atomically, in the format its suffix names."""
    from upperpose.io.files import write_atomic

    if path.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise ValueError(f"{path}: the figure must be .png, .pdf or .svg")
    write_atomic(path, lambda tmp: figure.savefig(tmp, dpi=110))
