"""How a synthetic person looks: skin tone, clothes, hair and body proportions.

Colours are BGR uint8-range floats (OpenCV's order), the albedo under white light.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from upperpose.model import BodyModel

# Skin tones, light to dark, as BGR albedo. Each keeps R - G inside the 20..80 skin rule of
# SPEC 4 under the renderer's light.
SKIN_TONES: dict[str, tuple[float, float, float]] = {
    "light": (170.0, 190.0, 236.0),
    "medium": (120.0, 155.0, 205.0),
    "tan": (95.0, 130.0, 180.0),
    "brown": (68.0, 95.0, 140.0),
    "dark": (45.0, 62.0, 98.0),
}
SHIRT_COLOURS: dict[str, tuple[float, float, float]] = {
    "red": (35.0, 30.0, 200.0),
    "blue": (160.0, 90.0, 40.0),
    "green": (70.0, 130.0, 50.0),
    "grey": (130.0, 130.0, 130.0),
    "white": (225.0, 225.0, 222.0),
    "navy": (80.0, 40.0, 25.0),
    "yellow": (40.0, 200.0, 225.0),
    "purple": (120.0, 50.0, 95.0),
    "black": (35.0, 35.0, 38.0),
    "teal": (140.0, 130.0, 30.0),
}
HAIR_COLOURS: dict[str, tuple[float, float, float]] = {
    "black": (22.0, 22.0, 25.0),
    "dark_brown": (25.0, 38.0, 55.0),
    "brown": (40.0, 65.0, 100.0),
    "blond": (60.0, 125.0, 175.0),
    "grey": (115.0, 115.0, 120.0),
}
TROUSER_COLOURS: dict[str, tuple[float, float, float]] = {
    "denim": (110.0, 70.0, 45.0),
    "black": (30.0, 30.0, 32.0),
    "khaki": (110.0, 150.0, 170.0),
    "grey": (90.0, 90.0, 95.0),
}
PATTERNS = ("plain", "stripes", "checks", "noise")
SLEEVES = ("short", "long")
BUILDS = ("average", "slim", "broad", "small", "tall")


@dataclass(frozen=True)
class Appearance:
    """The looks of one synthetic person.

    Attributes:
        skin: a key of `SKIN_TONES`.
        shirt: a key of `SHIRT_COLOURS`.
        pattern: one of `PATTERNS`.
        sleeves: "short" or "long".
        hair: a key of `HAIR_COLOURS`.
        trousers: a key of `TROUSER_COLOURS`.
        build: one of `BUILDS`: the body proportions (see `body_for_build`).
    """

    skin: str = "medium"
    shirt: str = "blue"
    pattern: str = "plain"
    sleeves: str = "short"
    hair: str = "dark_brown"
    trousers: str = "denim"
    build: str = "average"

    def __post_init__(self) -> None:
        for field, allowed in (
            ("skin", SKIN_TONES),
            ("shirt", SHIRT_COLOURS),
            ("pattern", PATTERNS),
            ("sleeves", SLEEVES),
            ("hair", HAIR_COLOURS),
            ("trousers", TROUSER_COLOURS),
            ("build", BUILDS),
        ):
            value = getattr(self, field)
            if value not in allowed:
                raise ValueError(f"unknown {field} {value!r}; choose from {', '.join(allowed)}")

    @classmethod
    def random(cls, rng: np.random.Generator) -> Appearance:
        """A random appearance drawn from `rng`."""

        def pick(options: object) -> str:
            keys = list(options)  # type: ignore[call-overload]
            return str(keys[int(rng.integers(len(keys)))])

        return cls(
            pick(SKIN_TONES), pick(SHIRT_COLOURS), pick(PATTERNS), pick(SLEEVES),
            pick(HAIR_COLOURS), pick(TROUSER_COLOURS), pick(BUILDS),
        )  # fmt: skip

    def to_dict(self) -> dict[str, str]:
        """Field name to value, for meta.json."""
        return asdict(self)


def body_for_build(build: str) -> BodyModel:
    """The body dimensions (metres) of a build, scaled from the adult averages.

    Raises:
        ValueError: unknown build.
    """
    # (overall length scale, width scale, limb length scale)
    scales = {
        "average": (1.0, 1.0, 1.0),
        "slim": (1.0, 0.88, 1.02),
        "broad": (1.03, 1.14, 1.0),
        "small": (0.9, 0.92, 0.92),
        "tall": (1.07, 1.0, 1.08),
    }
    if build not in scales:
        raise ValueError(f"unknown build {build!r}; choose from {', '.join(scales)}")
    length, width, limb = scales[build]
    d = BodyModel().as_dict()
    d["shoulder_width"] *= width * length
    d["torso_half_width"] *= width * length
    d["torso_half_depth"] *= width * length
    d["shoulder_height"] *= length
    d["torso_top"] *= length
    d["torso_bottom"] *= length
    d["head_offset"] *= length
    d["neck_length"] *= length
    d["head_radii"] = [r * (0.5 + 0.5 * length) for r in d["head_radii"]]
    d["upper_arm_length"] *= limb * length
    d["lower_arm_length"] *= limb * length
    d["upper_arm_radii"] = [r * width for r in d["upper_arm_radii"]]
    d["lower_arm_radii"] = [r * width for r in d["lower_arm_radii"]]
    return BodyModel(**d)
