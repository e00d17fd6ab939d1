"""Background estimation without a clean plate: recovers the plate, warns, and what it cannot do."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from upperpose.features import (
    CleanPlateWarning,
    FeatureConfig,
    background_from_video,
    compute_features,
    estimate_background,
)
from upperpose.features.background import iterative_masked_median
from upperpose.features.config import PersonTemplate
from upperpose.features.person_cut import find_face, grabcut_seed, person_in_median
from upperpose.lab.feature_scene import textured_background
from upperpose.lab.synth import ClipConfig, plan_clip, render_frame

H, W = 96, 128


def moving_square_frames(plate: np.ndarray, count: int, start: int = 0, size: int = 40) -> list[np.ndarray]:
    """A grey square that moves across the plate from frame `start` on, with camera noise."""
    rng = np.random.default_rng(3)
    frames = []
    for i in range(count):
        frame = plate.astype(np.float64)
        if i >= start:
            x = 5 + (i - start) * (W - size - 10) // max(count - start - 1, 1)
            frame[30 : 30 + size, x : x + size] = (90, 200, 60)
        frames.append(np.clip(frame + rng.normal(0, 2, frame.shape), 0, 255).astype(np.uint8))
    return frames


def error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a.astype(int) - b.astype(int)).max(axis=2)


def test_masked_median_recovers_plate_behind_a_moving_object() -> None:
    plate = textured_background(H, W, seed=2)
    frames = moving_square_frames(plate, 30, size=24)
    plain = np.median(np.stack(frames), axis=0).astype(np.uint8)
    estimated, cut = iterative_masked_median(frames, FeatureConfig(bg_mask_dilate=5))
    assert not cut  # no face: nobody to cut out
    # The plain median is pulled towards the object where it passed; the masked one is not.
    assert error(estimated, plate).mean() < error(plain, plate).mean()
    assert (error(estimated, plate) > 12).sum() < 0.005 * H * W
    assert error(estimated, plate).mean() < 2.5


def test_masked_median_keeps_an_object_that_hardly_moves() -> None:
    # The documented limit: where the object sits in most samples, no median can see behind it.
    plate = textured_background(H, W, seed=3)
    frames = moving_square_frames(plate, 30)
    frames += [frames[15]] * 30
    estimated, _ = iterative_masked_median(frames, FeatureConfig(bg_mask_dilate=5))
    assert (error(estimated, plate) > 30).sum() > 0.5 * 40 * 40


def test_empty_lead_in_gives_the_plate_and_warns() -> None:
    plate = textured_background(H, W, seed=4)
    frames = moving_square_frames(plate, 60, start=30)
    # The object then stays put for the rest of the clip: only the lead-in shows the plate there.
    frames += [frames[-1]] * 60
    with pytest.warns(CleanPlateWarning, match="clean plate"):
        background = estimate_background(frames[:30], frames[::3])
    assert background.estimated and background.method == "lead-in median"
    assert error(background.plate, plate).max() <= 6


def test_person_from_first_frame_falls_back_to_masked_median() -> None:
    plate = textured_background(H, W, seed=5)
    frames = moving_square_frames(plate, 40, start=0)
    with pytest.warns(CleanPlateWarning):
        background = estimate_background(frames[:30], frames)
    assert background.method == "masked median"
    assert (error(background.plate, plate) > 12).sum() < 0.02 * H * W


def test_background_from_video(tmp_path) -> None:
    plate = textured_background(H, W, seed=6)
    frames = moving_square_frames(plate, 50, start=30)
    path = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30, (W, H))
    for frame in frames:
        writer.write(frame)
    writer.release()
    with pytest.warns(CleanPlateWarning):
        background = background_from_video(path)
    assert background.size == (H, W)
    assert np.median(error(background.plate, plate)) < 8  # MJPG loses a little
    given = background_from_video(path, plate=plate)
    assert not given.estimated and np.array_equal(given.plate, plate)


@pytest.fixture(scope="module")
def still_person() -> tuple[list[np.ndarray], list[np.ndarray], np.ndarray]:
    """Ten frames of a person who stands in one place from frame 0 and waves, and the empty room."""
    size = {"width": 480, "height": 360, "fps": 20.0}
    plan = plan_clip(ClipConfig("wave_right", 60, seed=101, **size))
    room, _, _ = render_frame(plan_clip(ClipConfig("wave_right", 60, seed=101, empty_start=True, **size)), 0)
    rendered = [render_frame(plan, i) for i in range(0, 60, 6)]
    return [r[0] for r in rendered], [r[1] for r in rendered], room


def test_person_present_from_the_first_frame_is_cut_out_of_the_plate(still_person) -> None:
    frames, persons, room = still_person
    with pytest.warns(CleanPlateWarning):
        plain = estimate_background(frames[:1], frames, FeatureConfig(bg_cut_person=False))
    with pytest.warns(CleanPlateWarning):
        cut = estimate_background(frames[:1], frames)
    assert plain.method == "masked median" and cut.method == "masked median, person cut out"
    frame, person = frames[5], persons[5]

    def shows_person(plate: np.ndarray) -> float:
        """Share of the person's pixels where the plate looks like the person (I_sub misses them)."""
        return float((error(plate, frame)[person] <= 15).mean())

    def iou(background) -> float:
        sil = compute_features(frame, background).sil > 0
        return float((sil & person).sum() / (sil | person).sum())

    # The plain masked median keeps the torso and head; the cut plate does not.
    assert shows_person(plain.plate) > 0.5
    assert shows_person(cut.plate) < 0.05
    assert np.median(error(cut.plate, room)[person]) < 30  # filled with something like the room
    assert iou(cut) > iou(plain) + 0.25 and iou(cut) > 0.5
    # Away from the person the plate is the room.
    assert np.median(error(cut.plate, room)[~np.any(persons, axis=0)]) <= 4


def test_person_cut_finds_the_person_and_nothing_without_a_face(still_person) -> None:
    frames, persons, _ = still_person
    median = np.median(np.stack(frames), axis=0).astype(np.uint8)
    found = person_in_median(median, frames, FeatureConfig())
    assert found is not None
    always = np.all(persons, axis=0)
    assert (found[always] > 0).mean() > 0.9  # covers where the person always is
    assert (found > 0).sum() < 1.6 * np.any(persons, axis=0).sum()  # and not the room
    room = textured_background(H, W, seed=7)
    assert person_in_median(room, [room] * 3, FeatureConfig()) is None


def test_person_cut_finds_a_person_whose_head_moves_while_the_body_stays(still_person) -> None:
    # A head that nods and turns leaves no face in the median; the chest below the samples'
    # faces is still there and tells where the person stands.
    frames, persons, room = still_person
    median = np.median(np.stack(frames), axis=0).astype(np.uint8)
    face = find_face(frames[0], FeatureConfig())
    assert face is not None
    x, y, w, h = face
    head = (slice(max(y - h // 2, 0), y + h + h // 4), slice(x - w // 2, x + w + w // 2))
    headless = median.copy()
    headless[head] = room[head]
    assert find_face(headless, FeatureConfig()) is None
    found = person_in_median(headless, frames, FeatureConfig())
    assert found is not None
    below = np.zeros(found.shape, bool)
    below[y + 2 * h :, :] = True
    body = np.all(persons, axis=0) & below
    assert (found[body] > 0).mean() > 0.9


def test_person_cut_is_the_same_whatever_the_callers_random_state(still_person) -> None:
    frames, _, _ = still_person
    median = np.median(np.stack(frames), axis=0).astype(np.uint8)

    def draw() -> np.ndarray:
        return cv2.randu(np.zeros((1, 4)), 0.0, 1.0)

    cuts = []
    for seed in (3, 12345):
        cv2.setRNGSeed(seed)
        cuts.append(person_in_median(median, frames, FeatureConfig()))
        after = draw()  # the caller's generator, untouched by the cut
        cv2.setRNGSeed(seed)
        np.testing.assert_array_equal(after, draw())
    assert cuts[0] is not None and cuts[1] is not None
    np.testing.assert_array_equal(cuts[0], cuts[1])


def test_grabcut_seed_nests_its_regions() -> None:
    seed = grabcut_seed((480, 640), (300, 100, 50, 50), PersonTemplate())
    assert seed[125, 325] == cv2.GC_FGD  # face core
    assert seed[250, 325] == cv2.GC_FGD  # chest
    assert seed[400, 325 + 25] == cv2.GC_PR_FGD  # torso
    assert seed[400, 325 + 70] == cv2.GC_PR_BGD  # beside the torso, where an arm may hang
    assert seed[400, 325 + 200] == cv2.GC_BGD and seed[10, 10] == cv2.GC_BGD
    # A face at the bottom edge leaves no chest in view, and still makes a seed.
    low = grabcut_seed((480, 640), (300, 440, 40, 40), PersonTemplate())
    assert (low == cv2.GC_FGD).any() and (low == cv2.GC_BGD).any()


@pytest.mark.parametrize(
    "field, value",
    [
        ("bg_grabcut_scale", 0.5),
        ("bg_grabcut_iterations", 0),
        ("bg_inpaint_radius", 0),
        ("bg_face_min_skin", 1.5),
        ("blob_min_changed", -0.1),
        ("blob_ring", -1),
    ],
)
def test_person_cut_settings_are_checked(field, value) -> None:
    with pytest.raises(ValueError, match=field):
        FeatureConfig().replace(**{field: value})
