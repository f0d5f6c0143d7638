"""A report's figures drawn in two processes: each once, none lost, no process left; a child
started early draws while the report goes on."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from clearance.analysis.figures.drawing import draw, figures_in_parallel, start_child

fork_only = pytest.mark.skipif(not hasattr(os, "fork"), reason="drawing in a second process needs os.fork")


def _mark(folder: Path, i: int) -> None:
    """A stand-in figure: appends the drawing process's id to its own file."""
    with open(folder / f"fig{i}.txt", "a") as f:
        f.write(f"{os.getpid()}\n")


def _fails_in_child(folder: Path, i: int, parent: int) -> None:
    if os.getpid() != parent:
        raise RuntimeError("a figure that fails in the child")
    _mark(folder, i)


def _children() -> set[int]:
    """This process's child processes, running or exited and not yet waited for (Linux /proc)."""
    out: set[int] = set()
    for task in Path("/proc/self/task").iterdir():
        out |= {int(pid) for pid in (task / "children").read_text().split()}
    return out


@pytest.fixture
def no_child_left():
    """Fails the test when a child process started during it is still there at its end."""
    if not Path("/proc/self/task").is_dir():
        pytest.skip("listing child processes needs Linux /proc")
    before = _children()
    yield
    assert _children() <= before


def test_outside_the_block_a_figure_is_drawn_at_once(tmp_path):
    draw(_mark, tmp_path, 0)
    assert (tmp_path / "fig0.txt").read_text() == f"{os.getpid()}\n"


@fork_only
@pytest.mark.parametrize("processes", [1, 2])
def test_every_queued_figure_is_drawn_once(tmp_path, processes, no_child_left):
    with figures_in_parallel(processes):
        for i in range(40):
            draw(_mark, tmp_path, i)
        assert not list(tmp_path.iterdir())  # queued, not drawn, inside the block
    pids = [(tmp_path / f"fig{i}.txt").read_text().split() for i in range(40)]
    assert all(len(p) == 1 for p in pids)  # once each
    if processes == 1:
        assert {p[0] for p in pids} == {str(os.getpid())}


@fork_only
def test_a_figure_the_child_could_not_draw_is_drawn_here(tmp_path, no_child_left):
    parent = os.getpid()
    with figures_in_parallel(2):
        for i in range(12):
            draw(_fails_in_child, tmp_path, i, parent)
    for i in range(12):  # every figure exists once, all drawn by this process
        assert (tmp_path / f"fig{i}.txt").read_text() == f"{parent}\n"


@fork_only
def test_an_error_here_is_raised_after_the_child_is_waited_for(tmp_path, no_child_left):
    def fails(i: int) -> None:
        raise ValueError(f"figure {i}")

    with pytest.raises(ValueError, match="figure"), figures_in_parallel(2):
        for i in range(6):
            draw(fails, i)


def test_a_block_left_by_an_exception_draws_nothing(tmp_path):
    with pytest.raises(KeyError), figures_in_parallel(2):
        draw(_mark, tmp_path, 0)
        raise KeyError("output")
    assert not list(tmp_path.iterdir())
    draw(_mark, tmp_path, 1)  # and the queue is gone: outside a block, drawn at once
    assert (tmp_path / "fig1.txt").exists()


def _sleep_mark(folder: Path, i: int) -> None:
    time.sleep(0.05)
    _mark(folder, i)


@fork_only
def test_a_child_started_early_draws_while_this_process_goes_on(tmp_path, no_child_left):
    with figures_in_parallel(2):
        for i in range(6):
            draw(_sleep_mark, tmp_path, i)
        start_child()
        for i in range(6, 9):  # queued after the child started: drawn here at the end
            draw(_mark, tmp_path, i)
        deadline = time.monotonic() + 10  # generous: the child is a fork, drawing within ms
        while not list(tmp_path.iterdir()) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert list(tmp_path.iterdir())  # the child has drawn while the block was still open
    pids = [(tmp_path / f"fig{i}.txt").read_text().split() for i in range(9)]
    assert all(len(p) == 1 for p in pids)  # once each
    assert {p[0] for p in pids[6:]} == {str(os.getpid())}
    assert str(os.getpid()) not in {p[0] for p in pids[:1]}  # the first was the child's


@fork_only
def test_a_block_left_by_an_exception_waits_for_a_child_started_early(tmp_path, no_child_left):
    with pytest.raises(KeyError), figures_in_parallel(2):
        for i in range(4):
            draw(_sleep_mark, tmp_path, i)
        start_child()
        draw(_mark, tmp_path, 99)
        raise KeyError("output")
    assert not (tmp_path / "fig99.txt").exists()  # queued after the start: not drawn
    drawn = list(tmp_path.iterdir())
    assert all(p.read_text().count("\n") == 1 for p in drawn)  # what the child drew, once each
