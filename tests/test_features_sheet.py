"""Contact sheet tiles (features/sheet.py)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from upperpose.features.sheet import TILE_WIDTH, label_tile


@pytest.mark.parametrize(
    "detail", ["12.6%", "estimated: masked median, person cut out, refined while tracking", "x" * 200]
)
def test_a_tile_label_is_never_written_over_its_title(detail: str) -> None:
    tile = label_tile(np.zeros((240, 320), np.uint8), "background", detail)
    bar = tile[1:21].astype(int)
    # The title is white and grey; the detail is drawn tinted (more red than blue).
    tinted = (bar[..., 2] - bar[..., 0]) > 15
    title_end = cv2.getTextSize("background", cv2.FONT_HERSHEY_SIMPLEX, 0.5, 1)[0][0] + 5
    assert tinted.any()  # the detail is there, cut short if need be
    assert not tinted[:, : title_end + 2].any()
    assert tile.shape[1] == TILE_WIDTH
