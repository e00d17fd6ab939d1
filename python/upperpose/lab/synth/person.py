"""The synthetic person: smooth solids posed by the true skeleton, ray cast and shaded.

The body is deliberately not the tracker's model: limbs are tapered capsules with round
joints, the trunk a stack of elliptic slabs with sloping shoulders, a waist and hips running
out of the frame, the head an ellipsoid with ears, hair and a photographed face, the hands flat
ellipsoids with a thumb. Only the skeleton is shared: every solid hangs off
the tracker model's points (`upperpose.skeleton(pose, root, body)["model_points"]`), and the
ground truth is that skeleton's anatomical joints, exact by construction: the centre of the
head above the centre of the face (on which the head ellipsoid is centred), glenohumeral centres
inside the shoulder's ball, palm centres `PALM_TO_WRIST` beyond the wrist.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np
import numpy.typing as npt

from upperpose.lab.synth.appearance import HAIR_COLOURS, SHIRT_COLOURS, SKIN_TONES, TROUSER_COLOURS, Appearance
from upperpose.lab.synth.face import sample_face
from upperpose.lab.synth.raycast import Ellipsoid, FloatArray, Hits, Trunk, sweep
from upperpose.model import BodyModel, Pose, skeleton

# Surface kinds; a pixel's kind decides its material.
SHIRT, SKIN, HEAD, HAIR = "shirt", "skin", "head", "hair"
HAND_HALF_LENGTH = 0.085  # middle of the hand (the forearm cone's end) to the fingertips, metres
# Wrist to palm centre as a share of the lower arm's length: 4.6 cm on the default body (the
# validation set's convention; half of de Leva's wrist-to-third-metacarpale length is 4.3 cm).
PALM_TO_WRIST = 0.135
SLEEVE_PAD = 0.012  # how far cloth stands off the arm, metres
SHORT_SLEEVE = 0.5  # share of the upper arm a short sleeve covers


@dataclass(frozen=True)
class Surface:
    """A group of solids sharing a material and a texture frame.

    Attributes:
        kind: SHIRT (shirt above the belt, trousers below), SKIN, HEAD or HAIR.
        origin: `(3,)` origin of the texture frame, camera frame, metres.
        axes: `(3, 3)` texture frame axes as columns.
        radii: `(3,)` scale of normalised coordinates (HEAD only); ones otherwise.
        belt: the texture frame's y (metres) below which the trunk wears trousers.
    """

    kind: str
    origin: FloatArray
    axes: FloatArray
    radii: FloatArray
    belt: float = np.inf


@dataclass(frozen=True)
class Light:
    """Directional light plus ambient light.

    Attributes:
        direction: `(3,)` unit vector from the surface towards the light, camera frame.
        ambient: ambient share.
        diffuse: directional share.
        tint: `(3,)` BGR multiplier of the light's colour.
    """

    direction: FloatArray
    ambient: float = 0.42
    diffuse: float = 0.7
    tint: tuple[float, float, float] = (0.95, 1.0, 1.04)


class _Builder:
    def __init__(self) -> None:
        self.solids: list[Ellipsoid] = []
        self.surfaces: list[Surface] = []
        self.trunk: Trunk | None = None

    def surface(
        self, kind: str, origin: FloatArray, axes: FloatArray, radii: FloatArray | None = None, belt: float = np.inf
    ) -> int:
        self.surfaces.append(Surface(kind, origin, axes, np.ones(3) if radii is None else radii, belt))
        return len(self.surfaces) - 1


def _trunk(b: _Builder, sk: dict[str, FloatArray], body: BodyModel) -> None:
    root, axes = sk["root"], sk["torso"]
    d = body.as_dict()
    hw, hd = d["torso_half_width"], d["torso_half_depth"]
    sy = -d["shoulder_height"]
    reach = d["shoulder_width"] / 2
    # The belt sits 0.6 of the model torso's length below the root (0.30 m for the default
    # body), scaled with the build; the tracker's torso reaching the hips does not move it.
    belt = 0.6 * d["torso_bottom"]
    g = b.surface(SHIRT, root, axes, belt=belt)
    # (y below the root, half-width, half-depth): sloping shoulders, chest, waist, hips, thighs.
    profile = [
        (sy - 0.075, 0.065, 0.055),
        (sy - 0.05, reach * 0.45, hd * 0.7),
        (sy - 0.025, reach * 0.68, hd * 0.78),
        (sy - 0.005, reach * 0.85, hd * 0.85),
        (sy + 0.03, reach * 0.97, hd * 0.95),
        (sy + 0.12, hw * 1.04, hd * 1.05),
        (0.15, hw * 0.9, hd * 0.95),
        (belt + 0.04, hw * 0.98, hd * 1.0),
        (belt + 0.22, hw * 1.08, hd * 0.95),
        (0.95, hw * 1.05, hd * 0.9),
    ]
    b.trunk = Trunk.from_knots(root, axes, profile, g)


def _head(b: _Builder, sk: dict[str, FloatArray], body: BodyModel, rng: np.random.Generator) -> None:
    d = body.as_dict()
    axes, centre = sk["torso"], sk["model_points"][0]
    radii = np.array(d["head_radii"]) * np.array([1.1, 1.02, 1.05])
    neck = sk["neck_base"]
    skin = b.surface(SKIN, centre, axes)
    top = centre + axes[:, 1] * radii[1] * 0.45 + axes[:, 2] * 0.02
    b.solids.extend(sweep(neck + axes[:, 1] * 0.02, top, axes, (0.064, 0.058), (0.056, 0.052), skin, 0.008))
    head = b.surface(HEAD, centre, axes, radii)
    b.solids.append(Ellipsoid(centre, axes, radii, head))
    for side in (-1.0, 1.0):
        ear = centre + axes[:, 0] * side * radii[0] * 0.93 + axes[:, 1] * 0.005 + axes[:, 2] * 0.01
        b.solids.append(Ellipsoid(ear, axes, np.array([0.014, 0.03, 0.02]), skin))
    hair = b.surface(HAIR, centre, axes, radii)
    volume = 1.0 + 0.08 * float(rng.random())
    hair_centre = centre - axes[:, 1] * 0.018 + axes[:, 2] * 0.02
    b.solids.append(Ellipsoid(hair_centre, axes, radii * np.array([1.06 * volume, 0.97, 1.04]), hair))


def _arm(b: _Builder, sk: dict[str, FloatArray], body: BodyModel, side: str, sleeves: str) -> None:
    d = body.as_dict()
    j = sk["model_points"]
    shoulder, elbow, hand = (j[1], j[3], j[5]) if side == "right" else (j[2], j[4], j[6])
    upper, lower = sk[f"{side}_upper"], sk[f"{side}_lower"]
    ru, rl = d["upper_arm_radii"], d["lower_arm_radii"]
    sleeve = b.surface(SHIRT, shoulder, upper)
    skin = b.surface(SKIN, elbow, lower)
    # `hand` is the middle of the hand; the wrist lies short of the palm centre (the joint).
    palm = sk["joints"][5 if side == "right" else 6]
    wrist = palm - lower[:, 1] * PALM_TO_WRIST * d["lower_arm_length"]
    pad = SLEEVE_PAD
    b.solids.append(Ellipsoid(shoulder, upper, np.full(3, ru[0] + pad), sleeve))
    if sleeves == "short":
        cut = shoulder + (elbow - shoulder) * SHORT_SLEEVE
        rc = ru[0] + (ru[1] - ru[0]) * SHORT_SLEEVE
        b.solids.extend(
            sweep(shoulder, cut, upper, (ru[0] + pad, ru[0] + pad), (rc + pad, rc + pad), sleeve, 0.006, 0.012)
        )
        arm_skin = b.surface(SKIN, shoulder, upper)
        b.solids.extend(sweep(shoulder, elbow, upper, (ru[0], ru[0]), (ru[1], ru[1]), arm_skin))
        b.solids.extend(sweep(elbow, wrist, lower, (rl[0], rl[0]), (rl[1] * 0.8, rl[1] * 0.7), skin))
    else:
        b.solids.extend(sweep(shoulder, elbow, upper, (ru[0] + pad, ru[0] + pad), (ru[1] + pad, ru[1] + pad), sleeve))
        cuff = b.surface(SHIRT, elbow, lower)
        b.solids.extend(
            sweep(elbow, wrist, lower, (rl[0] + pad, rl[0] + pad), (rl[1] + pad * 0.7, rl[1] + pad * 0.7), cuff)
        )
        b.solids.extend(
            sweep(
                wrist - lower[:, 1] * 0.02, wrist, lower, (rl[1] * 0.8, rl[1] * 0.7), (rl[1] * 0.8, rl[1] * 0.7), skin
            )
        )
    # Flat hand centred on the middle of the hand, palm facing the frame's -Z in A-pose.
    b.solids.append(Ellipsoid(hand, lower, np.array([0.043, HAND_HALF_LENGTH, 0.02]), skin))
    outward = -1.0 if side == "right" else 1.0
    thumb = hand - lower[:, 1] * 0.025 + lower[:, 0] * outward * 0.04 - lower[:, 2] * 0.01
    b.solids.append(Ellipsoid(thumb, lower, np.array([0.014, 0.035, 0.014]), skin))


def person_solids(
    pose: Pose, root: npt.ArrayLike, body: BodyModel, appearance: Appearance, rng: np.random.Generator
) -> tuple[list[Ellipsoid], Trunk, list[Surface]]:
    """All solids of the person at `pose`: ellipsoids, the trunk, and their surfaces."""
    sk = skeleton(pose, root, body)
    b = _Builder()
    _trunk(b, sk, body)
    _head(b, sk, body, rng)
    for side in ("right", "left"):
        _arm(b, sk, body, side, appearance.sleeves)
    assert b.trunk is not None
    return b.solids, b.trunk, b.surfaces


class Texture:
    """Seeded procedural textures: fabric, folds, skin and hair variation.

    Every pattern is a sum of sines of the surface's own coordinates (metres), so it moves with
    the body and stays the same from frame to frame.
    """

    def __init__(self, rng: np.random.Generator) -> None:
        self.waves = [
            (rng.normal(size=(n, 3)), rng.uniform(0, 2 * np.pi, n), freq)
            for n, freq in ((6, 9.0), (6, 25.0), (8, 160.0))
        ]
        self.stripe = 0.025 + 0.02 * float(rng.random())
        self.second = rng.uniform(0.45, 0.8)

    def noise(self, p: FloatArray, level: int) -> FloatArray:
        """Smooth noise in [-1, 1] at `(N, 3)` points; level 0 folds, 1 blotches, 2 weave."""
        dirs, phase, freq = self.waves[level]
        return cast(FloatArray, np.sin(p @ dirs.T * freq + phase).mean(axis=1) * 1.6)

    def cloth(self, base: FloatArray, pattern: str, p: FloatArray) -> FloatArray:
        """Shirt albedo `(N, 3)` for pattern at texture-frame points `p`."""
        colour = np.repeat(base[None, :], len(p), axis=0)
        if pattern == "stripes":
            band = (np.floor(p[:, 1] / self.stripe) % 2)[:, None]
            colour = colour * (1 - band) + (colour * self.second + 255 * (1 - self.second) * 0.7) * band
        elif pattern == "checks":
            a = np.sin(p[:, 0] / self.stripe * np.pi) > 0.3
            c = np.sin(p[:, 1] / self.stripe * np.pi) > 0.3
            colour = colour * np.where(a ^ c, self.second, 1.0)[:, None] * np.where(a & c, 0.7, 1.0)[:, None]
        elif pattern == "noise":
            colour = colour * (1.0 + 0.18 * self.noise(p * 3.0, 1))[:, None]
        colour = colour * (1.0 + 0.04 * self.noise(p, 2))[:, None]
        return colour


def shade_person(
    hits: Hits,
    surfaces: list[Surface],
    appearance: Appearance,
    light: Light,
    texture: Texture,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """Colours every person pixel.

    Returns:
        `(M, 3)` float BGR colours of the hit pixels (`hits.pixels` order) and `(M,)` whether
        each shows skin (face, neck, arms, hands).
    """
    colours = np.zeros((len(hits.pixels), 3))
    is_skin = np.zeros(len(hits.pixels), bool)
    skin = np.array(SKIN_TONES[appearance.skin])
    shirt = np.array(SHIRT_COLOURS[appearance.shirt])
    trousers = np.array(TROUSER_COLOURS[appearance.trousers])
    hair = np.array(HAIR_COLOURS[appearance.hair])
    order = np.argsort(hits.group, kind="stable")
    bounds = np.searchsorted(hits.group[order], np.arange(len(surfaces) + 1))
    for index, surf in enumerate(surfaces):
        sel = order[bounds[index] : bounds[index + 1]]
        if len(sel) == 0:
            continue
        p = (hits.point[sel] - surf.origin) @ surf.axes
        n = hits.normal[sel]
        skin_here = np.zeros(len(p), bool)
        if surf.kind == SHIRT:
            albedo = texture.cloth(shirt, appearance.pattern, p)
            below = p[:, 1] > surf.belt
            if below.any():
                albedo[below] = trousers * (1.0 + 0.1 * texture.noise(p[below] * 2.0, 2))[:, None]
            albedo *= (1.0 + 0.12 * texture.noise(p, 0))[:, None]  # folds
        elif surf.kind == SKIN:
            albedo = skin * (1.0 + 0.05 * texture.noise(p, 1))[:, None]
            skin_here[:] = True
        else:
            q = p / surf.radii
            if surf.kind == HAIR:
                albedo = hair * (1.0 + 0.25 * texture.noise(p * np.array([1.0, 0.15, 1.0]), 2))[:, None]
            else:
                face = sample_face(appearance.skin, q[:, 0], q[:, 1])
                alpha = (face[:, 3] * (q[:, 2] < -0.2))[:, None]
                albedo = face[:, :3] * alpha + skin * (1.0 - alpha)
                hairline = (
                    (q[:, 1] < -0.62 + 0.35 * q[:, 0] ** 2)
                    | ((np.abs(q[:, 0]) > 0.82) & (q[:, 1] < 0.05))
                    | (q[:, 2] > 0.1)
                )
                albedo[hairline] = hair
                skin_here = ~hairline
        lambert = np.clip(n @ light.direction, 0.0, 1.0)
        shade = light.ambient + light.diffuse * lambert
        if surf.kind == HEAD:
            shade = 0.5 * shade + 0.5 * (light.ambient + light.diffuse * 0.8)  # the photo has its own light
        colours[sel] = albedo * shade[:, None] * np.array(light.tint)
        is_skin[sel] = skin_here
    return colours, is_skin
