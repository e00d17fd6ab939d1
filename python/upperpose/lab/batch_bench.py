"""Throughput of `upperpose.batch`: videos per hour and frames per second, local and Ray, 1 and 2 CPUs.

Not a test: wall-clock numbers depend on the machine and its load. Each run tracks the whole
corpus into a fresh folder (nothing skipped); the configurations take turns, `--repeat` rounds,
and the table gives the median and range of each. Ray runs on a private Ray of this machine,
started for each run with as many CPUs as the run's jobs and listening on the loopback
interface only; its start-up (several seconds) is timed apart from the batch.

    python -m upperpose.lab.batch_bench CORPUS_DIR [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

from upperpose.batch import run

CONFIGS = (("local", 1), ("local", 2), ("ray", 1), ("ray", 2))


def one_run(corpus: str, backend: str, jobs: int) -> dict[str, float]:
    """One batch of the corpus: wall seconds of the batch (and of Ray's start), videos and frames."""
    ray_start = 0.0
    if backend == "ray":
        # Before Ray loads: every process of this private Ray listens on 127.0.0.1 only.
        os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
        import ray

        t0 = time.perf_counter()
        ray.init(num_cpus=jobs, include_dashboard=False, log_to_driver=False)
        ray_start = time.perf_counter() - t0
    try:
        with tempfile.TemporaryDirectory(prefix="upperpose-batch-bench-") as out:
            t0 = time.perf_counter()
            result = run([corpus], out, jobs=jobs if backend == "local" else 1, backend=backend)
            wall = time.perf_counter() - t0
    finally:
        if backend == "ray":
            ray.shutdown()
    if result.failed:
        raise RuntimeError(f"{result.failed} videos failed: {[r['error'] for r in result.rows if r['error']]}")
    frames = sum(r["frames"] for r in result.rows)
    return {"wall_s": wall, "ray_start_s": ray_start, "videos": len(result.rows), "frames": frames}


def main() -> None:
    """Prints the table."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("corpus", help="folder of videos (e.g. clip folders from `upperpose synth`)")
    parser.add_argument("--repeat", type=int, default=3, help="rounds over the configurations (default 3)")
    args = parser.parse_args()
    runs: dict[tuple[str, int], list[dict[str, float]]] = {c: [] for c in CONFIGS}
    for _ in range(args.repeat):
        for backend, jobs in CONFIGS:
            r = one_run(args.corpus, backend, jobs)
            runs[(backend, jobs)].append(r)
            print(f"{backend} x{jobs}: {r['wall_s']:.1f} s (+{r['ray_start_s']:.1f} s Ray start)", flush=True)
    print("\n| backend | jobs / Ray CPUs | videos per hour | frames per second | wall s | Ray start s |")
    print("| --- | --- | --- | --- | --- | --- |")
    for (backend, jobs), rs in runs.items():
        cells = " | ".join(_cell(rs, key) for key in ("vph", "fps", "wall_s", "ray_s"))
        print(f"| {backend} | {jobs} | {cells} |")


def _cell(rs: list[dict[str, float]], key: str) -> str:
    values = [_measure(r, key) for r in rs]
    return f"{statistics.median(values):.0f} ({min(values):.0f}-{max(values):.0f})"


def _measure(r: dict[str, float], key: str) -> float:
    if key == "vph":
        return 3600 * r["videos"] / r["wall_s"]
    if key == "fps":
        return r["frames"] / r["wall_s"]
    return r["wall_s"] if key == "wall_s" else r["ray_start_s"]


if __name__ == "__main__":
    main()
