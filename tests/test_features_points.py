"""Head and hand points from skin blobs: matching, far end, merged blobs (SPEC 4)."""

from __future__ import annotations

import cv2
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.features import FeatureConfig, find_skin_blobs, locate_points
from upperpose.features.blobs import is_shade
from upperpose.features.points import beyond_image, hands_beyond_image

CONFIG = FeatureConfig()


def joints(head, right_hand, left_hand, right_elbow=None, left_elbow=None) -> np.ndarray:
    """Predicted joints (JOINT_NAMES order) with shoulders 100 px apart below the head."""
    rs, ls = (head[0] - 50, head[1] + 70), (head[0] + 50, head[1] + 70)
    re = right_elbow or (rs[0] - 10, rs[1] + 60)
    le = left_elbow or (ls[0] + 10, ls[1] + 60)
    return np.array([head, rs, ls, re, le, right_hand, left_hand], np.float64)


def blobs_of(*shapes) -> list:
    skin = np.zeros((480, 640), np.uint8)
    for draw in shapes:
        draw(skin)
    edge = cv2.morphologyEx(skin, cv2.MORPH_GRADIENT, np.ones((3, 3), np.uint8))
    return find_skin_blobs(skin, edge, CONFIG)


def face(skin):
    cv2.ellipse(skin, (320, 100), (28, 36), 0, 0, 360, 255, -1)


def disc(centre, radius):
    """A filled skin disc (a hand), for `blobs_of`."""
    return lambda skin: cv2.circle(skin, centre, radius, 255, -1)


def bar(start, end, width):
    """A straight skin bar `width` px thick (a bare forearm or upper arm), for `blobs_of`."""
    return lambda skin: cv2.line(skin, start, end, 255, width)


def test_three_separate_blobs_are_matched() -> None:
    blobs = blobs_of(
        face,
        disc((200, 300), 14),
        disc((440, 310), 14),
    )
    head, right, left = locate_points(blobs, joints((318, 104), (205, 295), (436, 305)), CONFIG)
    assert not (head.merged or right.merged or left.merged)
    assert np.hypot(right.xy[0] - 200, right.xy[1] - 300) < 3
    assert np.hypot(left.xy[0] - 440, left.xy[1] - 310) < 3
    assert abs(head.xy[0] - 320) < 2


def test_hands_together_are_merged() -> None:
    def together(s):
        return cv2.ellipse(s, (320, 330), (30, 14), 0, 0, 360, 255, -1)

    blobs = blobs_of(face, together)
    head, right, left = locate_points(blobs, joints((320, 100), (305, 330), (335, 330)), CONFIG)
    assert right.merged and left.merged and right.blob == left.blob
    assert not head.merged


def test_hand_near_face_but_separate_is_not_merged() -> None:
    hand = disc((372, 112), 12)  # 12 px gap to the face
    blobs = blobs_of(face, hand, disc((200, 300), 14))
    # The prediction of the left hand lies between face and hand: the assignment still separates them.
    head, _, left = locate_points(blobs, joints((320, 100), (200, 300), (360, 110)), CONFIG)
    assert not head.merged and not left.merged
    assert np.hypot(left.xy[0] - 372, left.xy[1] - 112) < 3


def test_a_hand_on_the_face_takes_no_scrap_of_skin() -> None:
    # Left hand on the face (one blob) and a scrap of hair-coloured skin above the face, 81 px:
    # under a tenth of a hand (shoulders 100 px apart: 100 px). Without the floor the hand took
    # the scrap and neither was reported merged.
    hand = disc((342, 118), 14)
    scrap = disc((352, 58), 5)
    blobs = blobs_of(face, hand, scrap, disc((200, 300), 14))
    prediction = joints((320, 100), (200, 300), (345, 105))
    head, _, left = locate_points(blobs, prediction, CONFIG)
    assert left.merged and head.merged and left.blob == head.blob
    assert blobs[head.blob].area > 1000
    _, _, left = locate_points(blobs, prediction, FeatureConfig(part_min_share=0.0))
    assert not left.merged and blobs[left.blob].area < 100


def test_a_hand_on_the_face_shares_it_rather_than_take_a_free_blob_farther_away() -> None:
    # Left hand at the mouth (one blob with the face) and the bare right upper arm 60-70 px
    # from the predicted hand, within its gate (90 px). Taking the arm's blob, the hand's point
    # would be the arm's far end, across the body.
    hand = disc((338, 128), 14)
    upper_arm = bar((275, 160), (265, 215), 16)
    blobs = blobs_of(face, hand, upper_arm, disc((200, 300), 14))
    prediction = joints((320, 100), (200, 300), (335, 122))
    head, right, left = locate_points(blobs, prediction, CONFIG)
    assert left.merged and head.merged and left.blob == head.blob
    assert not right.merged and np.hypot(right.xy[0] - 200, right.xy[1] - 300) < 3
    # Only distinct blobs (the matching before sharing had a cost): the arm's blob.
    _, _, left = locate_points(blobs, prediction, CONFIG.replace(blob_share_cost=10.0))
    assert not left.merged and blobs[left.blob].bbox[0] < 290


def test_a_hand_cut_by_the_border_is_a_box_beyond_it() -> None:
    # A bare forearm raised out of the top of the frame: its visible end is the border, not the
    # hand. With the image's size the hand is reported as a box from the far end's pixels up
    # to a frame's height above the border, widened by the far end's length along it.
    forearm = bar((450, 120), (460, 0), 22)
    blobs = blobs_of(face, forearm)
    prediction = joints((320, 100), (150, 400), (458, 10), left_elbow=(448, 125))
    _, _, left = locate_points(blobs, prediction, CONFIG)
    assert not left.merged and left.xy[1] < 30  # without the size: a point at the border
    _, _, left = locate_points(blobs, prediction, CONFIG, size=(480, 640))
    assert left.merged
    x0, y0, x1, y1 = left.box
    assert y0 == -480 and 0 < y1 <= 60 and x0 < 440 and x1 > 470
    # A hand well inside the frame stays a point.
    inside = joints((320, 100), (150, 400), (458, 125), left_elbow=(448, 230))
    _, _, left = locate_points(blobs_of(face, bar((450, 220), (460, 120), 22)), inside, CONFIG, size=(480, 640))
    assert not left.merged and left.box is None


def test_a_hand_predicted_out_of_the_image_without_skin_is_kept_beyond_the_border() -> None:
    # A hand that left the frame by the bottom (a person near a webcam) shows no skin: its box is
    # the band beyond the bottom border, a frame's size deep and wide on either side of the image.
    # A hand with no skin predicted inside the image (a sleeve, a hand behind the back) gets none.
    blobs = blobs_of(face)
    prediction = joints((320, 100), (200, 700), (500, 300))
    right, left = (locate_points(blobs, prediction, CONFIG, size=(480, 640)))[1:]
    assert right is None and left is None
    assert hands_beyond_image((right, left), prediction, (480, 640)) == ((-640.5, 479.5, 1279.5, 959.5), None)
    # The border it is farthest past: 30 px beyond the left, 10 beyond the top.
    assert beyond_image(np.array([-30.5, -10.5]), (480, 640)) == (-640.5, -480.5, -0.5, 959.5)
    assert beyond_image(np.array([639.0, 479.0]), (480, 640)) is None  # the last pixel is inside
    assert beyond_image(np.array([np.nan, 700.0]), (480, 640)) is None
    assert hands_beyond_image((right, left), None, (480, 640)) == (None, None)  # start-up: no prediction


@settings(max_examples=200, deadline=None)
@given(st.floats(-2000, 2000), st.floats(-2000, 2000))
def test_the_box_beyond_the_image_never_holds_an_image_pixel(x: float, y: float) -> None:
    box = beyond_image(np.array([x, y]), (480, 640))
    inside = -0.5 <= x <= 639.5 and -0.5 <= y <= 479.5
    assert (box is None) == inside
    if box is not None:
        x0, y0, x1, y1 = box
        # Its overlap with the image's extent is at most its edge on the border.
        assert min(x1, 639.5) - max(x0, -0.5) <= 0 or min(y1, 479.5) - max(y0, -0.5) <= 0
        # The prediction's own border band holds the prediction, when within a frame of the image.
        if -640.5 <= x <= 1279.5 and -480.5 <= y <= 959.5:
            assert x0 <= x <= x1 and y0 <= y <= y1


def test_far_end_of_a_forearm_blob() -> None:
    # Bare forearm from (200, 250) to (140, 370) ending in the hand: the point is near the hand.
    forearm = bar((200, 250), (140, 370), 22)
    hand = disc((133, 384), 15)
    blobs = blobs_of(face, forearm, hand)
    prediction = joints((320, 100), (138, 378), (500, 300), right_elbow=(202, 246))
    _, right, left = locate_points(blobs, prediction, CONFIG)
    assert left is None  # nothing near the predicted left hand
    blob = blobs[right.blob]
    assert np.hypot(right.xy[0] - 133, right.xy[1] - 384) < 10
    assert np.hypot(blob.centroid[0] - 133, blob.centroid[1] - 384) > 40


def test_no_blob_within_gate_is_absent() -> None:
    blobs = blobs_of(face)
    head, right, left = locate_points(blobs, joints((320, 100), (100, 450), (560, 450)), CONFIG)
    assert head is not None and right is None and left is None


def test_startup_assigns_by_side_of_head() -> None:
    blobs = blobs_of(
        face,
        disc((200, 330), 14),
        disc((460, 330), 16),
    )
    head, right, left = locate_points(blobs, None, CONFIG)
    assert head.xy[1] < 120 and right.xy[0] < 260 and left.xy[0] > 400
    one_hand = blobs_of(face, disc((460, 330), 16))
    head, right, left = locate_points(one_hand, None, CONFIG)
    assert right is None and left is not None
    assert locate_points([], None, CONFIG) == [None, None, None]


def test_foreshortened_forearm_shortens_the_hand_slab() -> None:
    # Forearm pointing at the camera: elbow (200, 290) projects 37 px from the palm (212, 325),
    # a third of an upright forearm (0.94 x 100 px shoulders); the bare forearm and the hand
    # form one short blob. A full slab (50 px) would take the whole blob, forearm included.
    forearm = bar((200, 284), (210, 318), 24)
    hand = disc((212, 328), 15)
    blobs = blobs_of(face, forearm, hand)
    prediction = joints((320, 100), (212, 325), (500, 300), right_elbow=(200, 290))
    _, right, _ = locate_points(blobs, prediction, CONFIG)
    full = locate_points(blobs, prediction, CONFIG.replace(hand_min_foreshortening=1.0))[1]
    assert np.hypot(right.xy[0] - 212, right.xy[1] - 328) < 5
    assert np.hypot(full.xy[0] - 212, full.xy[1] - 328) > 9


def test_a_forearm_predicted_hanging_finds_its_hand_along_the_blob() -> None:
    # Clapping: the bare right forearm points inwards (elbow below the shoulder, hand at the
    # inner end) while the prediction has it hanging. Along the prediction the "hand" would be
    # the middle of the whole bar (31 px off); along the blob's long axis it is the inner end,
    # near the point a correct prediction gives (whose slab is shorter: the blob reaches its
    # elbow).
    forearm = bar((262, 300), (322, 300), 20)
    hand = disc((330, 300), 13)
    blobs = blobs_of(face, forearm, hand)
    hanging = locate_points(blobs, joints((320, 100), (265, 305), (500, 300), right_elbow=(262, 250)), CONFIG)[1]
    along = locate_points(blobs, joints((320, 100), (330, 300), (500, 300), right_elbow=(262, 300)), CONFIG)[1]
    assert np.hypot(hanging.xy[0] - 330, hanging.xy[1] - 300) < 13
    assert np.hypot(along.xy[0] - 330, along.xy[1] - 300) < 7


def test_a_blob_up_the_bare_upper_arm_keeps_the_predicted_forearm() -> None:
    # Short sleeves, forearm towards the camera: the blob is the bare upper arm down to the
    # elbow and the foreshortened hand below it. Its long axis points up the arm, to the
    # shoulder: the point stays at the hand.
    upper_arm = bar((270, 190), (270, 250), 18)
    hand = disc((274, 262), 12)
    blobs = blobs_of(face, upper_arm, hand)
    right = locate_points(blobs, joints((320, 100), (274, 262), (500, 300), right_elbow=(270, 250)), CONFIG)[1]
    assert np.hypot(right.xy[0] - 274, right.xy[1] - 262) < 8


def test_hand_alone_keeps_the_full_slab() -> None:
    # Long sleeves: the blob is the hand alone, away from the elbow; foreshortening changes nothing.
    blobs = blobs_of(face, lambda s: cv2.ellipse(s, (212, 330), (12, 20), 0, 0, 360, 255, -1))
    prediction = joints((320, 100), (212, 330), (500, 300), right_elbow=(205, 300))
    _, right, _ = locate_points(blobs, prediction, CONFIG)
    assert np.hypot(right.xy[0] - 212, right.xy[1] - 330) < 1.5


def test_outline_edges_just_outside_the_blob_count_once_dilated() -> None:
    # A hand whose skin mask stops a pixel short of its outline's edge band (shading, colour
    # blending): I_edge as it is misses the blob; dilated 3x3, as the extractor passes it, the
    # band's inner ring counts.
    skin = np.zeros((480, 640), np.uint8)
    cv2.circle(skin, (300, 300), 15, 255, -1)
    edge = np.zeros_like(skin)
    cv2.circle(edge, (300, 300), 17, 255, 2)  # radii 16..18
    assert find_skin_blobs(skin, edge, CONFIG) == []
    (blob,) = find_skin_blobs(skin, cv2.dilate(edge, np.ones((3, 3), np.uint8)), CONFIG)
    assert 0.1 < blob.gradient < 0.2  # the outer ring of the disc: about 2 * pi * 15 / (pi * 15^2)


def test_head_point_hardly_moves_with_the_hairline() -> None:
    # Head centred at (320, 100), 56 x 72 px, on a neck. With the hair taken for skin the blob is
    # the whole head; without it the blob starts 20 px lower, at the hairline. The top of the
    # blob moves 20 px; the head point, the centre of the widest disc, much less.
    def neck(s):
        return cv2.rectangle(s, (305, 130), (335, 165), 255, -1)

    def bald(s):
        return cv2.ellipse(s, (320, 100), (28, 36), 0, 0, 360, 255, -1)

    def hair(s):
        bald(s)
        s[:80] = 0

    prediction = joints((320, 100), (150, 400), (500, 400))
    points = [locate_points(blobs_of(head, neck), prediction, CONFIG)[0].xy for head in (bald, hair)]
    assert np.hypot(points[0][0] - 320, points[0][1] - 100) < 2  # 100.8
    assert np.hypot(points[1][0] - 320, points[1][1] - 100) < 9  # 108.1
    # The centroid of the top half shoulder width moved 12 px (92.0 -> 103.9).
    assert points[1][1] - points[0][1] < 8


def test_a_limb_that_differs_from_the_room_only_in_colour_is_kept() -> None:
    # A dark forearm hanging in front of a dark sofa: no grey-level edge (P_SB = 0), but it is
    # all I_sub and its outline borders the unchanged room: kept. A skin-coloured patch inside
    # changed clothing (I_sub all round) and a patch that does not differ from the plate are not.
    skin = np.zeros((480, 640), np.uint8)
    sub = np.zeros_like(skin)
    edge = np.zeros_like(skin)
    cv2.rectangle(skin, (100, 300), (125, 400), 255, -1)  # forearm
    cv2.rectangle(sub, (100, 250), (125, 400), 255, -1)  # forearm and sleeve
    cv2.rectangle(sub, (300, 250), (420, 479), 255, -1)  # clothes ...
    cv2.rectangle(skin, (340, 320), (380, 380), 255, -1)  # ... with a skin-coloured patch
    cv2.rectangle(skin, (500, 100), (540, 140), 255, -1)  # unchanged: not in I_sub
    kept = find_skin_blobs(skin, edge, CONFIG, sub)
    assert [b.bbox for b in kept] == [(100, 300, 26, 101)]
    assert kept[0].gradient == 0.0
    assert find_skin_blobs(skin, edge, CONFIG) == []  # without I_sub: P_SB alone, as before
    assert find_skin_blobs(skin, edge, CONFIG.replace(blob_min_changed=1.1), sub) == []


def test_a_shadow_on_skin_coloured_furniture_is_not_a_limb() -> None:
    # Two orange cushions on a blue sofa, both skin-coloured. The person's shadow darkens the
    # first to 0.85 of the plate (I_sub, no new edge); a bare forearm hangs in front of the
    # second. The colour test alone keeps both; the shadow is a shade of the plate and goes.
    plate = np.full((480, 640, 3), (150, 110, 90), np.uint8)
    cv2.rectangle(plate, (100, 300), (160, 360), (84, 113, 155), -1)
    cv2.rectangle(plate, (400, 280), (470, 420), (84, 113, 155), -1)
    frame = plate.copy()
    frame[300:361, 100:161] = np.round(plate[300:361, 100:161] * 0.85).astype(np.uint8)
    cv2.rectangle(frame, (420, 300), (445, 400), (120, 150, 205), -1)
    skin = np.zeros((480, 640), np.uint8)
    cv2.rectangle(skin, (100, 300), (160, 360), 255, -1)
    cv2.rectangle(skin, (420, 300), (445, 400), 255, -1)
    sub, edge = skin.copy(), np.zeros_like(skin)
    kept = find_skin_blobs(skin, edge, CONFIG, sub, frame, plate)
    assert [b.bbox for b in kept] == [(420, 300, 26, 101)]
    assert len(find_skin_blobs(skin, edge, CONFIG, sub)) == 2  # without the plate: colour alone
    assert len(find_skin_blobs(skin, edge, CONFIG.replace(blob_shade_spread=0.0), sub, frame, plate)) == 2


@settings(max_examples=60, deadline=None)
@given(
    colour=st.tuples(*[st.integers(60, 140)] * 3),
    factor=st.floats(0.5, 1.2),
    tint=st.floats(0.1, 0.5),
    channel=st.integers(0, 2),
)
def test_a_shade_is_one_factor_on_every_channel(
    colour: tuple[int, int, int], factor: float, tint: float, channel: int
) -> None:
    # The plate's colour times one factor is a shade (rounded to whole levels); one channel
    # scaled `tint` more is a new colour.
    plate = np.full((20, 30, 3), colour, np.uint8)
    pixels = np.zeros((10, 12), np.uint8)
    pixels[2:8, 3:9] = 255
    shaded = np.round(plate * factor).astype(np.uint8)
    assert is_shade(pixels, (5, 4), shaded, plate, CONFIG)
    scale = np.full(3, factor)
    scale[channel] *= 1.0 + tint
    tinted = np.round(plate * scale).astype(np.uint8)
    assert not is_shade(pixels, (5, 4), tinted, plate, CONFIG)
    assert not is_shade(pixels, (5, 4), shaded, plate, CONFIG.replace(blob_shade_spread=0.0))


def test_hand_leaving_the_face_does_not_push_the_head_onto_it() -> None:
    # The model's hand is still on the face (top) while the real hand has just left it (below
    # the chin): matched by total distance alone, the head would take the hand's blob.
    hand = disc((300, 160), 12)  # 12 px below the chin
    blobs = blobs_of(face, hand, disc((440, 310), 14))
    predicted = joints((320, 100), (320, 80), (436, 305))
    head, right, _ = locate_points(blobs, predicted, CONFIG)
    assert blobs[head.blob].distance_to((320, 100)) == 0 and abs(head.xy[1] - 100) < 20
    # The model's hand deep in the face, 0.7 shoulder widths from the real one: at the default
    # `blob_share_cost` (0.45) it shares the face (both merged) rather than take the hand's blob.
    assert head.merged and right.merged and right.blob == head.blob
    # With distinct blobs only, the hand takes its own blob and the head keeps the face.
    head, right, _ = locate_points(blobs, predicted, CONFIG.replace(blob_share_cost=10.0))
    assert not head.merged and abs(head.xy[1] - 100) < 20
    assert np.hypot(right.xy[0] - 300, right.xy[1] - 160) < 8
    # The priority alone: with the smaller floor on a part's blob (`part_min_share` 0.1), the
    # hand's blob is large enough for the head, which takes it without the priority.
    swapped, _, _ = locate_points(
        blobs, predicted, CONFIG.replace(head_priority=1.0, part_min_share=0.1, blob_share_cost=10.0)
    )
    assert abs(swapped.xy[1] - 160) < 10, "without the priority the head takes the hand's blob"


def test_hand_merged_with_the_face_is_boxed_clear_of_the_head() -> None:
    hand = disc((300, 145), 14)  # overlaps the chin
    blobs = blobs_of(face, hand)
    head, right, _ = locate_points(blobs, joints((320, 100), (300, 145), (440, 310)), CONFIG)
    assert head.merged and right.merged and right.box is not None
    x0, y0, x1, y1 = right.box
    # Farther than head_length shoulder widths (50 px) from the head: the bottom of the hand.
    assert y0 > 136 and y1 <= 160 and 285 <= x0 <= x1 <= 315
    assert head.box is None


def test_hands_together_keep_the_whole_blob() -> None:
    blobs = blobs_of(face, lambda s: cv2.ellipse(s, (320, 330), (30, 14), 0, 0, 360, 255, -1))
    _, right, left = locate_points(blobs, joints((320, 100), (305, 330), (335, 330)), CONFIG)
    assert right.merged and left.merged and right.box is None and left.box is None
