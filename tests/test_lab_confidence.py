"""The confidence re-measurement's pure parts (python -m upperpose.lab.confidence), on constructed numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from upperpose.lab.confidence import (
    Joint,
    format_check,
    format_rows,
    low_share,
    main,
    resamplings,
    share_rows,
)


def test_low_share_is_the_percentile_of_the_pooled_share_over_resamplings() -> None:
    hits, counts = np.array([10, 0]), np.array([10, 10])
    resamples = np.array([[0, 0], [0, 1], [1, 1], [1, 0], [0, 1]])
    # Shares 1, 0.5, 0, 0.5, 0.5: sorted 0, .5, .5, .5, 1; the 10th percentile lies 0.4 of the way from 0 to 0.5.
    assert low_share(hits, counts, resamples) == pytest.approx(0.2)
    assert low_share(hits, counts, resamples, percentile=50) == pytest.approx(0.5)


def test_low_share_pools_joints_and_skips_resamplings_without_any() -> None:
    hits, counts = np.array([3, 0, 1]), np.array([4, 0, 4])
    resamples = np.array([[1, 1, 1], [0, 2, 1]])  # the first has no joints of the group
    assert low_share(hits, counts, resamples) == pytest.approx(0.5)
    assert math.isnan(low_share(hits, counts, np.array([[1, 1, 1]])))


def test_low_share_of_equal_clips_is_their_share() -> None:
    assert low_share(np.array([8, 4, 8]), np.array([10, 5, 10]), resamplings(3)) == pytest.approx(0.8)


def test_resamplings_are_seeded_and_draw_clips_with_replacement() -> None:
    drawn = resamplings(16)
    assert drawn.shape == (1000, 16)
    assert drawn.min() == 0 and drawn.max() == 15
    assert np.array_equal(drawn, resamplings(16))
    assert not np.array_equal(drawn, resamplings(16, seed=1))


TABLES = {"hand": ((0.1, 0.9), (math.inf, 0.2))}
FIXED = {"shoulder": 0.3, "hand_lost": 0.05}


def joints() -> list[Joint]:
    made = [Joint(0, "hand", 0.05, 0.9, 3.0), Joint(1, "hand", 0.02, 0.9, 12.0), Joint(1, "hand", 0.1, 0.2, 10.0)]
    made += [Joint(c, "shoulder", None, 0.3, e) for c, e in ((0, 1.0), (0, 20.0), (1, 2.0), (1, 4.0))]
    return made + [Joint(0, "new", None, 0.0, 30.0)]


def test_share_rows_split_table_groups_by_gap_and_keep_the_order() -> None:
    rows = share_rows(joints(), 2, resamplings(2), TABLES, FIXED)
    assert [(r.group, r.upto, r.joints) for r in rows] == [
        ("hand", 0.1, 2),
        ("hand", math.inf, 1),  # a gap at the bound belongs to the next row, as `lookup` reads it
        ("shoulder", None, 4),
        ("hand_lost", None, 0),
        ("new", None, 1),
    ]
    hand, far, shoulder, lost, new = rows
    assert (hand.share, far.share, shoulder.share, new.share) == (0.5, 1.0, 0.75, 0.0)
    assert hand.low == 0.0 and far.low == 1.0  # resamplings with only clip 1's near hand exist
    assert 0.5 <= shoulder.low <= 0.75
    assert math.isnan(lost.share) and math.isnan(lost.low)
    assert (hand.now, far.now, shoulder.now, lost.now) == (0.9, 0.2, 0.3, 0.05)
    assert math.isnan(new.now)


def test_format_rows_prints_tables_to_paste() -> None:
    text = format_rows(share_rows(joints(), 2, resamplings(2), TABLES, FIXED))
    code = text[text.index("TABLES") :].replace(": dict[str, Table]", "").replace(": dict[str, float]", "")
    pasted: dict[str, object] = {}
    exec(code, {"math": math}, pasted)
    assert pasted["TABLES"] == {"hand": ((0.1, 0.0), (math.inf, 1.0))}
    shoulder = share_rows(joints(), 2, resamplings(2), TABLES, FIXED)[2].low
    # A group without joints keeps its number.
    assert pasted["FIXED"] == {"shoulder": round(shoulder, 2), "hand_lost": 0.05, "new": 0.0}


def test_format_check_reports_the_joints_at_half_or_more() -> None:
    text = format_check(joints())
    assert "confidence >= 0.5: 25.0 % of the joints, 50.0 % of them within 10 px" in text
    assert "confidence 0.3-0.5:      4 joints, mean 0.30, within 10 px 75.0 %" in text


def test_missing_validation_folder_is_one_clear_line(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    assert main([str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no validation set at" in err and "nowhere" in err
    assert main([str(tmp_path)]) == 2
    assert "no clips" in capsys.readouterr().err
