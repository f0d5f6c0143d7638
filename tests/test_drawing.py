"""A report's figures drawn in two processes: each once, none lost, no process left."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from clearance.analysis.figures.drawing import draw, figures_in_parallel

fork_only = pytest.mark.skipif(not hasattr(os, "fork"), reason="drawing in a second process needs os.fork")


def _mark(folder: Path, i: int) -> None:
    """A stand-in figure: appends the drawing process's id to its own file."""
    with open(folder / f"fig{i}.txt", "a") as f:
        f.write(f"{os.getpid()}\n")


def _fails_in_child(folder: Path, i: int, parent: int) -> None:
    if os.getpid() != parent:
        raise RuntimeError("a figure that fails in the child")
    _mark(folder, i)


def _no_child_left() -> bool:
    try:
        os.waitpid(-1, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


def test_outside_the_block_a_figure_is_drawn_at_once(tmp_path):
    draw(_mark, tmp_path, 0)
    assert (tmp_path / "fig0.txt").read_text() == f"{os.getpid()}\n"


@fork_only
@pytest.mark.parametrize("processes", [1, 2])
def test_every_queued_figure_is_drawn_once(tmp_path, processes):
    with figures_in_parallel(processes):
        for i in range(40):
            draw(_mark, tmp_path, i)
        assert not list(tmp_path.iterdir())  # queued, not drawn, inside the block
    pids = [(tmp_path / f"fig{i}.txt").read_text().split() for i in range(40)]
    assert all(len(p) == 1 for p in pids)  # once each
    if processes == 1:
        assert {p[0] for p in pids} == {str(os.getpid())}
    assert _no_child_left()


@fork_only
def test_a_figure_the_child_could_not_draw_is_drawn_here(tmp_path):
    parent = os.getpid()
    with figures_in_parallel(2):
        for i in range(12):
            draw(_fails_in_child, tmp_path, i, parent)
    for i in range(12):  # every figure exists once, all drawn by this process
        assert (tmp_path / f"fig{i}.txt").read_text() == f"{parent}\n"
    assert _no_child_left()


@fork_only
def test_an_error_here_is_raised_after_the_child_is_waited_for(tmp_path):
    def fails(i: int) -> None:
        raise ValueError(f"figure {i}")

    with pytest.raises(ValueError, match="figure"), figures_in_parallel(2):
        for i in range(6):
            draw(fails, i)
    assert _no_child_left()


def test_a_block_left_by_an_exception_draws_nothing(tmp_path):
    with pytest.raises(KeyError), figures_in_parallel(2):
        draw(_mark, tmp_path, 0)
        raise KeyError("output")
    assert not list(tmp_path.iterdir())
    draw(_mark, tmp_path, 1)  # and the queue is gone: outside a block, drawn at once
    assert (tmp_path / "fig1.txt").exists()
