"""Every threshold of the image features (SPEC 4) in one frozen configuration object."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Literal

from upperpose.exceptions import InputError

SkinSpace = Literal["rgb", "ycrcb", "hsv", "rgb+ycrcb"]
SKIN_SPACES: tuple[str, ...] = ("rgb", "ycrcb", "hsv", "rgb+ycrcb")
BackgroundModel = Literal["online", "prepass"]
BACKGROUND_MODELS: tuple[str, ...] = ("online", "prepass")


@dataclass(frozen=True)
class PersonTemplate:
    """Where a person stands relative to their face, for cutting them out of an estimated plate.

    Units: `w` and `h` are the width and height of the detected face box `(x, y, w, h)`; heights
    are measured down from the box's top edge, half widths from its centre line. The body model's
    adult averages give a shoulder width of about two face widths. Three nested regions seed
    GrabCut: sure person (face core, chest), probable person (head, neck, torso down to the image
    bottom), probable background (a wider band around them, where arms and hair may be);
    everything else is sure background.
    """

    head_centre: float = 0.45
    """Head ellipse centre below the box top, in h."""

    head_radii: tuple[float, float] = (0.7, 0.85)
    """Probable person: head ellipse semi-axes (w, h) (the face box holds the face, not the hair)."""

    neck: tuple[float, float, float] = (0.35, 0.9, 1.6)
    """Probable person: neck rectangle (half width in w, top in h, bottom in h)."""

    torso_top: float = 1.4
    """Probable person: top of the torso trapezoid, in h."""

    torso_half_widths: tuple[float, float] = (0.8, 0.7)
    """Probable person: torso half width at its top and at the image bottom, in w (the body
    model's torso is 0.32 m wide, a face box about 0.2 m). Arms hanging beside the torso are
    left to the colour model, so that the room between arm and torso is not taken for the
    person."""

    reach_top: float = 0.9
    """Probable background band: top of its trapezoid, in h."""

    reach_head_radii: tuple[float, float] = (1.2, 1.4)
    """Probable background band: ellipse semi-axes (w, h) around the head."""

    reach_half_widths: tuple[float, float] = (1.8, 2.2)
    """Probable background band: half width at its top and at the image bottom, in w (arms
    hanging in the A-pose; a wider band lets GrabCut take more of the room beside the person)."""

    sure_face: tuple[float, float, float, float] = (0.25, 0.25, 0.75, 0.8)
    """Sure person: the face box's core (left, top, right, bottom as fractions of w and h)."""

    sure_chest: tuple[float, float, float] = (0.45, 2.0, 3.2)
    """Sure person: chest rectangle (half width in w, top in h, bottom in h)."""

    arm_zone: tuple[float, float] = (4.0, 6.0)
    """A bare arm that never moves (`bg_cut_bare_arms`) lies within this half width (w) of
    the face's centre line and above this height (h): an arm's span either side."""

    arm_contact: tuple[float, float] = (1.5, 4.0)
    """Such an arm meets the cut-out person (on average) between these heights (h): where the
    upper arm hangs, from the shoulders to about the elbows; not beside the head, and not at
    the hips, where chairs and tables stand against a person."""

    arm_min_reach: float = 1.0
    """Such an arm reaches at least this far (w) beyond the cut-out person (a forearm is about
    1.5 face heights long; a skin-coloured scrap of the room beside the person does not)."""

    arm_max_area: float = 3.0
    """Such an arm covers at most this many face boxes (a forearm and hand cover about two)."""

    arm_min_still: float = 0.9
    """Such an arm shows in the samples this often (mean over its pixels of the share of samples
    that match the median there): an arm the person moves is seen past in the other samples."""

    arm_min_thickness: float = 0.1
    """Such an arm is at least this thick (w; twice its pixels' mean distance to its edge, half
    the width of a bar): not the skin-coloured edge line of an object."""

    def __post_init__(self) -> None:
        sizes = {
            "arm_zone": self.arm_zone,
            "arm_contact": self.arm_contact,
            "arm_min_reach": (self.arm_min_reach,),
            "arm_max_area": (self.arm_max_area,),
            "arm_min_thickness": (self.arm_min_thickness,),
        }
        for name, values in sizes.items():
            if not all(math.isfinite(v) and v >= 0 for v in values):
                raise InputError(f"bg_person.{name} must be finite and >= 0, got {getattr(self, name)}")
        if not self.arm_contact[0] <= self.arm_contact[1]:
            raise InputError(f"bg_person.arm_contact must run from top to bottom, got {self.arm_contact}")
        if not 0.0 <= self.arm_min_still <= 1.0:
            raise InputError(f"bg_person.arm_min_still must be within 0..1, got {self.arm_min_still}")


@dataclass(frozen=True)
class FeatureConfig:
    """Thresholds and sizes of the image features; pixel values are 0..255 unless stated.

    Lengths in pixels are for a 640x480 frame; they do not scale with the image.
    Change one field with `dataclasses.replace(config, field=value)` or `config.replace(...)`.
    """

    sub_threshold: int = 15
    """I_sub: a pixel is foreground when any of its B, G, R values differs from the
    background's by more than this."""

    sub_open: int = 3
    """I_sub: side of the square opening that removes isolated noise pixels (0 or 1: none)."""

    sub_close: int = 0
    """I_sub: side of the square closing that fills small holes (0 or 1: none; the closing
    of I_sil fills them in the silhouette)."""

    edge_threshold: int = 120
    """I_edge: threshold on |dx_frame - dx_background| + |dy_frame - dy_background|, the
    3x3 Sobel derivatives of the grey frame and the grey background (int16 units; a
    step of 30 grey levels across a pixel gives 120)."""

    edge_blur: int = 3
    """I_edge: side of the Gaussian blur applied to both grey images before Sobel, against
    compression noise (0 or 1: none)."""

    motion_threshold: int = 15
    """I_motion: grey-level absolute difference between consecutive frames counted as motion."""

    skin_space: SkinSpace = "rgb+ycrcb"
    """I_skin0 colour rule: "rgb" is the thesis' 20 <= R - G <= 80 (§2.5); "ycrcb" and "hsv"
    are the alternatives §5.2 asks for (ranges below); "rgb+ycrcb" keeps pixels inside both the
    R - G band and the YCrCb rule's Cr/Cb box, at any brightness (the R - G band alone also
    takes yellow and purple cloth)."""

    rgb_rg_min: int = 20
    """RGB rule: smallest R - G of a skin pixel."""

    rgb_rg_max: int = 80
    """RGB rule: largest R - G of a skin pixel."""

    ycrcb_min: tuple[int, int, int] = (40, 135, 80)
    """YCrCb rule: lower bounds of (Y, Cr, Cb) (OpenCV 8-bit YCrCb, Cr and Cb offset by 128)."""

    ycrcb_max: tuple[int, int, int] = (255, 175, 130)
    """YCrCb rule: upper bounds of (Y, Cr, Cb)."""

    hsv_hue_max: int = 22
    """HSV rule: skin hue is 0..hsv_hue_max or 180 - hsv_hue_max..180 (OpenCV hue is 0..180)."""

    hsv_min_sv: tuple[int, int] = (40, 50)
    """HSV rule: smallest saturation and value of a skin pixel."""

    hsv_max_s: int = 190
    """HSV rule: largest saturation of a skin pixel (saturated reds are clothes, not skin)."""

    person_skin: bool = True
    """I_skin0: once the tracker has found the person's face, skin is the
    face's hue and saturation (within `person_skin_sigmas` spreads, widened for dark and grey
    pixels) instead of the generic rule, except around the head (features/person_skin.py). The
    generic rules take in khaki, beige and wood as well as every skin tone, and lose dark skin
    in shadow."""

    person_skin_sigmas: float = 3.0
    """Person's skin: half-axes of the (hue, saturation) ellipse in spreads."""

    person_skin_min_hue_spread: float = 2.0
    """Person's skin: floor of the hue spread, in OpenCV hue steps (of 180)."""

    person_skin_min_saturation_spread: float = 12.0
    """Person's skin: floor of the saturation spread (of 255)."""

    background_skin_dilate: int = 3
    """Background skin mask: side of its dilation, so that the blurred rims of skin-coloured
    background objects are dropped too (0 or 1: none)."""

    skin_open: int = 3
    """I_skin: side of the square opening that removes speckle (0 or 1: none)."""

    sil_edge_trim: int = 2
    """I_sil: edge-only pixels within this many pixels of the outside of I_sub | I_edge | I_skin
    are dropped. Sobel on a blurred image marks about two pixels on each side of the person's
    outline, so the plain union of Eq. 3.4.1-1 grows the silhouette by a rim (0: plain union)."""

    sil_close: int = 7
    """I_sil: side of the square closing of I_sub | I_edge | I_skin (0 or 1: none)."""

    feature_dilate: int = 3
    """Packed edge and motion maps: side of the square dilation, so that a model contour one
    pixel off still counts (SPEC 5: 1-2 px; 3 means one pixel each way)."""

    blob_min_area: int = 60
    """Skin blobs: smallest area in pixels."""

    blob_min_gradient: float = 0.06
    """Skin blobs: smallest blob gradient probability P_SB = sum(I_edge) / N (Eq. 3.4.4.2-1,
    I_edge as 0/1, dilated 3x3 so that the blob's outline edges count); a static skin-coloured
    object that slipped through has P_SB near 0. Twice the 0.03 used on the undilated I_edge:
    the dilation about doubles the width of an outline's edge band."""

    blob_min_changed: float = 0.9
    """Skin blobs: a blob below `blob_min_gradient` is kept when at least this share of it is
    I_sub and its outline is the person's outline (`blob_min_room_outline`): a limb that
    differs from the room in colour but hardly in grey level (a dark arm over a dark sofa;
    features/blobs.py `stands_out_in_colour`). Above 1: never."""

    blob_min_room_outline: float = 0.25
    """Skin blobs: for that, at least this share of a `blob_ring`-pixel ring around the blob
    must be outside I_sub (the room, not more of the person)."""

    blob_shade_spread: float = 0.04
    """Skin blobs: a blob kept only by its colour change is dropped when that change is a shade
    of the plate, its B, G, R each the plate's times factors that spread by at most this share
    of their mean (a shadow on skin-coloured furniture; features/blobs.py `is_shade`). 0: never."""

    blob_ring: int = 2
    """Skin blobs: width in pixels of the ring around a blob checked against I_sub."""

    hand_gate: float = 0.9
    """Hand and head matching: largest distance from the predicted joint to the nearest
    blob pixel, in units of the predicted shoulder width."""

    blob_share_cost: float = 0.45
    """Hand and head matching: what sharing a blob with another part adds to the matching's
    total distance, in predicted shoulder widths (half the `hand_gate`; from twice the gate on,
    parts share only when no other blob is within the gate). A hand predicted on the face's
    blob (a hand at the mouth) then shares it rather than take a free blob farther away (bare
    skin of the other arm), whose far end would pull the arm there and mark it lost."""

    head_priority: float = 3.0
    """Hand and head matching: the head's distance counts this many times a hand's when blobs
    are shared out. The head moves least and is matched most reliably; when a hand leaves the
    face, a model hand still on the face must not take the face's blob and push the head onto
    the hand's."""

    part_min_share: float = 0.25
    """Hand and head matching: no part takes a blob smaller than this share of the part's
    expected area (`points.PART_AREAS`, from the predicted shoulder width). Smaller blobs are
    scraps of the face, the hair or an arm: with a hand on the face the hand would take one
    and not be reported merged, the head would take one, and the cost would then pull the arm
    to the scrap and charge the true pose for being far from it (docs/features.md)."""

    hand_length: float = 0.5
    """Hand point: the point is the centroid of the last `hand_length` shoulder widths of
    the blob along the forearm (the hand, with fingers), so that a blob that also covers
    the forearm (short sleeves) still gives the hand."""

    forearm_length: float = 0.94
    """Hand point: the 2D elbow-to-hand length of a forearm parallel to the image, in shoulder
    widths (the body model's default 0.34 m / 0.36 m). A shorter predicted forearm is
    foreshortened and so is the hand: its slab (`hand_length`) shrinks in proportion."""

    hand_min_foreshortening: float = 0.5
    """Hand point: the slab shrinks to at most this fraction of `hand_length` (a hand seen
    end-on still spans its width, about half its length)."""

    forearm_reach: float = 0.25
    """Hand point: the slab is shortened only when the blob comes within this fraction of the
    predicted forearm's 2D length of the predicted elbow (a bare forearm in the blob)."""

    head_length: float = 0.5
    """Head point: the centre of the largest disc inside the head blob's convex hull is searched
    in the top `head_length` shoulder widths of the blob along the neck-to-head direction (keeps
    a bare neck or chest out)."""

    split_chroma: float = 0.05
    """Head and hand split: a blob the matcher would share between the head and a hand is split
    when its pixels further than this from both the face's and the hand's chromaticity
    ((R, G) / (R + G + B), which shading hardly changes) separate them: hair that passed the
    skin rule joining a hand on it to the face (features/split.py). Skin, also shaded, lies
    within about 0.04 of its part's colour; brown or blond hair about 0.06 from the face."""

    split_sample: float = 0.15
    """Head and hand split: the face's and the hand's colours are the median over the blob's
    pixels within this many shoulder widths of the predicted head and hand."""

    split_max_overlap: float = 0.15
    """Head and hand split: the hand's piece may share at most this fraction of its area with
    the head piece's convex hull (a hand beside the head); more is hair round the head that
    stayed connected to the hand, and the blob stays merged."""

    min_shoulder_px: float = 20.0
    """Smallest shoulder width in pixels used for the scale of gates (a turned torso
    foreshortens the predicted shoulders)."""

    startup_shoulder_faces: float = 2.2
    """At start-up (no prediction): shoulder width assumed, in face-blob widths."""

    motion_dilate: int = 9
    """Motion flags: side of the dilation of each part's previous projection."""

    motion_perimeter_fraction: float = 0.5
    """Motion flags: a part moves when its motion count exceeds this fraction of the
    perimeter of its projection (§3.4.3: one half)."""

    arm_torso_erode: int = 0
    """Arm silhouette: pixels the torso region is shrunk by before it is cut out (0: the
    torso+neck+head projection as it is)."""

    exposure_tolerance: float = 0.04
    """Light changes: when the frame's median brightness ratio to the plate, in some colour
    channel, is off by more than this, I_sub and I_edge compare against the plate scaled by
    the ratio (features/exposure.py). 0 compensates every frame; a large value never."""

    exposure_step: int = 8
    """Light changes: the ratio is measured on every `exposure_step`-th pixel of each row and
    column."""

    bg_max_samples: int = 40
    """Background estimation: most frames sampled over the video for the temporal median."""

    bg_threshold: int = 25
    """Background estimation: colour difference that marks a sample pixel as foreground
    (same measure as `sub_threshold`)."""

    bg_mask_dilate: int = 15
    """Background estimation: side of the dilation of each sample's foreground mask."""

    bg_iterations: int = 2
    """Background estimation: rounds of (median, mask foreground, masked median)."""

    bg_lead_seconds: float = 1.0
    """Background estimation: length of the lead-in checked for an empty scene."""

    bg_static_fraction: float = 0.003
    """Background estimation: a lead-in frame is static when at most this fraction of its
    pixels differ from the first frame (same measure and threshold as `bg_threshold`)."""

    bg_face_min_skin: float = 0.3
    """Background estimation: a face box counts as a person only when at least this share of it
    is skin (real faces are mostly skin, false boxes on shelves and furniture mostly not: the
    sixteen faces of the external validation set's first frames hold 0.39-0.90 skin, a false
    box on the development set's empty room 0.11)."""

    bg_face_samples: int = 8
    """Background estimation: when the median image shows no face (the head moved too much),
    faces are looked for in this many samples spread over the clip."""

    bg_face_steady: float = 0.75
    """Background estimation: when no face box in the median image or the samples is mostly skin,
    a box the cascade finds in one place and size in at least this share of the samples is the
    person's face (a real face under cool or dim light fails the skin rule, while false boxes
    come and go). 0 turns this off."""

    bg_face_agreement: float = 0.25
    """Background estimation: a sample's face anchors the person cut only when the median image
    agrees with the sample on at least this share of the face box (the person stood there long
    enough to be in the median; within `bg_person_match`)."""

    bg_cut_person: bool = True
    """Background estimation: cut the person who stays put out of the temporal median (found
    from their face and segmented by GrabCut, `features/person_cut.py`) and fill the pixels no
    sample shows uncovered by inpainting. False: the masked median alone, which keeps them."""

    bg_person: PersonTemplate = PersonTemplate()
    """Background estimation: the body region around the face that seeds the person cut."""

    bg_cut_bare_arms: bool = True
    """Background estimation: add to the cut-out person the bare arms (in the person's skin
    colour, learnt from the face) that stay put beside them; the body template leaves an arm
    held out from the body in the room, and a median keeps it in the plate."""

    bg_grabcut_scale: float = 2.0
    """Background estimation: the median image is shrunk by this factor for GrabCut (speed)."""

    bg_grabcut_iterations: int = 5
    """Background estimation: GrabCut iterations."""

    bg_grabcut_runs: int = 5
    """Background estimation: GrabCut runs, seeded 0, 1, ... (its k-means start is random);
    a pixel is the person when most runs say so. The same video gives the same plate."""

    bg_person_match: int = 25
    """Background estimation: a sample pixel inside the cut-out person counts as the person when
    it differs from the median by at most this in every channel (elsewhere the person moved)."""

    bg_person_dilate: int = 7
    """Background estimation: side of the dilation of the cut-out person in each sample (margin
    for GrabCut's outline)."""

    bg_inpaint_radius: int = 5
    """Background estimation: radius of the inpainting (Telea) that fills the pixels no sample
    shows without the person."""

    bg_model: BackgroundModel = "prepass"
    """Without a clean plate, for a file: "prepass" estimates a plate from the whole video before
    tracking (`features/background.py`), "online" learns the background while tracking
    (`features/online.py`; no pass over the video first, but less accurate on the validation and
    development sets, docs/features.md). A live camera or stream always learns it online."""

    bg_refine_estimate: bool = True
    """A plate estimated before tracking (`bg_model` "prepass") goes on learning while tracking,
    as the online model does (`features/online.py`): the ghosts of the person the estimate kept
    fade where the room shows away from the tracked person."""

    bg_online_rate: float = 0.02
    """Online background: the running mean's rate once it has seen 1/rate frames (before, the
    plain mean of the frames so far); sets how fast it follows slow light changes."""

    bg_online_change_rate: float = 0.1
    """Online background: the rate for pixels away from the person that differ from the model
    (I_sub): the room behind where the person stood at the start, moved furniture."""

    bg_online_margin: int = 12
    """Online background: the person's region (the model's projection) is grown by this many
    pixels before the rest is learnt (clothes and hair outside the cones, a fit a little off)."""

    bg_online_reach: float = 4.2
    """Online background: before the first fit, the pixels within this many face widths of
    either shoulder (below the face) are the person's reach and are not learnt (filled by
    inpainting in the first frame)."""

    bg_online_grabcut_runs: int = 1
    """Online background: GrabCut runs that cut the person out of the first frame (inside the
    reach above; see `bg_grabcut_runs`)."""

    bg_online_hold_skin: bool = True
    """Online background: also leave the first frame's skin within the reach out (bare arms that
    GrabCut gave to the room; but also wooden doors and desks, whose inpainted fill then reads
    as skin beside the hands until the first fit)."""

    bg_online_busy_dilate: int = 7
    """Online background: side of the dilation of the skin and motion pixels that are not
    learnt (a hand the fit missed, a motion trail)."""

    bg_online_refresh: int = 5
    """Online background: its plate's derived images (grey derivatives, skin mask) are
    recomputed every this many frames."""

    def __post_init__(self) -> None:
        if self.skin_space not in SKIN_SPACES:
            raise InputError(f"skin_space must be one of {', '.join(SKIN_SPACES)}, got {self.skin_space!r}")
        if self.bg_model not in BACKGROUND_MODELS:
            raise InputError(f"bg_model must be one of {', '.join(BACKGROUND_MODELS)}, got {self.bg_model!r}")
        for name in ("bg_online_rate", "bg_online_change_rate"):
            if not 0 < getattr(self, name) <= 1:
                raise InputError(f"{name} must be within (0, 1], got {getattr(self, name)}")
        if not 0 <= self.rgb_rg_min <= self.rgb_rg_max <= 255:
            raise InputError(f"need 0 <= rgb_rg_min <= rgb_rg_max <= 255, got {self.rgb_rg_min}, {self.rgb_rg_max}")
        for name in (
            "sub_open",
            "sub_close",
            "edge_blur",
            "background_skin_dilate",
            "skin_open",
            "sil_edge_trim",
            "sil_close",
            "feature_dilate",
            "motion_dilate",
            "arm_torso_erode",
            "bg_mask_dilate",
            "bg_person_dilate",
            "bg_person_match",
            "bg_online_margin",
            "bg_online_busy_dilate",
            "blob_ring",
            "blob_min_changed",
            "blob_min_room_outline",
            "blob_shade_spread",
            "part_min_share",
        ):
            if not getattr(self, name) >= 0:  # NaN too
                raise InputError(f"{name} must be >= 0, got {getattr(self, name)}")
        if self.edge_blur > 1 and self.edge_blur % 2 == 0:
            raise InputError(f"edge_blur must be odd, got {self.edge_blur}")
        for name in (
            "hand_gate",
            "head_priority",
            "hand_length",
            "forearm_length",
            "hand_min_foreshortening",
            "forearm_reach",
            "head_length",
            "split_chroma",
            "person_skin_sigmas",
            "person_skin_min_hue_spread",
            "person_skin_min_saturation_spread",
            "split_sample",
            "split_max_overlap",
            "min_shoulder_px",
            "startup_shoulder_faces",
            "bg_lead_seconds",
            "bg_online_reach",
        ):
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be positive, got {getattr(self, name)}")
        if not 0 <= self.blob_share_cost < math.inf:
            raise InputError(f"blob_share_cost must be a number >= 0, got {self.blob_share_cost}")
        if not self.exposure_tolerance >= 0:
            raise InputError(f"exposure_tolerance must be >= 0, got {self.exposure_tolerance}")
        if self.exposure_step < 1:
            raise InputError(f"exposure_step must be >= 1, got {self.exposure_step}")
        for name in ("bg_face_min_skin", "bg_face_steady", "bg_face_agreement"):
            if not 0 <= getattr(self, name) <= 1:
                raise InputError(f"{name} must be within 0..1, got {getattr(self, name)}")
        if not self.bg_grabcut_scale >= 1:
            raise InputError(f"bg_grabcut_scale must be >= 1, got {self.bg_grabcut_scale}")
        for name in (
            "bg_grabcut_iterations",
            "bg_grabcut_runs",
            "bg_inpaint_radius",
            "bg_face_samples",
            "bg_online_refresh",
            "bg_online_grabcut_runs",
        ):
            if getattr(self, name) < 1:
                raise InputError(f"{name} must be >= 1, got {getattr(self, name)}")
        if self.bg_max_samples < 3:
            raise InputError(f"bg_max_samples must be >= 3, got {self.bg_max_samples}")

    def replace(self, **changes: object) -> FeatureConfig:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)  # type: ignore[arg-type]
