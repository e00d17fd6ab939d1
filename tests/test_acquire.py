"""Start-up and re-acquisition from any pose (fit/acquire.py and the tracker's use of it)."""

from __future__ import annotations

import dataclasses
import functools
import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

import upperpose
from tracker_helpers import write_video
from upperpose.exceptions import InputError
from upperpose.features import Background, FeatureExtractor
from upperpose.fit import NO_PERSON, TRACKED, StateMachine, StaticFit, Tracker, TrackerConfig
from upperpose.fit.acquire import agreement, global_fit, restart_seed
from upperpose.fit.outputs import OutputPaths, track_to_files
from upperpose.fit.search import reseeded
from upperpose.fit.startup import any_pose_points, startup_points
from upperpose.io.posefile import load_poses
from upperpose.lab.startup_frames import startup_frames
from upperpose.lab.synth import ClipConfig, ClipPlan, motion_angles, plan_clip, render_frame
from upperpose.lab.synth.scene import clean_plate

FPS = 15.0

# -- the silhouette test ----------------------------------------------------------------------


def test_agreement_of_rectangles() -> None:
    sil = np.zeros((100, 100), np.uint8)
    sil[20:80, 30:50] = 1  # 60 x 20 = 1200 px
    labels = np.zeros_like(sil)
    labels[20:60, 30:60] = 3  # 40 x 30 = 1200 px, 800 of them on the silhouette
    share = agreement(sil, labels, margin=1)  # margin 1: no growth
    assert share.on_silhouette == pytest.approx(800 / 1200)
    # the silhouette above the model's lowest row (row 59) is 40 x 20, all of it under the model
    assert share.explained == pytest.approx(1.0)
    sil[20:60, 0:10] = 1  # an arm's worth of silhouette the model does not reach: 400 px more
    share = agreement(sil, labels, margin=1)
    assert share.explained == pytest.approx(800 / 1200)
    assert agreement(sil, labels, margin=61).explained == pytest.approx(1.0)  # 30 px of growth reach it
    assert not share.passes(0.6, 0.7) and share.passes(0.6, 0.6)
    assert agreement(sil, np.zeros_like(sil)) == type(share)(0.0, 0.0)


def test_a_hand_raised_beside_the_head_is_a_hand() -> None:
    plate = np.full((240, 320, 3), 90, np.uint8)
    frame = plate.copy()
    skin = (110, 140, 200)
    cv2.ellipse(frame, (160, 60), (14, 18), 0, 0, 360, skin, -1)  # the head
    cv2.rectangle(frame, (95, 20), (110, 70), skin, -1)  # the right hand, raised beside it
    cv2.rectangle(frame, (200, 120), (212, 165), skin, -1)  # the left hand, down
    extract = FeatureExtractor(Background.from_plate(plate))
    features = extract(frame)
    face = (146, 44, 28, 32)
    # Without a prediction the highest of the three largest blobs is the head: the raised hand.
    assert features.points_array()[0][0] == pytest.approx(102.5)
    points = any_pose_points(features, face, extract.config).points_array()
    assert np.allclose(points[0], [159.5, 59.5])  # the face centre
    assert 95 <= points[1][0] <= 110 and points[1][1] < 45  # the raised hand's far end, above
    assert 200 <= points[2][0] <= 212 and points[2][1] > 145  # the lowered hand's far end, below
    assert np.all(np.isnan(startup_points(face, features.blobs, extract.config)[1]))  # the A-pose check's: none


@pytest.mark.parametrize(
    "bad",
    [
        {"any_pose_frames": -1},
        {"acquire_restarts": 1.5},
        {"acquire_on_silhouette": 1.2},
        {"acquire_explained": -0.1},
        {"acquire_hand_share": float("nan")},
    ],
)
def test_bad_any_pose_settings_are_refused(bad: dict) -> None:
    with pytest.raises(InputError, match=next(iter(bad))):
        TrackerConfig(**bad)


def test_state_machine_starts_at_once() -> None:
    sm = StateMachine()
    sm.startup(True, False)
    sm.start()
    assert sm.status == TRACKED and sm.has_person
    with pytest.raises(RuntimeError):
        sm.start()


@dataclasses.dataclass
class Call:
    pose: np.ndarray
    mode: str
    parts: tuple[str, ...]
    restart: int


def test_global_fit_keeps_the_lowest_cost_in_the_same_regions() -> None:
    # A double whose cost is the distance of the arms from a target pose; its full-range
    # searches find the target only on the second restart, and the full-range regions make
    # every *searched* fit look 0.5 cheaper, as larger regions do: only the rescoring
    # (parts empty) may decide.
    target = upperpose.Pose.a_pose().angles.copy()
    target[3:8] = [-1.4, 0.0, 1.1, 1.4, 0.0]
    calls: list[Call] = []

    def fit(pose: np.ndarray, root: np.ndarray, mode: str, parts: tuple[str, ...], restart: int) -> Any:
        calls.append(Call(pose.copy(), mode, parts, restart))
        out = pose.copy()
        if mode == "initial" and parts:
            out[3:8] = target[3:8] if restart == 2 else out[3:8] + 0.3
        cost = float(np.abs(out - target).sum()) - (0.5 if parts and mode == "initial" else 0.0)
        return StaticFit(out, root, np.zeros((7, 3)), np.zeros((7, 2)), cost)

    best = global_fit(fit, [upperpose.Pose.a_pose().angles], np.array([0.0, 0.0, 2.0]), restarts=3)
    assert np.allclose(best.pose, target)
    searched = [c for c in calls if c.parts]
    assert [(c.mode, c.restart) for c in searched] == [
        ("trajectory", 0),
        ("initial", 1),
        ("initial", 2),
        ("initial", 3),
    ]
    assert all(c.parts == ("right_arm", "left_arm") for c in searched[1:])
    assert sum(1 for c in calls if not c.parts and c.mode == "initial") == 4  # every candidate rescored
    with pytest.raises(ValueError):
        global_fit(fit, [], np.zeros(3), 1)


def test_restarts_search_with_their_own_seeds() -> None:
    seeds = [restart_seed(7, r) for r in range(4)]
    assert seeds[0] == 7 and len(set(seeds)) == 4 and all(0 <= s < 2**64 for s in seeds)
    assert restart_seed(2**64 - 1, 1) < 2**64
    config = upperpose.SearchConfig(particles=30, threads=2, optimizer="apsopf", sigma=0.5, weights={"edge": 1.0})
    other = reseeded(config, 99)
    names = [n for n in dir(config) if not n.startswith("_")]
    assert other.seed == 99
    assert {n: getattr(other, n) for n in names if n != "seed"} == {n: getattr(config, n) for n in names if n != "seed"}


# -- rendered clips ---------------------------------------------------------------------------


def _plan(angles: np.ndarray, present: np.ndarray) -> ClipPlan:
    """A small clip (320x240, 15 fps, 2 m) with the given angles and presence per frame."""
    config = ClipConfig(frames=len(angles), fps=FPS, width=320, height=240, depth=2.0, seed=5)
    return dataclasses.replace(plan_clip(config), angles=angles, present=present)


def _motion(name: str, frames: int, skip_seconds: float) -> np.ndarray:
    """A motion without the A-pose lead-in, from `skip_seconds` into it (the person is mid-motion)."""
    skip = int(round(skip_seconds * FPS))
    angles = motion_angles(name, frames + skip, FPS, np.random.default_rng([5, 0x5E17]), a_pose_seconds=0.0)
    return angles[skip:]


@functools.lru_cache(maxsize=2)
def _rendered(kind: str) -> tuple[ClipPlan, list[np.ndarray]]:
    if kind == "midstart":
        angles = _motion("wave_right", 20, 1.0)
        present = np.ones(len(angles), bool)
    else:  # the person waves, leaves for two seconds and comes back waving the other hand
        before, away, after = 15, int(2 * FPS), 22
        angles = np.vstack([_motion("wave_right", before + away, 1.0), _motion("wave_left", after, 1.0)])
        present = np.ones(len(angles), bool)
        present[before : before + away] = False
    plan = _plan(angles, present)
    return plan, [render_frame(plan, i)[0] for i in range(len(angles))]


def _track(
    plan: ClipPlan, frames: list[np.ndarray], config: TrackerConfig | None = None
) -> list[upperpose.TrackResult]:
    tracker = Tracker(plan.camera, clean_plate(plan), config or TrackerConfig(), fps=FPS)
    return [tracker.update(frame) for frame in frames]


def _arm_errors(plan: ClipPlan, result: upperpose.TrackResult) -> np.ndarray:
    """Image distances of the fitted elbows and hands from the truth, pixels."""
    truth = upperpose.project(plan.camera, plan.joints_3d(result.frame))
    return np.hypot(*(np.asarray(result.joints_2d)[3:] - truth[3:]).T)


def _shoulder_px(plan: ClipPlan, frame: int) -> float:
    return float(np.hypot(*np.subtract(*upperpose.project(plan.camera, plan.joints_3d(frame))[1:3])))


def _follows(plan: ClipPlan, results: list[upperpose.TrackResult]) -> None:
    """The person's pose, not one that merely covers the silhouette: from the sixth frame on,
    every elbow and hand stays within half a shoulder width of the truth, and over all frames
    a quarter on average. The first frames may still be off: the start-up fit can leave a
    raised arm straight (by up to 0.8 shoulder widths over seeds 0-7) until the trajectory
    search corrects it, within four frames on both clips and every one of those seeds."""
    shoulder = _shoulder_px(plan, results[0].frame)
    errors = np.array([_arm_errors(plan, r) for r in results])
    assert np.all(errors[5:] < shoulder / 2)
    assert float(errors.mean()) < shoulder / 4


def test_a_clip_that_starts_mid_motion_starts_within_15_frames() -> None:
    plan, frames = _rendered("midstart")
    right_z_up, right_x_down = plan.angles[0, 5], plan.angles[0, 6]
    assert right_z_up > 1.0 and right_x_down > 1.0  # waving from the first frame: no A-pose
    results = _track(plan, frames)
    start = next(r.frame for r in results if r.pose is not None)
    assert start < 15
    _follows(plan, results[start:])


def test_without_any_pose_fits_the_a_pose_check_starts_the_waving_clip_wrong() -> None:
    # Why the A-pose fit is put to the test: the raised hand counts as "below" the head, the
    # check passes, and the fit around the A-pose leaves the arm straight.
    plan, frames = _rendered("midstart")
    results = _track(plan, frames, TrackerConfig(any_pose_frames=0))
    start = next(r for r in results if r.pose is not None)
    assert start.frame < 15 and np.max(_arm_errors(plan, start)) > _shoulder_px(plan, start.frame) / 2


def test_a_person_who_leaves_and_comes_back_in_another_pose_is_tracked_again() -> None:
    plan, frames = _rendered("return")
    results = _track(plan, frames)
    back = int(np.flatnonzero(plan.present[15:])[0]) + 15
    assert any(r.status == NO_PERSON for r in results[15:back])  # gone while away
    assert plan.angles[back, 10] > 1.0  # back waving the other hand (left_z_up), not in the A-pose
    regained = next(r.frame for r in results[back:] if r.pose is not None)
    assert regained - back <= FPS  # within a second of the return
    _follows(plan, results[regained:])


def test_startup_frames_of_a_pose_file() -> None:
    statuses = ["no_person", "initialising", "no_person", "initialising", "initialising", "tracked", "lost"]
    poses = {
        "frames": [
            {"frame": i, "status": s, "joints_2d": [[0, 0]] * 7 if s in ("tracked", "lost") else None}
            for i, s in enumerate(statuses)
        ]
    }
    assert startup_frames(poses) == {"face": 1, "stable": 4, "pose": 5}
    assert startup_frames({"frames": [{"frame": 0, "status": "no_person", "joints_2d": None}]}) == {
        "face": None,
        "stable": None,
        "pose": None,
    }


@pytest.mark.parametrize("ends_away", [False, True])
def test_the_pose_file_records_each_start_up_s_body(
    tmp_path: Path, ends_away: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    import upperpose.fit.outputs as outputs

    plan, frames = _rendered("return")
    back = int(np.flatnonzero(plan.present[15:])[0]) + 15
    kept = frames[: back - 5] if ends_away else frames  # the person still away when the video ends
    video = write_video(tmp_path / "clip.mp4", kept, FPS)
    cv2.imwrite(str(tmp_path / "plate.png"), clean_plate(plan))
    drawn: dict[int, dict[str, Any]] = {}

    def draw(frame: np.ndarray, result: upperpose.TrackResult, camera: Any, body: upperpose.BodyModel) -> np.ndarray:
        if result.pose is not None:
            drawn[result.frame] = json.loads(json.dumps(body.as_dict()))
        return frame

    monkeypatch.setattr(outputs, "draw_overlay", draw)
    out = tmp_path / "poses.json"
    track_to_files(
        video,
        OutputPaths(out, bvh=tmp_path / "poses.bvh", overlay=tmp_path / "overlay.mp4"),
        config=TrackerConfig(),
        background=tmp_path / "plate.png",
        focal=plan.camera.focal,
    )
    doc = load_poses(out)
    posed = [f["frame"] for f in doc["frames"] if f.get("angles") is not None]
    starts = [f["frame"] for f in doc["bodies"]]
    assert starts[0] == posed[0]
    if ends_away:
        assert len(starts) == 1
    else:  # measured again when the person came back
        regained = next(p for p in posed if p >= back)
        assert starts == [posed[0], regained]
        assert doc["bodies"][0]["body"] != doc["bodies"][1]["body"]
    # The last posed frame's body, not the averages the tracker returns to when the person leaves.
    averages = json.loads(json.dumps(upperpose.BodyModel().as_dict()))  # as the file holds them
    assert doc["body"] == doc["bodies"][-1]["body"] != averages
    # The overlay draws each frame with the body it was fitted with (it leaves the smoother six
    # frames late, when the tracker may already hold another).
    assert sorted(drawn) == posed
    for frame, body in drawn.items():
        assert body == next(b["body"] for b in reversed(doc["bodies"]) if b["frame"] <= frame)
