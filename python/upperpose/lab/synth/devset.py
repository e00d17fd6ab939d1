"""The development set: twelve fixed clips that cover every motion, look and option.

`upperpose synth --devset OUTDIR` regenerates it, the same bytes every time (given the same
OpenCV build). Clip folders are named `NN-motion`. `upperpose synth --devset --holdout K OUTDIR`
writes held-out set K: the same twelve recipes with other seeds and looks (see `holdout_set`).
"""

from __future__ import annotations

import dataclasses

from upperpose.lab.synth.appearance import Appearance
from upperpose.lab.synth.scene import ClipConfig

DEVSET: list[tuple[str, ClipConfig]] = [
    (
        "01-wave_right",
        ClipConfig(
            "wave_right", 240, 101, appearance=Appearance("light", "red", "plain", "short", "brown", "denim", "average")
        ),
    ),
    (
        "02-wave_left",
        ClipConfig(
            "wave_left", 240, 102, appearance=Appearance("dark", "white", "stripes", "long", "black", "black", "broad")
        ),
    ),
    (
        "03-arms_overhead",
        ClipConfig(
            "arms_overhead",
            210,
            103,
            appearance=Appearance("medium", "green", "checks", "short", "blond", "khaki", "slim"),
        ),
    ),
    (
        "04-drink",
        ClipConfig(
            "drink", 240, 104, appearance=Appearance("tan", "blue", "noise", "long", "dark_brown", "denim", "average")
        ),
    ),
    (
        "05-cross_arms",
        ClipConfig(
            "cross_arms", 210, 105, appearance=Appearance("brown", "yellow", "plain", "short", "black", "grey", "tall")
        ),
    ),
    (
        "06-clap",
        ClipConfig(
            "clap", 180, 106, appearance=Appearance("light", "navy", "stripes", "long", "grey", "khaki", "small")
        ),
    ),
    (
        "07-point",
        ClipConfig(
            "point", 270, 107, appearance=Appearance("dark", "teal", "plain", "short", "black", "denim", "slim")
        ),
    ),
    (
        "08-hand_to_head",
        ClipConfig(
            "hand_to_head",
            270,
            108,
            appearance=Appearance("medium", "purple", "checks", "long", "brown", "black", "broad"),
        ),
    ),
    (
        "09-random_walk",
        ClipConfig(
            "random_walk",
            300,
            109,
            appearance=Appearance("tan", "grey", "noise", "short", "dark_brown", "denim", "average"),
        ),
    ),
    (
        "10-wave_right-walk_in",
        ClipConfig(
            "wave_right",
            240,
            110,
            empty_start=True,
            appearance=Appearance("brown", "red", "checks", "long", "black", "denim", "tall"),
        ),
    ),
    (
        "11-clap-walk_in-lighting",
        ClipConfig(
            "clap",
            210,
            111,
            empty_start=True,
            lighting_ramp=True,
            appearance=Appearance("light", "black", "plain", "short", "blond", "grey", "average"),
        ),
    ),
    (
        "12-random_walk-step_closer",
        ClipConfig(
            "random_walk",
            270,
            112,
            step_closer=True,
            appearance=Appearance("dark", "blue", "stripes", "long", "black", "khaki", "small"),
        ),
    ),
]


def holdout_set(k: int) -> list[tuple[str, ClipConfig]]:
    """Held-out set `k` (k >= 1): the development set's recipes on clips no tuning has seen.

    Each clip keeps its motion, length and options (walk-in, lighting ramp, step closer) and
    takes the seed `1000 k + its dev-set seed`, which draws a new room, depth, light, motion
    speeds and, since the looks are left unset, a new skin tone, shirt, sleeves, hair and build.
    """
    if not (isinstance(k, int) and k >= 1):
        raise ValueError(f"held-out set number must be a positive integer, got {k!r}")
    return [(name, dataclasses.replace(c, seed=1000 * k + c.seed, appearance=None)) for name, c in DEVSET]
