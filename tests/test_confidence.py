"""Per-joint confidence and visibility: high where the evidence agrees; off the image 0; lost arms unobserved."""

from __future__ import annotations

import csv
import json
from types import SimpleNamespace

import cv2
import numpy as np
import pytest

from tracker_helpers import TruthFitter, camera_of, clip, truth
from upperpose.features.frame import POINT_ABSENT, POINT_FOUND, POINT_MERGED
from upperpose.fit import Tracker, TrackerConfig
from upperpose.fit.confidence import (
    EXCESS_LIMIT,
    FIXED,
    JUMP_LIMIT,
    SETTLE_FRAMES,
    TABLES,
    JointConfidence,
    group_share,
    lookup,
    shares,
)
from upperpose.fit.recovery import hand_distances
from upperpose.fit.visibility import inside_image, visibility
from upperpose.io.output import PoseRecorder
from upperpose.io.posefile import load_poses, schema
from upperpose.io.video import VideoReader

# Head, shoulders, elbows, hands of a 640x480 frame (model points equal to the joints here).
JOINTS = np.array([[320, 100], [260, 170], [380, 170], [240, 260], [400, 260], [230, 340], [410, 340]], float)


def features(points: list[tuple[float, float] | None], merged: tuple[bool, bool, bool] = (False, False, False)):  # type: ignore[no-untyped-def]
    """The parts of FrameFeatures that confidence reads: head and hand points and their status."""
    made = [
        None if p is None else SimpleNamespace(xy=p, merged=m, blob=k) for k, (p, m) in enumerate(zip(points, merged))
    ]
    status = np.array([POINT_ABSENT if p is None else POINT_MERGED if p.merged else POINT_FOUND for p in made])
    xy = np.array([[np.nan, np.nan] if p is None else p for p in points], float)
    return SimpleNamespace(head=made[0], points=made, blobs=[], point_status=lambda: status, points_array=lambda: xy)


CALM = {"right_arm": 0.0, "left_arm": 0.0}


def confidence(joints=JOINTS, f=None, lost=(), moved=(), excess=CALM, history=None):  # type: ignore[no-untyped-def]
    f = f if f is not None else features([(320, 100), (230, 340), (440, 340)])
    history = history or JointConfidence()
    return shares(history.groups(joints, JOINTS, f, hand_distances(JOINTS, f), lost, moved, excess, (480, 640)))


def test_tables_fall_with_the_gap_and_stay_in_range() -> None:
    for name, table in TABLES.items():
        shares = [s for _, s in table]
        assert shares == sorted(shares, reverse=True), name
        assert all(0.0 <= s <= 1.0 for s in shares) and table[-1][0] == np.inf, name
    assert lookup(TABLES["hand_settled"], 0.0) == TABLES["hand_settled"][0][1]
    assert lookup(TABLES["hand_settled"], 0.05) == TABLES["hand_settled"][1][1]  # the bound is exclusive
    assert lookup(TABLES["hand_settled"], 5.0) == TABLES["hand_settled"][-1][1]
    assert group_share("shoulder", None) == FIXED["shoulder"]
    with pytest.raises(ValueError, match="needs a gap"):
        group_share("hand_settled", None)
    # At the same gap a settled hand is at least as sure as an unsettled one.
    for gap in (0.0, 0.07, 0.12, 0.17, 0.25, 1.0):
        assert lookup(TABLES["hand_settled"], gap) >= lookup(TABLES["hand_unsettled"], gap)


def test_confidence_follows_the_evidence() -> None:
    # Shoulders 120 px apart: the right hand sits on its blob, the left one is 30 px (0.25 widths) off.
    c = confidence()
    assert c[0] == TABLES["head"][0][1] == 0.97 and c[1] == c[2] == FIXED["shoulder"]
    assert c[5] == TABLES["hand_settled"][0][1] == 0.87 and c[3] == TABLES["elbow_settled"][0][1]
    assert c[6] == lookup(TABLES["hand_settled"], 0.25) == 0.05 and c[4] == TABLES["elbow_settled"][1][1]
    lost = confidence(lost=("left_arm",))
    assert (lost[4], lost[6]) == (FIXED["elbow_lost"], FIXED["hand_lost"]) and lost[5] == c[5]
    hands_together = features([(320, 100), (230, 340), None], (False, True, False))
    merged = confidence(f=hands_together)
    assert merged[5] == FIXED["hand_merged"] and merged[3] == FIXED["elbow_merged"]
    assert merged[6] == FIXED["hand_no_skin"] == 0.0  # the left hand shows no skin
    head_off = confidence(f=features([(320, 130), (230, 340), (410, 340)]))  # 30 px: 0.25 widths
    assert head_off[0] == TABLES["head"][-1][1]


def test_an_arm_is_unsettled_after_a_recovery_a_jump_or_unexplained_silhouette() -> None:
    settled = TABLES["hand_settled"][0][1]
    unsettled = TABLES["hand_unsettled"][0][1]
    history = JointConfidence()
    assert confidence(moved=("right_arm",), history=history)[5] == unsettled
    later = [confidence(history=history)[5] for _ in range(SETTLE_FRAMES)]
    assert later == [unsettled] * (SETTLE_FRAMES - 1) + [settled]  # settled again after SETTLE_FRAMES frames
    assert confidence(excess={"right_arm": EXCESS_LIMIT, "left_arm": 0.0})[5] == unsettled
    history = JointConfidence()
    confidence(history=history)
    jumped = JOINTS + [0.0, JUMP_LIMIT * 120 + 1.0]  # the whole body moved down by more than the limit
    shifted = features([(320, 100 + 19), (230, 340 + 19), (440, 340 + 19)])
    evidence = (jumped, jumped, shifted, hand_distances(jumped, shifted), (), (), CALM, (480, 640))
    model_jump = shares(history.groups(*evidence))
    assert model_jump[5] == unsettled
    history.reset()
    fresh = shares(history.groups(*evidence))
    assert fresh[5] == settled


def test_joints_outside_the_image_have_none_and_are_unobserved() -> None:
    off = JOINTS.copy()
    off[6] = [700.0, 340.0]
    off[0] = [320.0, -3.0]
    off[3] = [-0.5, 479.5]  # on the edge of the outermost pixels: inside
    c = confidence(joints=off, f=features([(320, 100), (230, 340), (410, 340)]))
    assert c[6] == 0.0 and c[0] == 0.0 and c[5] == TABLES["hand_settled"][0][1] and c[3] > 0
    assert list(inside_image(off, (480, 640))) == [False, True, True, True, True, True, False]
    assert visibility(off, (), (480, 640)) == ["unobserved"] + ["observed"] * 5 + ["unobserved"]


def test_a_lost_arms_elbow_and_hand_are_unobserved() -> None:
    assert visibility(JOINTS, ("left_arm",), (480, 640)) == ["observed"] * 4 + ["unobserved", "observed", "unobserved"]
    assert visibility(JOINTS, ("right_arm", "left_arm"), (480, 640)).count("unobserved") == 4
    nan = JOINTS.copy()
    nan[1] = np.nan
    assert visibility(nan, (), (480, 640))[1] == "unobserved"


def test_tracked_frames_carry_confidences_in_range() -> None:
    folder = clip()
    tracker = Tracker(camera_of(folder), cv2.imread(str(folder / "background.png")), TrackerConfig(), fps=15.0,
                      fitter=TruthFitter(truth(folder)))  # fmt: skip
    seen = 0
    with VideoReader(folder / "video.mp4") as reader:
        for frame in reader:
            r = tracker.update(frame)
            if r.status in ("tracked", "lost"):
                assert r.confidence is not None and r.confidence.shape == (7,)
                assert np.all((r.confidence >= 0) & (r.confidence <= 1))
                assert r.to_record()["confidence"] == [round(float(v), 3) for v in r.confidence]
                assert r.to_record()["visibility"] == list(r.visibility or ()) and len(r.visibility or ()) == 7
                seen += 1
            else:
                assert r.confidence is None and r.to_record()["confidence"] is None
                assert r.to_record()["visibility"] is None
    assert seen > 10


def test_a_lost_arm_is_written_whole_and_marked_unobserved(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # The search double puts the right arm overhead on frames 36-47 while the hand is down: the
    # arm is lost (test_tracker.test_real_loss_is_detected_and_recovered). Its elbow and hand are
    # written with their coordinates (the pose stays whole) and marked unobserved.
    folder = clip()
    tracker = Tracker(camera_of(folder), cv2.imread(str(folder / "background.png")), TrackerConfig(), fps=15.0,
                      fitter=TruthFitter(truth(folder), wrong=range(36, 48)))  # fmt: skip
    with VideoReader(folder / "video.mp4") as reader, PoseRecorder(reader.width, reader.height, 15.0) as recorder:
        for frame in reader:
            recorder.add(tracker.update(frame))
        recorder.write_json(tmp_path / "poses.json", 1.0)
        recorder.write_csv(tmp_path / "poses.csv")
    doc = load_poses(tmp_path / "poses.json")
    lost = [f for f in doc["frames"] if f["status"] == "lost"]
    assert lost
    for f in lost:
        assert f["visibility"] == ["observed"] * 3 + ["unobserved", "observed", "unobserved", "observed"]
        assert all(len(p) == 2 and np.all(np.isfinite(p)) for p in f["joints_2d"])
        assert (f["confidence"][3], f["confidence"][5]) == (FIXED["elbow_lost"], FIXED["hand_lost"])
    tracked = [f for f in doc["frames"] if f["status"] == "tracked"]
    assert tracked and all(f["visibility"] == ["observed"] * 7 for f in tracked)
    with (tmp_path / "poses.csv").open() as f:
        rows = {r["frame"]: r for r in csv.DictReader(f)}
    row = rows[str(lost[0]["frame"])]
    assert (row["right_hand_visibility"], row["left_hand_visibility"]) == ("unobserved", "observed")
    assert float(row["right_hand_x"]) == pytest.approx(lost[0]["joints_2d"][5][0], abs=1e-3)
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.validate(json.loads((tmp_path / "poses.json").read_text()), schema())
