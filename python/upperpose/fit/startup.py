"""Start-up (thesis §3.3, SPEC 6): find a frontal face, check the A-pose, measure the person.

(Start-up from any other pose is `upperpose.fit.acquire`; its head and hand points are
`any_pose_points` here.)

A person is present when OpenCV's frontal Haar cascade finds a face and three skin blobs (head,
two hands) pass the geometry of Eq. 3.3.1-1: r_d = min(d1, d2) / max(d1, d2) >= 0.6 and
3 <= d3 / face width <= 12. The face detector runs only while no person is tracked.

Measuring (SPEC 2): the body model stays metric. The depth of the root comes from the width of
the face box, whose metric size was measured on the synthetic development set (FACE_WIDTH_M);
X and Y from the face centre. Starting from adult averages, the arm lengths are scaled by the
ratio of the measured to the modelled shoulder-to-hand distance in the A-pose (mean of the two
arms; when they disagree by more than 0.15 the one nearer 1; clamped to +-20 % so that one bad
blob cannot make a giant). The shoulder width can be
measured from the silhouette (`measure_body(silhouette=...)`) but is not by default (see there):
the tracker chooses the width, then the head's height above the shoulders, by fitting the
start-up frame with each candidate (`fit_bodies`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError
from upperpose.features import FeatureConfig, FrameFeatures, SkinBlob, SkinPoint
from upperpose.features.faces import FaceBox, FaceDetector, choose_face, face_centre
from upperpose.features.points import far_end, principal_direction, unit
from upperpose.model import BodyModel, Camera, Pose, model_points, project, render_masks

# Width of OpenCV's frontal-face box in metres, as found at 1.5x downscale on the dev set's
# start-up frames (single frames vary by about +-8 %: use a median over several frames).
FACE_WIDTH_M = 0.166
# How far from the face a hand may be, in face widths: the default body's hands hang 5.6 face
# widths from its face in the A-pose; a body 20 % larger (start-up's clamp) seen with a face box
# 8 % small (the box's spread over frames) puts them at 7.3.
HAND_REACH_FACES = 8.0
# The dimensions scaled together as the body's width.
WIDTH_KEYS: tuple[Literal["shoulder_width", "torso_half_width", "torso_half_depth"], ...] = (
    "shoulder_width",
    "torso_half_width",
    "torso_half_depth",
)
# Joint indices (JOINT_NAMES order).
HEAD, R_SHOULDER, L_SHOULDER, R_ELBOW, L_ELBOW, R_HAND, L_HAND = range(7)


def hand_candidates(face: FaceBox, blobs: list[SkinBlob], below: bool = True) -> list[int]:
    """Indices of the blobs that may be hands.

    Blobs clear of the face box, whose centroid lies within `HAND_REACH_FACES` face widths of
    the face and which are at most 2.5 face areas (a bare forearm and hand is about one; a
    skin-coloured shirt or khaki trousers are one huge blob); with `below`, only those whose
    centroid lies below the face (the A-pose).
    """
    x, y, w, h = face
    head = face_centre(face)
    out = []
    for index, blob in enumerate(blobs):
        cx, cy = blob.centroid
        bx, by, bw, bh = blob.bbox
        overlaps = bx < x + w and bx + bw > x and by < y + h and by + bh > y
        far = np.hypot(cx - head[0], cy - head[1]) > HAND_REACH_FACES * w
        if not (overlaps or far or (below and cy < head[1] + 0.5 * w) or blob.area > 2.5 * w * h):
            out.append(index)
    return out


def hand_blobs(face: FaceBox, blobs: list[SkinBlob], below: bool = True) -> dict[int, int]:
    """The hand blob on each side of the face: point slot (1 right, 2 left) -> blob index.

    On each side of the face the largest of the `hand_candidates` is the hand.
    """
    head = face_centre(face)
    sides: dict[int, int] = {}
    for index in hand_candidates(face, blobs, below):
        slot = 1 if blobs[index].centroid[0] < head[0] else 2  # image left = the subject's right hand
        if slot not in sides or blobs[index].area > blobs[sides[slot]].area:
            sides[slot] = index
    return sides


def hand_point(face: FaceBox, blob: SkinBlob, config: FeatureConfig) -> npt.NDArray[np.float64]:
    """A hand blob's far end along its long axis, pointing away from the head.

    (Short sleeves show the forearm too: the blob's centre is not the hand.)
    """
    head = face_centre(face)
    outward = unit(np.subtract(blob.centroid, head))
    axis = principal_direction(blob)
    direction = outward
    if axis is not None and outward is not None:
        direction = axis if float(axis @ outward) >= 0 else -axis
    if direction is None:
        return np.asarray(blob.centroid, dtype=np.float64)
    return np.asarray(far_end(blob, direction, config.hand_length * config.startup_shoulder_faces * face[2]))


def startup_points(face: FaceBox, blobs: list[SkinBlob], config: FeatureConfig) -> npt.NDArray[np.float64]:
    """Head and hand points for the A-pose check: `(3, 2)` head, right hand, left hand; NaN if absent.

    The head is the face centre; the hands are the `hand_blobs` below the face, each at its
    `hand_point`.
    """
    points = np.full((3, 2), np.nan)
    points[0] = face_centre(face)
    for slot, index in hand_blobs(face, blobs).items():
        points[slot] = hand_point(face, blobs[index], config)
    return points


def any_pose_points(features: FrameFeatures, face: FaceBox, config: FeatureConfig) -> FrameFeatures:
    """The frame's features with head and hand points found around the face, in any pose.

    Without a prediction the features take the three largest skin blobs and call the highest
    the head (§3.3.2); a hand raised beside the head then becomes the head. Here the head is
    the face (on the blob that holds its centre), and the hands are the `hand_blobs` at any
    height.
    """
    centre = face_centre(face)
    holder = next((i for i, blob in enumerate(features.blobs) if blob.distance_to(centre) == 0.0), None)
    head = None if holder is None else SkinPoint((float(centre[0]), float(centre[1])), False, holder)
    hands: list[SkinPoint | None] = [None, None]
    for slot, index in hand_blobs(face, features.blobs, below=False).items():
        x, y = hand_point(face, features.blobs[index], config)
        hands[slot - 1] = SkinPoint((float(x), float(y)), False, index)
    return dataclasses.replace(features, head=head, right_hand=hands[0], left_hand=hands[1])


@dataclass(frozen=True)
class APoseCheck:
    """The geometry check of Eq. 3.3.1-1 on head and hand points.

    Attributes:
        passed: both hands found, below the head, r_d and d3 within range.
        r_d: min(d1, d2) / max(d1, d2) (NaN without both hands).
        d3_faces: distance between the hands in face widths (NaN without both hands).
        reason: why it failed ("" when it passed).
    """

    passed: bool
    r_d: float
    d3_faces: float
    reason: str


def check_apose(
    points: npt.NDArray[np.float64],
    face_width: float,
    min_ratio: float = 0.6,
    d3_range: tuple[float, float] = (3.0, 12.0),
) -> APoseCheck:
    """Checks head and hands `(3, 2)` for the A-pose (SPEC 6: r_d >= 0.6, 3 <= d3 / face <= 12)."""
    head, right, left = points
    if not (np.all(np.isfinite(right)) and np.all(np.isfinite(left))):
        return APoseCheck(False, float("nan"), float("nan"), "two hand blobs not found")
    d1 = float(np.hypot(*(left - head)))
    d2 = float(np.hypot(*(right - head)))
    r_d = min(d1, d2) / max(d1, d2, 1e-9)
    d3 = float(np.hypot(*(right - left))) / max(face_width, 1e-9)
    if right[1] <= head[1] or left[1] <= head[1]:
        return APoseCheck(False, r_d, d3, "hands not below the head")
    if r_d < min_ratio:
        return APoseCheck(False, r_d, d3, f"r_d {r_d:.2f} < {min_ratio}")
    if not d3_range[0] <= d3 <= d3_range[1]:
        return APoseCheck(False, r_d, d3, f"d3 {d3:.1f} face widths outside {d3_range}")
    return APoseCheck(True, r_d, d3, "")


def depth_from_face(camera: Camera, face_width_px: float) -> float:
    """Root depth in metres from the face box width (Z = f * W / w; perspective cameras)."""
    if camera.kind == "perspective":
        return float(camera.focal * FACE_WIDTH_M / max(face_width_px, 1.0))
    return float(camera.reference_depth or 2.2)


def pixels_per_metre(camera: Camera, depth: float) -> float:
    """The image scale at `depth` (perspective), or the camera's fixed scale, pixels per metre."""
    if camera.kind == "perspective":
        return float(camera.focal / max(depth, 1e-3))
    if camera.kind == "weak_perspective":
        return float(camera.focal / (camera.reference_depth or depth))
    return float(camera.focal)


def root_from_head(
    camera: Camera, head_px: npt.ArrayLike, depth: float, pose: Pose | npt.ArrayLike, body: BodyModel
) -> npt.NDArray[np.float64]:
    """The root position that puts the model's head at pixel `head_px` with the root at `depth`.

    The head's offset from the root comes from the model at `pose` (so a leaning torso is
    accounted for); the head is back-projected at the root's depth plus that offset. "Head" is
    the head ellipsoid's centre, on the face (`model_points`), not the anatomical head centre.
    """
    offset = model_points(pose, np.zeros(3), body)[HEAD]
    u, v = np.asarray(head_px, dtype=np.float64)
    head_z = depth + offset[2]
    if camera.kind == "perspective":
        hx = (u - camera.cx) * head_z / camera.focal
        hy = (v - camera.cy) * head_z / camera.focal
    else:
        scale = pixels_per_metre(camera, depth)
        hx, hy = (u - camera.cx) / scale, (v - camera.cy) / scale
    return np.array([hx - offset[0], hy - offset[1], depth])


def _run_width(silhouette: npt.NDArray[np.uint8], row: int, x: float) -> float | None:
    """Width of the run of silhouette pixels in `row` that contains column `x` (None if none)."""
    height, width = silhouette.shape
    if not (0 <= row < height and 0 <= int(round(x)) < width):
        return None
    line = silhouette[row] > 0
    c = int(round(x))
    if not line[c]:
        return None
    off = np.flatnonzero(~line)
    left = off[off < c]
    right = off[off > c]
    a = int(left[-1]) + 1 if left.size else 0
    b = int(right[0]) if right.size else width
    return float(b - a)


def shoulder_span(
    silhouette: npt.NDArray[np.uint8], joints_2d: npt.NDArray[np.float64], drop_px: float
) -> float | None:
    """Median silhouette width over five rows `drop_px` below the shoulder line, through the neck."""
    neck = 0.5 * (joints_2d[R_SHOULDER] + joints_2d[L_SHOULDER])
    row = int(round(neck[1] + drop_px))
    widths = [w for r in range(row - 2, row + 3) if (w := _run_width(silhouette, r, neck[0])) is not None]
    return float(np.median(widths)) if widths else None


def measure_body(
    camera: Camera,
    face: FaceBox,
    points: npt.NDArray[np.float64],
    base: BodyModel | None = None,
    silhouette: npt.NDArray[np.uint8] | None = None,
    face_width_px: float | None = None,
    max_change: float = 0.2,
) -> tuple[BodyModel, npt.NDArray[np.float64]]:
    """The person's body model and root from the A-pose.

    1. Depth from the face width (`face_width_px`, e.g. a median over the start-up frames).
    2. Shoulder and torso width: the silhouette's width a little below the shoulder line,
       against the same width of the model rendered in the A-pose.
    3. Arm lengths: shoulder-to-hand distances of the measured hands against the model's.
    Each ratio is clamped to `max_change`; everything else keeps the adult averages.

    Args:
        camera: the camera.
        face: the face box of this frame (its centre places the head).
        points: `(3, 2)` head, right hand, left hand (hands may be NaN: arms keep the averages).
        base: dimensions to start from (adult averages when None).
        silhouette: I_sil of this frame, for the shoulder width (None: not measured). The
            tracker leaves it out: the silhouette just below the shoulders is wider than the
            cone model's for the same person (sloping shoulders, clothes, the silhouette's
            closing), so it overstates the width.
        face_width_px: face width for the depth; this frame's box when None.
        max_change: the largest relative change of a measured dimension.

    Returns:
        (body, root): the body model and the root position (metres, camera frame).
    """
    body = base or BodyModel()
    depth = depth_from_face(camera, face_width_px or face[2])
    pose = Pose.a_pose()
    head = face_centre(face)
    low, high = 1.0 - max_change, 1.0 + max_change
    root = root_from_head(camera, head, depth, pose, body)
    if silhouette is not None:
        model = project(camera, model_points(pose, root, body))
        height, width = silhouette.shape
        drop = 0.06 * camera.focal / depth if camera.kind == "perspective" else 0.06 * camera.focal
        rendered = render_masks(pose, root, camera, width, height, body)["silhouette"]
        measured, modelled = shoulder_span(silhouette, model, drop), shoulder_span(rendered, model, drop)
        if measured and modelled:
            body = widened(body, float(np.clip(measured / modelled, low, high)))
            root = root_from_head(camera, head, depth, pose, body)
    model = project(camera, model_points(pose, root, body))
    ratios = []
    for shoulder, hand, point in ((R_SHOULDER, R_HAND, 1), (L_SHOULDER, L_HAND, 2)):
        got = points[point]
        if np.all(np.isfinite(got)) and np.all(np.isfinite(model[[shoulder, hand]])):
            length = float(np.hypot(*(model[hand] - model[shoulder])))
            if length > 1.0:
                ratios.append(float(np.hypot(*(got - model[shoulder]))) / length)
    if len(ratios) == 2 and abs(ratios[0] - ratios[1]) > 0.15:
        ratios = [min(ratios, key=lambda r: abs(r - 1.0))]  # one hand point is off: trust the other
    if ratios:
        k = float(np.clip(np.median(ratios), low, high))
        dims = body.as_dict()
        dims["upper_arm_length"] = dims["upper_arm_length"] * k
        dims["lower_arm_length"] = dims["lower_arm_length"] * k
        body = BodyModel(**dims)
    return body, root


def widened(body: BodyModel, factor: float) -> BodyModel:
    """`body` with the shoulder width and the torso's half-width and half-depth times `factor`."""
    dims = body.as_dict()
    for key in WIDTH_KEYS:
        dims[key] = dims[key] * factor
    return BodyModel(**dims)


def head_raised(body: BodyModel, factor: float) -> BodyModel:
    """`body` with the head's height above the shoulders times `factor`, the neck still reaching it."""
    dims = body.as_dict()
    rise = dims["head_offset"] * (factor - 1.0)
    dims["head_offset"] = dims["head_offset"] + rise
    dims["neck_length"] = max(dims["neck_length"] + rise, 0.01)
    return BodyModel(**dims)


@dataclass(frozen=True)
class StartupFit:
    """The start-up fit of one candidate body.

    Attributes:
        candidate: the candidate as given (before `place` measured it).
        body: the measured body that was fitted.
        root: its root position, metres.
        fit: the fit (`upperpose.FrameFit` or alike).
    """

    candidate: BodyModel
    body: BodyModel
    root: npt.NDArray[np.float64]
    fit: Any


def fit_bodies(
    fitter: Callable[..., Any],
    features: Any,
    pose: npt.ArrayLike,
    candidates: Sequence[BodyModel],
    camera: Camera,
    place: Callable[[BodyModel], tuple[BodyModel, npt.ArrayLike]],
    best: StartupFit | None = None,
    score: Callable[[Any], float] = lambda fit: float(fit.cost),
    **fit_args: Any,
) -> StartupFit:
    """Fits the frame once per candidate body; keeps the fit of the lowest `score`.

    Start-up measures the person only roughly (the face box gives the depth to about 10 %, the
    silhouette's width is not the model's), and a model of the wrong size fits a frontal person
    best misplaced: too wide, it turns; with the head too high above the shoulders, the
    shoulders sit off their silhouette for the whole clip. The cost itself decides.

    Args:
        fitter: `upperpose.fit_frame` or a callable with its signature.
        features: the frame's features.
        pose: the pose to search around.
        candidates: the bodies to try.
        camera: the camera.
        place: a candidate's measured body and root (e.g. arm lengths measured from that
            candidate's shoulders, the head put on the face).
        best: a fit already made, to be beaten.
        score: what is compared (lower is better); the fit's whole cost by default.
        fit_args: passed on to `fitter` (mode, window_scale, search, ...).

    Returns:
        The fit of the lowest score (the first of equals).
    """
    if best is None and not candidates:
        raise InputError("candidates must not be empty")
    for candidate in candidates:
        body, root = place(candidate)
        root = np.ascontiguousarray(root, dtype=np.float64)
        fit = fitter(features, np.asarray(pose, dtype=np.float64), root, body, camera, **fit_args)
        if best is None or score(fit) < score(best.fit):
            best = StartupFit(candidate, body, root, fit)
    assert best is not None
    return best


__all__ = [
    "FACE_WIDTH_M",
    "HAND_REACH_FACES",
    "WIDTH_KEYS",
    "APoseCheck",
    "StartupFit",
    "FaceBox",
    "FaceDetector",
    "any_pose_points",
    "check_apose",
    "choose_face",
    "depth_from_face",
    "face_centre",
    "fit_bodies",
    "hand_blobs",
    "hand_candidates",
    "hand_point",
    "head_raised",
    "measure_body",
    "shoulder_span",
    "pixels_per_metre",
    "root_from_head",
    "startup_points",
    "widened",
]
