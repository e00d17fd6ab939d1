"""The tracked person's own skin colour, learnt from their face at start-up.

The generic skin rules (R - G band, YCrCb box) take in beige, khaki, tan and wood as well as
every skin tone, and lose dark skin in shadow (its R - G falls under the band); a hand beside
khaki trousers then joins them in one blob and its point goes to the trousers' far end. Hue and
saturation do not change when the light dims or brightens, and one person's face and hands
share them; so once the face is known, skin is what lies within a few spreads of the face's hue
and saturation. Light skin and khaki differ by about ten hue steps (of 180) while a face's
pixels spread over two to four. A colour shared with the room (dark skin and brown wood) is
left to the room's own mask, made from the clean plate with the same model.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.checks import Frame, Mask
from upperpose.features.config import FeatureConfig
from upperpose.features.skin import skin_mask

HUE_STEPS = 180  # OpenCV's 8-bit hue: 0..179, red at both ends
# The table's second axis packs saturation (top 5 bits) and brightness (top 3 bits) into one byte:
# OpenCV back-projects at most two channels of a three-channel image through a 2-D table.
SATURATION_STEP, VALUE_BINS = 8, 8
PACK_SATURATION = np.array([v & 0xF8 for v in range(256)], np.uint8)
PACK_VALUE = np.array([v >> 5 for v in range(256)], np.uint8)
# The face box's core: cheeks, nose and mouth; clear of hair, brows and the background.
CORE = (0.25, 0.35, 0.75, 0.85)  # left, top, right, bottom as fractions of the box
MIN_SAMPLES = 50
MIN_VALUE_SHARE = 0.4  # darker than this share of the face's brightness: not judged skin
CHANNEL_NOISE = 4.0  # grey levels of noise in a channel difference (sensor, compression)
MAX_HUE_SPREAD = 6.0  # hue steps: greyer or darker pixels than that allows are not judged by hue
MIN_SATURATION_SHARE = 0.4  # greyer than this share of the face's saturation: not skin
ROOM_MARGIN = 1.5  # the plate's skin-coloured room: within this many times the skin's ellipse


@dataclass(frozen=True)
class PersonSkin:
    """A person's skin as an ellipse in (hue, saturation), and its look-up table.

    Attributes:
        hue, saturation: the face's median hue (0..179) and saturation (0..255).
        hue_spread, saturation_spread: their robust standard deviations, at least the floors.
        table: `(180, 256)` float32, 255 where (hue, packed saturation and brightness) is the
            person's skin (the histogram `cv2.calcBackProject` reads).
        room_table: the same with the ellipse grown by `ROOM_MARGIN` and no brightness or
            saturation floor: what counts as skin-coloured room in the clean plate (a margin, so
            that noise does not carry the room's pixels just inside the ellipse).
    """

    hue: float
    saturation: float
    hue_spread: float
    saturation_spread: float
    table: npt.NDArray[np.float32]
    room_table: npt.NDArray[np.float32]

    @classmethod
    def from_face(
        cls,
        frame: Frame,
        face: tuple[int, int, int, int],
        skin: Mask,
        sigmas: float,
        min_hue_spread: float,
        min_saturation_spread: float,
    ) -> PersonSkin | None:
        """The model from the skin pixels (generic rule) of the face box's core.

        Args:
            frame: `(H, W, 3)` uint8 BGR.
            face: the face box `(x, y, w, h)` in pixels.
            skin: `(H, W)` generic skin mask of the frame (nonzero = skin).
            sigmas: the ellipse's half-axes in robust standard deviations.
            min_hue_spread: floor of the hue spread, hue steps (noise, shading, and hands a
                little redder or paler than the face).
            min_saturation_spread: floor of the saturation spread.

        Returns:
            The model, or None when the core holds fewer than 50 skin pixels.
        """
        height, width = skin.shape
        x, y, w, h = face
        x0, x1 = max(int(x + CORE[0] * w), 0), min(int(x + CORE[2] * w), width)
        y0, y1 = max(int(y + CORE[1] * h), 0), min(int(y + CORE[3] * h), height)
        if x1 <= x0 or y1 <= y0:
            return None
        hsv = cv2.cvtColor(np.ascontiguousarray(frame[y0:y1, x0:x1]), cv2.COLOR_BGR2HSV)
        keep = skin[y0:y1, x0:x1] > 0
        if np.count_nonzero(keep) < MIN_SAMPLES:
            return None
        # Hue around the face's circular mean, so that reds either side of 0 stay together.
        angles = hsv[..., 0][keep].astype(np.float64) * (2 * np.pi / HUE_STEPS)
        centre = float(np.arctan2(np.sin(angles).mean(), np.cos(angles).mean())) * HUE_STEPS / (2 * np.pi)
        hues = _wrapped(hsv[..., 0][keep].astype(np.float64) - centre)
        saturations = hsv[..., 1][keep].astype(np.float64)
        hue = (centre + float(np.median(hues))) % HUE_STEPS
        hues -= np.median(hues)
        saturation = float(np.median(saturations))
        hue_spread = max(1.4826 * float(np.median(np.abs(hues))), min_hue_spread)
        saturation_spread = max(1.4826 * float(np.median(np.abs(saturations - saturation))), min_saturation_spread)
        value = float(np.median(hsv[..., 2][keep]))
        table, room_table = _tables(hue, saturation, value, hue_spread, saturation_spread, sigmas)
        return cls(hue, saturation, hue_spread, saturation_spread, table, room_table)

    def mask(self, frame: Frame, hsv: Frame | None = None, out: Mask | None = None, room: bool = False) -> Mask:
        """255 where a pixel's colour is the person's skin's.

        Args:
            frame: `(H, W, 3)` uint8 BGR.
            hsv: scratch `(H, W, 3)` uint8 for the conversion (allocated when None).
            out: output `(H, W)` uint8 (allocated when None).
            room: use `room_table` (for the clean plate).
        """
        converted = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV, dst=hsv)
        hue, saturation, value = cv2.split(converted)
        cv2.LUT(saturation, PACK_SATURATION, dst=saturation)
        cv2.add(saturation, cv2.LUT(value, PACK_VALUE, dst=value), dst=saturation)
        # Channel 0 of the first plane and channel 0 of the second (OpenCV numbers the channels
        # of the listed planes in a row): no merged copy of the two.
        table = self.room_table if room else self.table
        found = cv2.calcBackProject([hue, saturation], [0, 1], table, [0, HUE_STEPS, 0, 256], 1, dst=out)
        return np.asarray(found, dtype=np.uint8)


def skin_of_face(
    frame: Frame, face: tuple[int, int, int, int], config: FeatureConfig, whole_face: bool = False
) -> PersonSkin | None:
    """`PersonSkin.from_face` with `config`'s spreads, the generic rule read inside the face box only.

    Args:
        frame: `(H, W, 3)` uint8 BGR.
        face: the face box `(x, y, w, h)`, pixels.
        config: `person_skin_*` settings and the generic rule's.
        whole_face: learn from every pixel of the face's core (a face the generic rule fails on).
    """
    x, y, w, h = face
    box = (slice(max(y, 0), max(y + h, 0)), slice(max(x, 0), max(x + w, 0)))
    skin = np.zeros(frame.shape[:2], np.uint8)
    if skin[box].size:
        skin[box] = 255 if whole_face else skin_mask(np.ascontiguousarray(frame[box]), config)
    return PersonSkin.from_face(
        frame, face, skin, config.person_skin_sigmas, config.person_skin_min_hue_spread,
        config.person_skin_min_saturation_spread,
    )  # fmt: skip


def _tables(
    hue: float, saturation: float, value: float, hue_spread: float, saturation_spread: float, sigmas: float
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """The skin's and the room's tables over (hue, packed saturation and brightness)."""
    # Hue and saturation are noisier the darker and greyer the pixel (a channel's noise over a
    # smaller max - min): each spread is at least that noise. Pixels darker or greyer than the
    # floors are not judged by colour at all.
    packed = np.arange(256)
    values = ((packed & 7) + 0.5) * (256 / VALUE_BINS)
    sats = (packed & 0xF8) + SATURATION_STEP / 2
    sat_spreads = np.maximum(saturation_spread, 255 * CHANNEL_NOISE / values)[None, :]
    hue_noise = np.minimum((HUE_STEPS / 6) * CHANNEL_NOISE * 255 / (sats * values), MAX_HUE_SPREAD)
    hue_spreads = np.maximum(hue_spread, hue_noise)[None, :]
    h_grid = _wrapped(np.arange(HUE_STEPS, dtype=np.float64) - hue)[:, None] / hue_spreads
    s_grid = (sats - saturation)[None, :] / sat_spreads
    distance = np.sqrt(h_grid**2 + s_grid**2)
    judged = ((values >= MIN_VALUE_SHARE * value) & (sats >= MIN_SATURATION_SHARE * saturation))[None, :]
    table = np.where((distance <= sigmas) & judged, 255, 0).astype(np.float32)
    room_table = np.where(distance <= ROOM_MARGIN * sigmas, 255, 0).astype(np.float32)
    return table, room_table


def _wrapped(hues: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Hue differences brought into -90..90 (the hue circle has 180 steps)."""
    return (hues + HUE_STEPS / 2) % HUE_STEPS - HUE_STEPS / 2
