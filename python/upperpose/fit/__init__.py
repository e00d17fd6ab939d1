"""Stage 3, the fit: the per-frame search and the tracker (thesis Fig. 3.6-1) around it.

`search` wraps the Rust annealed particle swarm (one frame's fit); `tracker` runs start-up
(`person_finder`, over `startup` and `acquire`), the root and its depth (`root`), lost hands
(`recovery`), the arms' corrections (`arm_corrections`) and the status (`state`) frame after
frame; `pipeline` streams a video through it. See docs/tracker.md. Typical use::

    tracker = Tracker(camera, background)
    for frame in frames:
        result = tracker.update(frame)
"""

from upperpose.fit.pipeline import track_video
from upperpose.fit.search import FrameFit, SearchConfig, fit_frame
from upperpose.fit.state import INITIALISING, LOST, NO_PERSON, STATUSES, TRACKED, StateMachine
from upperpose.fit.tracker import PARTS, StaticFit, Tracker, TrackerConfig, TrackResult

__all__ = [
    "INITIALISING",
    "LOST",
    "NO_PERSON",
    "PARTS",
    "STATUSES",
    "TRACKED",
    "FrameFit",
    "SearchConfig",
    "StateMachine",
    "StaticFit",
    "TrackResult",
    "Tracker",
    "TrackerConfig",
    "fit_frame",
    "track_video",
]
