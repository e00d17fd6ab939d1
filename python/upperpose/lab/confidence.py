"""Re-measures the per-joint confidence numbers (`upperpose.fit.confidence` TABLES and FIXED).

Each joint falls into a group by its evidence (`JointConfidence.groups`), and each group's number
is the share of its joints within 10 px of the truth on the external validation set, taken as the
10th percentile over 1000 resamplings of the clips (drawn with replacement, seeded, so the same
run prints the same numbers). This tool tracks every clip as `run.py` of the validation set does
(the clip's clean plate and focal length, the given seed, smoothed output), records each joint's
group and gap beside its error against `gt.json`, and prints per group (and per gap row of a
table group) the count, the measured share and the 10th percentile, then TABLES and FIXED ready
to paste. The check: the share of joints whose current confidence is at least 0.5, and how many
of those are within 10 px (docs/RESULTS.md, "Confidence").

    python -m upperpose.lab.confidence VALIDATION_DIR [--seed 0] [--check-only]

VALIDATION_DIR holds one folder per clip with `video.mp4`, `background.png`, `meta.json` and
`gt.json` (the external validation set; it is not part of the project).

After changing the tracker, run it on seed 0, paste the tables into `upperpose/fit/confidence.py`
and rerun the check (also on seed 1). One run of the 16 clips takes a minute or a few.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from upperpose.fit.confidence import FIXED, TABLES, JointConfidence, Table
from upperpose.fit.pipeline import VideoTracking
from upperpose.fit.smoothing import DEFAULT_LAG, PoseSmoother
from upperpose.fit.tracker import TrackerConfig
from upperpose.result import TrackResult

IntArray = npt.NDArray[np.int64]
Groups = list[tuple[str, float | None]]
WITHIN_PX = 10.0
RESAMPLES = 1000
PERCENTILE = 10.0
BANDS = ((0.9, 1.01), (0.8, 0.9), (0.5, 0.8), (0.3, 0.5), (0.1, 0.3), (0.0, 0.1))


class Joint(NamedTuple):
    """One written joint of one posed frame: its clip, group, gap, confidence and error in pixels."""

    clip: int
    group: str
    gap: float | None
    confidence: float
    error: float


class Row(NamedTuple):
    """A group, or one gap row of a table group (`upto`: the row's gap bound), measured, and its number now."""

    group: str
    upto: float | None
    joints: int
    share: float
    low: float
    now: float


class _Recorder(JointConfidence):
    """The tracker's own confidence, keeping the groups of the frame it last saw."""

    def __init__(self) -> None:
        super().__init__()
        self.last: Groups | None = None

    def groups(self, *args: Any, **kwargs: Any) -> Groups:
        self.last = super().groups(*args, **kwargs)
        return self.last


def track_clip(folder: Path, seed: int, index: int) -> list[Joint]:
    """Tracks one clip as `upperpose track --background --focal --seed` does; one Joint per posed joint."""
    meta = json.loads((folder / "meta.json").read_text())
    truth = {f["frame"]: f["joints_2d"] for f in json.loads((folder / "gt.json").read_text())["frames"]}
    recorder = _Recorder()
    found: dict[int, Groups] = {}  # frame: its joints' groups, as the tracker saw them
    joints: list[Joint] = []

    def score(result: TrackResult) -> None:
        gt = truth.get(result.frame)
        if result.joints_2d is None or result.confidence is None or gt is None:
            return
        errors = np.hypot(*(result.joints_2d - np.asarray(gt, dtype=float)).T)
        for (group, gap), conf, err in zip(found[result.frame], result.confidence, errors):
            joints.append(Joint(index, group, gap, float(conf), float(err)))

    config = TrackerConfig(seed=seed)
    with VideoTracking(
        folder / "video.mp4", folder / "background.png", focal=meta["camera"]["focal"], config=config
    ) as run:
        run.tracker._confidence = recorder  # the tracker's own grouping, recorded as it goes
        smoother: PoseSmoother[None] = PoseSmoother(run.camera, DEFAULT_LAG)
        for _, result in run.frames():
            if recorder.last is not None:
                found[result.frame], recorder.last = recorder.last, None
            for done, _ in smoother.push(result, run.tracker.body, None):
                score(done)
        for done, _ in smoother.flush():
            score(done)
    return joints


def resamplings(clips: int, seed: int = 0, count: int = RESAMPLES) -> IntArray:
    """`count` resamplings of the clips with replacement: each row holds `clips` clip indices."""
    drawn: IntArray = np.random.default_rng(seed).integers(0, clips, (count, clips))
    return drawn


def low_share(hits: IntArray, counts: IntArray, resamples: IntArray, percentile: float = PERCENTILE) -> float:
    """The `percentile` of the pooled share hits / counts over resamplings of the clips.

    `hits` and `counts` are per clip; resamplings in which the group has no joints are skipped.
    NaN when it has none at all.
    """
    n = counts[resamples].sum(axis=1)
    if not np.any(n > 0):
        return math.nan
    return float(np.percentile(hits[resamples].sum(axis=1)[n > 0] / n[n > 0], percentile))


def share_rows(
    joints: Sequence[Joint],
    clips: int,
    resamples: IntArray,
    tables: dict[str, Table] = TABLES,
    fixed: dict[str, float] = FIXED,
) -> list[Row]:
    """Per group (a table group per gap row, nearest first) the count, share within 10 px and low share.

    The groups and rows are those of `tables` and `fixed`, then any other group the joints show.
    """
    clip = np.array([j.clip for j in joints], dtype=np.int64)
    group = np.array([j.group for j in joints], dtype=object)
    gap = np.array([math.nan if j.gap is None else j.gap for j in joints], dtype=float)
    within = np.array([j.error <= WITHIN_PX for j in joints], dtype=bool)

    def row(name: str, upto: float | None, mask: npt.NDArray[np.bool_], now: float) -> Row:
        hits = np.bincount(clip[mask & within], minlength=clips)
        counts = np.bincount(clip[mask], minlength=clips)
        share = float(within[mask].mean()) if mask.any() else math.nan
        return Row(name, upto, int(mask.sum()), share, low_share(hits, counts, resamples), now)

    rows = []
    for name in [*tables, *fixed, *sorted(set(group) - set(tables) - set(fixed))]:
        mask = group == name
        if name not in tables:
            rows.append(row(name, None, mask, fixed.get(name, math.nan)))
            continue
        below = 0.0
        for upto, now in tables[name]:
            rows.append(row(name, upto, mask & (gap >= below) & (gap < upto), now))
            below = upto
    return rows


def _bound(upto: float | None) -> str:
    return "math.inf" if upto is not None and math.isinf(upto) else f"{upto:g}"


def _paste(r: Row) -> str:
    """The row's new number: its low share to two places (a row without joints keeps its number now)."""
    return f"{r.now if math.isnan(r.low) else r.low:.2f}"


def format_rows(rows: Sequence[Row]) -> str:
    """The measurement beside the number now, then TABLES and FIXED to paste into `upperpose.fit.confidence`."""
    lines = [f"{'group':18s} {'gap <':>6s} {'joints':>6s} {'share':>6s} {'p10':>6s} {'now':>6s}"]
    for r in rows:
        upto = "" if r.upto is None else f"{r.upto:g}"
        lines.append(f"{r.group:18s} {upto:>6s} {r.joints:6d} {r.share:6.3f} {r.low:6.3f} {r.now:6.2f}")
    lines.append("TABLES: dict[str, Table] = {")
    for name in dict.fromkeys(r.group for r in rows if r.upto is not None):
        cells = ", ".join(f"({_bound(r.upto)}, {_paste(r)})" for r in rows if r.group == name)
        lines.append(f'    "{name}": ({cells}),')
    lines += ["}", "FIXED: dict[str, float] = {"]
    lines += [f'    "{r.group}": {_paste(r)},' for r in rows if r.upto is None]
    return "\n".join([*lines, "}"])


def format_check(joints: Sequence[Joint]) -> str:
    """The share of joints at confidence >= 0.5, those within 10 px, and each band's share within 10 px."""
    conf = np.array([j.confidence for j in joints], dtype=float)
    within = np.array([j.error <= WITHIN_PX for j in joints], dtype=bool)
    high = conf >= 0.5
    lines = [
        f"joints {len(conf)}, within 10 px {100 * within.mean():.1f} %",
        f"confidence >= 0.5: {100 * high.mean():.1f} % of the joints, {100 * within[high].mean():.1f} % of them "
        "within 10 px",
    ]
    for lo, hi in BANDS:
        band = (conf >= lo) & (conf < hi)
        if band.any():
            lines.append(
                f"  confidence {lo:.1f}-{min(hi, 1.0):.1f}: {band.sum():6d} joints, mean {conf[band].mean():.2f}, "
                f"within 10 px {100 * within[band].mean():.1f} %"
            )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """The command line (see the module's docstring)."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("validation", type=Path, help="the validation set: one folder per clip with gt.json")
    parser.add_argument("--seed", type=int, default=0, help="the tracker's seed (the resamplings' is fixed: 0)")
    parser.add_argument("--clips", default="", help="comma-separated clip prefixes, e.g. v01,v05 (default: all)")
    parser.add_argument("--check-only", action="store_true", help="print only the check, not the tables")
    args = parser.parse_args(argv)
    if not args.validation.is_dir():
        print(f"upperpose.lab.confidence: no validation set at {args.validation}", file=sys.stderr)
        return 2
    folders = sorted(p for p in args.validation.iterdir() if (p / "gt.json").is_file())
    folders = [p for p in folders if not args.clips or any(p.name.startswith(c) for c in args.clips.split(","))]
    if not folders:
        print(f"upperpose.lab.confidence: no clips (CLIP/gt.json) in {args.validation}", file=sys.stderr)
        return 2
    joints: list[Joint] = []
    for k, folder in enumerate(folders):
        clip = track_clip(folder, args.seed, k)
        print(f"{folder.name}: {len(clip)} joints", file=sys.stderr, flush=True)
        joints += clip
    print(f"seed {args.seed}, {len(folders)} clips")
    if not args.check_only:
        print(format_rows(share_rows(joints, len(folders), resamplings(len(folders)))))
    print(format_check(joints))
    return 0


if __name__ == "__main__":
    sys.exit(main())
