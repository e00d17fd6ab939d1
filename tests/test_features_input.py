"""Bit packing for the Rust cost, configuration checks and bad input to the features."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from upperpose.features import (
    Background,
    FeatureConfig,
    FeatureExtractor,
    pack_rows,
    row_stride,
    unpack_rows,
)
from upperpose.features.background import estimate_background


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 40).flatmap(
        lambda h: st.integers(1, 200).flatmap(lambda w: arrays(np.uint8, (h, w), elements=st.sampled_from([0, 1, 255])))
    )
)
def test_pack_rows_round_trip_and_layout(mask: np.ndarray) -> None:
    height, width = mask.shape
    words = pack_rows(mask)
    assert words.shape == (height, -(-width // 64)) == (height, row_stride(width))
    assert words.dtype == np.dtype("<u8") and words.flags.c_contiguous
    np.testing.assert_array_equal(unpack_rows(words, width), mask > 0)
    # Reference layout of raster.rs BitMask: bit (x % 64) of word x // 64, least significant first.
    ys, xs = np.nonzero(mask)
    for y, x in zip(ys[:20].tolist(), xs[:20].tolist()):
        assert (int(words[y, x // 64]) >> (x % 64)) & 1 == 1
    total_bits = sum(int(w).bit_count() for w in words.ravel())
    assert total_bits == int((mask > 0).sum())  # no stray bits past the right edge


def test_pack_rows_exact_words() -> None:
    mask = np.zeros((2, 70), bool)
    mask[0, 0] = mask[0, 63] = mask[1, 64] = mask[1, 69] = True
    words = pack_rows(mask)
    assert words.tolist() == [[1 | (1 << 63), 0], [0, 1 | (1 << 5)]]
    assert words.tobytes()[:1] == b"\x01"  # little-endian: the leftmost pixel is in the first byte


def test_pack_rows_rejects_non_2d() -> None:
    with pytest.raises(ValueError, match=r"\(H, W\)"):
        pack_rows(np.zeros((2, 3, 3)))
    with pytest.raises(ValueError, match="stride|must be"):
        unpack_rows(np.zeros((2, 1), np.uint64), 65)


@pytest.fixture(scope="module")
def extractor() -> FeatureExtractor:
    return FeatureExtractor(Background.from_plate(np.full((48, 64, 3), 100, np.uint8)))


@pytest.mark.parametrize(
    ("frame", "message"),
    [
        (np.zeros((48, 64), np.uint8), "grayscale"),
        (np.zeros((48, 64, 1), np.uint8), "grayscale"),
        (np.zeros((48, 64, 4), np.uint8), r"\(H, W, 3\)"),
        (np.zeros((48, 64, 3), np.float32), "uint8"),
        (np.zeros((0, 0, 3), np.uint8), "empty"),
        (np.zeros((48, 0, 3), np.uint8), "empty"),
        (np.zeros((96, 128, 3), np.uint8), "128x96 but the background is 64x48"),
    ],
)
def test_bad_frames_raise_value_error(extractor: FeatureExtractor, frame: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        extractor(frame)  # type: ignore[arg-type]


@pytest.mark.parametrize("frame", [[[1, 2, 3]], None])
def test_non_arrays_raise_type_error(extractor: FeatureExtractor, frame: object) -> None:
    with pytest.raises(TypeError, match="numpy array"):
        extractor(frame)  # type: ignore[arg-type]


def test_bad_masks_and_joints_raise_value_error(extractor: FeatureExtractor) -> None:
    frame = np.zeros((48, 64, 3), np.uint8)
    with pytest.raises(ValueError, match="part_labels"):
        extractor(frame, part_labels=np.zeros((48, 63), np.uint8))
    with pytest.raises(ValueError, match="part_labels"):
        extractor(frame, part_labels=np.zeros((48, 64), np.float64))
    with pytest.raises(ValueError, match="predicted_joints"):
        extractor(frame, predicted_joints=np.zeros((6, 2)))
    with pytest.raises(ValueError, match="torso_region"):
        extractor(frame, torso_region=np.zeros((47, 64), bool))


def test_bad_backgrounds_raise_value_error() -> None:
    with pytest.raises(ValueError, match="background is grayscale"):
        Background.from_plate(np.zeros((48, 64), np.uint8))
    with pytest.raises(ValueError, match="background is empty"):
        Background.from_plate(np.zeros((0, 64, 3), np.uint8))
    with pytest.raises(ValueError, match="at least one frame"):
        estimate_background([], [])
    with pytest.raises(ValueError, match="sample 1 is 32x48"):
        estimate_background([], [np.zeros((48, 64, 3), np.uint8), np.zeros((48, 32, 3), np.uint8)])


@pytest.mark.parametrize(
    "changes",
    [
        {"skin_space": "lab"},
        {"rgb_rg_min": 90},
        {"sub_close": -1},
        {"edge_blur": 4},
        {"hand_gate": 0.0},
        {"person_skin_sigmas": 0.0},
        {"person_skin_min_hue_spread": -1.0},
        {"bg_max_samples": 2},
    ],
)
def test_bad_config_raises_value_error(changes: dict[str, object]) -> None:
    with pytest.raises(ValueError):
        FeatureConfig(**changes)  # type: ignore[arg-type]


def test_config_is_frozen_and_replaceable() -> None:
    config = FeatureConfig()
    with pytest.raises(AttributeError):
        config.sub_threshold = 3  # type: ignore[misc]
    assert config.replace(skin_space="hsv").skin_space == "hsv"
    with pytest.raises(ValueError):
        config.replace(skin_space="nope")
