"""Synthetic clips: exact truth on the rendered body, findable faces, determinism, file layout."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from upperpose import joint_limits
from upperpose.cli import main
from upperpose.io.posefile import load_poses
from upperpose.lab.evaluate import evaluate
from upperpose.lab.synth import (
    DEVSET,
    MOTIONS,
    Appearance,
    ClipConfig,
    load_masks,
    load_meta,
    motion_angles,
    plan_clip,
    render_frame,
    write_clip,
)
from upperpose.lab.synth.appearance import BUILDS, body_for_build
from upperpose.lab.synth.devset import holdout_set
from upperpose.lab.synth.scene import EMPTY_SECONDS, WALK_IN_SECONDS
from upperpose.model import model_points, penetrates

SMALL = {"width": 320, "height": 240}


def first_a_pose_frame(config: ClipConfig) -> int:
    """The first frame showing the person in the start-up A-pose."""
    return int(round((EMPTY_SECONDS + WALK_IN_SECONDS) * config.fps)) if config.empty_start else 0


@pytest.mark.parametrize("name", list(MOTIONS))
def test_motions_stay_inside_the_anatomical_ranges(name: str) -> None:
    angles = motion_angles(name, 300, 30.0, np.random.default_rng(7))
    limits = joint_limits("anatomical")
    for k, intervals in enumerate(limits):
        lo, hi = min(a for a, _ in intervals), max(b for _, b in intervals)
        assert angles[:, k].min() >= lo - 1e-9 and angles[:, k].max() <= hi + 1e-9, name
    speed = np.abs(np.diff(angles, axis=0)).max() * 30.0
    assert speed < 12.0, f"{name} moves at {speed:.1f} rad/s"
    assert not np.allclose(angles[0], angles[-1]) or name in ("cross_arms",)
    np.testing.assert_allclose(angles[0, 5], 0.6, atol=1e-9)  # starts in the A-pose


@pytest.mark.parametrize("name", list(MOTIONS))
def test_motions_keep_the_arms_out_of_the_trunk_and_each_other(name: str) -> None:
    # The tracker may not search where its non-penetration rule fails (SPEC 5): a truth there
    # would score the rule, not the tracker. Every build, since bodies change the clearances.
    root = np.array([0.1, 0.15, 2.3])
    for build in BUILDS:
        body = body_for_build(build)
        angles = motion_angles(name, 360, 60.0, np.random.default_rng(3), body)
        bad = [i for i, a in enumerate(angles) if penetrates(a, root, body)]
        assert not bad, f"{name} ({build}): the arms penetrate on {len(bad)} of 360 frames, first {bad[0]}"


def test_claps_bring_the_hands_together_on_every_build() -> None:
    for build in BUILDS:
        body = body_for_build(build)
        angles = motion_angles("clap", 300, 30.0, np.random.default_rng(5), body)
        gaps = [np.linalg.norm(j[5] - j[6]) for j in (model_points(a, [0, 0, 2.2], body) for a in angles)]
        forearm = sum(body.lower_arm_radii) / 2
        assert 1.3 * forearm < min(gaps) < 1.7 * forearm, build


def test_truth_joints_land_on_the_rendered_body() -> None:
    appearance = Appearance("medium", "red", "plain", "short", "black", "denim", "average")
    for motion, frames in (("wave_right", (0, 70, 80)), ("clap", (50, 60)), ("arms_overhead", (60,)), ("point", (55,))):
        plan = plan_clip(ClipConfig(motion, 90, seed=3, appearance=appearance, noise=0.0))
        for i in frames:
            image, person, skin = render_frame(plan, i)
            px = np.round(plan.camera.project(plan.joints_3d(i))).astype(int)
            for j, (x, y) in enumerate(px):
                assert person[y, x], f"{motion} frame {i}: joint {j} at {(x, y)} is off the body"
            for j in (0, 5, 6):  # head and hands show skin
                x, y = px[j]
                assert skin[y - 1 : y + 2, x - 1 : x + 2].any(), f"{motion} frame {i}: joint {j} not on skin"
    # In the A-pose, the pixel colours say what is there: skin on the hands, the red shirt at the shoulders.
    plan = plan_clip(ClipConfig("wave_right", 5, seed=3, appearance=appearance, noise=0.0))
    image, _, _ = render_frame(plan, 0)
    px = np.round(plan.camera.project(plan.joints_3d(0))).astype(int)
    for j in (5, 6):
        b, g, r = image[px[j][1], px[j][0]].astype(int)
        assert 20 <= r - g <= 80 and r > b, f"hand {j} colour {(b, g, r)} is not skin"
    for j in (1, 2):
        b, g, r = image[px[j][1], px[j][0]].astype(int)
        assert r > 100 and r > 2 * g and r > 2 * b, f"shoulder {j} colour {(b, g, r)} is not the red shirt"


def test_face_detector_finds_every_devset_face() -> None:
    cascade = cv2.CascadeClassifier(cv2.data.haarcascades + "haarcascade_frontalface_default.xml")
    for name, config in DEVSET:
        plan = plan_clip(config)
        i = first_a_pose_frame(config)
        image, _, _ = render_frame(plan, i)
        faces = cascade.detectMultiScale(cv2.cvtColor(image, cv2.COLOR_BGR2GRAY), 1.1, 5, minSize=(20, 20))
        head = plan.camera.project(plan.joints_3d(i))[0]
        hits = [f for f in faces if f[0] <= head[0] <= f[0] + f[2] and f[1] <= head[1] <= f[1] + f[3]]
        assert hits, f"{name}: no face found around the head at {head.round()} (found {list(map(list, faces))})"


def test_holdout_sets_keep_the_recipes_and_draw_new_clips() -> None:
    first, second = holdout_set(1), holdout_set(2)
    assert [n for n, _ in first] == [n for n, _ in DEVSET] == [n for n, _ in second]
    fields = ("motion", "frames", "empty_start", "lighting_ramp", "step_closer", "width", "height", "fps")
    for (_, dev), (_, one), (_, two) in zip(DEVSET, first, second):
        assert all(getattr(dev, f) == getattr(one, f) == getattr(two, f) for f in fields)
        assert len({dev.seed, one.seed, two.seed}) == 3
        assert one.appearance is None
    looks = {plan_clip(c).appearance for _, c in first}
    assert len(looks) >= 10, "the looks are drawn per clip"
    assert not looks & {c.appearance for _, c in DEVSET}
    with pytest.raises(ValueError, match="positive integer"):
        holdout_set(0)


def test_renders_are_deterministic_per_seed() -> None:
    a = plan_clip(ClipConfig("random_walk", 40, seed=5, **SMALL))
    b = plan_clip(ClipConfig("random_walk", 40, seed=5, **SMALL))
    c = plan_clip(ClipConfig("random_walk", 40, seed=6, **SMALL))
    np.testing.assert_array_equal(a.angles, b.angles)
    for i in (0, 39):
        fa, fb, fc = render_frame(a, i)[0], render_frame(b, i)[0], render_frame(c, i)[0]
        assert np.array_equal(fa, fb)
        assert not np.array_equal(fa, fc)
    assert not np.allclose(a.angles, c.angles)


def test_empty_start_has_no_person_then_walks_in() -> None:
    plan = plan_clip(ClipConfig("clap", 60, seed=2, empty_start=True, **SMALL))
    assert not plan.present[:30].any() and plan.present[30:].all()
    _, person, _ = render_frame(plan, 10)
    assert not person.any()
    _, person, _ = render_frame(plan, 50)
    assert person.sum() > 2000


def test_step_closer_and_lighting_ramp() -> None:
    plan = plan_clip(ClipConfig("point", 150, seed=4, step_closer=True, lighting_ramp=True, **SMALL))
    assert plan.roots[0, 2] - plan.roots[-1, 2] == pytest.approx(0.5, abs=0.02)
    assert plan.gains.min() < 0.7 and plan.gains[0] == 1.0


def test_lower_stands_the_person_lower_and_nothing_else() -> None:
    # A webcam's head-and-shoulders framing: the same clip with the person 0.24 m lower. Only the
    # roots' y moves, by exactly that, and each joint's image row by focal * 0.24 / its depth.
    config = ClipConfig("wave_right", 20, seed=5, depth=1.0, focal=860.0, **SMALL)
    high, low = plan_clip(config), plan_clip(dataclasses.replace(config, lower=0.24))
    np.testing.assert_allclose(low.roots - high.roots, np.tile([0.0, 0.24, 0.0], (20, 1)), atol=1e-12)
    np.testing.assert_array_equal(low.angles, high.angles)
    for i in (0, 19):
        a, b = high.joints_3d(i), low.joints_3d(i)
        shift = high.camera.project(b)[:, 1] - high.camera.project(a)[:, 1]
        np.testing.assert_allclose(shift, 860.0 * 0.24 / a[:, 2], rtol=1e-9)
    with pytest.raises(ValueError, match="lower must be within"):
        ClipConfig("wave_right", 20, lower=float("nan"))


def test_clip_folder_layout(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "clip"
    code = main(
        [
            "synth",
            str(out),
            "--motion",
            "drink",
            "--frames",
            "12",
            "--seed",
            "3",
            "--width",
            "320",
            "--height",
            "240",
            "--empty-start",
            "--skin",
            "dark",
        ]
    )
    assert code == 0
    assert {p.name for p in out.iterdir()} == {"video.mp4", "background.png", "gt.json", "meta.json", "masks.npz"}
    meta = load_meta(out)
    assert meta["camera"] == {"focal": 320.0, "cx": 159.5, "cy": 119.5}
    assert meta["appearance"]["skin"] == "dark" and meta["motion"] == "drink" and meta["frames"] == 12
    assert isinstance(meta["description"], str) and "\n" not in meta["description"]
    gt = load_poses(out / "gt.json")
    assert [f["status"] for f in gt["frames"]] == ["no_person"] * 12  # 12 frames < the empty second
    masks = load_masks(out / "masks.npz")
    assert masks["person"].shape == (12, 240, 320) and not masks["person"].any()
    video = cv2.VideoCapture(str(out / "video.mp4"))
    count = 0
    while video.read()[0]:
        count += 1
    assert count == 12
    assert cv2.imread(str(out / "background.png")).shape == (240, 320, 3)


def test_written_truth_matches_masks_and_scores_zero(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    config = ClipConfig("cross_arms", 8, seed=9, **SMALL)
    write_clip(config, tmp_path / "c")
    gt = load_poses(tmp_path / "c" / "gt.json")
    masks = load_masks(tmp_path / "c" / "masks.npz")
    for f, mask in zip(gt["frames"], masks["person"]):
        assert f["status"] == "tracked"
        for x, y in np.round(f["joints_2d"]).astype(int):
            assert mask[y, x]
    assert evaluate(gt, gt).mpjpe_2d_px == 0.0
    assert main(["eval", str(tmp_path / "c" / "gt.json"), str(tmp_path / "c" / "gt.json"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["coverage"] == 1.0
    # Same config, same truth and masks.
    write_clip(config, tmp_path / "d")
    assert (tmp_path / "c" / "gt.json").read_bytes() == (tmp_path / "d" / "gt.json").read_bytes()
    assert (tmp_path / "c" / "masks.npz").read_bytes() == (tmp_path / "d" / "masks.npz").read_bytes()


def test_bad_synth_arguments(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    # Bad option values: argparse's usage line and exit 2, the message naming the option.
    for argv, message in [
        (["--motion", "moonwalk"], "unknown motion 'moonwalk'"),
        (["--frames", "0"], "--frames must be within 1..100000, got 0"),
        (["--holdout", "1"], "--holdout goes with --devset"),
        (["--devset", "--holdout", "-1"], "--holdout must be a positive integer, got -1"),
    ]:
        with pytest.raises(SystemExit) as exc:
            main(["synth", str(tmp_path / "x"), *argv])
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith("usage: upperpose synth") and message in err
    assert not (tmp_path / "x").exists()
    with pytest.raises(ValueError, match="unknown skin"):
        Appearance(skin="green")
