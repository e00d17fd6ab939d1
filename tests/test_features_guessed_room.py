"""Where an estimated plate is a guess (no sample showed the room there), its colours are not
room skin: a guess drawn in from a person's outline often has their colours, and as room skin
it would hide the hands held in front of the body. Learning while tracking ends the guess where
the room shows and agrees with it."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from upperpose.exceptions import InputError
from upperpose.features import Background, FeatureConfig, FeatureExtractor, compute_features
from upperpose.features.online import OnlineBackground
from upperpose.lab.feature_scene import SKIN_BGR, textured_background

H, W = 240, 320
GUESS = (slice(60, 200), slice(100, 220))  # where the person stood in every sample
HAND = ((160, 130), (18, 11))  # centre, half axes: a hand held in front of the chest


def scene() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The estimated plate (the guess filled with skin colour), the guess's mask, a frame with a
    blue shirt over the guess and a bare hand on it, and the hand's mask."""
    room = textured_background(H, W, seed=4)
    plate = room.copy()
    plate[GUESS] = SKIN_BGR
    guess = np.zeros((H, W), np.uint8)
    guess[GUESS] = 255
    frame = room.copy()
    frame[GUESS] = (150, 60, 30)  # the shirt
    hand = np.zeros((H, W), np.uint8)
    cv2.ellipse(hand, *HAND, 0, 0, 360, 255, -1)
    frame[hand > 0] = SKIN_BGR
    rng = np.random.default_rng(2)
    frame = np.clip(frame + rng.normal(0, 2, frame.shape), 0, 255).astype(np.uint8)
    return plate, guess, frame, hand > 0


def test_a_hand_over_a_skin_coloured_guess_is_skin() -> None:
    plate, guess, frame, hand = scene()
    as_room = Background.from_plate(plate, estimated=True)
    as_guess = Background.from_plate(plate, estimated=True, unseen=guess)
    assert as_room.skin[guess > 0].all() and not as_guess.skin[guess > 0].any()
    size = FeatureConfig().background_skin_dilate
    beyond = cv2.dilate(guess, np.ones((size, size), np.uint8)) == 0  # the guess's dilated rim aside
    np.testing.assert_array_equal(as_guess.skin[beyond], as_room.skin[beyond])
    # The hand matches the guess's colour, so it differs from the plate nowhere (no I_sub):
    # only the room skin decides.
    hidden = compute_features(frame, as_room)
    shown = compute_features(frame, as_guess)
    assert hidden.skin0[hand].mean() > 0.95
    assert hidden.skin[hand].mean() < 0.05
    assert shown.skin[hand].mean() > 0.8
    assert not shown.skin[(guess > 0) & ~cv2.dilate(hand.astype(np.uint8), np.ones((5, 5))).astype(bool)].any()


def test_a_guess_is_not_room_skin_even_beside_skin_coloured_room() -> None:
    # The price, a documented limit: a sofa beside the person that the guess's rim reaches over
    # is room skin only where the samples showed it.
    plate, guess, _, _ = scene()
    plate[150:240, 200:320] = SKIN_BGR  # the sofa, overlapping the guess's lower right
    background = Background.from_plate(plate, estimated=True, unseen=guess)
    assert background.skin[150:240, 220:320].all()
    assert not background.skin[guess > 0].any()


def test_the_learnt_skin_colour_spares_the_guess_too() -> None:
    plate, guess, frame, _ = scene()
    extract = FeatureExtractor(Background.from_plate(plate, estimated=True, unseen=guess))
    extract.learn_skin(frame, (148, 123, 24, 14), whole_face=True)  # learnt on the hand's skin
    assert extract.person_skin is not None
    assert extract.person_skin.mask(plate, room=True)[guess > 0].mean() > 0.9  # the guess's colour
    assert not extract.room_skin[guess > 0].any()


def test_an_unseen_mask_of_another_size_is_named() -> None:
    plate = textured_background(H, W, seed=1)
    with pytest.raises(InputError, match="unseen"):
        Background.from_plate(plate, unseen=np.zeros((H, W + 1), np.uint8))


def test_learning_ends_the_guess_where_the_room_agrees_with_it() -> None:
    plate, guess, _, _ = scene()
    config = FeatureConfig()
    model = OnlineBackground.from_estimate(Background.from_plate(plate, config, estimated=True, unseen=guess))
    np.testing.assert_array_equal(model.guessed, guess)
    person = np.zeros((H, W), np.uint8)
    person[120:200, 100:160] = 255  # still over the guess's lower left
    changed = np.zeros((H, W), np.uint8)
    changed[60:100, 180:220] = 255  # the room there differs from the guess
    for _ in range(config.bg_online_refresh):
        model.learn(plate, person, changed=changed)
    held = cv2.dilate(person, np.ones((2 * config.bg_online_margin + 1,) * 2, np.uint8)) > 0
    learnt_agreeing = (guess > 0) & ~held & (changed == 0)
    assert not model.guessed[learnt_agreeing].any()
    assert model.guessed[held & (guess > 0)].all()
    assert model.guessed[(changed > 0) & ~held].all()
    # The refreshed plate carries the guess that is left: the skin-coloured room shown where the
    # guess was is room skin now, the rest of the guess is not.
    np.testing.assert_array_equal(model.background.unseen, model.guessed)
    assert model.background.skin[learnt_agreeing].all()
    assert not model.background.skin[model.guessed > 0].any()
