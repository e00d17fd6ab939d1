"""The lab's probe of the cost at the true arm pose (upperpose.lab.truth_cost)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import upperpose
from tracker_helpers import clip, truth
from upperpose.fit import StaticFit, fit_frame
from upperpose.lab.truth_cost import ARMS, TruthCostProbe, arm_angles_for, probe_clip

ROOT = np.array([0.0, 0.1, 2.2])
OVERHEAD = [0.0, 0.0, 2.8, 0.0]  # y_up, x_up, z_up, x_down: the arm raised sideways overhead


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("arm", ["right_arm", "left_arm"])
def test_arm_angles_put_elbow_and_hand_on_the_given_pixels(arm: str, seed: int) -> None:
    camera = upperpose.Camera.for_image(640, 480)
    body = upperpose.BodyModel()
    rng = np.random.default_rng(seed)
    pose = np.zeros(13)
    sl, elbow, hand = ARMS[arm]
    pose[sl] = rng.uniform([-1.0, -0.3, 0.0, 0.0], [1.0, 2.5, 2.5, 2.2])
    target = upperpose.project(camera, upperpose.forward_kinematics(pose, ROOT, body))
    start = pose.copy()
    start[sl] = 0.0
    angles, left = arm_angles_for(start, ROOT, body, camera, arm, target)
    found = start.copy()
    found[sl] = angles
    joints = upperpose.project(camera, upperpose.forward_kinematics(found, ROOT, body))
    assert left < 5.0  # summed over elbow and hand; the probe drops poses left more than 10 px off
    assert np.hypot(*(joints[[elbow, hand]] - target[[elbow, hand]]).T).sum() == pytest.approx(left)
    # The other arm, the torso and the head stay where they were.
    others = [j for j in range(7) if j not in (elbow, hand)]
    assert np.allclose(joints[others], target[others], atol=1e-6)


def _overhead_truth(gt: dict[str, Any], frames: range) -> dict[int, np.ndarray]:
    """The clip's true joints, but with the right arm overhead on `frames` (a wrong truth)."""
    out = {}
    for f in gt["frames"]:
        if f.get("joints_2d") is None:
            continue
        joints = np.asarray(f["joints_2d"], dtype=np.float64)
        if f["frame"] in frames:
            joints = joints.copy()
            joints[[3, 5]] = joints[1] + np.array([[-30.0, -40.0], [-40.0, -95.0]])
        out[f["frame"]] = joints
    return out


def test_a_wrong_truth_costs_more_than_the_fit_of_the_image() -> None:
    folder = clip()
    gt = truth(folder)
    wrong = range(38, 44)
    # The stated arm is drawn in pixels, not from the tracker's measured body: the model's arm
    # reaches it within 16-17 px (elbow and hand summed), still 100 px from the image's arm.
    probe = TruthCostProbe(_overhead_truth(gt, wrong), threshold_px=40.0, max_residual_px=20.0)
    probes = probe_clip(folder, probe=probe)
    assert probes, "the probe should fire where the stated truth is far from the fit"
    assert {p.frame for p in probes} <= set(wrong)
    assert all(p.arm == "right_arm" for p in probes)
    assert all(p.truth_cost > p.fit_cost for p in probes)
    # The arm overhead leaves the image's arm uncovered: the silhouette term says so.
    assert np.mean([p.term_difference["sil"] for p in probes]) > 0


def test_a_wrong_fit_costs_more_than_the_truth() -> None:
    folder = clip()
    gt = truth(folder)
    wrong = range(38, 44)

    def raise_right_arm(features: Any, prediction: Any, root: Any, body: Any, camera: Any, **kw: Any) -> Any:
        fit = fit_frame(features, prediction, root, body, camera, **kw)
        if kw["frame_index"] not in wrong or kw["mode"] != "trajectory":
            return fit
        pose = np.array(fit.pose)
        pose[ARMS["right_arm"][0]] = OVERHEAD
        joints = upperpose.forward_kinematics(pose, fit.root, body)
        return StaticFit(pose, np.array(fit.root), joints, upperpose.project(camera, joints), float(fit.cost))

    true_joints = {f["frame"]: np.asarray(f["joints_2d"]) for f in gt["frames"] if f.get("joints_2d") is not None}
    probe = TruthCostProbe(true_joints, max_residual_px=15.0, search=raise_right_arm)
    probes = probe_clip(folder, probe=probe)
    assert {p.frame for p in probes} & set(wrong)
    assert all(p.truth_cost < p.fit_cost for p in probes if p.frame in wrong)
