"""Figures of an allocation (Agg, without pyplot; see `clearance.analysis.figures.canvas`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

from clearance.analysis.design.allocation import Allocation
from clearance.analysis.figures.canvas import new_figure, save_png

__all__ = ["plot_allocation", "plot_front", "plot_surrogate", "plot_verification"]


def _plain_log(ax: Axes, *, x: bool = False, y: bool = True) -> None:
    """Log axes labelled with plain numbers at 1, 2 and 5 of each decade."""
    for on, axis in ((x, ax.xaxis), (y, ax.yaxis)):
        if on:
            axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(FormatStrFormatter("%g"))
            axis.set_minor_formatter(NullFormatter())


def plot_allocation(a: Allocation, path: str | Path, *, unit: str, scale: float) -> None:
    """Clearance per joint: the allocation, the equal design, the bounds.

    Args:
        a: the allocation.
        path: the PNG to write.
        unit, scale: unused here (clearances are drawn in mm); kept so every allocation
            figure is called alike.
    """
    p = a.problem
    fig = new_figure(max(5.0, 1.2 * len(p.joints) + 2), 4)
    ax = fig.add_subplot()
    x = np.arange(len(p.joints))
    lo, hi = np.asarray(p.lower) * 1e3, np.asarray(p.upper) * 1e3
    ax.vlines(x, lo, hi, colors="0.6", lw=6, alpha=0.5, label="bounds")
    if a.allocated is not None:
        ax.plot(x, np.asarray(a.allocated.clearances) * 1e3, "o", ms=9, color="C0",
                label=f"allocation (cost {a.allocated.cost:.4g})")  # fmt: skip
    if a.equal is not None:
        ax.plot(x, np.asarray(a.equal.clearances) * 1e3, "s", ms=7, mfc="none", color="C3",
                label=f"equal clearance (cost {a.equal.cost:.4g})")  # fmt: skip
    ax.set_yscale("log")
    _plain_log(ax)
    ax.set_xticks(x, list(p.joints))
    ax.set_xlabel("joint")
    ax.set_ylabel("radial clearance [mm]")
    ax.set_title(f"clearance allocation ({p.measure.replace('_', ' ')} within budget)")
    ax.grid(alpha=0.3, which="both", axis="y")
    ax.legend(fontsize=8)
    save_png(fig, path)


def plot_front(a: Allocation, path: str | Path, *, unit: str, scale: float) -> None:
    """Cost against budget: the allocation's front and the equal designs, verified points marked.

    Args:
        a: the allocation.
        path: the PNG to write.
        unit: the output measure's unit as shown (e.g. "µrad").
        scale: factor from the measure's SI value to ``unit``.
    """
    fig = new_figure(6.5, 4.5)
    ax = fig.add_subplot()
    for which, colour, marker, label in (("allocated", "C0", "o", "allocation"), ("equal", "C3", "s", "equal")):
        pts = [(r.budgets[0] * scale, getattr(r, which)) for r in a.front if getattr(r, which) is not None]
        if not pts:
            continue
        b = np.array([x for x, _ in pts])
        cost = np.array([d.cost for _, d in pts])
        verified = np.array([d.mean[0] * scale for _, d in pts])
        ax.plot(b, cost, "-", color=colour, lw=1, label=f"{label}: cost against the budget it was solved for")
        met = np.array([d.meets for _, d in pts])
        ax.plot(verified[met], cost[met], marker, color=colour, ls="none",
                label=f"{label}: verified mean, >= {a.problem.target_share:.0%} of runs within budget")  # fmt: skip
        ax.plot(verified[~met], cost[~met], marker, color=colour, mfc="none", ls="none",
                label=f"{label}: verified mean, fewer within budget")  # fmt: skip
    ax.axvline(a.budgets[0] * scale, color="0.4", ls="--", lw=1, label="the budget")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log(ax, x=True, y=True)
    ax.set_xlabel(f"budget, or verified mean, of the {a.problem.measure.replace('_', ' ')} [{unit}]")
    ax.set_ylabel("cost  sum(a + b / c[mm])")
    ax.set_title(f"cost against budget (front designs verified with {a.settings.front_runs} runs)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    save_png(fig, path)


def plot_verification(a: Allocation, path: str | Path, *, unit: str, scale: float) -> None:
    """Per-run values of the verification ensembles against the budget (first operating point).

    Args:
        a: the allocation.
        path: the PNG to write.
        unit: the output measure's unit as shown (e.g. "µrad").
        scale: factor from the measure's SI value to ``unit``.
    """
    designs = [(f"allocation {i + 1}", d) for i, d in enumerate(a.allocation_iterations)]
    designs += [(f"equal {i + 1}", d) for i, d in enumerate(a.equal_iterations)]
    designs.append(("lower bounds", a.lower_bound))
    if a.reference is not None:
        designs.append(("reference", a.reference))
    fig = new_figure(max(6.0, 0.9 * len(designs) + 2), 4.5)
    ax = fig.add_subplot()
    rng = np.random.default_rng(0)  # horizontal jitter of the points only
    for i, (name, d) in enumerate(designs):
        v = np.asarray(d.values[0]) * scale
        colour = "0.5" if name == "reference" else "C2" if d.meets else "C3"
        ax.plot(i + 0.15 * rng.uniform(-1, 1, len(v)), v, ".", color=colour, alpha=0.7)
        ax.errorbar(i + 0.3, d.mean[0] * scale, yerr=d.std[0] * scale, fmt="_", color="k", capsize=3)
    ax.axhline(a.budgets[0] * scale, color="0.3", ls="--", lw=1, label="budget")
    ax.set_xticks(range(len(designs)), [n for n, _ in designs], rotation=30, ha="right", fontsize=8)
    ax.set_ylabel(f"{a.problem.measure.replace('_', ' ')} [{unit}]")
    ax.set_title("verification ensembles: green meets the target share, red not, grey sets the budget", fontsize=9)
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    fig.subplots_adjust(bottom=0.25)
    save_png(fig, path)


def plot_surrogate(a: Allocation, path: str | Path, *, unit: str, scale: float) -> None:
    """The response surface's predictions against the fitted runs (first operating point).

    Args:
        a: the allocation.
        path: the PNG to write.
        unit: the output measure's unit as shown (e.g. "µrad").
        scale: factor from the measure's SI value to ``unit``.
    """
    s = a.surrogates[0]
    y = np.asarray(s.values) * scale
    pred = s.predict(np.asarray(s.points)) * scale
    fig = new_figure(5.5, 5)
    ax = fig.add_subplot()
    fig.subplots_adjust(left=0.17, bottom=0.12)
    ax.loglog(y, pred, "o", mfc="none", color="C0", label="design and verification points")
    lim = [min(y.min(), pred.min()) * 0.9, max(y.max(), pred.max()) * 1.1]
    ax.plot(lim, lim, "k-", lw=1, label="equal")
    fit, loo = s.relative_error
    _plain_log(ax, x=True, y=True)
    ax.set_xlabel(f"simulated {a.problem.measure.replace('_', ' ')} [{unit}]")
    ax.set_ylabel(f"response surface [{unit}]")
    ax.set_title(f"surrogate fit: RMS error {fit:.1%} (leave-one-out {loo:.1%})")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    save_png(fig, path)
