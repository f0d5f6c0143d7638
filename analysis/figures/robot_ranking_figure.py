"""The figure of a robot's play ranking: each kind's scores and all candidates' mean deviations, with 95 % intervals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from clearance.analysis.figures.canvas import new_figure, save_png
from clearance.analysis.sweeps.criticality import CriticalityRanking
from clearance.analysis.sweeps.robot_ranking import ARCMIN, RobotRanking

__all__ = ["plot_robot_ranking"]

_COLOURS = {"radial": "C0", "backlash": "C3"}


def _bars(ax: Axes, ranking: CriticalityRanking, scale: float, colours: list[str]) -> None:
    scores = list(ranking.scores)
    y = np.arange(len(scores))[::-1]
    values = np.array([s.score for s in scores]) * scale
    low = values - np.array([s.ci_low for s in scores]) * scale
    high = np.array([s.ci_high for s in scores]) * scale - values
    ax.barh(y, values, color=colours, alpha=0.8)
    ax.errorbar(values, y, xerr=[np.maximum(low, 0), np.maximum(high, 0)], fmt="none", ecolor="k", capsize=3, lw=1)
    ax.set_yticks(y, [s.joint for s in scores], fontsize=8)
    ax.grid(axis="x", alpha=0.3)
    ax.set_xlim(left=0)


def plot_robot_ranking(ranking: RobotRanking, *, path: str | Path | None = None) -> Figure:
    """Bars of each kind's score (mean deviation / play) and of every candidate's mean deviation.

    Args:
        ranking: the ranking (`rank_plays`).
        path: PNG path to save to.
    """
    kinds = list(ranking.by_kind)
    n = len(kinds) + 1
    rows = max(len(ranking.overall.scores), 3)
    label = 0.3 + 0.065 * max(len(s.joint) for s in ranking.overall.scores)  # room for the hinge names [in]
    width, height = 5.5 * n, 1.7 + 0.3 * rows
    panel = (width * 0.985 - label * n) / n
    fig = new_figure(width, height)
    gs = fig.add_gridspec(
        1, n, left=label / width, right=0.985, top=1 - 0.8 / height, bottom=0.65 / height, wspace=label / panel
    )
    ax = fig.add_subplot(gs[0, 0])
    colours = [_COLOURS.get(s.joint.rsplit("(", 1)[-1].rstrip(")"), "0.5") for s in ranking.overall.scores]
    _bars(ax, ranking.overall, 1e6, colours)
    ax.set_xlabel("mean end-effector deviation [µm]")
    ax.set_title("all candidates at the plays given", fontsize=10)
    for k, kind in enumerate(kinds, start=1):
        ax = fig.add_subplot(gs[0, k])
        r = ranking.by_kind[kind]
        size = ranking.sizes[kind]
        if kind == "backlash":
            scale, unit, play = 1e6 * ARCMIN, "µm per arcmin", f"b = {size / ARCMIN:g}'"
        else:
            scale, unit, play = 1.0, "µm per µm of c", f"c = {size * 1e3:g} mm"
        _bars(ax, r, scale, [_COLOURS.get(kind, "0.5")] * len(r.scores))
        ax.set_xlabel(f"score: mean deviation / play [{unit}]")
        ax.set_title(f"{kind} play alone ({play})", fontsize=10)
    fig.suptitle(
        f"Which hinge's play moves {ranking.site} most: {len(ranking.cells)} grid cells, 95 % intervals", fontsize=11
    )
    if path is not None:
        save_png(fig, path)
    return fig
