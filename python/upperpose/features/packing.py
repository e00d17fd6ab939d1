"""Bit-packed masks in the layout of the Rust rasteriser's `BitMask` (rust/upperpose-core/src/raster.rs).

Layout: one row after another, top to bottom; each row is `stride = ceil(W / 64)` little-endian
`u64` words; bit `i` of word `k` (least significant bit first) is pixel `x = 64 k + i`. Bits past
the right edge of the image are zero.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from upperpose.exceptions import InputError

WORD_BITS = 64


def row_stride(width: int) -> int:
    """Words per packed row of an image `width` pixels wide."""
    return -(-int(width) // WORD_BITS)


def pack_rows(mask: npt.ArrayLike) -> npt.NDArray[np.uint64]:
    """Packs a mask into rows of little-endian u64 words, least significant bit = leftmost pixel.

    Args:
        mask: `(H, W)` bool or integer array; any nonzero value is a set pixel.

    Returns:
        `(H, ceil(W / 64))` C-contiguous array of dtype `<u8` (uint64 on little-endian hosts).

    Raises:
        ValueError: `mask` is not two-dimensional.
    """
    array = np.asarray(mask)
    if array.ndim != 2:
        raise InputError(f"mask must be (H, W), got shape {array.shape}")
    height, width = array.shape
    stride = row_stride(width)
    packed = np.packbits(array, axis=1, bitorder="little")
    pad = stride * 8 - packed.shape[1]
    if pad:
        packed = np.concatenate([packed, np.zeros((height, pad), np.uint8)], axis=1)
    return np.ascontiguousarray(packed).view("<u8").reshape(height, stride)


def unpack_rows(words: npt.ArrayLike, width: int) -> npt.NDArray[np.uint8]:
    """Inverse of `pack_rows`: `(H, stride)` u64 words back to an `(H, width)` 0/1 uint8 mask.

    Raises:
        ValueError: not two-dimensional, or `stride` does not match `width`.
    """
    array = np.ascontiguousarray(words, dtype="<u8")
    if array.ndim != 2 or array.shape[1] != row_stride(width):
        raise InputError(f"words must be (H, {row_stride(width)}) for width {width}, got shape {array.shape}")
    as_bytes = array.view(np.uint8).reshape(array.shape[0], -1)
    return np.unpackbits(as_bytes, axis=1, count=width, bitorder="little")
