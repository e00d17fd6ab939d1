"""The online background (no clean plate): learns the room behind a moving person, keeps the
pixels under the person, follows slow light changes, and its memory does not grow."""

from __future__ import annotations

import warnings

import cv2
import numpy as np
import pytest
from tests.tracker_helpers import TruthFitter, camera_of, clip, clip_frames, truth

import upperpose
from upperpose.exceptions import InputError
from upperpose.features import Background, CleanPlateWarning, FeatureConfig
from upperpose.features.faces import FaceDetector, choose_face
from upperpose.features.online import OnlineBackground, body_region
from upperpose.features.skin import skin_mask
from upperpose.fit import Tracker, TrackerConfig
from upperpose.fit.pipeline import load_background
from upperpose.lab.feature_scene import render_scene, textured_background
from upperpose.lab.synth import ClipConfig, plan_clip, render_frame
from upperpose.model import Pose
from upperpose.result import NO_PERSON, TRACKED

H, W = 240, 320


def error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest channel difference per pixel."""
    return np.abs(a.astype(int) - b.astype(int)).max(axis=2)


def walk(plate: np.ndarray, count: int, x0: float = -0.5, x1: float = 0.5) -> list:
    """The rendered person (short sleeves, noise) crossing the plate from x0 to x1 metres."""
    pose = Pose.a_pose()
    return [
        render_scene(pose, plate, root=(x0 + (x1 - x0) * i / max(count - 1, 1), 0.15, 3.0), seed=i, short_sleeves=True)
        for i in range(count)
    ]


def test_learns_the_room_behind_a_moving_person_and_keeps_the_pixels_under_them() -> None:
    plate = textured_background(H, W, seed=4)
    scenes = walk(plate, 60)
    # Started on the first frame with the person in it and no face known: the person is learnt
    # there, and only the frames after show the room behind them.
    model = OnlineBackground(scenes[0].frame)
    first = scenes[0].mask
    for scene in scenes[1:]:
        changed = (error(scene.frame, model.background.plate) > 15).astype(np.uint8)
        model.learn(scene.frame, scene.mask.astype(np.uint8), changed=changed)
    learnt = model.background.plate
    # The room where the person stood at first and has left is the plate again, near enough
    # not to read as I_sub (the changed pixels are learnt fast, the rest of the person's
    # imprint fades at the slow rate).
    recent = np.logical_or.reduce([s.mask for s in scenes[-30:]]).astype(np.uint8)
    kernel = np.ones((2 * FeatureConfig().bg_online_margin + 1,) * 2, np.uint8)
    uncovered = first & (cv2.dilate(recent, kernel) == 0)  # for 30 frames at least
    assert uncovered.sum() > 1000
    assert (error(learnt, plate)[uncovered] > FeatureConfig().sub_threshold).mean() < 0.05
    # Everywhere else the plate, within the camera noise.
    room = ~np.logical_or.reduce([s.mask for s in scenes])
    assert np.percentile(error(learnt, plate)[room], 95) <= 6


def test_keeps_the_pixels_under_the_person() -> None:
    plate = textured_background(H, W, seed=8)
    scenes = walk(plate, 30, -0.05, 0.05)  # swaying: the torso covers its middle all along
    model = OnlineBackground(scenes[0].frame)
    start = model.mean.copy()
    for scene in scenes[1:]:
        model.learn(scene.frame, scene.mask.astype(np.uint8))
    always = np.logical_and.reduce([s.mask for s in scenes[1:]])
    assert always.sum() > 500
    np.testing.assert_array_equal(model.mean[always], start[always])
    # Beside the person, beyond the margin, the room was learnt (running mean of noisy frames).
    assert model.frames == 30 and model.unseen == 0.0


def test_the_first_frame_leaves_out_the_body_around_a_face_and_inpaints_it() -> None:
    plate = textured_background(H, W, seed=5)
    scene = render_scene(Pose.a_pose(), plate, root=(0.0, 0.15, 3.0), short_sleeves=True)
    head = scene.joints[0]
    face = (round(head[0] - 12), round(head[1] - 12), 24, 24)
    config = FeatureConfig()
    region = body_region((H, W), [face], config)
    assert region[scene.mask].mean() > 0.97  # the A-pose lies in the reach
    model = OnlineBackground(scene.frame, [face], config)
    unseen = model.seen == 0
    assert unseen[scene.mask].mean() > 0.9  # the person is not learnt
    assert 0 < model.unseen < 0.5
    # A pixel never seen is taken as it is the first time it is shown away from the person.
    moved = render_scene(Pose.a_pose(), plate, root=(0.6, 0.15, 3.0), short_sleeves=True)
    model.learn(moved.frame, moved.mask.astype(np.uint8))
    near = cv2.dilate(moved.mask.astype(np.uint8), np.ones((2 * config.bg_online_margin + 3,) * 2, np.uint8)) > 0
    shown = scene.mask & ~near
    assert shown.sum() > 300
    assert np.median(error(model.mean, plate)[shown]) <= 4


def test_follows_a_slow_change_of_light() -> None:
    plate = textured_background(H, W, seed=6)
    rng = np.random.default_rng(0)
    model = OnlineBackground(plate)
    gains = np.linspace(1.0, 0.75, 300)  # a lamp dimming by a quarter over 10 s at 30 fps
    for gain in gains:
        frame = np.clip(plate * gain + rng.normal(0, 2, plate.shape), 0, 255).astype(np.uint8)
        model.learn(frame, None)
    dimmed = np.clip(plate * gains[-1], 0, 255)
    # The mean lags a steady ramp by about 1/rate frames: here 50 frames, 0.04 of the light.
    lag = (gains[-50] - gains[-1]) * plate.astype(float)
    assert np.abs(model.mean - dimmed).mean() <= lag.mean() + 1.0
    assert np.abs(model.mean - dimmed).mean() < 0.25 * np.abs(plate - dimmed).mean()


def test_memory_does_not_grow_with_the_frames() -> None:
    plate = textured_background(H, W, seed=7)
    scenes = walk(plate, 8)
    model = OnlineBackground(scenes[0].frame)
    before = {name: (a.shape, a.nbytes) for name, a in model.arrays().items()}
    mean, seen = model.mean, model.seen
    for i in range(400):
        scene = scenes[i % len(scenes)]
        model.learn(scene.frame, scene.mask.astype(np.uint8), scene.mask.astype(np.uint8))
    after = {name: (a.shape, a.nbytes) for name, a in model.arrays().items()}
    assert after == before
    assert model.mean is mean and model.seen is seen  # updated in place


def test_bad_settings_are_named() -> None:
    with pytest.raises(InputError, match="bg_model"):
        FeatureConfig(bg_model="median")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="bg_online_rate"):
        FeatureConfig(bg_online_rate=0.0)


@pytest.mark.parametrize("model", ["online", "prepass"])
def test_no_plate_warns_and_chooses_the_model(model: str) -> None:
    folder = clip()
    config = FeatureConfig(bg_model=model)  # type: ignore[arg-type]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CleanPlateWarning)
        background, clean = load_background(None, folder / "video.mp4", (H, W), config)
    assert not clean and any(issubclass(w.category, CleanPlateWarning) for w in caught)
    assert (background is None) == (model == "online")


def test_the_tracker_learns_the_room_and_tracks_without_a_plate() -> None:
    folder = clip()
    gt = truth(folder)
    plate = np.asarray(upperpose.io.video.read_background(folder / "background.png", (H, W)))
    tracker = Tracker(camera_of(folder), None, fps=15.0, fitter=TruthFitter(gt))
    assert tracker.learns_background and tracker.background is None
    statuses = [tracker.update(frame).status for frame in clip_frames(folder)]
    assert statuses[0] == NO_PERSON
    start = statuses.index(TRACKED)
    first_person = next(i for i, f in enumerate(gt["frames"]) if f["status"] == "tracked")
    assert start < first_person + 15
    assert statuses[start:].count(TRACKED) >= 0.9 * len(statuses[start:])
    # The clip opens on the empty room: the learnt background is that room, and stays it
    # around the person once they stand in it.
    assert tracker.background is not None and tracker.background.method == "online"
    threshold = FeatureConfig().sub_threshold
    wrong = (error(tracker.background.plate, plate) > threshold).mean()
    compressed = (error(clip_frames(folder)[0], plate) > threshold).mean()  # the video's own loss
    assert wrong < compressed + 0.01, (wrong, compressed)


def test_black_first_frames_do_not_become_the_room() -> None:
    # A webcam's first frames are often black: the model that started from one starts again
    # from the first frame that shows another scene, and the run goes as without them.
    folder = clip()
    gt = truth(folder)
    plate = np.asarray(upperpose.io.video.read_background(folder / "background.png", (H, W)))
    frames = clip_frames(folder)
    runs = []
    for lead in (0, 6):
        tracker = Tracker(camera_of(folder), None, fps=15.0, fitter=TruthFitter(gt))
        black = [tracker.update(np.zeros_like(frames[0])) for _ in range(lead)]
        assert all(r.status == NO_PERSON for r in black)
        runs.append(([tracker.update(frame).status for frame in frames], tracker.background))
    (plain, _), (after_black, background) = runs
    assert after_black.count(TRACKED) >= plain.count(TRACKED) - 2 > 20
    threshold = FeatureConfig().sub_threshold
    assert background is not None and (error(background.plate, plate) > threshold).mean() < 0.05


def ghosted(plate: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`plate` with a shirt-coloured patch in its top-left corner (a ghost of the person), and
    the patch's mask."""
    ghost = np.zeros(plate.shape[:2], bool)
    ghost[10:50, 10:60] = True
    out = plate.copy()
    out[ghost] = (40, 160, 200)
    return out, ghost


def test_an_estimated_plate_goes_on_learning_and_its_ghost_fades() -> None:
    plate = textured_background(H, W, seed=9)
    start, ghost = ghosted(plate)
    config = FeatureConfig()
    estimate = Background.from_plate(start, config, estimated=True, method="masked median")
    model = OnlineBackground.from_estimate(estimate)
    assert model.background.method == "masked median, refined while tracking"
    np.testing.assert_array_equal(model.background.plate, start)
    assert model.unseen == 0.0
    person = np.zeros((H, W), np.uint8)
    person[100:200, 140:200] = 255
    person[30:40, 10:60] = 255  # the person stands over the ghost's lower rows
    changed = ghost.astype(np.uint8) * np.uint8(255)
    for _ in range(30):
        model.learn(plate, person, changed=changed)
    # Frames that differ from the estimate move it at the change rate from the first frame on
    # (the estimate is not young): the ghost fades as 0.9^n; under the person it stays.
    held = cv2.dilate(person, np.ones((2 * config.bg_online_margin + 1,) * 2, np.uint8)) > 0
    faded = ghost & ~held
    expected = plate.astype(np.float32) + (start.astype(np.float32) - plate) * (1 - config.bg_online_change_rate) ** 30
    np.testing.assert_allclose(model.mean[faded], expected[faded], atol=0.01)
    np.testing.assert_array_equal(model.mean[held], start[held].astype(np.float32))
    assert error(model.background.plate, plate)[faded].max() <= 10


@pytest.mark.parametrize(("estimated", "refine"), [(True, True), (True, False), (False, True)])
def test_the_tracker_refines_an_estimated_plate_and_never_a_given_one(estimated: bool, refine: bool) -> None:
    folder = clip()
    gt = truth(folder)
    plate = np.asarray(upperpose.io.video.read_background(folder / "background.png", (H, W)))
    start, ghost = ghosted(plate)
    config = FeatureConfig(bg_refine_estimate=refine)
    background = Background.from_plate(start, config, estimated=estimated, method="masked median")
    tracker = Tracker(camera_of(folder), background, TrackerConfig(features=config), fps=15.0, fitter=TruthFitter(gt))
    assert not tracker.learns_background  # start-up waits as with a plate: no inpainted guess behind the person
    statuses = [tracker.update(frame).status for frame in clip_frames(folder)]
    assert statuses.count(TRACKED) >= 20  # of 50: the clip opens on the empty room
    assert tracker.background is not None
    if estimated and refine:
        assert tracker.background.method == "masked median, refined while tracking"
        assert error(tracker.background.plate, plate)[ghost].mean() < 10  # the patch showed 100+
    else:
        np.testing.assert_array_equal(tracker.background.plate, start)


@pytest.mark.parametrize("gains", [(1.0, 1.0, 1.0), (1.3, 1.0, 0.75)], ids=["neutral", "bluish"])
def test_the_first_frame_leaves_out_a_person_whose_face_fails_the_skin_rule(gains) -> None:
    # Under a bluish webcam's light the face is no longer "skin", but the cascade still finds
    # it: the person standing there from the first frame must not be learnt as the room.
    plan = plan_clip(ClipConfig("wave_right", 20, seed=101, width=W, height=H, fps=15.0))
    frame, person, _ = render_frame(plan, 0)
    frame = np.clip(frame * np.array(gains), 0, 255).astype(np.uint8)
    boxes = FaceDetector()(frame)
    assert boxes
    assert (choose_face(boxes, skin_mask(frame, FeatureConfig())) is None) == (gains != (1.0, 1.0, 1.0))
    tracker = Tracker(upperpose.Camera.perspective(float(W), (W - 1) / 2, (H - 1) / 2), None, fps=15.0)
    tracker.update(frame)
    assert tracker.background is not None
    kept = error(tracker.background.plate, frame)[person] <= FeatureConfig().sub_threshold
    assert kept.mean() < 0.3  # the person's pixels are inpainted, not taken as the room
