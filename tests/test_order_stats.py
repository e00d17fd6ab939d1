"""`features.order_stats.kth_smallest` against numpy's sort, the reference it replaces."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.exceptions import InputError
from upperpose.features.order_stats import kth_smallest


@settings(max_examples=60, deadline=None)
@given(
    count=st.integers(1, 12),
    shape=st.tuples(st.integers(1, 9), st.integers(1, 9), st.sampled_from([1, 3])),
    levels=st.sampled_from([2, 3, 256]),
    seed=st.integers(0, 2**32 - 1),
    per_pixel=st.booleans(),
)
def test_kth_smallest_is_the_sorted_stack_at_k(count, shape, levels, seed, per_pixel) -> None:
    # Few levels make ties, and values at 0 and 255, likely.
    rng = np.random.default_rng(seed)
    stack = np.linspace(0, 255, levels).round().astype(np.uint8)[rng.integers(0, levels, (count, *shape))]
    k = rng.integers(0, count, shape) if per_pixel else int(rng.integers(0, count))
    expected = np.take_along_axis(np.sort(stack, axis=0), np.broadcast_to(k, shape)[None], axis=0)[0]
    np.testing.assert_array_equal(kth_smallest(stack, k), expected)


def test_more_than_255_values_are_counted_without_overflow() -> None:
    rng = np.random.default_rng(4)
    stack = rng.integers(0, 256, (300, 4, 5), dtype=np.uint8)
    for k in (0, 149, 255, 256, 299):
        np.testing.assert_array_equal(kth_smallest(stack, k), np.sort(stack, axis=0)[k])


def test_the_median_of_a_known_stack() -> None:
    stack = np.array([[7, 0], [3, 255], [5, 255]], np.uint8)[:, None, :]  # 3 images of 1x2
    np.testing.assert_array_equal(kth_smallest(stack, 1), [[5, 255]])
    np.testing.assert_array_equal(kth_smallest(stack, 0), [[3, 0]])
    np.testing.assert_array_equal(kth_smallest(stack, np.array([[2, 0]])), [[7, 0]])


@pytest.mark.parametrize("k", [-1, 3, np.array([0, 3])])
def test_a_k_outside_the_stack_is_refused(k) -> None:
    with pytest.raises(InputError, match="k must lie within 0..2"):
        kth_smallest(np.zeros((3, 1, 2), np.uint8), k)


def test_an_empty_stack_is_refused() -> None:
    with pytest.raises(InputError, match="no values"):
        kth_smallest(np.zeros((0, 2, 2), np.uint8), 0)
