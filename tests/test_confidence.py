"""Per-joint confidence: in [0, 1], high where the skin evidence agrees, low for lost arms and off-image joints."""

from __future__ import annotations

from types import SimpleNamespace

import cv2
import numpy as np
import pytest

from tracker_helpers import TruthFitter, camera_of, clip, truth
from upperpose.features.frame import POINT_ABSENT, POINT_FOUND, POINT_MERGED
from upperpose.fit import Tracker, TrackerConfig
from upperpose.fit.confidence import (
    ELBOW,
    ELBOW_SUPPORTED,
    HAND_SHARES,
    HEAD_SHARES,
    LOST,
    SHOULDER,
    UNSUPPORTED_HAND,
    joint_confidence,
    share,
    support,
)
from upperpose.fit.recovery import hand_distances
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


def test_support_falls_with_the_gap_and_maps_to_measured_shares() -> None:
    assert support(0.0, 120.0) == 1.0
    assert support(30.0, 120.0) == pytest.approx(np.exp(-1.0))
    assert support(None, 120.0) is None
    assert support(60.0, 120.0) < support(30.0, 120.0)  # type: ignore[operator]
    shares = [share(v, HAND_SHARES) for v in (1.0, 0.85, 0.7, 0.1)]
    assert shares == sorted(shares, reverse=True) and shares[0] == HAND_SHARES[0][1]


def test_confidence_follows_the_evidence() -> None:
    f = features([(320, 100), (230, 340), (440, 340)])  # right hand on its blob, left hand 30 px off
    c = joint_confidence(JOINTS, JOINTS, f, hand_distances(JOINTS, f), (), (480, 640))
    assert c[0] == share(1.0, HEAD_SHARES) and c[1] == c[2] == SHOULDER
    assert c[5] == share(1.0, HAND_SHARES) and c[3] == ELBOW_SUPPORTED
    assert c[6] == share(float(np.exp(-1.0)), HAND_SHARES) and c[4] == ELBOW
    assert c[6] < c[5]
    lost = joint_confidence(JOINTS, JOINTS, f, hand_distances(JOINTS, f), ("left_arm",), (480, 640))
    assert lost[4] == lost[6] == LOST and lost[5] == c[5]
    hands_together = features([(320, 100), (230, 340), None], (False, True, False))
    merged = joint_confidence(JOINTS, JOINTS, hands_together, hand_distances(JOINTS, hands_together), (), (480, 640))
    assert merged[5] == merged[6] == UNSUPPORTED_HAND


def test_joints_outside_the_image_have_none() -> None:
    off = JOINTS.copy()
    off[6] = [700.0, 340.0]
    off[0] = [320.0, -3.0]
    f = features([(320, 100), (230, 340), (410, 340)])
    c = joint_confidence(off, JOINTS, f, hand_distances(JOINTS, f), (), (480, 640))
    assert c[6] == 0.0 and c[0] == 0.0 and c[5] == share(1.0, HAND_SHARES)


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
                seen += 1
            else:
                assert r.confidence is None and r.to_record()["confidence"] is None
    assert seen > 10
