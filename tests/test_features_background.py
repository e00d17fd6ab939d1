"""Background estimation without a clean plate: recovers the plate, warns, and what it cannot do."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.exceptions import InputError
from upperpose.features import (
    Background,
    CleanPlateWarning,
    FeatureConfig,
    background_from_video,
    compute_features,
    estimate_background,
)
from upperpose.features.background import (
    iterative_masked_median,
    masked_median,
    median_pair,
    sample_video,
    showing_the_room,
)
from upperpose.features.config import PersonTemplate
from upperpose.features.faces import FaceDetector
from upperpose.features.parallel import THREADS_ENV, worker_count
from upperpose.features.person_cut import find_face, grabcut_seed, person_in_median, with_bare_arms
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
    estimated, cut, _ = iterative_masked_median(frames, FeatureConfig(bg_mask_dilate=5))
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
    estimated = iterative_masked_median(frames, FeatureConfig(bg_mask_dilate=5)).plate
    assert (error(estimated, plate) > 30).sum() > 0.5 * 40 * 40


def reference_masked_median(stack: np.ndarray, foreground: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """Pixel by pixel: the middle (lower for an even count) of the unmasked samples' values."""
    out = fallback.copy()
    for y, x in np.ndindex(*foreground.shape[1:]):
        kept = np.sort(stack[~foreground[:, y, x], y, x], axis=0)
        if len(kept):
            out[y, x] = kept[(len(kept) - 1) // 2]
    return out


@settings(max_examples=25, deadline=None)
@given(
    count=st.integers(1, 9),
    height=st.integers(1, 70),
    seed=st.integers(0, 2**32 - 1),
    masked_share=st.sampled_from([0.0, 0.3, 0.9, 1.0]),
    levels=st.sampled_from([3, 256]),
)
def test_masked_median_is_the_median_of_the_unmasked_samples(count, height, seed, masked_share, levels) -> None:
    # Few levels make ties with the masked values' 255 likely; heights beyond one band of rows
    # check that the bands join up.
    rng = np.random.default_rng(seed)
    stack = np.linspace(0, 255, levels).round().astype(np.uint8)[rng.integers(0, levels, (count, height, 5, 3))]
    foreground = rng.random((count, height, 5)) < masked_share
    fallback = rng.integers(0, 256, (height, 5, 3)).astype(np.uint8)
    expected = reference_masked_median(stack, foreground, fallback)
    np.testing.assert_array_equal(masked_median(stack, foreground, fallback), expected)
    np.testing.assert_array_equal(masked_median(stack, foreground, fallback, median_pair(stack)[1]), expected)
    median, lower = median_pair(stack)
    np.testing.assert_array_equal(median, np.median(stack, axis=0).astype(np.uint8))
    np.testing.assert_array_equal(lower, np.sort(stack, axis=0)[(count - 1) // 2])


def test_the_plate_is_the_same_on_any_number_of_threads(still_person, monkeypatch) -> None:
    frames, _, _ = still_person
    plates = []
    for threads in ("1", "3"):
        monkeypatch.setenv(THREADS_ENV, threads)
        plates.append(iterative_masked_median(frames, FeatureConfig()).plate)
    np.testing.assert_array_equal(plates[0], plates[1])


@pytest.mark.parametrize("value", ["0", "-2", "two", ""])
def test_a_bad_thread_count_is_named(monkeypatch, value) -> None:
    monkeypatch.setenv(THREADS_ENV, value)
    with pytest.raises(InputError, match=THREADS_ENV):
        worker_count()


def test_empty_lead_in_gives_the_plate_and_warns() -> None:
    plate = textured_background(H, W, seed=4)
    frames = moving_square_frames(plate, 60, start=30)
    # The object then stays put for the rest of the clip: only the lead-in shows the plate there.
    frames += [frames[-1]] * 60
    with pytest.warns(CleanPlateWarning, match="clean plate"):
        background = estimate_background(frames[:30], frames[::3])
    assert background.estimated and background.method == "lead-in median"
    assert error(background.plate, plate).max() <= 6


def test_black_first_frames_are_not_the_room() -> None:
    # A webcam's first frames are often black (or a recording fades in): a still, empty
    # lead-in, but not the room that the rest of the video shows.
    plate = textured_background(H, W, seed=4)
    black = np.zeros_like(plate)
    frames = [black] * 12 + moving_square_frames(plate, 60, start=0)
    with pytest.warns(CleanPlateWarning):
        background = estimate_background(frames[:30], frames[::3])
    assert background.method != "lead-in median"
    off = error(background.plate, plate) > 12
    assert np.median(error(background.plate, plate)) <= 2 and off.mean() < 0.2  # a black plate: all off
    kept = showing_the_room(frames[::3], FeatureConfig())
    assert len(kept) == 20 and not any(f is black for f in kept)


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


@pytest.mark.parametrize("count", [7, 50, 123])
def test_sample_video_keeps_the_lead_in_and_every_step_th_frame(tmp_path, count) -> None:
    # The frames between samples are only decoded; the kept ones must be those a full read gives.
    frames = moving_square_frames(textured_background(H, W, seed=8), count, size=20)
    path = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30, (W, H))
    for frame in frames:
        writer.write(frame)
    writer.release()
    capture = cv2.VideoCapture(str(path))
    decoded = []
    while (read := capture.read())[0]:
        decoded.append(read[1])
    config = FeatureConfig(bg_max_samples=10, bg_lead_seconds=0.1)
    lead, samples, fps = sample_video(path, config)
    step = -(-count // 10)
    assert fps == 30 and len(decoded) == count
    assert len(lead) == 3 and all(np.array_equal(a, b) for a, b in zip(lead, decoded[:3]))
    assert len(samples) == len(decoded[::step])
    assert all(np.array_equal(a, b) for a, b in zip(samples, decoded[::step]))


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


def test_the_estimate_marks_where_it_guessed(still_person) -> None:
    # No sample shows the room behind the torso of a person who stands still: the plate there
    # is inpainted, a guess, and is marked so (`Background.unseen`); nothing far from them is.
    frames, persons, _ = still_person
    with pytest.warns(CleanPlateWarning):
        background = estimate_background(frames[:1], frames)
    assert background.unseen is not None
    unseen = background.unseen > 0
    always = np.all(persons, axis=0)
    assert unseen[always].mean() > 0.8
    # Within the samples' masks grown by `bg_mask_dilate` (15 px) and GrabCut's edge.
    near = cv2.dilate(np.any(persons, axis=0).astype(np.uint8), np.ones((41, 41), np.uint8)) > 0
    assert not unseen[~near].any()
    with pytest.warns(CleanPlateWarning):
        assert estimate_background(frames[:1], frames, FeatureConfig(bg_cut_person=False)).unseen is None


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


def test_a_face_under_cool_light_still_anchors_the_person_cut(still_person) -> None:
    # A bluish webcam: the face fails the skin rule in every frame, but the cascade finds it in
    # one place in all of them, so the person who stood there is still cut out of the plate.
    frames, persons, _ = still_person
    cool = [np.clip(f * np.array([1.3, 1.0, 0.75]), 0, 255).astype(np.uint8) for f in frames]
    median = np.median(np.stack(cool), axis=0).astype(np.uint8)
    assert FaceDetector(downscale=1.0)(median)  # the cascade sees the face,
    assert find_face(median, FeatureConfig()) is None  # the skin rule refuses it
    assert person_in_median(median, cool, FeatureConfig(bg_face_steady=0.0)) is None
    found = person_in_median(median, cool, FeatureConfig())
    assert found is not None
    assert (found[np.all(persons, axis=0)] > 0).mean() > 0.9
    assert (found > 0).sum() < 1.6 * np.any(persons, axis=0).sum()
    with pytest.warns(CleanPlateWarning):
        assert estimate_background(cool[:1], cool).method == "masked median, person cut out"


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


def test_bare_arms_held_out_for_the_whole_video_are_cut_out_of_the_plate() -> None:
    # A person who holds the A-pose in every sample: the body template leaves the forearms
    # in the room, so without their skin the plate keeps them and I_sil never sees them.
    plan = plan_clip(ClipConfig("wave_right", 60, seed=9, width=480, height=360, fps=20.0))
    frame, person, _ = render_frame(plan, 0)
    samples = [frame] * 3
    plain_config = FeatureConfig(bg_cut_bare_arms=False)
    plain = person_in_median(frame, samples, plain_config)
    cut = person_in_median(frame, samples, FeatureConfig())
    assert plain is not None and cut is not None
    missed = person & (plain == 0)  # the arms outside the template
    assert missed.sum() > 0.1 * person.sum()
    assert (cut[missed] > 0).mean() > 0.8
    assert ((cut > 0) & ~person).sum() < 0.03 * person.sum()  # and hardly any room

    def arm_in_sil(config: FeatureConfig) -> float:
        plate = iterative_masked_median(samples, config).plate
        sil = compute_features(frame, Background.from_plate(plate, config)).sil > 0
        return float(sil[missed].mean())

    assert arm_in_sil(plain_config) < 0.2
    assert arm_in_sil(FeatureConfig()) > 0.7


def bare_arm_scene() -> tuple[np.ndarray, np.ndarray, tuple[int, int, int, int], dict[str, np.ndarray]]:
    """A face and a torso (the cut-out person) and skin-coloured regions beside them.

    Returns the image, the person mask, the face box and the regions: an arm out from the
    torso's side at chest height, a bar beside the head, a one-pixel line from the torso, and
    a block as large as a door against the other side of the torso.
    """
    rng = np.random.default_rng(0)
    image = np.full((240, 320, 3), (200, 190, 180), np.uint8)
    person = np.zeros(image.shape[:2], np.uint8)
    skin = (120, 150, 210)

    def paint(region: np.ndarray, colour: tuple[int, int, int]) -> None:
        noisy = np.array(colour) + rng.normal(0, 3, (int(region.sum()), 3))
        image[region] = np.clip(noisy, 0, 255).astype(np.uint8)

    def line(start: tuple[int, int], end: tuple[int, int], thickness: int) -> np.ndarray:
        drawn = np.zeros(image.shape[:2], np.uint8)
        cv2.line(drawn, start, end, 255, thickness)
        return (drawn > 0) & (person == 0)

    face = (140, 40, 40, 40)
    person[40:80, 140:180] = 255
    person[80:240, 120:200] = 255
    rows = np.indices(person.shape)[0]
    paint((rows < 80) & (person > 0), skin)
    paint((rows >= 80) & (person > 0), (160, 60, 40))
    regions = {
        "arm": line((200, 110), (260, 180), 16),
        "beside the head": line((180, 55), (240, 55), 16),
        "thin line": line((120, 120), (60, 140), 1),
        "door": np.zeros(image.shape[:2], bool),
    }
    regions["door"][90:240, 20:119] = True
    for region in regions.values():
        paint(region, skin)
    return image, person, face, regions


def test_only_arm_shaped_skin_that_stays_put_is_added_to_the_person() -> None:
    image, person, face, regions = bare_arm_scene()
    added = (with_bare_arms(image, person, face, [image] * 4, FeatureConfig()) > 0) & (person == 0)
    assert added[regions["arm"]].all()
    assert not added[~regions["arm"]].any()  # the bar beside the head, the line, the door
    # An arm that is elsewhere in half the samples: the median sees past it there anyway.
    moved = image.copy()
    moved[regions["arm"]] = (200, 190, 180)
    added = with_bare_arms(image, person, face, [image, image, moved, moved], FeatureConfig()) > 0
    assert not added[regions["arm"]].any()


@pytest.mark.parametrize(
    "field, value",
    [("arm_min_still", 1.5), ("arm_contact", (4.0, 1.5)), ("arm_zone", (float("nan"), 6.0)), ("arm_max_area", -1.0)],
)
def test_bare_arm_settings_are_checked(field, value) -> None:
    with pytest.raises(ValueError, match=field):
        PersonTemplate(**{field: value})


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
        ("blob_shade_spread", -0.01),
        ("blob_shade_spread", float("nan")),
        ("blob_min_room_outline", float("nan")),
    ],
)
def test_person_cut_settings_are_checked(field, value) -> None:
    with pytest.raises(ValueError, match=field):
        FeatureConfig().replace(**{field: value})
