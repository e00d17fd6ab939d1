"""Image features of SPEC 4 (thesis §3.4); see docs/features.md.

Background, I_sub, I_edge, I_motion, I_skin, I_sil, skin blobs, head and hand points, motion
flags, arm silhouette.

Typical use::

    background = Background.from_plate(plate)          # or background_from_video(path)
    extract = FeatureExtractor(background)
    for frame in frames:
        features = extract(frame, predicted_joints, part_labels)
"""

from upperpose.features.background import (
    Background,
    CleanPlateWarning,
    background_from_video,
    estimate_background,
    sample_video,
)
from upperpose.features.blobs import SkinBlob, find_skin_blobs
from upperpose.features.config import SKIN_SPACES, FeatureConfig, PersonTemplate
from upperpose.features.extractor import FeatureExtractor, compute_features
from upperpose.features.frame import (
    POINT_ABSENT,
    POINT_FOUND,
    POINT_MERGED,
    FrameFeatures,
)
from upperpose.features.packing import pack_rows, row_stride, unpack_rows
from upperpose.features.parts import (
    MOTION_GROUPS,
    MotionFlag,
    arm_silhouette,
    motion_flags,
)
from upperpose.features.points import POINT_NAMES, SkinPoint, locate_points
from upperpose.features.skin import skin_mask

__all__ = [
    "MOTION_GROUPS",
    "POINT_ABSENT",
    "POINT_FOUND",
    "POINT_MERGED",
    "POINT_NAMES",
    "SKIN_SPACES",
    "PersonTemplate",
    "Background",
    "CleanPlateWarning",
    "FeatureConfig",
    "FeatureExtractor",
    "FrameFeatures",
    "MotionFlag",
    "SkinBlob",
    "SkinPoint",
    "arm_silhouette",
    "background_from_video",
    "compute_features",
    "estimate_background",
    "find_skin_blobs",
    "locate_points",
    "motion_flags",
    "pack_rows",
    "row_stride",
    "sample_video",
    "skin_mask",
    "unpack_rows",
]
