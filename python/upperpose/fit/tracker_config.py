"""`TrackerConfig`: the tracker's settings, their defaults and their checks.

The search's own settings are `upperpose.SearchConfig` (checked by the core); `search_config`
builds it from the fields here. Settings files (TOML) are `fit/settings.py`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from upperpose.exceptions import InputError
from upperpose.features import FeatureConfig
from upperpose.fit.search import Limits, Optimizer, SearchConfig


@dataclass(frozen=True)
class TrackerConfig:
    """Settings of the tracker (the search's own settings go to `upperpose.SearchConfig`).

    Attributes:
        particles, iterations, threads, seed, limits, optimizer, sigma: passed to `SearchConfig`
            when `search` is None (None keeps the search's default). `optimizer` is "apso" (ours),
            "pso", "simplex" or "apsopf" (the thesis' baselines, docs/baselines.md); `sigma` is
            APSOPF's Gaussian redistribution.
        root_window: half-width in metres of the torso stage's search over the root's X and Y
            around the estimate of `RootEstimator` (also used after start-up and losses).
        search: a ready `upperpose.SearchConfig`; overrides the fields above.
        search_options: keyword arguments of `upperpose.SearchConfig` that override the fields
            above (for example `{"weights": {"edge": 1.0}, "seed": 3}`), when `search` is None.
        features: feature thresholds; the background's when None.
        skip_static: search only the parts whose motion flag is set (§3.4.3); False searches
            every part every frame.
        confirm_frames: frames in a row the start-up check must pass.
        face_only_frames: after this many frames in a row with a stable face but no start
            (neither the A-pose check nor a fit that explains the silhouette), start anyway
            with the best fit from any pose.
        face_only_frames_learnt: `face_only_frames` while the background is learnt (no clean
            plate): until the first fit the room behind the person is a guess (inpainted), and
            skin-coloured room there joins the hands' blobs, so the checks rarely pass.
        any_pose_frames: from this many frames in a row with a stable face on, a frame that
            fails the A-pose check is fitted from any pose (`upperpose.fit.acquire`); 0 turns
            this off (the A-pose check, or `face_only_frames`, then starts tracking).
        acquire_restarts: full-range searches of the arms per any-pose fit.
        acquire_on_silhouette, acquire_explained, acquire_hand_share: a start-up fit explains
            the frame when at least `acquire_on_silhouette` of its projection lies on the
            silhouette, `acquire_explained` of the silhouette (above the projection's lowest
            row) lies near the projection, and neither hand lies farther than
            `acquire_hand_share` shoulder widths from its skin point. An any-pose fit starts
            tracking only then; an A-pose fit that does not is replaced by an any-pose fit
            that does.
        leave_frames: frames in a row without the person before going back to "no_person".
        presence_share: the person is present while at least this share of the model's last
            projection is covered by the silhouette, or the head's skin blob lies within a
            shoulder width of the model's head.
        lost_threshold, lost_frames: lost detection (SPEC 5: one shoulder width, several frames).
        unexplained_share: an arm also counts a miss when the silhouette on its side that the
            model leaves unexplained exceeds its level of the first ten tracked frames (the
            person's shape is not the model's) by this share of one arm's projected area.
        velocity_damping: share of last frame's velocity kept in the prediction.
        recovery_window_scale: trajectory windows are widened by this factor on the frame after
            a recovery.
        startup_window_scale: the first frame is searched around the A-pose with trajectory
            windows widened by this factor.
        startup_width_scales: the torso and shoulder widths tried at start-up, as factors of
            the adult averages; the fit with the lowest cost is kept (a model of the wrong
            width fits best turned, and then stays turned); up to 1.35, as wide as a person in
            long sleeves looks to the cost. Empty: the averages.
        startup_head_scales: then the head's height above the shoulders, as factors of the
            averages besides 1 (the width's fit), at the chosen width; the fit whose torso
            stage costs least is kept (the face box's depth is about 10 % off, which leaves
            the shoulders too high or low); only +-5 %: further out, the cost chose wrongly
            on bodies other than the model's own. Empty: the averages.
        startup_frontal: fit the start-up frame with the torso's turn held at zero. Off by
            default: the turn's own window (+-0.05 rad x 3) is already narrow, and holding it
            costs more frames than it saves (docs/tracker.md).
        velocity_window_gain: an arm's trajectory windows are widened by 1 + gain x its last
            frame-to-frame change (largest angle change, in units of 0.15 rad at 30 fps), so
            that a fast wave does not outrun them.
        fair_recovery: a lost arm's full-range fit replaces the trajectory fit only when it
            costs less in the same image regions (a stage's cost depends on its region: the
            Sil term counts every mismatch inside it, and the full-range regions are larger).
        doubt_share, doubt_frames: an arm whose fitted hand has been farther than `doubt_share`
            shoulder widths from its skin evidence for `doubt_frames` frames in a row (short of
            lost) is searched once over its anatomical ranges, like a lost arm; that fit is
            taken when it costs less and its hand lies nearer the skin point. `doubt_frames` 0
            turns this off.
        reach_share, reach_candidates: an arm whose fitted hand lies farther than `reach_share`
            shoulder widths from its hand's skin point (or, with no blob matched, from the
            nearest skin blob no part holds) is also sought from there: up to
            `reach_candidates` arm poses that put the hand on that point (`fit.reach`) are
            scored, and the best is searched in widened windows; the result is taken when it
            costs less and its hand lies nearer the point. `reach_candidates` 0 turns this off.
        untangle_hands: when both hands hold skin blobs of their own and the fitted hands lie
            crossed in the image, the other labelling of the two blobs is also tried (both arms
            sought from the swapped points as above); the lower cost wins. Needs the reach.
        untangle_refine: untangling seeds each arm from the `untangle_refine` cheapest of those
            arm poses, and from the one whose elbow lies nearest the fit's (the labels were
            wrong, not the elbows), each first searched in widened windows: the cheapest result
            wins. The table's grid is coarse: unrefined, a straight arm raised towards the
            camera beat the bent arm that, refined, costs less (a clap's elbows 50-70 px high
            for the rest of the clip). 0 takes the cheapest pose unrefined.
        face_check_frames, face_drift_share: every `face_check_frames` frames while tracking,
            frontal faces of the person's size are sought around the model's head; one farther
            than `face_drift_share` face widths from it on two checks in a row moves the root
            under it (the head had followed a hand away). `face_check_frames` 0 turns this off.
        steady_face_frames: at start-up, a face the cascade finds in one place and size this
            many frames in a row is the person's even when the generic skin rule finds too
            little skin in it (cool or dim light); the person's skin colour is then learnt
            from the whole face. 0 turns this off.
        work_pixels: videos whose frames have more pixels are tracked at a reduced size of
            about this many pixels, shape kept (`fit.work_size`; the pose file's joints stay in
            the video's pixels); 0 tracks every frame at its own size. Applies to
            `VideoTracking`, `track_video` and the command line, not to `Tracker` itself.
    """

    particles: int | None = None
    iterations: int | None = None
    threads: int | None = None
    seed: int = 0
    limits: Limits = "anatomical"
    optimizer: Optimizer = "apso"
    sigma: float | None = None
    root_window: float = 0.04
    search: SearchConfig | None = None
    features: FeatureConfig | None = None
    skip_static: bool = True
    confirm_frames: int = 3
    face_only_frames: int = 15
    face_only_frames_learnt: int = 3
    any_pose_frames: int = 2
    acquire_restarts: int = 4
    acquire_on_silhouette: float = 0.85
    acquire_explained: float = 0.85
    acquire_hand_share: float = 0.5
    leave_frames: int = 8
    presence_share: float = 0.3
    lost_threshold: float = 1.0
    lost_frames: int = 5
    unexplained_share: float = 0.6
    velocity_damping: float = 0.7
    recovery_window_scale: float = 2.0
    startup_window_scale: float = 3.0
    startup_width_scales: tuple[float, ...] = (0.75, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2, 1.25, 1.3, 1.35)
    startup_head_scales: tuple[float, ...] = (0.95, 1.05)
    startup_frontal: bool = False
    velocity_window_gain: float = 0.5
    fair_recovery: bool = True
    doubt_share: float = 0.25
    doubt_frames: int = 3
    reach_share: float = 0.5
    reach_candidates: int = 6
    untangle_hands: bool = True
    untangle_refine: int = 3
    face_check_frames: int = 5
    face_drift_share: float = 0.5
    steady_face_frames: int = 8
    work_pixels: int = 640 * 480
    search_options: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        def whole(name: str, low: int, value: object) -> None:
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise InputError(f"{name} must be an integer >= {low}, got {value!r}")

        def real(name: str, value: object, low: float, high: float = math.inf, open_low: bool = False) -> None:
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            if not ok or not (value > low if open_low else value >= low) or value > high:  # type: ignore[operator]
                bound = (f"> {low:g}" if open_low else f">= {low:g}") + (
                    "" if high == math.inf else f" and <= {high:g}"
                )
                raise InputError(f"{name} must be a finite number {bound}, got {value!r}")

        for name in ("particles", "iterations", "threads"):
            if getattr(self, name) is not None:
                whole(name, 1, getattr(self, name))
        whole("seed", 0, self.seed)
        if self.seed >= 2**64:
            raise InputError(f"seed must be below 2**64, got {self.seed}")
        whole("confirm_frames", 1, self.confirm_frames)
        for name in (
            "face_only_frames",
            "face_only_frames_learnt",
            "leave_frames",
            "lost_frames",
            "doubt_frames",
            "reach_candidates",
            "untangle_refine",
            "any_pose_frames",
            "face_check_frames",
            "steady_face_frames",
            "work_pixels",
        ):
            whole(name, 0, getattr(self, name))
        whole("acquire_restarts", 0, self.acquire_restarts)
        for name in ("presence_share", "velocity_damping", "acquire_on_silhouette", "acquire_explained"):
            real(name, getattr(self, name), 0.0, 1.0)
        for name in ("root_window", "unexplained_share", "doubt_share", "velocity_window_gain", "acquire_hand_share"):
            real(name, getattr(self, name), 0.0)
        for name in (
            "lost_threshold",
            "recovery_window_scale",
            "startup_window_scale",
            "reach_share",
            "face_drift_share",
        ):
            real(name, getattr(self, name), 0.0, open_low=True)
        if self.sigma is not None:
            real("sigma", self.sigma, 0.0, open_low=True)
        for name in ("startup_width_scales", "startup_head_scales"):
            for k, v in enumerate(getattr(self, name)):
                real(f"{name}[{k}]", v, 0.0, open_low=True)
        self.search_config()  # the search's own ranges (at most 10,000 particles, ...) live in the core

    def search_config(self) -> SearchConfig:
        """The `upperpose.SearchConfig` to use."""
        if self.search is not None:
            return self.search
        given = {
            "particles": self.particles,
            "iterations": self.iterations,
            "threads": self.threads,
            "sigma": self.sigma,
        }
        kwargs = {
            "seed": self.seed,
            "limits": self.limits,
            "optimizer": self.optimizer,
            "root_window": self.root_window,
            "initial_root_window": self.root_window,
            **{k: v for k, v in given.items() if v is not None},
        }
        return SearchConfig(**{**kwargs, **self.search_options})


__all__ = ["TrackerConfig"]
