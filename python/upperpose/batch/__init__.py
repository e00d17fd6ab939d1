"""Many videos in one run: `run(inputs, out_dir, jobs=..., backend=...)`, resumable and isolated.

Every video is tracked into its own pose file (and optionally CSV, BVH and overlay) under the
output folder, in the inputs' folder layout, with a summary of all of them. A video an earlier
run finished with the same settings is skipped; one that fails is recorded and the rest go on;
Ctrl-C leaves every finished file whole and no partial one. Backends: "local" (this machine,
`jobs` processes) and "ray" (one Ray task per video; `pip install 'upperpose[ray]'`).

    import upperpose.batch
    result = upperpose.batch.run(["recordings/"], "poses/", jobs=2)
    print(result.failed, result.summary)
"""

from upperpose.batch.runner import BACKENDS, BatchInterrupted, BatchResult, run

__all__ = ["BACKENDS", "BatchInterrupted", "BatchResult", "run"]
