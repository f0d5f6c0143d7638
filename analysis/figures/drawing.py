"""A report's figures drawn in two processes at once.

Drawing is most of what a default run waits for (matplotlib builds each axes in Python), and
the figures of a report do not depend on each other. Inside `figures_in_parallel`, `draw`
queues a figure call instead of making it; when the block ends the queue is drawn by this
process and, where asked and the system can fork, one forked child, each taking the next
figure from a shared pipe until none is left (so the two share the work whatever each figure
costs). Every figure is drawn once: the child reports the figures it finished, and any it did
not finish (it failed, or was killed) is drawn again here, where an error is raised as usual.
The child is always waited for, so no process outlives the call.

Outside the block `draw` calls the function at once, so the figure functions keep working
one by one for library users.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["draw", "figures_in_parallel"]

_Job = tuple[Callable[..., Any], tuple[Any, ...], dict[str, Any]]
_queue: list[_Job] | None = None
_MAX_JOBS = 255  # one byte per figure in the pipe


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
            (where ``os.fork`` exists). A block left by an exception draws nothing.
    """
    global _queue
    outer, _queue = _queue, []
    try:
        yield
        jobs = _queue
    finally:
        _queue = outer
    _draw_all(jobs, processes)


def _draw_all(jobs: list[_Job], processes: int) -> None:
    if processes < 2 or len(jobs) < 2 or not hasattr(os, "fork"):
        for fn, args, kwargs in jobs:
            fn(*args, **kwargs)
        return
    for start in range(0, len(jobs), _MAX_JOBS):
        _draw_two(jobs[start : start + _MAX_JOBS])


def _draw_two(jobs: list[_Job]) -> None:
    """Draw ``jobs`` here and in one forked child; redraw here whatever the child did not finish."""
    todo_r, todo_w = os.pipe()
    done_r, done_w = os.pipe()
    os.write(todo_w, bytes(range(len(jobs))))  # fits the pipe's buffer (at most 255 bytes)
    os.close(todo_w)
    pid = os.fork()
    if pid == 0:  # the child: take figures until none is left, report each one finished
        status = 1
        try:
            os.close(done_r)
            _take(jobs, todo_r, lambda i: os.write(done_w, bytes([i])))
            status = 0
        finally:
            os._exit(status)  # no atexit handlers, no flushing of the parent's buffers
    os.close(done_w)
    mine: set[int] = set()
    try:
        _take(jobs, todo_r, mine.add)
    finally:
        os.close(todo_r)
        os.waitpid(pid, 0)
        theirs = set(_read_all(done_r))
        os.close(done_r)
    for i in range(len(jobs)):
        if i not in mine and i not in theirs:  # the child failed on it or did not get to it
            fn, args, kwargs = jobs[i]
            fn(*args, **kwargs)


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
