"""A face box in one place over frames spread across a video (`faces.steady_face`)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.features.faces import same_place, steady_face


def test_same_place_measures_centre_and_width_in_the_references_widths() -> None:
    reference = (100, 80, 40, 40)  # centre (119.5, 99.5)
    assert same_place((108, 80, 40, 40), reference, 0.25)  # centre 8 px off: 0.2 widths
    assert not same_place((110, 80, 40, 40), reference, 0.25)  # 10 px: 0.25 widths, not less
    assert same_place((96, 76, 48, 48), reference, 0.25)  # 8 px wider, centre unchanged
    assert not same_place((95, 75, 50, 50), reference, 0.25)  # 10 px wider


def test_a_face_in_most_samples_is_steady_and_boxes_that_come_and_go_are_not() -> None:
    face, nudged, small = (100, 80, 40, 40), (103, 82, 41, 41), (400, 300, 30, 30)
    frames = [[face], [nudged, small], [face], [], [nudged]]
    assert steady_face(frames, 0.75) == nudged  # both in 4 of 5 frames: the larger
    assert steady_face(frames, 0.85) is None
    assert steady_face(frames, 0.0) is None  # the rule is off
    assert steady_face([], 0.5) is None
    # Each false box in one frame only, at its own place: none is steady.
    assert steady_face([[(20 * k, 10, 30, 30)] for k in range(1, 9)], 0.25) is None
    # Two boxes each in every frame: the larger wins.
    assert steady_face([[small, face]] * 3, 0.75) == face


@settings(max_examples=60, deadline=None)
@given(
    frames=st.integers(4, 12),
    present=st.data(),
    seed=st.integers(0, 2**16),
    share=st.sampled_from([0.5, 0.75, 1.0]),
)
def test_a_jittering_face_is_steady_exactly_when_it_is_in_enough_samples(frames, present, seed, share) -> None:
    # A face jittering by at most 2 px and 2 px of width (40 px wide: pairs stay within 0.25
    # widths) in `count` of the frames, plus a false box at a new place in every frame.
    count = present.draw(st.integers(0, frames))
    rng = np.random.default_rng(seed)
    boxes = []
    for k in range(frames):
        frame = [(int(300 + 35 * k) % 600, int(20 + 45 * k) % 400, 30, 30)]
        if k < count:
            dx, dy, dw = rng.integers(-2, 3, size=3)
            frame.append((100 + int(dx), 80 + int(dy), 40 + int(dw), 40 + int(dw)))
        boxes.append(frame)
    found = steady_face(boxes, share)
    if count >= share * frames:
        assert found is not None and same_place(found, (100, 80, 40, 40), 0.25)
    elif count < share * frames:
        assert found is None
