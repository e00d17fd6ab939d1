"""Measures the features against a clip folder's truth (docs/dataset.md).

Silhouette IoU, head and hand points, merged blobs, skin precision and recall, skin blobs off the
person.  `python -m upperpose.lab.features_devset DEVSET_DIR [--skin rgb ycrcb hsv]` prints one row per
clip. The prediction given to the point matcher is the previous frame's true joints (a perfect
tracker), so the numbers isolate the features from the tracker. As in the tracker, the person's
skin colour is learnt from the first face found (`FeatureConfig.person_skin`).
"""

from __future__ import annotations

import argparse
import json
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from upperpose.features.background import (
    Background,
    CleanPlateWarning,
    background_from_video,
)
from upperpose.features.config import SKIN_SPACES, FeatureConfig
from upperpose.features.extractor import FeatureExtractor
from upperpose.fit.startup import FaceDetector, choose_face

POINT_JOINTS = (0, 5, 6)  # head, right hand, left hand in JOINT_NAMES
POINT_TOLERANCE = 10.0


@dataclass
class ClipScore:
    """Feature accuracy on one clip.

    Attributes:
        iou: mean I_sil IoU against the true person mask over frames with a person.
        skin_precision, skin_recall: of I_skin against the true skin mask (pooled pixels).
        within: per point (head, right hand, left hand): share of scored frames within
            `POINT_TOLERANCE` px of the truth.
        scored: per point: frames scored (point's true blob not merged, part visible).
        merged_truth: per point: frames whose true blob is merged with another part.
        merged_reported: per point: of those, frames where the features said merged.
        missing: per point: scored frames where no point was found.
        stray_blobs: frames with a skin blob mostly off the person.
    """

    name: str
    method: str
    iou: float = 0.0
    skin_precision: float = 0.0
    skin_recall: float = 0.0
    within: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    scored: list[int] = field(default_factory=lambda: [0, 0, 0])
    merged_truth: list[int] = field(default_factory=lambda: [0, 0, 0])
    merged_reported: list[int] = field(default_factory=lambda: [0, 0, 0])
    missing: list[int] = field(default_factory=lambda: [0, 0, 0])
    median_error: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    stray_blobs: int = 0
    frames: int = 0


def load_masks(path: Path) -> dict[str, npt.NDArray[np.uint8]]:
    """masks.npz as packed rows per name (unpacked frame by frame to save memory)."""
    with np.load(path) as data:
        return {k: data[k] for k in data.files}


def unpack(packed: npt.NDArray[np.uint8], index: int, width: int) -> npt.NDArray[np.bool_]:
    """Frame `index` of a packed `(N, H, ceil(W/8))` mask stack."""
    return np.unpackbits(packed[index], axis=-1, count=width).astype(bool)


def true_merged(skin: npt.NDArray[np.bool_], points: npt.NDArray[np.float64]) -> tuple[list[bool], list[bool]]:
    """Which of head, right hand, left hand share a true skin component, and which are visible.

    A part is visible when a true skin pixel lies within 6 px of its joint; its component is
    the one of the nearest such pixel.
    """
    count, labels = cv2.connectedComponents(skin.astype(np.uint8), connectivity=8)
    del count
    height, width = skin.shape
    comps: list[int] = []
    for x, y in points:
        if not (np.isfinite(x) and np.isfinite(y)):
            comps.append(0)
            continue
        x0, x1 = int(max(x - 6, 0)), int(min(x + 7, width))
        y0, y1 = int(max(y - 6, 0)), int(min(y + 7, height))
        window = labels[y0:y1, x0:x1] if x1 > x0 and y1 > y0 else np.zeros((0, 0), np.int32)
        values, counts = np.unique(window[window > 0], return_counts=True)
        comps.append(int(values[np.argmax(counts)]) if len(values) else 0)
    visible = [c > 0 for c in comps]
    merged = [c > 0 and sum(c == o for o in comps) > 1 for c in comps]
    return merged, visible


def score_clip(folder: Path, config: FeatureConfig, estimated: bool = False) -> ClipScore:
    """Runs the features over a clip and scores them against its truth."""
    gt = json.loads((folder / "gt.json").read_text())
    truth_frames = {f["frame"]: f for f in gt["frames"]}
    masks = load_masks(folder / "masks.npz")
    width = int(masks["shape"][2])
    if estimated:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CleanPlateWarning)
            background = background_from_video(folder / "video.mp4", config)
    else:
        plate = cv2.imread(str(folder / "background.png"), cv2.IMREAD_COLOR)
        background = Background.from_plate(cast(npt.NDArray[np.uint8], plate), config)
    score = ClipScore(folder.name, background.method)
    extract = FeatureExtractor(background, config, reuse_buffers=True)
    detect_faces = FaceDetector()
    capture = cv2.VideoCapture(str(folder / "video.mp4"))
    ious: list[float] = []
    errors: list[list[float]] = [[], [], []]
    skin_tp = skin_fp = skin_fn = 0
    previous_joints = None
    index = 0
    while True:
        ok, frame = capture.read()
        if not ok:
            break
        entry = truth_frames.get(index, {})
        joints = np.asarray(entry["joints_2d"], np.float64) if entry.get("joints_2d") else None
        features = extract(
            cast(npt.NDArray[np.uint8], frame), previous_joints if previous_joints is not None else joints
        )
        if config.person_skin and extract.person_skin is None:
            face = choose_face(detect_faces(cast(npt.NDArray[np.uint8], frame)), features.skin)
            if face is not None:
                extract.learn_skin(cast(npt.NDArray[np.uint8], frame), face)
        person = unpack(masks["person"], index, width)
        skin = unpack(masks["skin"], index, width) if "skin" in masks else None
        sil = features.sil > 0
        if person.any():
            ious.append(float((sil & person).sum() / (sil | person).sum()))
        found = features.skin > 0
        if skin is not None:
            skin_tp += int((found & skin).sum())
            skin_fp += int((found & ~skin).sum())
            skin_fn += int((~found & skin).sum())
        if any(person[b.ys, b.xs].mean() < 0.5 for b in features.blobs):
            score.stray_blobs += 1
        if joints is not None and skin is not None:
            merged, visible = true_merged(skin, joints[list(POINT_JOINTS)])
            for k, point in enumerate(features.points):
                if not visible[k]:
                    continue
                if merged[k]:
                    score.merged_truth[k] += 1
                    score.merged_reported[k] += int(point is not None and point.merged)
                    continue
                score.scored[k] += 1
                if point is None or point.merged:
                    score.missing[k] += 1
                    errors[k].append(np.inf)
                else:
                    errors[k].append(float(np.hypot(*(np.asarray(point.xy) - joints[POINT_JOINTS[k]]))))
        previous_joints = joints
        index += 1
    capture.release()
    score.frames = index
    score.iou = float(np.mean(ious)) if ious else float("nan")
    score.skin_precision = skin_tp / max(skin_tp + skin_fp, 1)
    score.skin_recall = skin_tp / max(skin_tp + skin_fn, 1)
    for k in range(3):
        e = np.asarray(errors[k])
        score.within[k] = float((e <= POINT_TOLERANCE).mean()) if len(e) else float("nan")
        score.median_error[k] = float(np.median(e)) if len(e) else float("nan")
    return score


def main() -> None:
    """Prints per-clip scores for the chosen skin rules, with the clean plate and estimated."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("devset", type=Path)
    parser.add_argument("--skin", nargs="+", default=[FeatureConfig().skin_space], choices=SKIN_SPACES)
    parser.add_argument(
        "--estimated",
        action="store_true",
        help="also score with the estimated background",
    )
    parser.add_argument("--clips", nargs="*", help="clip folder names (default: all)")
    args = parser.parse_args()
    folders = sorted(p for p in args.devset.iterdir() if (p / "gt.json").exists())
    if args.clips:
        folders = [f for f in folders if f.name in args.clips]
    header = (
        f"{'clip':28s} {'skin':5s} {'background':15s} {'IoU':>5s} {'skinP':>5s} {'skinR':>5s} "
        f"{'head':>11s} {'right':>11s} {'left':>11s} {'merged rep/true':>18s} {'stray':>5s}"
    )
    print(header)
    for folder in folders:
        for skin in args.skin:
            config = FeatureConfig(skin_space=skin)
            for estimated in [False, True] if args.estimated else [False]:
                s = score_clip(folder, config, estimated)
                pts = " ".join(f"{100 * w:4.0f}%/{m:4.1f}" for w, m in zip(s.within, s.median_error))
                merged = ",".join(f"{r}/{t}" for r, t in zip(s.merged_reported, s.merged_truth))
                print(
                    f"{s.name:28s} {skin:5s} {s.method:15s} {s.iou:5.3f} {s.skin_precision:5.2f} "
                    f"{s.skin_recall:5.2f} {pts} {merged:>18s} {s.stray_blobs:5d}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
