"""Per-frame features (SPEC 4) and the `FrameFeatures` object the tracker consumes.

Images are `(H, W)` uint8, C-contiguous, 0 or 255. The maps the Rust cost matches are also
bit-packed (`packing.pack_rows`): silhouette, dilated edge, dilated motion and, when a torso
region is known, the arm silhouette.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.blobs import SkinBlob
from upperpose.features.checks import Mask, check_mask
from upperpose.features.packing import pack_rows
from upperpose.features.parts import MotionFlag, arm_silhouette
from upperpose.features.points import PixelBox, SkinPoint

Bits = npt.NDArray[np.uint64]

# Status codes of `FrameFeatures.point_status()`.
POINT_ABSENT, POINT_FOUND, POINT_MERGED = 0, 1, 2


@dataclass(frozen=True)
class FrameFeatures:
    """All image features of one frame.

    Attributes:
        sub, edge, motion, skin0, skin, sil: I_sub, I_edge, I_motion, I_skin0, I_skin, I_sil.
        edge_dilated, motion_dilated: I_edge and I_motion dilated by `feature_dilate`.
        arm_sil: I_sil outside the torso region, or None when no torso region was known.
        sil_bits, edge_bits, motion_bits, arm_bits: the same bit-packed, `(H, ceil(W/64))` `<u8`
            (and `cover_bits`, the skin the arms should cover, computed on first use).
        blobs: valid skin blobs, largest first.
        head, right_hand, left_hand: skin points (None when absent).
        hands_beyond: per hand (right, left), for one with no skin point that the prediction puts
            outside the image, the box beyond the border where it may lie (`beyond_image`).
        motion_flags: per-group motion flags ("torso", "right_arm", "left_arm"), or None when no
            previous projection was given (search every part).
        timings: CPU seconds per stage when timing was asked for, else empty.
    """

    sub: Mask
    edge: Mask
    motion: Mask
    skin0: Mask
    skin: Mask
    sil: Mask
    edge_dilated: Mask
    motion_dilated: Mask
    arm_sil: Mask | None
    sil_bits: Bits
    edge_bits: Bits
    motion_bits: Bits
    arm_bits: Bits | None
    blobs: list[SkinBlob]
    head: SkinPoint | None
    right_hand: SkinPoint | None
    left_hand: SkinPoint | None
    hands_beyond: tuple[PixelBox | None, PixelBox | None] = (None, None)
    motion_flags: dict[str, MotionFlag] | None = None
    timings: dict[str, float] = dataclasses.field(default_factory=dict)

    @functools.cached_property
    def mot_skin(self) -> Mask:
        """I_MotSkin = I_motion & I_skin (Eq. 3.4.3-1), computed on first use (display only)."""
        return cast(Mask, cv2.bitwise_and(self.motion, self.skin))

    @functools.cached_property
    def mot_edge(self) -> Mask:
        """I_MotEdge = I_motion & I_edge & I_skin (Eq. 3.4.3-2), computed on first use."""
        return cast(Mask, cv2.bitwise_and(self.mot_skin, self.edge))

    @functools.cached_property
    def mot_combined(self) -> Mask:
        """I_MotCombined = I_MotSkin & I_MotEdge (Eq. 3.4.3-3), computed on first use.

        The motion flags use I_motion instead (SPEC 4): this one never fires on a clothed torso.
        """
        return cast(Mask, cv2.bitwise_and(self.mot_skin, self.mot_edge))

    @functools.cached_property
    def cover_bits(self) -> Bits:
        """I_skin without the head's blob, bit-packed: the skin the arms should cover (Cover, docs/cost.md).

        The head's blob (face, neck, hair, and a hand merged with them) is not the arms' to cover.
        """
        skin = self.skin
        if self.head is not None:
            blob = self.blobs[self.head.blob]
            skin = skin.copy()
            skin[blob.ys, blob.xs] = 0
        return pack_rows(skin)

    @property
    def size(self) -> tuple[int, int]:
        """(height, width) in pixels."""
        return (int(self.sil.shape[0]), int(self.sil.shape[1]))

    @property
    def points(self) -> tuple[SkinPoint | None, SkinPoint | None, SkinPoint | None]:
        """(head, right_hand, left_hand)."""
        return (self.head, self.right_hand, self.left_hand)

    def points_array(self) -> npt.NDArray[np.float64]:
        """`(3, 2)` float64 (x, y) of head, right hand, left hand; NaN where absent or merged."""
        out = np.full((3, 2), np.nan)
        for k, point in enumerate(self.points):
            if point is not None and not point.merged:
                out[k] = point.xy
        return out

    def merged_boxes_array(self) -> npt.NDArray[np.float64]:
        """`(3, 4)` float64 (x0, y0, x1, y1) per point, the box of the merged blob holding it.

        The box is the whole blob's, or `SkinPoint.box` (the part of it where the point can
        be, which for a hand cut by the image's border reaches beyond the image); NaN rows for
        points that are absent or not merged. A merged blob gives no point for the parts it
        holds, but it does say that they are in it. An absent hand that left the image has its
        `hands_beyond` box.
        """
        out = np.full((3, 4), np.nan)
        for k, point in enumerate(self.points):
            beyond = self.hands_beyond[k - 1] if k > 0 else None
            if point is None and beyond is not None:
                out[k] = beyond
            elif point is not None and point.merged:
                if point.box is not None:
                    out[k] = point.box
                else:
                    x, y, w, h = self.blobs[point.blob].bbox
                    out[k] = (x, y, x + w - 1, y + h - 1)
        return out

    def point_status(self) -> npt.NDArray[np.uint8]:
        """`(3,)` uint8 per point: 0 absent, 1 found, 2 merged (POINT_ABSENT/FOUND/MERGED)."""
        return np.array(
            [POINT_ABSENT if p is None else POINT_MERGED if p.merged else POINT_FOUND for p in self.points],
            np.uint8,
        )

    def with_torso_region(self, torso_region: Mask) -> FrameFeatures:
        """A copy whose arm silhouette is cut with `torso_region` (e.g. the torso just fitted).

        Args:
            torso_region: `(H, W)` mask, nonzero inside torso, neck and head.

        Raises:
            ValueError: wrong shape or dtype.
        """
        region = check_mask(torso_region, "torso_region", self.size)
        arm = arm_silhouette(self.sil, cv2.compare(region, 0, cv2.CMP_GT))  # type: ignore[call-overload]
        return dataclasses.replace(self, arm_sil=arm, arm_bits=pack_rows(arm))

    def images(self) -> dict[str, Mask]:
        """Every feature image by name, for display."""
        named = {
            "I_sub": self.sub,
            "I_edge": self.edge,
            "I_motion": self.motion,
            "I_skin0": self.skin0,
            "I_skin": self.skin,
            "I_sil": self.sil,
            "I_MotSkin": self.mot_skin,
            "I_MotEdge": self.mot_edge,
            "I_MotCombined": self.mot_combined,
        }
        if self.arm_sil is not None:
            named["arm silhouette"] = self.arm_sil
        return named


__all__ = ["POINT_ABSENT", "POINT_FOUND", "POINT_MERGED", "FrameFeatures"]
