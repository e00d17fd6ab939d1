"""The face texture: scikit-image's public-domain `astronaut` photo, recoloured per skin tone.

The photo (NASA, public domain) ships inside the scikit-image wheel, so nothing is downloaded.
`FACE_BOX` names where the face sits in it; `face_sampler` maps head-surface coordinates to
photo pixels so that OpenCV's frontal-face Haar cascade finds the rendered face.
"""

from __future__ import annotations

import functools
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.exceptions import UpperposeError
from upperpose.lab.synth.appearance import SKIN_TONES

# Face oval in the 512x512 photo: centre and half-axes, pixels.
FACE_CENTRE = (222.0, 120.0)
FACE_HALF_AXES = (50.0, 53.0)
# Photo pixels per unit of the head ellipsoid's normalised coordinates, and the photo row of
# the head centre: eyes sit a little above the centre, the chin near the bottom.
PIXELS_PER_UNIT = (60.0, 66.0)
CENTRE_ROW = 106.0


@functools.lru_cache(maxsize=1)
def _photo() -> npt.NDArray[np.uint8]:
    try:
        from skimage import data  # imported lazily: scikit-image is slow to import
    except ImportError:
        raise UpperposeError("synthetic faces need scikit-image: pip install 'upperpose[synth]'") from None
    return np.ascontiguousarray(data.astronaut()[:, :, ::-1])  # type: ignore[no-untyped-call]  # RGB -> BGR


def _oval_alpha(shape: tuple[int, int]) -> npt.NDArray[np.float32]:
    ys, xs = np.mgrid[0 : shape[0], 0 : shape[1]].astype(np.float32)
    r = np.hypot((xs - FACE_CENTRE[0]) / FACE_HALF_AXES[0], (ys - FACE_CENTRE[1]) / FACE_HALF_AXES[1])
    return cast(npt.NDArray[np.float32], np.clip((1.08 - r) / 0.16, 0.0, 1.0).astype(np.float32))


@functools.lru_cache(maxsize=8)
def face_texture(skin: str) -> npt.NDArray[np.float32]:
    """The photo recoloured to a skin tone: `(512, 512, 4)` float32, BGR albedo and alpha.

    Inside the face oval the photo's shading detail is kept and its mean colour moved to the
    skin tone's; alpha fades from 1 inside the oval to 0 outside, where the plain skin shows.

    Raises:
        ValueError: unknown skin tone.
    """
    if skin not in SKIN_TONES:
        raise ValueError(f"unknown skin tone {skin!r}; choose from {', '.join(SKIN_TONES)}")
    photo = _photo()
    alpha = _oval_alpha(photo.shape[:2])
    ycc = cv2.cvtColor(photo, cv2.COLOR_BGR2YCrCb).astype(np.float32)
    inside = alpha > 0.9
    mean = ycc[inside].mean(axis=0)
    target = cv2.cvtColor(np.array([[SKIN_TONES[skin]]], np.float32) / 255.0, cv2.COLOR_BGR2YCrCb)[0, 0]
    target = target * np.array([255.0, 255.0, 255.0], np.float32)
    # Keep enough contrast on dark skin for the face to stay a face.
    gain = max(target[0] / mean[0], 0.75)
    out = ycc.copy()
    out[..., 0] = target[0] + (ycc[..., 0] - mean[0]) * gain
    out[..., 1:] = target[1:] + (ycc[..., 1:] - mean[1:]) * 0.8
    bgr = cv2.cvtColor(np.clip(out, 0, 255).astype(np.uint8), cv2.COLOR_YCrCb2BGR).astype(np.float32)
    return np.dstack([bgr, alpha])


def sample_face(skin: str, qx: npt.NDArray[np.float64], qy: npt.NDArray[np.float64]) -> npt.NDArray[np.float32]:
    """Face texture at normalised head coordinates (x right, y down, in units of the radii).

    Returns:
        `(N, 4)` float32: BGR albedo and alpha (0 where the face does not reach).
    """
    tex = face_texture(skin)
    mx = (FACE_CENTRE[0] + qx * PIXELS_PER_UNIT[0]).astype(np.float32).reshape(-1, 1)
    my = (CENTRE_ROW + qy * PIXELS_PER_UNIT[1]).astype(np.float32).reshape(-1, 1)
    out = cv2.remap(tex, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return cast(npt.NDArray[np.float32], out.reshape(-1, 4))
