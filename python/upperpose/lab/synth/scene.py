"""One synthetic clip: configuration, true trajectory, and frame-by-frame rendering.

`ClipConfig` fixes everything about a clip; `plan_clip` turns it into the true per-frame pose
and root (and whether the person is in view); `render_frames` yields each finished camera
frame with its exact person and skin masks. The same config and seed give the same bytes.
"""

from __future__ import annotations

import typing
from collections.abc import Iterator
from dataclasses import asdict, dataclass

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.lab.synth.appearance import Appearance, body_for_build
from upperpose.lab.synth.motions import MOTION_DESCRIPTIONS, MOTIONS, min_jerk, motion_angles
from upperpose.lab.synth.person import Light, Texture, person_solids, shade_person
from upperpose.lab.synth.raycast import cast
from upperpose.lab.synth.room import draw_room
from upperpose.model import ANGLE_NAMES, BodyModel, Camera, Pose, forward_kinematics

FloatArray = npt.NDArray[np.float64]
Mask = npt.NDArray[np.bool_]
EMPTY_SECONDS = 1.0  # scene without the person, with --empty-start
WALK_IN_SECONDS = 0.5  # the person walks in from the side
STEP_SECONDS = (2.0, 4.0)  # when the subject steps closer, with --step-closer
STEP_METRES = 0.5


@dataclass(frozen=True)
class ClipConfig:
    """Everything that defines a synthetic clip.

    Attributes:
        motion: a key of `upperpose.lab.synth.MOTIONS`.
        frames: number of frames.
        seed: seeds every random choice (room, looks left unset, speeds, noise).
        width: image width, pixels.
        height: image height, pixels.
        fps: frames per second.
        focal: focal length in pixels; the image width when None (SPEC 3).
        appearance: the person's looks; drawn from the seed when None.
        empty_start: the scene stays empty for a second before the person walks in.
        lighting_ramp: the light dims and recovers over the clip.
        step_closer: the subject steps half a metre towards the camera after two seconds.
        noise: sensor noise, standard deviation in grey levels.
        depth: distance of the body's root from the camera, metres; drawn when None.
        lower: metres the person stands lower than the seed puts them (camera frame, down); with
            a long focal length, 0.2-0.3 at 1 m frames head and shoulders as a webcam does.
    """

    motion: str = "wave_right"
    frames: int = 150
    seed: int = 0
    width: int = 640
    height: int = 480
    fps: float = 30.0
    focal: float | None = None
    appearance: Appearance | None = None
    empty_start: bool = False
    lighting_ramp: bool = False
    step_closer: bool = False
    noise: float = 2.5
    depth: float | None = None
    lower: float = 0.0

    def __post_init__(self) -> None:
        if self.motion not in MOTIONS:
            raise ValueError(f"unknown motion {self.motion!r}; motions are {', '.join(MOTIONS)}")
        if not (isinstance(self.frames, int) and self.frames > 0):
            raise ValueError(f"frames must be a positive integer, got {self.frames!r}")
        if not (
            isinstance(self.width, int) and isinstance(self.height, int) and self.width >= 64 and self.height >= 48
        ):
            raise ValueError(f"image size must be at least 64x48, got {self.width}x{self.height}")
        if not self.fps > 0:
            raise ValueError(f"fps must be positive, got {self.fps}")
        if self.focal is not None and not self.focal > 0:
            raise ValueError(f"focal must be positive, got {self.focal}")
        if not 0 <= self.noise <= 50:
            raise ValueError(f"noise must be within 0..50 grey levels, got {self.noise}")
        if self.depth is not None and not 1.0 <= self.depth <= 6.0:
            raise ValueError(f"depth must be within 1..6 metres, got {self.depth}")
        if not -1.0 <= self.lower <= 1.0:
            raise ValueError(f"lower must be within -1..1 metres, got {self.lower}")


@dataclass(frozen=True)
class ClipPlan:
    """The truth of a clip, decided before any pixel is drawn.

    Attributes:
        config: the clip's configuration.
        appearance: the person's looks.
        body: body dimensions, metres (truth joints use exactly these).
        camera: the camera.
        angles: `(N, 13)` true joint angles, radians.
        roots: `(N, 3)` true root positions, metres, camera frame.
        present: `(N,)` whether the person is in the scene.
        gains: `(N,)` overall light level per frame (1 = the clean plate's).
        light: the directional light.
        texture: the clothes' and skin's procedural texture.
        room: `(H, W, 3)` float32 BGR room at full light.
    """

    config: ClipConfig
    appearance: Appearance
    body: BodyModel
    camera: Camera
    angles: FloatArray
    roots: FloatArray
    present: npt.NDArray[np.bool_]
    gains: FloatArray
    light: Light
    texture: Texture
    room: npt.NDArray[np.float32]

    def joints_3d(self, i: int) -> FloatArray:
        """`(7, 3)` true joints of frame `i`, metres (forward kinematics of its pose)."""
        return forward_kinematics(Pose(self.angles[i]), self.roots[i], self.body)

    def description(self) -> str:
        """A one-line description for meta.json."""
        a, c = self.appearance, self.config
        extras = [
            n
            for n, on in (
                ("empty first second", c.empty_start),
                ("lighting ramp", c.lighting_ramp),
                ("steps closer", c.step_closer),
            )
            if on
        ]
        text = (
            f"{a.build} person, {a.skin} skin, {a.shirt} {a.pattern} shirt with {a.sleeves} sleeves, "
            f"{a.hair.replace('_', ' ')} hair, {MOTION_DESCRIPTIONS[c.motion]}"
        )
        return text + (f" ({', '.join(extras)})" if extras else "")


def plan_clip(config: ClipConfig) -> ClipPlan:
    """Draws every random choice of a clip from its seed and fixes the true trajectory."""
    rng = np.random.default_rng([config.seed, 0x5E17])
    room = draw_room(config.width, config.height, np.random.default_rng([config.seed, 1]))
    appearance = config.appearance or Appearance.random(np.random.default_rng([config.seed, 2]))
    body = body_for_build(appearance.build)
    camera = Camera.for_image(config.width, config.height, config.focal)
    n, fps = config.frames, config.fps
    times = np.arange(n) / fps
    depth = config.depth if config.depth is not None else float(rng.uniform(2.0, 2.5))
    # Head in the upper third: the root sits a little below the optical axis.
    base = np.array([rng.uniform(-0.12, 0.12), rng.uniform(0.1, 0.2) * depth / 2.2 + config.lower, depth])
    roots = np.repeat(base[None, :], n, axis=0)
    roots[:, 0] += 0.012 * np.sin(2 * np.pi * rng.uniform(0.1, 0.25) * times + rng.uniform(0, 6))
    roots[:, 1] += 0.006 * np.sin(2 * np.pi * rng.uniform(0.1, 0.25) * times + rng.uniform(0, 6))
    present = np.ones(n, bool)
    start = 0.0
    if config.empty_start:
        start = EMPTY_SECONDS + WALK_IN_SECONDS
        present[times < EMPTY_SECONDS] = False
        side = -1.0 if rng.random() < 0.5 else 1.0
        walk = min_jerk((times - EMPTY_SECONDS) / WALK_IN_SECONDS)
        roots[:, 0] += side * 1.6 * depth / 2.2 * (1.0 - walk)
    angles = motion_angles(config.motion, n, fps, rng, body, a_pose_seconds=1.0)
    if start > 0:
        shift = int(round(start * fps))
        angles = np.vstack([np.repeat(angles[:1], shift, axis=0), angles])[:n]
        # Walking in: arms swing, settling into the A-pose as the person arrives.
        walking = times < start
        swing = 0.35 * np.sin(2 * np.pi * 1.8 * times[walking])
        settle = min_jerk((times[walking] - EMPTY_SECONDS) / WALK_IN_SECONDS)[:, None]
        stride = angles[walking].copy()
        for side_name, sign in (("right", 1.0), ("left", -1.0)):
            stride[:, ANGLE_NAMES.index(f"{side_name}_x_up")] = sign * swing
            stride[:, ANGLE_NAMES.index(f"{side_name}_z_up")] = 0.2
        angles[walking] = stride * (1.0 - settle) + angles[walking] * settle
    if config.step_closer:
        ramp = min_jerk((times - STEP_SECONDS[0] - start) / (STEP_SECONDS[1] - STEP_SECONDS[0]))
        roots[:, 2] -= STEP_METRES * ramp
    gains = np.ones(n)
    if config.lighting_ramp:
        gains = (
            1.0 - 0.4 * np.sin(np.pi * np.clip((times - start - 1.0) / max(times[-1] - start - 1.0, 1e-9), 0, 1)) ** 2
        )
    direction = np.array([rng.uniform(-0.6, 0.6), rng.uniform(-0.9, -0.4), -0.7])
    light = Light(direction / np.linalg.norm(direction), ambient=float(rng.uniform(0.38, 0.48)))
    texture = Texture(np.random.default_rng([config.seed, 3]))
    return ClipPlan(config, appearance, body, camera, angles, roots, present, gains, light, texture, room)


def finish(image: npt.NDArray[np.float32], noise: float, rng: np.random.Generator) -> npt.NDArray[np.uint8]:
    """The camera's part: lens blur, sensor noise (shot and read), 8-bit quantisation."""
    blurred = cv2.GaussianBlur(image, (0, 0), 0.75)
    if noise > 0:
        shot = np.sqrt(np.clip(blurred, 0, 255) / 128.0)
        blurred = blurred + rng.standard_normal(blurred.shape, dtype=np.float32) * (noise * (0.5 + 0.5 * shot))
    return typing.cast(npt.NDArray[np.uint8], np.clip(blurred + 0.5, 0, 255).astype(np.uint8))


def clean_plate(plan: ClipPlan) -> npt.NDArray[np.uint8]:
    """The scene without the person at the clip's starting light, without sensor noise."""
    return finish(plan.room * np.float32(plan.gains[0]), 0.0, np.random.default_rng(0))


def render_frame(plan: ClipPlan, i: int) -> tuple[npt.NDArray[np.uint8], Mask, Mask]:
    """Frame `i` as the camera delivers it, before video compression.

    Returns:
        `(H, W, 3)` uint8 BGR frame, `(H, W)` person mask, `(H, W)` visible-skin mask.
    """
    c, cam = plan.config, plan.camera
    image = plan.room.copy()
    person = np.zeros((c.height, c.width), bool)
    skin = np.zeros_like(person)
    if plan.present[i]:
        solids, trunk, surfaces = person_solids(
            Pose(plan.angles[i]), plan.roots[i], plan.body, plan.appearance, np.random.default_rng([c.seed, 4])
        )
        hits = cast(solids, c.width, c.height, cam.focal, cam.cx, cam.cy, trunk)
        colours, is_skin = shade_person(hits, surfaces, plan.appearance, plan.light, plan.texture)
        image.reshape(-1, 3)[hits.pixels] = colours
        person, skin = hits.mask(), hits.mask(is_skin)
    image *= np.float32(plan.gains[i])
    return finish(image, c.noise, np.random.default_rng([c.seed, 5, i])), person, skin


def render_frames(plan: ClipPlan) -> Iterator[tuple[npt.NDArray[np.uint8], Mask, Mask]]:
    """`render_frame` for every frame in order."""
    for i in range(plan.config.frames):
        yield render_frame(plan, i)


def config_dict(config: ClipConfig) -> dict[str, object]:
    """The config as plain JSON values."""
    d = asdict(config)
    d["appearance"] = None if config.appearance is None else config.appearance.to_dict()
    return d
