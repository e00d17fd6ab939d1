"""What did the image say where a tracked hand is far off? Far-off hands by their skin evidence.

A hand farther than `threshold_px` from the truth either had no usable evidence (no skin of
its own: none at all, a blob shared with the head or the other hand, a hand cut by the border),
misleading evidence (its skin point is itself far from the true hand), or good evidence that the
fit did not follow (its skin point is near the true hand, the model's hand, which the point
measures, far from the point); the rest followed good evidence and still report the palm's
centre far off (where the model puts the palm behind the hand's middle). The cures differ: the
features, the matching, or the search and the body. For the last class it
also counts the frames where the arm was fitted nearly straight at the point and still could not
reach it: no arm shorter than the distance from its shoulder to the camera ray through the
point puts the hand there, so the body's arm is too short from that shoulder.

    python -m upperpose.lab.hand_evidence CLIP_DIR... [--seed S] [--no-plate] [--threshold PX]

CLIP_DIR as for `upperpose.lab.truth_cost` (video.mp4, gt.json, optionally background.png and
meta.json).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import numpy.typing as npt

from upperpose.features import FrameFeatures
from upperpose.fit.fitter import Fitter
from upperpose.fit.pipeline import VideoTracking
from upperpose.fit.tracker import TrackerConfig
from upperpose.lab.truth_cost import clip_inputs
from upperpose.model import BodyModel, Camera, model_points, project
from upperpose.result import TrackResult

FloatArray = npt.NDArray[np.float64]
CLASSES = (
    "no skin",
    "on the head's blob",
    "on the other hand's blob",
    "cut by the border",
    "skin point off",
    "skin point right, fit far",
    "skin point right, fit near it",
)
# Per hand: its skin point's row in `FrameFeatures.points`, and its shoulder, elbow and hand joints.
HANDS = ((1, 1, 3, 5), (2, 2, 4, 6))
# A fitted arm is straight when its hand is this share of its length from the shoulder, and the
# point is beyond its reach when the arm would have to be this much longer.
STRAIGHT, BEYOND = 0.9, 1.05


def ray_distance(camera: Camera, pixel: FloatArray, point: FloatArray) -> float:
    """Distance in metres from the 3D `point` to the camera ray through `pixel` (a pinhole)."""
    direction = np.array([(pixel[0] - camera.cx) / camera.focal, (pixel[1] - camera.cy) / camera.focal, 1.0])
    direction /= np.linalg.norm(direction)
    return float(np.linalg.norm(point - (point @ direction) * direction))


def beyond_reach(camera: Camera, model: FloatArray, arm: tuple[int, int, int], pixel: FloatArray) -> bool:
    """Whether the arm (model points, metres) is fitted straight and still too short to reach `pixel`."""
    shoulder, elbow, hand = (model[j] for j in arm)
    length = float(np.linalg.norm(elbow - shoulder) + np.linalg.norm(hand - elbow))
    if camera.kind != "perspective" or length <= 0 or np.linalg.norm(hand - shoulder) < STRAIGHT * length:
        return False
    return ray_distance(camera, pixel, shoulder) > BEYOND * length


def classify(
    result: TrackResult,
    features: FrameFeatures,
    truth: FloatArray,
    body: BodyModel,
    camera: Camera,
    threshold_px: float,
) -> list[tuple[str, bool]]:
    """(class, beyond the straight arm's reach) of each hand of the frame farther than `threshold_px` from the truth.

    `result`, `truth` (`(7, 2)` pixels), `features` and `camera` in the same image (the
    tracker's working size).
    """
    if result.joints_2d is None or result.pose is None or result.root is None:
        return []
    model = model_points(result.pose, result.root, body)
    fitted = project(camera, model)
    joints = np.asarray(result.joints_2d, dtype=np.float64)
    out = []
    for row, shoulder, elbow, hand in HANDS:
        if float(np.hypot(*(joints[hand] - truth[hand]))) <= threshold_px:
            continue
        point, other, head = features.points[row], features.points[3 - row], features.points[0]
        reach = False
        if point is None:
            kind = "no skin"
        elif point.merged and head is not None and point.blob == head.blob:
            kind = "on the head's blob"
        elif point.merged and other is not None and point.blob == other.blob:
            kind = "on the other hand's blob"
        elif point.merged:
            kind = "cut by the border"
        elif float(np.hypot(*(np.asarray(point.xy) - truth[hand]))) > threshold_px:
            kind = "skin point off"
        elif float(np.hypot(*(fitted[hand] - np.asarray(point.xy)))) > threshold_px:
            kind = "skin point right, fit far"
            reach = beyond_reach(camera, model, (shoulder, elbow, hand), np.asarray(point.xy, dtype=np.float64))
        else:
            kind = "skin point right, fit near it"
        out.append((kind, reach))
    return out


def survey_clip(
    clip: Path, seed: int = 0, plate: bool = True, threshold_px: float = 25.0, fitter: Fitter | None = None
) -> tuple[Counter[str], int]:
    """Tracks a clip; the far-off hands per class (and "beyond reach"), and the hands compared.

    Pixels are the tracker's working size (the video's unless it is larger than that).
    `fitter`: the search (`upperpose.fit_frame` when None).
    """
    truth, focal, background = clip_inputs(clip, plate)
    counts: Counter[str] = Counter()
    compared = 0
    run = VideoTracking(clip / "video.mp4", background, focal=focal, config=TrackerConfig(seed=seed), fitter=fitter)
    try:
        for _, result in run.frames():
            features = run.tracker.features
            if features is None or result.joints_2d is None or result.frame not in truth:
                continue
            compared += 2
            joints = run.work.to_work(np.asarray(result.joints_2d, dtype=np.float64))
            work = dataclasses.replace(result, joints_2d=joints)
            found = classify(
                work,
                features,
                run.work.to_work(truth[result.frame]),
                run.tracker.body,
                run.tracker.camera,
                threshold_px,
            )
            for kind, reach in found:
                counts[kind] += 1
                counts["beyond reach"] += reach
    finally:
        run.close()
    return counts, compared


def report(name: str, counts: Counter[str], compared: int) -> str:
    """One line: far-off hands of the hands compared, then each class with a count."""
    far = sum(counts[k] for k in CLASSES)
    listed = ", ".join(f"{k} {counts[k]}" for k in CLASSES if counts[k])
    reach = f" ({counts['beyond reach']} of them beyond the straight arm's reach)" if counts["beyond reach"] else ""
    return f"{name}: {far} of {compared} hands far off" + (f": {listed}" if listed else "") + reach


def main(argv: list[str] | None = None) -> int:
    """Prints, per clip and over all, the far-off hands by their skin evidence."""
    parser = argparse.ArgumentParser(prog="python -m upperpose.lab.hand_evidence", description=__doc__.split("\n")[0])
    parser.add_argument("clips", type=Path, nargs="+", help="clip folders (video.mp4, gt.json)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-plate", action="store_true")
    parser.add_argument("--threshold", type=float, default=25.0, help="pixels from the truth that count as far off")
    args = parser.parse_args(argv)
    total: Counter[str] = Counter()
    hands = 0
    for clip in args.clips:
        counts, compared = survey_clip(clip, args.seed, not args.no_plate, args.threshold)
        print(report(clip.name, counts, compared), flush=True)
        total += counts
        hands += compared
    if len(args.clips) > 1:
        print(report("all", total, hands))
    return 0


if __name__ == "__main__":
    sys.exit(main())
