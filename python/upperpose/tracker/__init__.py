"""The tracker (thesis Fig. 3.6-1): start-up, root and depth, search per frame, lost recovery.

See docs/tracker.md. Typical use::

    tracker = Tracker(camera, background)
    for frame in frames:
        result = tracker.update(frame)
"""

from upperpose.tracker.state import INITIALISING, LOST, NO_PERSON, STATUSES, TRACKED, StateMachine
from upperpose.tracker.tracker import PARTS, StaticFit, Tracker, TrackerConfig, TrackResult, default_fitter

__all__ = [
    "INITIALISING",
    "LOST",
    "NO_PERSON",
    "PARTS",
    "STATUSES",
    "TRACKED",
    "StateMachine",
    "StaticFit",
    "TrackResult",
    "Tracker",
    "TrackerConfig",
    "default_fitter",
]
