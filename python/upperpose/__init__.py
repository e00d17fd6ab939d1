"""upperpose: real-time 3D upper-body pose from one ordinary camera, with no trained model.

The method follows an annealed-particle-swarm thesis (see docs/): a truncated-cone body model
is projected into each frame and matched against image features.
"""

from upperpose._upperpose import __version__, joint_limits
from upperpose.exceptions import InputError, SearchError, UpperposeError, VideoError
from upperpose.fit import Tracker, TrackerConfig, TrackResult
from upperpose.fit.pipeline import track_video
from upperpose.fit.search import FrameFit, SearchConfig, fit_frame
from upperpose.model import (
    ANGLE_NAMES,
    JOINT_NAMES,
    PART_NAMES,
    BodyModel,
    Camera,
    Pose,
    forward_kinematics,
    project,
    render_labels,
    render_masks,
    skeleton,
    solids,
)

__all__ = [
    "ANGLE_NAMES",
    "JOINT_NAMES",
    "PART_NAMES",
    "BodyModel",
    "Camera",
    "FrameFit",
    "InputError",
    "Pose",
    "SearchConfig",
    "SearchError",
    "TrackResult",
    "Tracker",
    "TrackerConfig",
    "UpperposeError",
    "VideoError",
    "__version__",
    "fit_frame",
    "forward_kinematics",
    "joint_limits",
    "project",
    "render_labels",
    "render_masks",
    "skeleton",
    "track_video",
    "solids",
]
