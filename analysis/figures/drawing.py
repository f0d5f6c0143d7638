"""A report's figures drawn in two processes at once.

Drawing is most of what a default run waits for (matplotlib builds each axes in Python), and
the figures of a report do not depend on each other. Inside `figures_in_parallel`, `draw`
queues a figure call instead of making it; when the block ends the queue is drawn by this
process and, where asked and the system can fork, one forked child, each taking the next
figure from a shared pipe until none is left (so the two share the work whatever each figure
costs). `start_child` forks the child earlier, with the figures queued so far: it draws them
while this process goes on computing (a long run's report numbers); when the block ends this
process draws the figures queued after the start, then takes the child's that are left.
Every figure is drawn once: the child reports the figures it finished, and any it did not
finish (it failed, or was killed) is drawn again here, where an error is raised as usual.
The child is always waited for, so no process outlives the call.

Outside the block `draw` calls the function at once, so the figure functions keep working
one by one for library users.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["draw", "figures_in_parallel", "start_child"]

_Job = tuple[Callable[..., Any], tuple[Any, ...], dict[str, Any]]
_queue: list[_Job] | None = None
_processes = 1  # of the innermost block
_started: _Child | None = None  # a child forked by start_child in the innermost block
_MAX_JOBS = 255  # one byte per figure in the pipe


class _Child:
    """A forked child drawing ``jobs`` from a pipe, and the pipes to share and collect them."""

    def __init__(self, jobs: list[_Job]) -> None:
        self.jobs = jobs
        self.todo, todo_w = os.pipe()
        self.done, done_w = os.pipe()
        os.write(todo_w, bytes(range(len(jobs))))  # fits the pipe's buffer (at most 255 bytes)
        os.close(todo_w)
        self.pid = os.fork()
        if self.pid == 0:  # the child: take figures until none is left, report each one finished
            status = 1
            try:
                os.close(self.done)
                _take(jobs, self.todo, lambda i: os.write(done_w, bytes([i])))
                status = 0
            finally:
                os._exit(status)  # no atexit handlers, no flushing of the parent's buffers
        os.close(done_w)

    def abandon(self) -> None:
        """Take the figures the child has not without drawing them, and wait for it."""
        try:
            _read_all(self.todo)
        finally:
            os.close(self.todo)
            os.waitpid(self.pid, 0)
            os.close(self.done)

    def finish(self) -> None:
        """Take the figures the child has not, wait for it, redraw what it did not finish."""
        mine: set[int] = set()
        try:
            _take(self.jobs, self.todo, mine.add)
        finally:
            os.close(self.todo)
            os.waitpid(self.pid, 0)
            theirs = set(_read_all(self.done))
            os.close(self.done)
        for i in range(len(self.jobs)):
            if i not in mine and i not in theirs:  # the child failed on it or did not get to it
                fn, args, kwargs = self.jobs[i]
                fn(*args, **kwargs)


def draw(fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> None:
    """Draw a figure: ``fn(*args, **kwargs)`` now, or at the end of `figures_in_parallel`.

    Args:
        fn: a figure function that writes its file and whose return value is not needed.
        *args: its positional arguments.
        **kwargs: its keyword arguments.
    """
    if _queue is None:
        fn(*args, **kwargs)
    else:
        _queue.append((fn, args, kwargs))


@contextmanager
def figures_in_parallel(processes: int = 2) -> Iterator[None]:
    """Queue the figures `draw` is given inside the block; draw them when it ends.

    Args:
        processes: 1 draws them here, one after the other; 2 shares them with a forked child
            (where ``os.fork`` exists). A block left by an exception draws nothing (a child
            already started by `start_child` is still waited for).
    """
    global _queue, _processes, _started
    outer = (_queue, _processes, _started)
    _queue, _processes, _started = [], processes, None
    try:
        yield
        jobs, child = _queue, _started
    except BaseException:
        if _started is not None:
            _started.abandon()
        raise
    finally:
        _queue, _processes, _started = outer
    if child is None:
        _draw_all(jobs, processes)
        return
    try:
        _draw_all(jobs, 1)  # the figures only this process can draw first, then help with the child's
    except BaseException:  # (a full disk): the child is waited for, so it writes nothing after this
        child.abandon()
        raise
    child.finish()


def start_child() -> None:
    """Inside `figures_in_parallel` with two processes: fork the child now with the figures queued so far.

    Later figures are drawn by this process when the block ends. Does nothing outside a block,
    with one process, without ``os.fork``, with fewer than two queued figures or a child
    already started.
    """
    global _queue, _started
    if _queue is None or _started is not None or _processes < 2 or not hasattr(os, "fork") or len(_queue) < 2:
        return
    jobs, _queue = _queue[:_MAX_JOBS], _queue[_MAX_JOBS:]
    _started = _Child(jobs)


def _draw_all(jobs: list[_Job], processes: int) -> None:
    if processes < 2 or len(jobs) < 2 or not hasattr(os, "fork"):
        for fn, args, kwargs in jobs:
            fn(*args, **kwargs)
        return
    for start in range(0, len(jobs), _MAX_JOBS):
        _Child(jobs[start : start + _MAX_JOBS]).finish()


def _take(jobs: list[_Job], todo: int, finished: Callable[[int], object]) -> None:
    while chunk := os.read(todo, 1):
        fn, args, kwargs = jobs[chunk[0]]
        fn(*args, **kwargs)
        finished(chunk[0])


def _read_all(fd: int) -> bytes:
    parts = []
    while chunk := os.read(fd, 4096):
        parts.append(chunk)
    return b"".join(parts)
