"""Scripted motions: smooth joint-angle trajectories inside the anatomical ranges of SPEC 2.

A motion is a loop of keyframes (angle settings held or passed through) joined by minimum-jerk
blends, so speeds and accelerations stay human. Arm keyframes were found by inverse kinematics
against hand targets in front of the torso (hand at the mouth, on the head, crossed in front of
the chest, ...) with the arms kept out of the trunk and out of each other (the tracker's
non-penetration rule; tests check every frame for every build); the left arm mirrors the right
by the angle convention, so one setting serves both sides. Every clip starts with the A-pose of
SPEC 6 held for about a second; a slow sway of the torso runs underneath everything.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import cast

import numpy as np
import numpy.typing as npt

from upperpose.model import ANGLE_NAMES, BodyModel, Pose, model_points, penetrates

FloatArray = npt.NDArray[np.float64]
Key = dict[str, float]  # arm settings: y_up, x_up, z_up, x_down (left arm mirrors right)
Keys = list[tuple[float, FloatArray]]  # (seconds to reach it, 13 angles) keyframes
Script = Callable[[np.random.Generator, BodyModel], Keys]

A_ARM: Key = {"y_up": 0.0, "x_up": 0.0, "z_up": 0.6, "x_down": 0.0}
REST_ARM: Key = {"y_up": 0.0, "x_up": 0.1, "z_up": 0.22, "x_down": 0.15}
ARMS: dict[str, Key] = {
    "wave_in": {"y_up": -1.43, "x_up": 0.26, "z_up": 1.36, "x_down": 1.95},
    "wave_out": {"y_up": -1.42, "x_up": 0.0, "z_up": 1.12, "x_down": 1.45},
    "overhead": {"y_up": 0.0, "x_up": 2.9, "z_up": 0.15, "x_down": 0.1},
    "cup_low": {"y_up": 0.3, "x_up": 0.5, "z_up": 0.3, "x_down": 1.5},
    "drink": {"y_up": 0.45, "x_up": 1.16, "z_up": 0.44, "x_down": 2.24},
    "head": {"y_up": -1.57, "x_up": 0.19, "z_up": 1.89, "x_down": 2.25},
    # Crossed forearms, "behind" nearer the chest and "front" over it, searched for near the
    # hand targets so that on every build they stay 2.4 times the allowed distance apart.
    "cross_behind": {"y_up": 1.12, "x_up": 0.95, "z_up": 0.96, "x_down": 1.91},
    "cross_front": {"y_up": 1.01, "x_up": 0.83, "z_up": 0.91, "x_down": 1.54},
    "clap_in": {"y_up": 0.47, "x_up": 0.47, "z_up": 0.32, "x_down": 1.61},
    "clap_out": {"y_up": 0.01, "x_up": 0.08, "z_up": 0.17, "x_down": 1.94},
    "point": {"y_up": 0.0, "x_up": 1.5, "z_up": 0.12, "x_down": 0.05},
    # Elbow forwards and down, the palm against the cheek beside the jaw (the default body's
    # hand 8 cm out from the face's centre and 6 cm below it).
    "phone": {"y_up": 0.0, "x_up": 1.66, "z_up": 0.51, "x_down": 2.49},
}
# Safe sub-ranges for the random walk (radians): arms stay clear of the trunk.
WALK_RANGES = {"y_up": (-0.8, 0.8), "x_up": (-0.3, 1.6), "z_up": (0.25, 1.8), "x_down": (0.0, 1.8)}
A_POSE_SECONDS = 1.0
WALK_STEPS = 12  # random-walk keyframes per loop
WALK_TRIES = 100  # random-walk targets drawn at most per step before holding still
ARMS_CHECK_ROOT = np.array([0.0, 0.0, 2.2])  # any root: the arm checks are torso-relative


def min_jerk(s: FloatArray) -> FloatArray:
    """The minimum-jerk blend 10s^3 - 15s^4 + 6s^5 of `s` in [0, 1]."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10 - 15 * s + 6 * s * s)


def _pose(right: Key, left: Key, torso: Key | None = None) -> FloatArray:
    named = {f"right_{k}": v for k, v in right.items()} | {f"left_{k}": v for k, v in left.items()}
    named |= {f"torso_{k}": v for k, v in (torso or {}).items()}
    return cast(FloatArray, Pose(**named).angles.copy())


def keyframe_track(keys: Keys, times: FloatArray) -> FloatArray:
    """Blends `(duration, pose)` keyframes: each pose is reached after its duration.

    The sequence loops until `times` (seconds, from the first keyframe) run out.

    Returns:
        `(len(times), 13)` angles.
    """
    period = sum(d for d, _ in keys[1:])
    out = np.empty((len(times), 13))
    for i, t in enumerate(times):
        t = t % period if period > 0 else 0.0
        prev = keys[0][1]
        for duration, pose in keys[1:]:
            if t <= duration:
                out[i] = prev + (pose - prev) * min_jerk(np.array(t / max(duration, 1e-9)))
                break
            t -= duration
            prev = pose
        else:
            out[i] = keys[-1][1]
    return out


def keeps_apart(start: FloatArray, end: FloatArray, body: BodyModel, samples: int = 40) -> bool:
    """Whether the blend from pose `start` to `end` keeps the arms out of the trunk and of each other.

    The test is the tracker's non-penetration rule (SPEC 5), so a truth the search may not
    reach never enters the data. It is relative to the torso: root and torso sway do not
    change it.
    """
    return not any(penetrates(start + (end - start) * s, ARMS_CHECK_ROOT, body) for s in np.linspace(0.0, 1.0, samples))


def _cycle(a: FloatArray, steps: Keys) -> Keys:
    """A loop that starts and ends at the A-pose `a`."""
    return [(0.0, a), *steps, (0.8, a)]


def _wave(side: str) -> Script:
    def keys(rng: np.random.Generator, body: BodyModel) -> Keys:
        a = _pose(A_ARM, A_ARM)
        half = 1.0 / (2.0 * rng.uniform(1.2, 1.8))  # 1.2-1.8 Hz
        other = REST_ARM

        def at(name: str) -> FloatArray:
            return _pose(ARMS[name], other) if side == "right" else _pose(other, ARMS[name])

        swings = [(half, at("wave_in" if k % 2 else "wave_out")) for k in range(8)]
        return _cycle(a, [(0.9, at("wave_out")), *swings, (0.3, at("wave_out")), (0.5, _pose(REST_ARM, REST_ARM))])

    return keys


def _both(name: str, hold: float, rise: float = 1.0) -> Script:
    def keys(rng: np.random.Generator, body: BodyModel) -> Keys:
        a = _pose(A_ARM, A_ARM)
        p = _pose(ARMS[name], ARMS[name])
        return _cycle(a, [(rise * rng.uniform(0.9, 1.2), p), (hold, p)])

    return keys


def _drink(rng: np.random.Generator, body: BodyModel) -> Keys:
    a = _pose(A_ARM, A_ARM)
    low, up = _pose(ARMS["cup_low"], REST_ARM), _pose(ARMS["drink"], REST_ARM)
    return _cycle(a, [(0.8, low), (0.5, low), (0.9, up), (rng.uniform(0.8, 1.4), up), (0.8, low), (0.5, low)])


def _hand_to_head(rng: np.random.Generator, body: BodyModel) -> Keys:
    a = _pose(A_ARM, A_ARM)
    right, left = _pose(ARMS["head"], REST_ARM), _pose(REST_ARM, ARMS["head"])
    hold = rng.uniform(0.6, 1.0)
    return _cycle(a, [(1.1, right), (hold, right), (1.0, a), (1.1, left), (hold, left)])


def _phone(rng: np.random.Generator, body: BodyModel) -> Keys:
    a = _pose(A_ARM, A_ARM)
    call = _pose(ARMS["phone"], REST_ARM)
    return _cycle(a, [(1.1, call), (rng.uniform(1.2, 1.6), call), (1.0, a)])


def _cross(rng: np.random.Generator, body: BodyModel) -> Keys:
    # The right forearm goes in first and leaves last, so the left one passes in front of it
    # both ways; moving together, the forearms would pass through each other.
    a = _pose(A_ARM, A_ARM)
    behind = _pose(ARMS["cross_behind"], A_ARM)
    crossed = _pose(ARMS["cross_behind"], ARMS["cross_front"])
    return _cycle(a, [(rng.uniform(0.7, 0.9), behind), (0.8, crossed), (rng.uniform(1.0, 1.6), crossed), (0.6, behind)])


def _hand_gap(arm: Key, body: BodyModel) -> float:
    """Distance between the hands, metres, with both arms at the mirrored setting `arm`."""
    joints = model_points(_pose(arm, arm), ARMS_CHECK_ROOT, body)
    return float(np.linalg.norm(joints[5] - joints[6]))  # right and left hand


def _clap_in(body: BodyModel) -> Key:
    """The clap's inner setting with the horizontal swing that brings this body's hands together.

    Shoulder width and arm length differ between builds, so fixed angles would leave one
    body's hands apart and pass another's through each other. The hand joints end 1.5 mean
    forearm radii apart: palms meeting, as fixed angles gave the average build.
    """
    target = 0.75 * sum(body.lower_arm_radii)
    # Swing inwards until the hands first come that close (further on they pass each other).
    swings = np.arange(0.0, 1.2, 0.005)
    gaps = np.array([_hand_gap(ARMS["clap_in"] | {"y_up": float(y)}, body) for y in swings])
    closing = gaps <= target
    return ARMS["clap_in"] | {"y_up": float(swings[np.argmax(closing) if closing.any() else np.argmin(gaps)])}


def _clap(rng: np.random.Generator, body: BodyModel) -> Keys:
    a = _pose(A_ARM, A_ARM)
    clap_in = _clap_in(body)
    out, inn = _pose(ARMS["clap_out"], ARMS["clap_out"]), _pose(clap_in, clap_in)
    half = 1.0 / (2.0 * rng.uniform(1.6, 2.2))
    claps = [(half, inn if k % 2 == 0 else out) for k in range(10)]
    return _cycle(a, [(0.8, out), *claps])


def _point(rng: np.random.Generator, body: BodyModel) -> Keys:
    a = _pose(A_ARM, A_ARM)
    right, left = _pose(ARMS["point"], REST_ARM), _pose(REST_ARM, ARMS["point"])
    return _cycle(
        a, [(1.0, right), (rng.uniform(0.8, 1.2), right), (0.9, a), (1.0, left), (rng.uniform(0.8, 1.2), left)]
    )


def _random_walk(rng: np.random.Generator, body: BodyModel) -> Keys:
    a = _pose(A_ARM, A_ARM)
    steps: Keys = []
    prev = a
    for step in range(WALK_STEPS):
        for _ in range(WALK_TRIES):
            arms = [{k: float(rng.uniform(*r)) for k, r in WALK_RANGES.items()} for _ in range(2)]
            torso = {
                "y": float(rng.uniform(-0.3, 0.3)),
                "x": float(rng.uniform(-0.08, 0.15)),
                "z": float(rng.uniform(-0.1, 0.1)),
            }
            target = _pose(arms[0], arms[1], torso)
            # The last target must also clear the way back to the A-pose.
            if keeps_apart(prev, target, body) and (step < WALK_STEPS - 1 or keeps_apart(target, a, body)):
                break
        else:
            target = prev  # no clear way found: hold still (1 draw in 260 is redrawn, none held)
        steps.append((float(rng.uniform(0.8, 1.4)), target))
        prev = target
    return _cycle(a, steps)


MOTIONS: dict[str, Script] = {
    "wave_right": _wave("right"),
    "wave_left": _wave("left"),
    "arms_overhead": _both("overhead", 0.6, 1.1),
    "drink": _drink,
    "cross_arms": _cross,
    "clap": _clap,
    "point": _point,
    "hand_to_head": _hand_to_head,
    "phone": _phone,
    "random_walk": _random_walk,
}
MOTION_DESCRIPTIONS = {
    "wave_right": "waves with the right hand",
    "wave_left": "waves with the left hand",
    "arms_overhead": "raises both arms overhead and lowers them",
    "drink": "lifts a (mimed) cup to the mouth with the right hand",
    "cross_arms": "crosses the arms in front of the chest",
    "clap": "claps in front of the chest",
    "point": "points at the camera with one hand, then the other",
    "hand_to_head": "puts one hand on the head, then the other",
    "phone": "holds a (mimed) phone to the right ear",
    "random_walk": "moves slowly and randomly through the joint space",
}


def sway(times: FloatArray, rng: np.random.Generator) -> FloatArray:
    """Small, slow torso sway `(N, 13)` to add to any motion (only torso angles non-zero)."""
    out = np.zeros((len(times), 13))
    for name, amp in (("torso_y", 0.05), ("torso_x", 0.025), ("torso_z", 0.03)):
        freq, phase = rng.uniform(0.1, 0.3), rng.uniform(0, 2 * np.pi)
        out[:, ANGLE_NAMES.index(name)] = amp * np.sin(2 * np.pi * freq * times + phase)
    return out


def motion_angles(
    name: str,
    frames: int,
    fps: float,
    rng: np.random.Generator,
    body: BodyModel | None = None,
    a_pose_seconds: float = A_POSE_SECONDS,
) -> FloatArray:
    """The joint angles of a scripted motion, one row per frame.

    The first `a_pose_seconds` hold the A-pose; the motion loops after that.

    Args:
        name: a key of `MOTIONS`.
        frames: number of frames.
        fps: frames per second.
        rng: the clip's random generator (speeds, hold times, random-walk targets, sway).
        body: the body that moves (clap contact, arm clearance); adult averages when None.
        a_pose_seconds: start-up time in the A-pose.

    Returns:
        `(frames, 13)` angles in radians, `ANGLE_NAMES` order, inside the anatomical ranges,
        the arms never penetrating the trunk or each other.

    Raises:
        ValueError: unknown motion name.
    """
    if name not in MOTIONS:
        raise ValueError(f"unknown motion {name!r}; motions are {', '.join(MOTIONS)}")
    keys = MOTIONS[name](rng, body or BodyModel())
    times = np.arange(frames) / fps
    angles = keyframe_track(keys, np.maximum(times - a_pose_seconds, 0.0))
    return angles + sway(times, rng)
