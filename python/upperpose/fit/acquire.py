"""Start-up and re-acquisition from any pose (issue 25; thesis §5.2 names this its open problem).

Once a stable face is seen, the person's pose is searched globally: the torso around facing
the camera (wide trajectory windows, as the A-pose start-up), then both arms over their
anatomical ranges (mode "initial", the lost arm's search of §3.4.9), several times with
different random streams and from different starting poses. Every candidate is scored again
in the same image regions (a stage's cost depends on its region, as in the lost-arm
comparison) and the lowest cost is kept. Tracking starts when that fit explains the
silhouette (`Agreement`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.fit.fitter import PARTS
from upperpose.fit.recovery import ARMS

# Restart r searches with the seed `seed + r * RESTART_STRIDE` (mod 2**64; the core keys its
# random streams by seed, frame and stage): restarts differ from each other, are unlikely to
# repeat another seed's streams, and the same seed still gives the same fit whatever the
# thread count.
RESTART_STRIDE = 0x9E3779B97F4A7C15


def restart_seed(seed: int, restart: int) -> int:
    """The search seed of restart number `restart` (0: `seed` itself)."""
    return (seed + restart * RESTART_STRIDE) % (1 << 64)


@dataclass(frozen=True)
class Agreement:
    """How well a model's projection and the silhouette agree.

    Attributes:
        on_silhouette: share of the projection's pixels that are silhouette.
        explained: share of the silhouette's pixels, above the projection's lowest row (the
            legs are not modelled), that lie within `margin` / 2 pixels of the projection.
    """

    on_silhouette: float
    explained: float

    def passes(self, on_silhouette: float, explained: float) -> bool:
        """Both shares at least the given ones."""
        return self.on_silhouette >= on_silhouette and self.explained >= explained


def agreement(silhouette: npt.NDArray[np.uint8], labels: npt.NDArray[np.uint8], margin: int = 15) -> Agreement:
    """The `Agreement` of the model's part labels (0 = background) with the silhouette."""
    model = labels > 0
    area = int(np.count_nonzero(model))
    if area == 0:
        return Agreement(0.0, 0.0)
    sil = silhouette > 0
    on = float(np.count_nonzero(sil & model)) / area
    bottom = int(np.flatnonzero(model.any(axis=1))[-1]) + 1
    grown = cv2.dilate(model[:bottom].view(np.uint8), np.ones((margin, margin), np.uint8)) > 0
    above = sil[:bottom]
    total = int(np.count_nonzero(above))
    explained = float(np.count_nonzero(above & grown)) / total if total else 0.0
    return Agreement(on, explained)


def global_fit(
    fit: Callable[[npt.NDArray[np.float64], npt.NDArray[np.float64], str, tuple[str, ...], int], Any],
    starts: Sequence[npt.ArrayLike],
    root: npt.ArrayLike,
    restarts: int,
) -> Any:
    """The lowest-cost fit of a global search from several starting poses.

    Args:
        fit: `fit(pose, root, mode, parts, restart)`, one search (restart numbers its random
            streams); `parts` empty scores the pose without searching.
        starts: starting poses (at least one); the torso is searched around each in trajectory
            mode, then the arms over their ranges from there, `restarts` times in all (cycling
            through the starts). Each start's own trajectory fit is a candidate too.
        root: the root position, metres.
        restarts: full-range searches of the arms.

    Returns:
        The candidate of the lowest cost in the full-range search's regions.
    """
    if not starts:
        raise ValueError("starts must not be empty")
    root = np.asarray(root, dtype=np.float64)
    candidates = []
    for pose in starts:
        candidates.append(fit(np.asarray(pose, dtype=np.float64), root, "trajectory", PARTS, 0))
    for r in range(restarts):
        near = candidates[r % len(starts)]
        candidates.append(fit(np.asarray(near.pose, dtype=np.float64), np.asarray(near.root), "initial", ARMS, r + 1))
    scored = [
        (float(fit(np.asarray(c.pose, dtype=np.float64), np.asarray(c.root), "initial", (), 0).cost), k)
        for k, c in enumerate(candidates)
    ]
    return candidates[min(scored)[1]]


__all__ = ["RESTART_STRIDE", "Agreement", "agreement", "global_fit", "restart_seed"]
