"""What the tracker says about one frame: its status and, with a person, the fitted pose.

The statuses and the rules that move between them are in `upperpose.fit.state` (SPEC 6, 9).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
NO_PERSON, INITIALISING, TRACKED, LOST = "no_person", "initialising", "tracked", "lost"
STATUSES = (NO_PERSON, INITIALISING, TRACKED, LOST)
# A joint the image shows, or one outside the image or on a lost arm (`upperpose.fit.visibility`).
OBSERVED, UNOBSERVED = "observed", "unobserved"
VISIBILITIES = (OBSERVED, UNOBSERVED)


@dataclass(frozen=True)
class TrackResult:
    """The tracker's answer for one frame.

    Attributes:
        frame: frame number (0 = the first frame given to the tracker).
        status: "no_person", "initialising", "tracked" or "lost".
        pose: `(13,)` angles in radians (ANGLE_NAMES order), or None without a person.
        root: `(3,)` root position, metres, camera frame; or None.
        joints_2d: `(7, 2)` pixels (JOINT_NAMES order); or None.
        joints_3d: `(7, 3)` metres, camera frame; or None.
        cost: the search's cost at the fit; or None.
        searched: the parts searched this frame.
        lost_parts: the arms that are lost.
        timings: wall seconds per stage: "features", "startup", "search", "other".
        confidence: `(7,)` per joint in [0, 1] (`upperpose.fit.confidence`); or None.
        visibility: per joint "observed" or "unobserved" (`upperpose.fit.visibility`); or None.
    """

    frame: int
    status: str
    pose: FloatArray | None = None
    root: FloatArray | None = None
    joints_2d: FloatArray | None = None
    joints_3d: FloatArray | None = None
    cost: float | None = None
    searched: tuple[str, ...] = ()
    lost_parts: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)
    confidence: FloatArray | None = None
    visibility: tuple[str, ...] | None = None

    def to_record(self) -> dict[str, Any]:
        """The frame as a SPEC 9 "frames" entry (plus "root")."""

        def rows(a: FloatArray | None) -> list[list[float]] | None:
            return None if a is None else [[float(v) for v in row] for row in a]

        has_pose = self.status in (TRACKED, LOST) and self.pose is not None
        return {
            "frame": self.frame,
            "status": self.status,
            "joints_2d": rows(self.joints_2d) if has_pose else None,
            "joints_3d": rows(self.joints_3d) if has_pose else None,
            "angles": [float(v) for v in self.pose] if has_pose and self.pose is not None else None,
            "cost": float(self.cost) if has_pose and self.cost is not None and np.isfinite(self.cost) else None,
            "root": [float(v) for v in self.root] if has_pose and self.root is not None else None,
            "confidence": [round(float(v), 3) for v in self.confidence]
            if has_pose and self.confidence is not None
            else None,
            "visibility": list(self.visibility) if has_pose and self.visibility is not None else None,
        }
