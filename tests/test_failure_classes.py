"""The tracker's known failure classes (issue 24), each on a short rendered clip.

Every case renders a 320x240, 15 fps clip with `upperpose.lab.synth` (person at 2 m, focal
320 px: 1 cm is 1.6 px), tracks it with the real tracker (default settings, seed 0, the clip's
plate and camera) and checks what the class means for a user against the clip's truth. The
tolerances are in metres at the person's depth:

- a hand is where it is when it lies within a palm's width, `HAND_TOL` (8 cm, 12.8 px), of it;
- a hand is somewhere else when it is more than a hand's length, `LOST_TOL` (15 cm, 24 px), off.

A class the tracker fails today is marked `xfail(strict=True)` with the measured numbers: the
day it is fixed the test fails until the marker goes. Rendering and tracking take about 6 s a
clip, once per test process.
"""

from __future__ import annotations

import functools
import tempfile
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt
import pytest

import upperpose
from tracker_helpers import camera_of, clip_frames, truth, write_video
from upperpose.lab.synth import ClipConfig, write_clip
from upperpose.lab.synth.appearance import Appearance

FloatArray = npt.NDArray[np.float64]
HEAD, R_SHOULDER, L_SHOULDER, R_ELBOW, L_ELBOW, R_HAND, L_HAND = range(7)
DEPTH = 2.0
PX_PER_M = 320 / DEPTH  # focal = image width (320 px), person at DEPTH
HAND_TOL = 0.08 * PX_PER_M
LOST_TOL = 0.15 * PX_PER_M

# Same person, room and speeds for every case (the clip seed); only the class's ingredient varies.
_BASE = {"frames": 60, "fps": 15.0, "width": 320, "height": 240, "depth": DEPTH, "seed": 3}
CASES = {
    "clap": ClipConfig(motion="clap", appearance=Appearance(), **_BASE),  # type: ignore[arg-type]
    "hand_to_head": ClipConfig(motion="hand_to_head", appearance=Appearance(), **_BASE),  # type: ignore[arg-type]
    "phone": ClipConfig(motion="phone", appearance=Appearance(), **(_BASE | {"frames": 90})),  # type: ignore[arg-type]
    "cross_arms": ClipConfig(motion="cross_arms", appearance=Appearance(), **_BASE),  # type: ignore[arg-type]
    "wave": ClipConfig(motion="wave_right", appearance=Appearance(), **_BASE),  # type: ignore[arg-type]
    "wave_long_sleeves": ClipConfig(motion="wave_right", appearance=Appearance(sleeves="long"), **_BASE),  # type: ignore[arg-type]
    # A noisy sensor, then every frame through JPEG at quality 15 (blocks, smeared colour).
    "wave_noisy_compressed": ClipConfig(motion="wave_right", appearance=Appearance(), noise=12.0, **_BASE),  # type: ignore[arg-type]
}
JPEG_QUALITY = {"wave_noisy_compressed": 15}


@functools.cache
def tracked(case: str) -> tuple[FloatArray, FloatArray, list[str]]:
    """Renders and tracks a case: true and tracked joints `(frames, 7, 2)` (NaN without a pose), statuses."""
    folder = Path(tempfile.mkdtemp(prefix=f"upperpose-class-{case}-")) / "clip"
    config = CASES[case]
    write_clip(config, folder)
    if case in JPEG_QUALITY:
        params = [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY[case]]
        frames = [cv2.imdecode(cv2.imencode(".jpg", f, params)[1], cv2.IMREAD_COLOR) for f in clip_frames(folder)]
        write_video(folder / "video.mp4", frames, config.fps)
    results = list(
        upperpose.track_video(
            folder / "video.mp4",
            folder / "background.png",
            camera=camera_of(folder),
            config=upperpose.TrackerConfig(seed=0),
        )
    )
    gt = truth(folder)["frames"]
    nan = np.full((7, 2), np.nan)
    true = np.array([nan if g["joints_2d"] is None else g["joints_2d"] for g in gt], dtype=np.float64)
    fit = np.array([nan if r.joints_2d is None else r.joints_2d for r in results], dtype=np.float64)
    return true, fit, [r.status for r in results]


def errors(true: FloatArray, fit: FloatArray) -> FloatArray:
    """Per frame and joint, pixels (NaN where either has no pose)."""
    return np.linalg.norm(fit - true, axis=-1)  # type: ignore[no-any-return]


def gap(joints: FloatArray) -> FloatArray:
    """Per frame, the distance between the two hands, pixels."""
    return np.linalg.norm(joints[:, R_HAND] - joints[:, L_HAND], axis=-1)  # type: ignore[no-any-return]


def tracked_throughout(statuses: list[str]) -> bool:
    """Started within a third of a second and "tracked" (no arm lost) on every frame since."""
    start = statuses.index("tracked")
    return start <= 5 and statuses[start:] == ["tracked"] * (len(statuses) - start)


@pytest.mark.parametrize("case", ["clap", "hand_to_head", "phone", "cross_arms", "wave", "wave_long_sleeves"])
def test_no_arm_is_lost(case: str) -> None:
    assert tracked_throughout(tracked(case)[2])


@pytest.mark.xfail(
    strict=True,
    reason="measured 2026-12-04: where the true hands are <= 20 cm apart (9 frames, 19-30 px), in 7 of them the "
    "tracked hands are 20-30 px (13-19 cm) farther apart than the truth's and the right hand is 23-27 px off: "
    "the fitted hands stop short of each other",
)
def test_clapping_hands_meet() -> None:
    true, fit, _ = tracked("clap")
    together = gap(true) <= 0.20 * PX_PER_M
    assert together.sum() >= 5  # the clip does clap
    # Hands that touch must be shown touching: apart by at most 5 cm more than the truth's.
    assert np.max(gap(fit)[together] - gap(true)[together]) <= 0.05 * PX_PER_M
    assert np.max(errors(true, fit)[together][:, [R_HAND, L_HAND]]) <= HAND_TOL


def test_a_hand_on_the_head_is_followed_and_not_lost_afterwards() -> None:
    true, fit, _ = tracked("hand_to_head")
    err = errors(true, fit)
    # The palm against the side of the head lies 16 cm from the head's centre.
    on_head = np.linalg.norm(true[:, R_HAND] - true[:, HEAD], axis=-1) <= 0.20 * PX_PER_M
    assert on_head.sum() >= 5
    # While on the head the hand merges with the face's skin: it must still be put there...
    assert np.max(err[on_head, R_HAND]) <= HAND_TOL
    # ...and the arm must not be lost once the hand has left the head (issue 24: it was, for good).
    after = np.arange(len(err)) > np.flatnonzero(on_head)[-1]
    assert after.sum() >= 3
    assert np.max(err[after][:, [R_ELBOW, R_HAND]]) <= HAND_TOL


def test_a_hand_held_to_the_ear_is_put_there_and_found_back_down() -> None:
    true, fit, _ = tracked("phone")
    err = errors(true, fit)
    # Judged where the hand holds still (raising and lowering it take a third of a second at
    # 15 fps): against the cheek, 9-14 cm from the head's centre, its skin merges with the face's.
    still = np.r_[False, np.linalg.norm(np.diff(true[:, R_HAND], axis=0), axis=-1) < 0.5]
    at_ear = still & (np.linalg.norm(true[:, R_HAND] - true[:, HEAD], axis=-1) <= 0.15 * PX_PER_M)
    assert at_ear.sum() >= 10
    assert np.max(err[at_ear, R_HAND]) <= HAND_TOL
    back_down = still & (np.arange(len(err)) > np.flatnonzero(at_ear)[-1])
    assert back_down.sum() >= 5
    assert np.max(err[back_down][:, [R_ELBOW, R_HAND]]) <= HAND_TOL


def test_long_sleeves_hands_as_good_as_bare_forearms() -> None:
    true, fit, _ = tracked("wave_long_sleeves")
    err = errors(true, fit)[:, [R_HAND, L_HAND]]
    bare = errors(*tracked("wave")[:2])[:, [R_HAND, L_HAND]]
    # Without forearm skin only the hand's blob and the silhouette hold the arm: no hand elsewhere,
    # and on average within 2 cm of the same motion in short sleeves.
    assert np.nanmax(err) <= LOST_TOL
    assert np.nanmean(err) <= np.nanmean(bare) + 0.02 * PX_PER_M


def test_crossed_forearms_keep_the_hands_on_their_crossed_sides() -> None:
    true, fit, _ = tracked("cross_arms")
    # Facing the camera the right hand is on the image's left; crossed, it is on the right.
    crossed = true[:, R_HAND, 0] > true[:, L_HAND, 0] + 0.05 * PX_PER_M
    assert crossed.sum() >= 5
    assert np.all(fit[crossed, R_HAND, 0] > fit[crossed, L_HAND, 0])
    assert np.max(errors(true, fit)[crossed][:, [R_HAND, L_HAND]]) <= HAND_TOL


def test_noisy_compressed_video_tracks_as_well_as_clean() -> None:
    clean = errors(*tracked("wave")[:2])
    true, fit, statuses = tracked("wave_noisy_compressed")
    noisy = errors(true, fit)
    assert tracked_throughout(statuses)
    # Noise a webcam shows in dim light must not cost a user more than 1 cm on average, 3 cm on any joint.
    assert np.nanmean(noisy) <= np.nanmean(clean) + 0.01 * PX_PER_M
    assert np.all(np.nanmean(noisy, axis=0) <= np.nanmean(clean, axis=0) + 0.03 * PX_PER_M)
