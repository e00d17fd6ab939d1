"""The Ray backend: one Ray task per video on a Ray cluster (`pip install 'upperpose[ray]'`).

The driver (this process) decides which videos to skip, submits one task per remaining video
(one CPU each) and records each task's row as it ends. The workers write the outputs into the
batch's folder, which every node must then see at the same path (a shared folder); with
`collect` they track into a private temporary folder and return the files' bytes instead, and
the driver writes them (pose file last, each whole or not at all). Ctrl-C cancels the tasks
(Ray raises KeyboardInterrupt in a running one, which then writes nothing) and waits for them.
"""

from __future__ import annotations

import signal
import tempfile
import threading
from collections.abc import Generator, Sequence
from pathlib import Path
from typing import Any

from upperpose.batch.job import FAILED, Job, row, run_job
from upperpose.exceptions import InputError, UpperposeError, one_line
from upperpose.io.files import interrupts_held, write_atomic

Indexed = tuple[int, Job]
# Files a task returns with --collect: name relative to the batch folder -> bytes.
Files = dict[str, bytes]
# How long cancelled tasks get to end after Ctrl-C.
CANCEL_TIMEOUT_S = 60.0


def track_task(job: Job, out_dir: str | None) -> tuple[dict[str, Any], Files]:
    """The Ray task: tracks one video into `out_dir`, or with None returns its files' bytes."""
    if out_dir is not None:
        return run_job(job, Path(out_dir)), {}
    with tempfile.TemporaryDirectory(prefix="upperpose-batch-") as tmp:
        result = run_job(job, Path(tmp))
        made = [p for p in job.paths(Path(tmp)).given() if p.is_file()]
        return result, {p.relative_to(tmp).as_posix(): p.read_bytes() for p in made}


def run_ray(
    work: Sequence[Indexed], out_dir: Path, *, address: str | None, collect: bool
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    """Yields (index, row) per video as each task ends.

    Connects to the cluster at `address`, or uses the Ray already initialised in this process,
    or starts a local Ray (address None); a Ray this function started is shut down at the end.

    Raises:
        InputError: Ray is not installed.
        UpperposeError: the cluster cannot be reached.
    """
    try:
        import ray
    except ImportError:
        raise InputError("--backend ray needs Ray: pip install 'upperpose[ray]'") from None
    started = not ray.is_initialized()
    if started:
        # ray.init replaces the SIGTERM handler for good; SIGTERM must stay what it was (the command
        # line's: stop like Ctrl-C, so that the tasks are cancelled and the summary written).
        main = threading.current_thread() is threading.main_thread()
        sigterm = signal.getsignal(signal.SIGTERM) if main else None
        try:
            ray.init(address=address, include_dashboard=False, log_to_driver=False)
        except (ConnectionError, RuntimeError, ValueError) as err:
            where = address or "this machine"
            raise UpperposeError(f"cannot reach the Ray cluster at {where}: {one_line(err)}") from None
        finally:
            if sigterm is not None:
                signal.signal(signal.SIGTERM, sigterm)
    task = ray.remote(num_cpus=1)(track_task)
    target = None if collect else str(out_dir.resolve())
    pending = {task.remote(job, target): (index, job) for index, job in work}
    try:
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                index, job = pending.pop(ref)
                try:
                    result, files = ray.get(ref)
                except ray.exceptions.RayError as err:
                    result, files = row(job, FAILED, error=f"Ray task failed: {one_line(err)}"), {}
                _write_collected(out_dir, files)
                yield index, result
    finally:
        with interrupts_held():
            for ref in pending:
                ray.cancel(ref)
            if pending:
                ray.wait(list(pending), num_returns=len(pending), timeout=CANCEL_TIMEOUT_S)
            if started:
                ray.shutdown()


def _write_collected(out_dir: Path, files: Files) -> None:
    """Writes a task's returned files under `out_dir`, the pose file (.json) last."""
    for name in sorted(files, key=lambda n: n.endswith(".json")):
        target = out_dir / name
        target.parent.mkdir(parents=True, exist_ok=True)
        data = files[name]
        write_atomic(target, lambda tmp, data=data: tmp.write_bytes(data))  # type: ignore[misc]


__all__ = ["run_ray", "track_task"]
