"""The one executor and progress bar behind every sweep, ranking, batch of runs and benchmark.

`open_executor` hands out a `concurrent.futures.Executor`: the caller's own (left running),
a Dask cluster's when a scheduler address is given (its client is closed on exit), or a
local process pool with the ``spawn`` context (shut down on exit, pending work cancelled).
Sweep callables must be picklable (module-level functions or `functools.partial`), since
every point runs in another process. `Progress` is a tqdm bar on a terminal, a line every few
seconds elsewhere (`clearance.progress`), or nothing when progress is off.

The local pool's workers never outlive the process that started them: each watches its
parent's pid from a thread and exits when the parent is gone (killed with SIGKILL, say, when
nothing can be cleaned up), and each ignores SIGINT, so a Ctrl-C reaches the parent alone,
which ends its workers at once (`terminate_workers`) instead of waiting for their points.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from clearance.progress import ProgressDisplay

__all__ = [
    "PARENT_POLL_S",
    "SCHEDULER_TIMEOUT",
    "DASK_INSTALL",
    "Pool",
    "Progress",
    "SchedulerError",
    "open_executor",
    "require_dask",
    "terminate_workers",
]

PARENT_POLL_S = 0.2
"""How often a local worker checks that its parent is alive [s]."""

DASK_INSTALL = "pip install 'dask[distributed]'"
"""The command that installs what a Dask scheduler address needs."""


SCHEDULER_TIMEOUT = 5.0
"""How long a Dask scheduler is waited for before it counts as unreachable [s] (Dask's own
default is 30 s; a scheduler on the network answers within milliseconds)."""


class SchedulerError(RuntimeError):
    """A Dask scheduler cannot be used: Dask is not installed, or the scheduler cannot be reached."""


def require_dask() -> None:
    """Check that ``dask.distributed`` can be imported.

    Raises:
        SchedulerError: it cannot; the message gives the install command.
    """
    try:
        import dask.distributed  # noqa: F401
    except ImportError:
        raise SchedulerError(
            f"a Dask scheduler needs dask.distributed, which is not installed: {DASK_INSTALL}"
        ) from None


def _watch_parent(parent: int) -> None:
    while True:
        time.sleep(PARENT_POLL_S)
        if os.getppid() != parent:
            os._exit(1)


def _init_worker(parent: int) -> None:
    """Initializer of a local worker: ignore SIGINT, exit when the parent ``parent`` is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch_parent, args=(parent,), name="parent-watch", daemon=True).start()


def terminate_workers(pool: ProcessPoolExecutor) -> None:
    """End a local pool's worker processes now (their running tasks are lost) and shut it down."""
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        if proc.is_alive():
            proc.terminate()
    pool.shutdown(wait=False, cancel_futures=True)


@dataclass(frozen=True)
class Pool:
    """An executor and how many tasks it runs at once (``slots``)."""

    executor: Executor
    slots: int


@contextmanager
def open_executor(
    executor: Executor | None = None,
    *,
    scheduler_address: str | None = None,
    max_workers: int | None = None,
) -> Iterator[Pool]:
    """The executor of a sweep, for the duration of a ``with`` block.

    Args:
        executor: an executor of the caller's; used as is and not shut down here.
        scheduler_address: Dask scheduler address (``dask[distributed]`` installed); its
            client's executor is used and the client closed on exit.
        max_workers: processes of the local pool (default: CPU count).

    Yields:
        `Pool` with the executor and its number of slots (workers or Dask threads).

    Raises:
        SchedulerError: Dask is not installed, or the scheduler cannot be reached.
    """
    if executor is not None:
        yield Pool(executor, max_workers or getattr(executor, "_max_workers", None) or os.cpu_count() or 1)
        return
    if scheduler_address is not None:
        require_dask()
        from dask.distributed import Client

        try:
            client = Client(scheduler_address, timeout=f"{SCHEDULER_TIMEOUT}s")
        except (OSError, TimeoutError, ValueError) as err:
            raise SchedulerError(f"cannot reach the Dask scheduler at {scheduler_address!r}: {err}") from None
        try:
            yield Pool(client.get_executor(), max(1, sum(client.nthreads().values())))
        finally:
            client.close()
        return
    pool = ProcessPoolExecutor(
        max_workers=max_workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_init_worker,
        initargs=(os.getpid(),),
    )
    try:
        yield Pool(pool, max_workers or os.cpu_count() or 1)
    except BaseException:
        terminate_workers(pool)  # interrupted or failed: the running tasks' results are not wanted
        raise
    pool.shutdown(wait=True, cancel_futures=True)


class Progress:
    """A progress display of finished tasks (`clearance.progress.progress_bar`); nothing when disabled or empty.

    Use as a context manager; `step` counts finished tasks and shows a short label.
    """

    def __init__(
        self, total: int, *, enabled: bool = True, desc: str = "runs", unit: str = "run", initial: int = 0
    ) -> None:
        self._bar: ProgressDisplay | None = None
        if enabled and total:
            from clearance.progress import progress_bar

            self._bar = progress_bar(total, initial=initial, unit=unit, desc=desc, smoothing=0.1)

    def __enter__(self) -> Progress:
        return self

    def step(self, n: int = 1, label: str | None = None) -> None:
        """Count ``n`` finished tasks; ``label`` (the last task's name) is shown beside the bar."""
        if self._bar is not None:
            if label is not None:
                self._bar.set_postfix_str(label[:60])
            self._bar.update(n)

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.close()
