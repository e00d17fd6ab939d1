"""The local backend: the videos of a batch on this machine, one at a time or in N processes.

With one job the videos run in this process. With more, each video runs in a process of its
own (spawned, so that nothing of the parent's threads is inherited; a crash ends one video,
not the batch), at most N at a time. The parent owns the interrupt: children ignore Ctrl-C, and
on Ctrl-C or SIGTERM the parent sends each running child SIGTERM, which the child turns into
KeyboardInterrupt, so that it writes nothing of its unfinished video, and waits for them.
"""

from __future__ import annotations

import multiprocessing
import signal
from collections import deque
from collections.abc import Generator, Sequence
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess
from pathlib import Path
from typing import Any, cast

from upperpose.batch.job import FAILED, Job, row, run_job
from upperpose.batch.progress import BatchProgress
from upperpose.io.files import interrupts_held

Indexed = tuple[int, Job]
# Children report their frames this often, not every frame: messages cost the parent's time.
FRAME_REPORT_EVERY = 10
# How long a child may take to clean up after SIGTERM before it is killed.
STOP_TIMEOUT_S = 60.0


def run_local(
    work: Sequence[Indexed], out_dir: Path, jobs: int, progress: BatchProgress
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    """Yields (index, row) per video as each ends (in order of ending)."""
    if jobs <= 1:
        for index, job in work:

            def on_frame(done: int, total: int | None, status: str, index: int = index) -> None:
                progress.frame(index, done)

            yield index, run_job(job, out_dir, on_frame)
        return
    yield from _in_processes(work, out_dir, jobs, progress)


def _in_processes(
    work: Sequence[Indexed], out_dir: Path, jobs: int, progress: BatchProgress
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    context = multiprocessing.get_context("spawn")
    waiting = deque(work)
    running: dict[Connection, tuple[int, Job, BaseProcess]] = {}
    try:
        while waiting or running:
            while waiting and len(running) < jobs:
                index, job = waiting.popleft()
                reader, writer = context.Pipe(duplex=False)
                process = context.Process(target=_child, args=(job, out_dir, writer), daemon=True)
                # Ctrl-C here waits until the child is started and known, to be stopped with the rest
                # (half started, it would print a traceback). The child inherits the blocked signal:
                # it cannot be interrupted while it starts, and then ignores Ctrl-C.
                with interrupts_held():
                    unblocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
                    try:
                        process.start()
                        running[reader] = (index, job, process)
                    finally:
                        signal.pthread_sigmask(signal.SIG_SETMASK, unblocked)
                writer.close()  # the child holds the only writing end: its exit is the reader's end of file
            for ready in wait(list(running)):
                reader = cast(Connection, ready)
                index, job, child = running[reader]
                result = _drain(reader, index, progress)
                if result is None:
                    continue
                del running[reader]
                reader.close()
                child.join()
                yield index, result if isinstance(result, dict) else _died(job, child)
    finally:
        # Also on Ctrl-C or SIGTERM (KeyboardInterrupt), and when the caller stops early.
        with interrupts_held():
            _stop([child for _, _, child in running.values()])


def _drain(reader: Connection, index: int, progress: BatchProgress) -> dict[str, Any] | bool | None:
    """Reads what the child sent: its row, False when it ended without one, None while it runs."""
    while reader.poll():
        try:
            kind, value = reader.recv()
        except EOFError:
            return False
        if kind == "row":
            return dict(value)
        progress.frame(index, int(value))
    return None


def _died(job: Job, child: BaseProcess) -> dict[str, Any]:
    return row(job, FAILED, error=f"the process tracking it ended without a result (exit code {child.exitcode})")


def _stop(children: list[BaseProcess]) -> None:
    for child in children:
        child.terminate()
    for child in children:
        child.join(STOP_TIMEOUT_S)
        if child.is_alive():
            child.kill()
            child.join()


def _child(job: Job, out_dir: Path, conn: Connection) -> None:
    """A child process: tracks one video, sends frame counts and then its row."""
    # The parent decides what Ctrl-C does; SIGTERM from it means: stop, writing nothing partial.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    signal.signal(signal.SIGTERM, _interrupt)

    def on_frame(done: int, total: int | None, status: str) -> None:
        if done % FRAME_REPORT_EVERY == 0:
            conn.send(("frames", done))

    try:
        conn.send(("row", run_job(job, out_dir, on_frame)))
    except KeyboardInterrupt:
        pass  # nothing of the video was written; the parent records it as not run
    finally:
        conn.close()


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


__all__ = ["run_local"]
