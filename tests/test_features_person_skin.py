"""The person's own skin colour (features/person_skin.py): learnt from the face, used for I_skin."""

from __future__ import annotations

import numpy as np
import pytest

from upperpose import Camera, Pose
from upperpose.features import Background, FeatureConfig, FeatureExtractor
from upperpose.features.person_skin import PersonSkin
from upperpose.features.skin import skin_mask
from upperpose.lab.feature_scene import render_scene, textured_background
from upperpose.model import model_points

CONFIG = FeatureConfig()
# BGR, light to dark (the generic rule's test tones), and cloth that the generic rule takes.
SKIN_TONES = [(180, 200, 240), (120, 150, 200), (70, 100, 150), (40, 60, 100), (25, 40, 70)]
KHAKI, TAN_CLOTH, GREY, WHITE = (110, 150, 170), (70, 130, 160), (128, 128, 128), (225, 225, 222)


def patch(colour: tuple[float, ...], rng: np.random.Generator, size: int = 40) -> np.ndarray:
    values = np.asarray(colour, float)[None, None, :] + rng.normal(0, 2.5, (size, size, 3))
    return np.clip(values, 0, 255).astype(np.uint8)


def learnt(face: np.ndarray, box: tuple[int, int, int, int]) -> PersonSkin:
    model = PersonSkin.from_face(
        face, box, skin_mask(face, CONFIG), CONFIG.person_skin_sigmas, CONFIG.person_skin_min_hue_spread,
        CONFIG.person_skin_min_saturation_spread,
    )  # fmt: skip
    assert model is not None
    return model


@pytest.mark.parametrize("tone", SKIN_TONES)
def test_own_skin_in_shade_passes_and_cloth_does_not(tone: tuple[int, int, int]) -> None:
    rng = np.random.default_rng(sum(tone))
    model = learnt(patch(tone, rng, 100), (0, 0, 100, 100))
    for shade in (1.0, 0.6):  # in the light and in shadow: hue and saturation stay
        assert (model.mask(patch(tuple(shade * v for v in tone), rng)) > 0).mean() > 0.95
    for cloth in (KHAKI, TAN_CLOTH, GREY, WHITE):
        assert (model.mask(patch(cloth, rng)) > 0).mean() < 0.02


def test_dark_skin_in_shadow_the_generic_rule_loses_is_kept() -> None:
    # R - G of dark skin at half the light is 18, under the generic rule's 20.
    rng = np.random.default_rng(3)
    tone = (45, 62, 98)
    model = learnt(patch(tone, rng, 100), (0, 0, 100, 100))
    shaded = patch(tuple(0.5 * v for v in tone), rng)
    assert (skin_mask(shaded, CONFIG) > 0).mean() < 0.5
    assert (model.mask(shaded) > 0).mean() > 0.95


def test_hue_wraps_around_red() -> None:
    # A reddish face whose hues straddle 0/180 is one cluster, not two ends of the scale.
    rng = np.random.default_rng(4)
    face = patch((100, 95, 170), rng, 100)  # BGR with B > G: hue just below 180
    face[::2] = patch((95, 100, 170), rng, 100)[::2]  # G > B: hue just above 0
    model = learnt(face, (0, 0, 100, 100))
    assert model.hue < 4 or model.hue > 176
    assert model.hue_spread < 4


def test_too_few_skin_pixels_learn_nothing() -> None:
    grey = patch(GREY, np.random.default_rng(5), 100)
    assert PersonSkin.from_face(grey, (0, 0, 100, 100), skin_mask(grey, CONFIG), 3.0, 2.0, 12.0) is None
    assert PersonSkin.from_face(grey, (200, 200, 50, 50), np.full((100, 100), 255, np.uint8), 3.0, 2.0, 12.0) is None


@pytest.fixture(scope="module")
def plate() -> np.ndarray:
    return textured_background(480, 640, seed=11)


def face_box(pose: Pose) -> tuple[int, int, int, int]:
    joints = Camera.for_image(640, 480).project(model_points(pose, (0.0, 0.15, 2.2)))
    size = int(0.4 * np.hypot(*(joints[1] - joints[2])))
    return int(joints[0][0] - size / 2), int(joints[0][1] - size / 2), size, size


def test_tan_trousers_beside_a_hand_no_longer_join_its_blob(plate: np.ndarray) -> None:
    pose = Pose.a_pose()
    scene = render_scene(pose, plate, seed=8)
    hand = scene.joints[5]
    frame = scene.frame.copy()
    # Tan cloth (R - G = 30: generic skin) from the hand inwards, as trousers by a hanging hand.
    y0, x0 = int(hand[1]) - 20, int(hand[0]) + 12
    frame[y0 : y0 + 60, x0 : x0 + 60] = patch(TAN_CLOTH, np.random.default_rng(9), 60)
    extract = FeatureExtractor(Background.from_plate(plate))
    clean = extract(scene.frame, scene.joints).right_hand
    assert clean is not None
    generic = extract(frame, scene.joints)
    assert generic.skin[y0 + 30, x0 + 30] > 0
    merged = [b for b in generic.blobs if b.distance_to(hand) == 0.0]
    assert merged and merged[0].bbox[2] > 60

    assert extract.learn_skin(scene.frame, face_box(pose)) is not None
    own = extract(frame, scene.joints)
    assert not own.skin[y0 : y0 + 60, x0 + 8 : x0 + 60].any()
    blob = [b for b in own.blobs if b.distance_to(hand) == 0.0]
    assert blob and blob[0].bbox[2] < 40
    # The hand's point is where it is without the cloth.
    assert own.right_hand is not None and np.hypot(*np.subtract(own.right_hand.xy, clean.xy)) < 2

    extract.forget_skin()
    assert extract(frame, scene.joints).skin[y0 + 30, x0 + 30] > 0


@pytest.mark.parametrize("estimated", [False, True])
def test_room_in_the_persons_skin_colour_stays_out(plate: np.ndarray, estimated: bool) -> None:
    # A wooden panel in the plate of nearly the person's colour: not skin after learning either,
    # whether the plate is a photo or an estimate.
    pose = Pose.a_pose()
    first = render_scene(pose, plate, seed=12)
    tone = first.frame[int(first.joints[0][1]), int(first.joints[0][0])].astype(float)
    room = plate.copy()
    room[30:110, 480:600] = np.clip(tone * 0.9 + (4, -4, 0), 0, 255).astype(np.uint8)
    scene = render_scene(pose, room, seed=13)
    background = Background.from_plate(room, estimated=estimated, method="masked median" if estimated else "given")
    extract = FeatureExtractor(background)
    assert np.array_equal(extract.room_skin, background.skin)  # the generic rule's room skin
    assert extract.learn_skin(scene.frame, face_box(pose)) is not None
    # The room in the person's colour (the panel) and the generic rule's room skin.
    assert extract.room_skin[40:100, 490:590].mean() > 250
    assert not np.any(background.skin & ~extract.room_skin)
    features = extract(scene.frame, scene.joints)
    assert features.skin0[40:100, 490:590].mean() > 200  # its colour is the person's ...
    assert not features.skin[30:110, 480:600].any()  # ... but it is the room's
    assert len(features.blobs) == 3


def test_forgetting_the_persons_skin_leaves_the_generic_rules_room_skin(plate: np.ndarray) -> None:
    pose = Pose.a_pose()
    scene = render_scene(pose, plate, seed=12)
    background = Background.from_plate(plate)
    extract = FeatureExtractor(background)
    assert extract.learn_skin(scene.frame, face_box(pose)) is not None
    assert np.count_nonzero(extract.room_skin) > np.count_nonzero(background.skin)
    extract.forget_skin()
    assert np.array_equal(extract.room_skin, background.skin)


def test_person_skin_can_be_turned_off(plate: np.ndarray) -> None:
    pose = Pose.a_pose()
    scene = render_scene(pose, plate, seed=14)
    extract = FeatureExtractor(Background.from_plate(plate), CONFIG.replace(person_skin=False))
    assert extract.learn_skin(scene.frame, face_box(pose)) is None
    assert extract.person_skin is None


def test_a_face_too_cool_for_the_generic_rule_teaches_its_colour_whole(plate: np.ndarray) -> None:
    # Bluish light: the generic rule finds no skin in the face or at the hands. Learnt from the
    # whole face (start-up took it for its steadiness), the hands are skin again, even against
    # an estimated background.
    def cool(image: np.ndarray) -> np.ndarray:
        return np.clip(image * np.array([1.25, 1.0, 0.7]), 0, 255).astype(np.uint8)

    pose = Pose.a_pose()
    scene = render_scene(pose, plate, seed=16)
    frame, box = cool(scene.frame), face_box(pose)
    x, y, w, h = box
    assert (skin_mask(frame, CONFIG)[y : y + h, x : x + w] > 0).mean() < 0.05
    extract = FeatureExtractor(Background.from_plate(cool(plate), estimated=True, method="masked median"))
    assert extract(frame, scene.joints).right_hand is None
    assert extract.learn_skin(frame, box) is None
    assert extract.learn_skin(frame, box, whole_face=True) is not None
    features = extract(frame, scene.joints)
    for point, joint in ((features.right_hand, 5), (features.left_hand, 6)):
        assert point is not None and np.hypot(*np.subtract(point.xy, scene.joints[joint])) < 10
