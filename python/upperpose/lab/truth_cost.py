"""Does the cost prefer the truth where the tracker loses an arm?

A tracked arm far from the truth is either a search that missed a cheaper pose or a cost that
prefers the wrong one; the cure differs. `TruthCostProbe` is a fitter (`Tracker(fitter=...)`)
that runs `fit_frame` and, on each frame's trajectory fit whose hand lies more than
`threshold_px` from the truth's, fits that arm's angles to the truth's elbow and hand in the
image (`arm_angles_for`, on the tracker's own body, torso and root) and scores both poses with
the same features and regions (`fit_frame(..., mode="initial", search=())`).

    python -m upperpose.lab.truth_cost CLIP_DIR [--seed S] [--no-plate]

CLIP_DIR holds `video.mp4`, `gt.json` (a pose file of the truth), optionally `background.png`
and `meta.json` (`{"camera": {"focal": ...}}`), as the external validation set does. It prints
how often the truth costs less, and the mean per-term difference (truth minus fit) of the
arm's stage, unweighted, which names the term that pushes the fit away from the truth (Edge and
Motion enter the cost with a minus sign: there a negative difference counts against the truth;
docs/cost.md).
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from upperpose._upperpose import joint_limits
from upperpose.fit.pipeline import track_video
from upperpose.fit.search import fit_frame
from upperpose.fit.tracker import TrackerConfig
from upperpose.io.posefile import load_poses
from upperpose.model import BodyModel, Camera, forward_kinematics, project

FloatArray = npt.NDArray[np.float64]
# Per arm: its angles y_up, x_up, z_up, x_down in the pose, and its elbow and hand joints.
ARMS = {"right_arm": (slice(3, 7), 3, 5), "left_arm": (slice(8, 12), 4, 6)}
# The right arm's anatomical ranges of y_up, x_up, z_up, x_down (the left arm mirrors them).
_RANGES = joint_limits("anatomical")[3:7]
_LOW = np.array([min(low for low, _ in r) for r in _RANGES])
_HIGH = np.array([max(high for _, high in r) for r in _RANGES])
_GRID = np.array(
    list(
        itertools.product(
            np.linspace(-1.2, 1.2, 5), np.linspace(-0.6, 3.0, 10), np.linspace(-0.2, 3.0, 9), np.linspace(0.0, 2.5, 6)
        )
    )
)


def arm_angles_for(
    pose: npt.ArrayLike,
    root: npt.ArrayLike,
    body: BodyModel,
    camera: Camera,
    arm: str,
    joints_2d: npt.ArrayLike,
    steps: int = 600,
    starts: int = 5,
    seed: int = 0,
) -> tuple[FloatArray, float]:
    """The arm's angles that put its elbow and hand (anatomical joints) on `joints_2d`'s.

    A grid over the anatomical ranges, then a shrinking random local search from each of the
    `starts` best grid poses. Returns the
    angles (y_up, x_up, z_up, x_down) and the summed pixel distance of elbow and hand left.
    """
    sl, elbow, hand = ARMS[arm]
    base = np.array(pose, dtype=np.float64)
    origin = np.asarray(root, dtype=np.float64)
    target = np.asarray(joints_2d, dtype=np.float64)[[elbow, hand]]

    def residual(angles: FloatArray) -> float:
        base[sl] = angles
        joints = project(camera, forward_kinematics(base, origin, body))[[elbow, hand]]
        gap = float(np.hypot(*(joints - target).T).sum())
        return gap if np.isfinite(gap) else np.inf

    scores = np.array([residual(a) for a in _GRID])
    rng = np.random.default_rng(seed)
    best, best_gap = _GRID[int(np.argmin(scores))].copy(), float(scores.min())
    # Several starts: elbow and hand pin the arm's four angles only up to a few branches.
    for start in np.argsort(scores, kind="stable")[:starts]:
        here, gap_here = _GRID[start].copy(), float(scores[start])
        step = 0.2
        for k in range(steps):
            trial = np.clip(here + rng.normal(0.0, step, 4), _LOW, _HIGH)
            gap = residual(trial)
            if gap < gap_here:
                here, gap_here = trial, gap
            if k % 100 == 99:
                step /= 2.0
        if gap_here < best_gap:
            best, best_gap = here, gap_here
    return best, best_gap


@dataclass
class Probe:
    """One arm on one frame: how far off the fit was and what each pose costs."""

    frame: int
    arm: str
    hand_off_px: float
    fit_cost: float
    truth_cost: float
    term_difference: dict[str, float]


@dataclass
class TruthCostProbe:
    """A fitter that also scores the truth's arm poses where the fit's hand is far off.

    Args:
        truth: frame -> `(7, 2)` true joints in pixels.
        threshold_px: a fitted hand farther than this from the truth's is probed.
        max_residual_px: probes whose truth pose the model cannot reach closer than this
            (elbow plus hand, pixels) are dropped (another body cannot always match).
        search: the search that makes the fit being probed (`fit_frame`; tests pass a double).
    """

    truth: dict[int, FloatArray]
    threshold_px: float = 40.0
    max_residual_px: float = 10.0
    search: Callable[..., Any] = fit_frame
    probes: dict[tuple[int, str], Probe] = field(default_factory=dict)

    def __call__(self, features: Any, prediction: Any, root: Any, body: BodyModel, camera: Camera, **kw: Any) -> Any:
        """Fits as `fit_frame` does, and probes the fit's far-off arms on the way."""
        fit = self.search(features, prediction, root, body, camera, **kw)
        frame = int(kw.get("frame_index", -1))
        if kw.get("mode", "trajectory") != "trajectory" or frame not in self.truth:
            return fit
        pose, origin = np.asarray(fit.pose), np.asarray(fit.root)
        joints = np.asarray(fit.joints_2d)
        truth = self.truth[frame]
        same = dict(kw, mode="initial", search=())
        mine = None
        for arm, (sl, _, hand) in ARMS.items():
            off = float(np.hypot(*(joints[hand] - truth[hand])))
            if not off > self.threshold_px:
                continue
            angles, left = arm_angles_for(pose, origin, body, camera, arm, truth, seed=frame)
            if left > self.max_residual_px:
                continue
            true_pose = pose.copy()
            true_pose[sl] = angles
            if mine is None:  # the fit's own score, once per frame
                mine = fit_frame(features, pose, origin, body, camera, **same)
            theirs = fit_frame(features, true_pose, origin, body, camera, **same)
            difference = {t: theirs.terms[arm][t] - mine.terms[arm][t] for t in mine.terms[arm]}
            self.probes[(frame, arm)] = Probe(frame, arm, off, float(mine.cost), float(theirs.cost), difference)
        return fit


def clip_inputs(clip: Path, plate: bool = True) -> tuple[dict[int, FloatArray], float | None, Path | None]:
    """A clip folder's true 2D joints per frame, focal length (meta.json, if any) and clean plate (if kept)."""
    frames = load_poses(clip / "gt.json")["frames"]
    truth = {f["frame"]: np.asarray(f["joints_2d"], dtype=np.float64) for f in frames if f.get("joints_2d")}
    meta_path = clip / "meta.json"
    focal = json.loads(meta_path.read_text())["camera"]["focal"] if meta_path.is_file() else None
    background = clip / "background.png" if plate and (clip / "background.png").is_file() else None
    return truth, focal, background


def probe_clip(clip: Path, seed: int = 0, plate: bool = True, probe: TruthCostProbe | None = None) -> list[Probe]:
    """Tracks a clip with a `TruthCostProbe` (one on the clip's gt.json when None); its probes in frame order."""
    truth, focal, background = clip_inputs(clip, plate)
    probe = probe or TruthCostProbe(truth)
    for _ in track_video(clip / "video.mp4", background, focal=focal, config=TrackerConfig(seed=seed), fitter=probe):
        pass
    return [probe.probes[k] for k in sorted(probe.probes)]


def main(argv: list[str] | None = None) -> int:
    """Prints, per clip, how often the truth's arm pose costs less than the fit's where it is far off."""
    parser = argparse.ArgumentParser(prog="python -m upperpose.lab.truth_cost", description=__doc__.split("\n")[0])
    parser.add_argument("clips", type=Path, nargs="+", help="clip folders (video.mp4, gt.json)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-plate", action="store_true")
    args = parser.parse_args(argv)
    for clip in args.clips:
        probes = probe_clip(clip, args.seed, not args.no_plate)
        if not probes:
            print(f"{clip.name}: no arm far off (or none the model can reach)")
            continue
        cheaper = sum(p.truth_cost < p.fit_cost for p in probes)
        terms = {t: float(np.mean([p.term_difference[t] for p in probes])) for t in probes[0].term_difference}
        listed = " ".join(f"{t} {v:+.2f}" for t, v in sorted(terms.items()))
        print(f"{clip.name}: {len(probes)} far-off arms, the truth costs less in {cheaper}; truth - fit: {listed}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
