"""Arm corrections after a frame's trajectory fit, for arms its windows left in the wrong place.

In turn: lost or doubted arms (`recovery.py` detects them) are searched over their anatomical
ranges (§3.4.9); an arm whose hand is far from its skin evidence is sought from that evidence
(`reach.py`), and when both hands share one blob, from its end that no hand explains; crossed
hands are tried with their skin points' labels swapped. A correction is taken only when it
costs less in the same image regions (`FrameSearch.fair_cost`) and, where the hand is the
evidence, brings the hand nearer it. See docs/tracker.md.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.fit.fitter import FitLike, FrameSearch
from upperpose.fit.reach import ARM_JOINTS, ArmReach, hand_target, shared_blob_ends, unexplained
from upperpose.fit.recovery import ARMS, HAND_JOINT, HAND_POINT
from upperpose.fit.tracker_config import TrackerConfig
from upperpose.model import BodyModel, Camera, model_points, project

FloatArray = npt.NDArray[np.float64]


def nearer_hand_point(
    features: FrameFeatures, new: FitLike, old: FitLike, arm: str, camera: Camera, body: BodyModel
) -> bool:
    """Whether `new` puts the arm's hand nearer its matched (unmerged) skin point than `old`.

    The model's hand is the forearm cone's end (`model_points`), which the skin point measures.
    """
    point = features.points[HAND_POINT[arm]]
    if point is None or point.merged:
        return False
    xy = np.asarray(point.xy)
    joint = HAND_JOINT[arm]
    hands = [project(camera, model_points(f.pose, f.root, body))[joint] for f in (new, old)]
    gap = [float(np.hypot(*(xy - hand))) for hand in hands]
    return gap[0] < gap[1]


class ArmCorrections:
    """Corrects the arms of each frame's fit; keeps the person's reach table between frames.

    Args:
        config: the tracker's settings (`fair_recovery`, `reach_*`, `untangle_*`,
            `recovery_window_scale`).
    """

    def __init__(self, config: TrackerConfig) -> None:
        self.config = config
        self._reach: ArmReach | None = None

    def reset(self) -> None:
        """Forgets the reach table (a new person, or a new body)."""
        self._reach = None

    def correct(
        self, features: FrameFeatures, fit: FitLike, lost: list[str], doubted: list[str], search: FrameSearch
    ) -> tuple[FitLike, FrameFeatures, tuple[str, ...]]:
        """Every correction in turn.

        Returns the fit, the features that go with it (untangling relabels the hands) and the
        arms corrected.
        """
        fit, recovered = self.recover_arms(features, fit, lost, doubted, search)
        fit, reached = self.reach_hands(features, fit, search)
        fit, features, untangled = self.untangle_hands(features, fit, search)
        return fit, features, tuple(dict.fromkeys(recovered + reached + untangled))

    def recover_arms(
        self, features: FrameFeatures, fit: FitLike, lost: list[str], doubted: list[str], search: FrameSearch
    ) -> tuple[FitLike, tuple[str, ...]]:
        """Searches the lost and doubted arms over their anatomical ranges; the lower cost wins.

        Returns the fit to keep and the arms it moved.
        """
        if not (lost or doubted):
            return fit, ()
        wide = search.run(features, np.asarray(fit.pose), np.asarray(fit.root), "initial", tuple(lost + doubted))
        # A stage's cost depends on its region (Sil counts every mismatch inside it, Ratio
        # the silhouette there), and the wide search's regions are larger (everything the
        # arm can reach). Score the trajectory fit in the same regions before comparing.
        if self.config.fair_recovery:
            narrow_cost = search.fair_cost(features, np.asarray(fit.pose), np.asarray(fit.root))
        else:
            narrow_cost = float(fit.cost)
        # A doubted arm's new pose must also bring its hand nearer its skin point: a lower
        # cost alone took pointing arms (07) off to wrong minima.
        if float(wide.cost) < narrow_cost and all(
            nearer_hand_point(features, wide, fit, a, search.camera, search.body) for a in doubted
        ):
            return wide, tuple(lost + doubted)
        return fit, ()

    def reach_hands(
        self, features: FrameFeatures, fit: FitLike, search: FrameSearch
    ) -> tuple[FitLike, tuple[str, ...]]:
        """Seeks each arm whose hand is far from its skin evidence from that evidence.

        When neither moved, the free end of a blob both hands share (`_reach_free_end`).
        Returns the fit to keep and the arms it moved.
        """
        cfg = self.config
        if cfg.reach_candidates <= 0:
            return fit, ()
        camera, body = search.camera, search.body
        moved: list[str] = []
        fair: float | None = None
        for arm in ARMS:
            hands = project(camera, model_points(np.asarray(fit.pose), np.asarray(fit.root), body))
            shoulder_px = max(float(np.hypot(*(hands[1] - hands[2]))), 10.0)
            target = hand_target(features, arm, hands)
            if target is None or not unexplained(hands, target, cfg.reach_share * shoulder_px):
                continue
            root = np.asarray(fit.root)
            best = self._reach_seed(features, np.asarray(fit.pose), root, arm, target, shoulder_px, search)
            if best is None:
                continue
            found = search.run(features, best, root, "trajectory", (arm,), cfg.recovery_window_scale)
            if fair is None:
                fair = search.fair_cost(features, np.asarray(fit.pose), root)
            found_fair = search.fair_cost(features, np.asarray(found.pose), root)
            found_hand = project(camera, model_points(np.asarray(found.pose), root, body))[HAND_JOINT[arm]]
            if found_fair < fair and np.hypot(*(found_hand - target)) < np.hypot(*(hands[HAND_JOINT[arm]] - target)):
                fit, fair = found, found_fair
                moved.append(arm)
        if not moved:
            fit, moved_to_end = self._reach_free_end(features, fit, search)
            moved += moved_to_end
        return fit, tuple(moved)

    def _reach_free_end(self, features: FrameFeatures, fit: FitLike, search: FrameSearch) -> tuple[FitLike, list[str]]:
        """When both hands share one blob and one of its ends has no hand near, seeks either arm there.

        Crossed forearms make one blob; the matching gives both hands its centre, and the model
        keeps each hand on its own side, both hands then at one end (`shared_blob_ends`). Each
        arm is sought from the tabulated pose that puts its hand at the free end and keeps its
        elbow nearest where it is (the forearm swung across), and must end with its elbow within
        `reach_share` shoulder widths of the fit's: forearms side by side also make one blob,
        whose other end is their elbows. The cheaper in the same regions wins, if it costs less
        than the fit.
        """
        camera, body, root = search.camera, search.body, np.asarray(fit.root)
        pose = np.asarray(fit.pose)
        joints = project(camera, model_points(pose, root, body))
        shoulder_px = max(float(np.hypot(*(joints[1] - joints[2]))), 10.0)
        limit = self.config.reach_share * shoulder_px
        free = [end for end in shared_blob_ends(features, joints) if unexplained(joints, end, limit)]
        if len(free) != 1:
            return fit, []
        if self._reach is None:
            self._reach = ArmReach(body)
        best, best_fair, moved = fit, search.fair_cost(features, pose, root), []
        for arm in ARMS:
            elbow = ARM_JOINTS[arm][0]
            seeds = self._reach.candidates(
                arm, pose, root, camera, free[0], 1, limit, 0.15 * shoulder_px, near_elbow=joints[elbow]
            )
            if not seeds:
                continue
            found = search.run(features, seeds[0], root, "trajectory", (arm,), self.config.recovery_window_scale)
            found_fair = search.fair_cost(features, np.asarray(found.pose), root)
            found_elbow = project(camera, model_points(np.asarray(found.pose), root, body))[elbow]
            if found_fair < best_fair and float(np.hypot(*(found_elbow - joints[elbow]))) <= limit:
                best, best_fair, moved = found, found_fair, [arm]
        return best, moved

    def untangle_hands(
        self, features: FrameFeatures, fit: FitLike, search: FrameSearch
    ) -> tuple[FitLike, FrameFeatures, tuple[str, ...]]:
        """Tries the other labelling of the hands' skin points when the fitted arms cross.

        The matching labels the hand blobs by the prediction, so arms that the prediction carried
        past each other (two hands that met and parted) take each other's blobs and stay
        crossed. When both hands hold blobs of their own and the fitted hands lie crossed in the
        image, both arms are also sought from the swapped points (as `reach_hands` does) and
        scored against the swapped features; the lower cost wins, labelling included.

        Returns the fit, the features that go with it and the arms it moved.
        """
        right, left = features.right_hand, features.left_hand
        if (
            not self.config.untangle_hands
            or self.config.reach_candidates <= 0
            or right is None
            or left is None
            or right.merged
            or left.merged
            or right.blob == left.blob
        ):
            return fit, features, ()
        pose, root = np.asarray(fit.pose), np.asarray(fit.root)
        points = project(search.camera, model_points(pose, root, search.body))
        # Facing the camera, the right hand lies left of the left hand in the image.
        if not points[HAND_JOINT["right_arm"]][0] > points[HAND_JOINT["left_arm"]][0]:
            return fit, features, ()
        swapped = dataclasses.replace(features, right_hand=left, left_hand=right)
        shoulder_px = max(float(np.hypot(*(points[1] - points[2]))), 10.0)
        candidate = pose.copy()
        for arm, point in (("right_arm", left), ("left_arm", right)):
            # The labels, not the arms, were wrong: the elbows are where the fit put them, so
            # the pose that keeps this arm's elbow and moves only its hand is tried too.
            seed = self._reach_seed(
                swapped, candidate, root, arm, point.xy, shoulder_px, search, self.config.untangle_refine
            )
            if seed is None:
                return fit, features, ()
            candidate = seed
        found = search.run(swapped, candidate, root, "trajectory", ARMS, self.config.recovery_window_scale)
        mine = search.fair_cost(features, pose, root)
        theirs = search.fair_cost(swapped, np.asarray(found.pose), root)
        if theirs < mine:
            return found, swapped, ARMS
        return fit, features, ()

    def _reach_seed(
        self,
        features: FrameFeatures,
        pose: FloatArray,
        root: FloatArray,
        arm: str,
        target: npt.ArrayLike,
        shoulder_px: float,
        search: FrameSearch,
        refine: int = 0,
    ) -> FloatArray | None:
        """`pose` with `arm` moved to the cheapest pose found from tabulated poses with the hand near `target`.

        The candidates are scored as they are; with `refine` 0 the cheapest is returned. Else
        the `refine` cheapest, and the candidate whose elbow projects nearest `pose`'s own
        elbow (whatever its rank), are each searched in windows widened by
        `recovery_window_scale` and scored again, and the cheapest result is returned. None
        when no tabulated pose reaches the target. The table is made on first use (per body).
        """
        if self._reach is None:
            self._reach = ArmReach(search.body)
        elbow = None
        if refine > 0:
            elbow = project(search.camera, model_points(pose, root, search.body))[ARM_JOINTS[arm][0]]
        seeds = self._reach.candidates(
            arm,
            pose,
            root,
            search.camera,
            target,
            self.config.reach_candidates,
            tolerance_px=0.5 * shoulder_px,
            elbow_spread_px=0.15 * shoulder_px,
            near_elbow=elbow,
        )
        if not seeds:
            return None
        costs = [search.fair_cost(features, seed, root) for seed in seeds]
        if refine <= 0:
            return seeds[int(np.argmin(costs))]
        chosen = list(np.argsort(costs, kind="stable")[:refine])
        if 0 not in chosen:  # `candidates` puts the nearest elbow first
            chosen.append(0)
        best, best_cost = None, np.inf
        for k in chosen:
            found = search.run(features, seeds[k], root, "trajectory", (arm,), self.config.recovery_window_scale)
            cost = search.fair_cost(features, np.asarray(found.pose), root)
            if cost < best_cost:
                best, best_cost = np.array(found.pose, dtype=np.float64), cost
        return best if best is not None else seeds[int(np.argmin(costs))]


__all__ = ["ArmCorrections", "nearer_hand_point"]
