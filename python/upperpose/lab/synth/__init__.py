"""Synthetic clips with exactly known poses, for testing and tuning the tracker.

A person built from smooth solids (not the tracker's cones), dressed, with a photographed
face, moves through scripted motions in a procedurally drawn room; a camera model adds blur,
noise and video compression. Each clip is written as a clip folder (see `dataset`).
"""

from upperpose.lab.synth.appearance import Appearance, body_for_build
from upperpose.lab.synth.dataset import load_masks, load_meta, write_clip
from upperpose.lab.synth.devset import DEVSET
from upperpose.lab.synth.motions import MOTIONS, motion_angles
from upperpose.lab.synth.scene import ClipConfig, ClipPlan, plan_clip, render_frame, render_frames

__all__ = [
    "DEVSET",
    "MOTIONS",
    "Appearance",
    "ClipConfig",
    "ClipPlan",
    "body_for_build",
    "load_masks",
    "load_meta",
    "motion_angles",
    "plan_clip",
    "render_frame",
    "render_frames",
    "write_clip",
]
