"""The convergence figure of `clearance optimise` (Agg, without pyplot).

Top: the objective of every evaluated design in evaluation order, with its standard error,
coloured by the search's phase (start design, space-filling sample, simplex), the best so
far as a step line, designs the kinematics refused as crosses on the upper edge, and the
confirmation (fresh ensembles at the start design and at the optimum) to the right.
Bottom: where each design variable stood within its bounds (0: low, 1: high).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from clearance.analysis.design.optimise import OptimisationResult
from clearance.analysis.figures.canvas import new_figure, save_png

__all__ = ["plot_convergence"]

_PHASES = {"start": ("tab:red", "start design"), "sample": ("tab:blue", "sample"), "simplex": ("tab:green", "simplex")}


def plot_convergence(result: OptimisationResult, path: str | Path, *, scale: float = 1.0, unit: str = "") -> Path:
    """Draw the convergence of a design optimisation to a PNG.

    Args:
        result: the optimisation.
        path: PNG file (written atomically).
        scale: factor from the objective's SI unit to the unit shown (1e6 for µm).
        unit: the unit shown, for the axis label.

    Returns:
        ``path``.
    """
    fig = new_figure(8.0, 6.4)
    top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    trials = result.search.trials
    ok = [t for t in trials if t.estimate.feasible and math.isfinite(t.estimate.value)]
    for phase, (colour, label) in _PHASES.items():
        mine = [t for t in ok if t.phase == phase]
        if mine:
            top.errorbar(
                [t.index for t in mine],
                [t.estimate.value * scale for t in mine],
                yerr=[t.estimate.se * scale for t in mine],
                fmt="o",
                ms=4,
                color=colour,
                capsize=2,
                label=label,
            )
    best, run = [], math.inf
    for t in trials:
        if t in ok:
            run = min(run, t.estimate.value)
        best.append(run * scale)
    top.step([t.index for t in trials], best, where="post", color="0.3", lw=1.2, label="best so far")
    bad = [t.index for t in trials if t not in ok]
    if bad:
        top.plot(
            bad,
            [1.0] * len(bad),
            "x",
            color="0.5",
            transform=top.get_xaxis_transform(),
            clip_on=False,
            label="infeasible (kinematics)",
        )
    c = result.confirmation
    xc = len(trials) + 1
    top.errorbar(
        [xc, xc + 1],
        [c.start.value * scale, c.optimum.value * scale],
        yerr=[c.start.se * scale, c.optimum.se * scale],
        fmt="s",
        ms=6,
        color="black",
        capsize=3,
        label=f"confirmed (seed {c.seed}): start, optimum",
    )
    for x, text, est in ((xc, "start", c.start), (xc + 1, "optimum", c.optimum)):
        top.annotate(
            text,
            (x, est.value * scale),
            xytext=(-6, 0),
            textcoords="offset points",
            ha="right",
            va="center",
            fontsize=7,
        )
    top.axvline(len(trials) + 0.5, color="0.7", lw=0.8, ls="--")
    top.set_ylabel(f"{result.measure} [{unit}]" if unit else result.measure)
    fig.suptitle("Design optimisation: objective per design tried (ensemble mean ± s.e.)", fontsize=10, y=0.985)
    top.legend(fontsize=7, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=3, frameon=False)
    top.grid(alpha=0.3)
    for v in result.variables:
        xs = [t.index for t in trials]
        k = result.variables.index(v)
        bottom.plot(xs, [(t.x[k] - v.low) / (v.high - v.low) for t in trials], ".-", lw=0.8, ms=4, label=v.name)
    bottom.set_ylim(-0.05, 1.05)
    bottom.set_ylabel("position in bounds")
    bottom.set_xlabel("design tried (in order); confirmation at the right")
    bottom.legend(fontsize=7, loc="upper right")
    bottom.grid(alpha=0.3)
    bottom.set_xticks(np.arange(0, xc + 2, max(1, (xc + 2) // 12)))
    fig.subplots_adjust(left=0.11, right=0.97, top=0.87, bottom=0.09, hspace=0.08)
    return save_png(fig, path)
