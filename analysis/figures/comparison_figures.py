"""Figures that compare runs: trends over a parameter, overlaid responses, journal
positions against the drive phase and Poincaré panels side by side, criticality rankings of
related mechanisms.

Drawn on Agg figures without pyplot (`canvas.new_figure`). Every function returns the figure
and, given a path, saves a PNG atomically (`plots.save_figure`). Single-run figures are in
`plots` and `analysis_figures`; the Poincaré panels reuse `analysis_figures.plot_poincare`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

from clearance.analysis.chaos.poincare import PoincareClassification
from clearance.analysis.figures.analysis_figures import plot_poincare, quantity_label
from clearance.analysis.figures.canvas import new_figure, thin_path
from clearance.analysis.figures.plots import save_figure
from clearance.analysis.sweeps.criticality import CriticalityRanking
from clearance.results import SimulationResult

__all__ = [
    "OrbitPanel",
    "PoincarePanel",
    "TrendPanel",
    "plot_orbit_panels",
    "plot_orbit_phase_panels",
    "plot_output_overlay",
    "plot_poincare_panels",
    "plot_ranking_comparison",
    "plot_trends",
]


@dataclass(frozen=True)
class TrendPanel:
    """One panel of `plot_trends`: lines of a quantity against a parameter.

    Attributes:
        series: label -> (x, y) or (x, y, yerr) arrays, already in display units.
        xlabel, ylabel: axis labels with units.
        title: panel title.
        reference: label -> (x, y) points drawn as black markers (e.g. published values).
        logx, logy: logarithmic axes.
    """

    series: Mapping[str, tuple]
    xlabel: str
    ylabel: str
    title: str = ""
    reference: Mapping[str, tuple] = field(default_factory=dict)
    logx: bool = False
    logy: bool = False


def _panel_row(
    n: int, width: float, height: float, draw: Callable[[Axes, int], None], title: str, path: str | Path | None
) -> Figure:
    """A row of ``n`` panels; ``draw(ax, k)`` fills panel k."""
    fig = new_figure(width * n, height)
    axes = fig.subplots(1, n, squeeze=False)
    for k, ax in enumerate(axes[0]):
        draw(ax, k)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_trends(panels: Sequence[TrendPanel], *, title: str = "", path: str | Path | None = None) -> Figure:
    """Panels side by side, each with one line (markers, optional error bars) per series.

    Args:
        panels: the `TrendPanel`s.
        title: figure title.
        path: PNG path to save to.
    """

    def draw(ax: Axes, i: int) -> None:
        p = panels[i]
        for k, (label, data) in enumerate(p.series.items()):
            x, y = np.asarray(data[0], float), np.asarray(data[1], float)
            err = None if len(data) < 3 or data[2] is None else np.asarray(data[2], float)
            ax.errorbar(x, y, yerr=err, marker="os^Dvx"[k % 6], ms=5, lw=1.3, capsize=3, label=label)
        for k, (label, (x, y)) in enumerate(p.reference.items()):
            ax.plot(x, y, "k" + "*P"[k % 2], ms=10, ls="none", label=label)
        if p.logx:
            ax.set_xscale("log")
            xs = sorted({float(v) for data in p.series.values() for v in np.asarray(data[0], float)})
            ax.set_xticks(xs, [f"{v:g}" for v in xs])
            ax.xaxis.set_minor_formatter(NullFormatter())
            if len(xs) > 8:
                ax.tick_params(axis="x", labelrotation=45)
        if p.logy:
            ax.set_yscale("log")
            ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
            ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(p.xlabel)
        ax.set_ylabel(p.ylabel)
        if p.title:
            ax.set_title(p.title, fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)

    return _panel_row(len(panels), 5.2, 4.2, draw, title, path)


def plot_output_overlay(
    runs: Mapping[str, SimulationResult],
    output: str,
    *,
    window: tuple[float, float] | None = None,
    relative: bool = False,
    title: str = "",
    path: str | Path | None = None,
) -> Figure:
    """An output's displacement, velocity and acceleration for several runs, overlaid.

    The first run (typically the ideal mechanism) is drawn thick and grey behind the others.

    Args:
        runs: label -> result (all with ``output`` and its ``_vel``/``_acc``).
        output: output name.
        window: (t_start, t_end) shown [s]; default the whole runs.
        relative: show the displacement of each run minus the first run's (interpolated on
            its times), in µm (mrad for angles), instead of the displacement itself.
        title: figure title.
        path: PNG path to save to.
    """
    fig = new_figure(9.5, 8.5)
    axes = fig.subplots(3, 1, sharex=True)
    first = next(iter(runs.values()))
    for ax, key, what in zip(
        axes, (output, f"{output}_vel", f"{output}_acc"), ("displacement", "velocity", "acceleration")
    ):
        _, unit, scale = quantity_label(key)
        rel = relative and key == output
        if rel:
            unit, scale = ("mrad", 1e3) if unit == "rad" else ("µm", 1e6)
            what = f"displacement − {next(iter(runs))}"
        for k, (label, r) in enumerate(runs.items()):
            sel = slice(None) if window is None else (r.times >= window[0]) & (r.times <= window[1])
            style = {"color": "0.6", "lw": 2.2} if k == 0 else {"color": f"C{k - 1}", "lw": 0.9}
            y = r.outputs[key][sel]
            if rel:
                y = y - np.interp(r.times[sel], first.times, first.outputs[key])
            ax.plot(r.times[sel] * 1e3, y * scale, label=label, **style)
        ax.set_ylabel(f"{what} [{unit}]")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time [ms]")
    fig.suptitle(title or output)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
    return fig


@dataclass(frozen=True)
class OrbitPanel:
    """One journal orbit of `plot_orbit_panels`.

    Attributes:
        result: the run.
        joint: clearance joint name.
        clearance: radial clearance c [m].
        title: panel title.
        period: drive period [s] (for `plot_orbit_phase_panels`).
    """

    result: SimulationResult
    joint: str
    clearance: float
    title: str
    period: float | None = None


def plot_orbit_panels(panels: Sequence[OrbitPanel], *, title: str = "", path: str | Path | None = None) -> Figure:
    """Journal-centre orbits side by side, each inside its clearance circle (bearing frame, µm).

    Each panel draws its run's eccentricity path (thinned to about a pixel, `canvas.thin_path`)
    on the same scale as the others, so that a journal held off the wall (an oil film) and one
    sliding along it read at a glance.

    Args:
        panels: the `OrbitPanel`s (their ``period`` is not used).
        title: figure title.
        path: PNG path to save to.
    """
    reach = max(max(p.clearance, float(np.abs(p.result.joints[p.joint].eccentricity).max())) for p in panels)
    lim = 1.15 * reach * 1e6
    th = np.linspace(0.0, 2.0 * np.pi, 400)

    def draw(ax: Axes, k: int) -> None:
        p = panels[k]
        e = p.result.joints[p.joint].eccentricity * 1e6
        keep = thin_path(e[:, 0], e[:, 1])
        c = p.clearance * 1e6
        ax.plot(c * np.cos(th), c * np.sin(th), color="k", lw=1.0, ls="--", label=f"clearance circle, c = {c:g} µm")
        ax.plot(e[keep, 0], e[keep, 1], color="C0", lw=0.7, label="journal centre")
        ax.set_aspect("equal")
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_xlabel(f"{p.joint} eccentricity x [µm]")
        ax.set_ylabel(f"{p.joint} eccentricity y [µm]")
        ax.set_title(p.title, fontsize=10)
        ax.legend(loc="upper right", fontsize=7)
        ax.grid(alpha=0.3)

    return _panel_row(len(panels), 4.6, 4.6, draw, title, path)


def plot_orbit_phase_panels(panels: Sequence[OrbitPanel], *, title: str = "", path: str | Path | None = None) -> Figure:
    """Where the journal sits in its bearing against the drive phase, one colour per period.

    For each panel: the direction of the journal-centre eccentricity (bearing frame) [deg]
    against the drive phase t mod T [deg], coloured by the period index; points where the
    journal is off the bearing wall (penetration <= 0) are drawn as crosses. A periodic
    orbit repeats one curve; a non-periodic one spreads. Suits journals that mostly slide
    along the wall, whose orbit plot is the clearance circle itself.

    Args:
        panels: the `OrbitPanel`s, each with its ``period``.
        title: figure title.
        path: PNG path to save to.

    Raises:
        ValueError: a panel without a period.
    """
    periods = [p.period for p in panels if p.period is not None and p.period > 0]
    if len(periods) < len(panels):
        raise ValueError("every OrbitPanel needs a period > 0 s for plot_orbit_phase_panels")

    def draw(ax: Axes, k: int) -> None:
        p, period = panels[k], periods[k]
        r, jr = p.result, p.result.joints[p.joint]
        phase = np.mod(r.times, period) / period * 360.0
        angle = np.degrees(np.arctan2(jr.eccentricity[:, 1], jr.eccentricity[:, 0]))
        cycle = np.floor(r.times / period + 1e-9)
        free = jr.penetration <= 0
        sc = ax.scatter(phase[~free], angle[~free], c=cycle[~free], s=1.5, cmap="viridis", lw=0)
        if free.any():
            ax.scatter(phase[free], angle[free], c="C3", s=8, marker="x", lw=0.6, label="off the wall")
            ax.legend(loc="upper right", fontsize=8)
        ax.figure.colorbar(sc, ax=ax, label="drive period index k", ticks=np.unique(cycle[~free]))
        ax.set_xlim(0, 360)
        ax.set_xlabel("drive phase [deg]")
        ax.set_ylabel(f"direction of {p.joint} eccentricity [deg]")
        ax.set_title(p.title, fontsize=10)
        ax.grid(alpha=0.3)

    return _panel_row(len(panels), 5.6, 4.6, draw, title, path)


@dataclass(frozen=True)
class PoincarePanel:
    """One Poincaré section of `plot_poincare_panels`.

    Attributes:
        points: (K, 2) section points.
        names: the two quantity names.
        classification: the set's regime (or None).
        trajectory: (n, 2) trajectory drawn behind (or None).
        label: text before the panel title.
    """

    points: np.ndarray
    names: tuple[str, str]
    classification: PoincareClassification | None = None
    trajectory: np.ndarray | None = None
    label: str = ""


def plot_poincare_panels(panels: Sequence[PoincarePanel], *, title: str = "", path: str | Path | None = None) -> Figure:
    """Poincaré sections side by side (`figures.plot_poincare` in each panel).

    Args:
        panels: the `PoincarePanel`s.
        title: figure title.
        path: PNG path to save to.
    """

    def draw(ax: Axes, k: int) -> None:
        p = panels[k]
        plot_poincare(p.points, p.names, p.classification, trajectory=p.trajectory, ax=ax, label=p.label)

    return _panel_row(len(panels), 6.4, 5.4, draw, title, path)


def plot_ranking_comparison(
    rankings: Mapping[str, CriticalityRanking], *, title: str = "", path: str | Path | None = None
) -> Figure:
    """Grouped bars: each ranking's joint scores relative to its top score, 95 % intervals.

    Joints are in the first ranking's order; a joint missing from a ranking has no bar.

    Args:
        rankings: label -> `CriticalityRanking`.
        title: figure title.
        path: PNG path to save to.
    """
    first = next(iter(rankings.values()))
    joints = [s.joint for s in first.scores]
    n = len(rankings)
    width = 0.8 / n
    fig = new_figure(max(6.0, 1.3 * len(joints) + 2), 4.3)
    ax = fig.add_subplot()
    x = np.arange(len(joints))
    for k, (label, r) in enumerate(rankings.items()):
        by = {s.joint: s for s in r.scores}
        top = max(s.score for s in r.scores)
        vals = np.array([by[j].score / top if j in by else np.nan for j in joints])
        lo = np.array([(by[j].score - by[j].ci_low) / top if j in by else 0 for j in joints])
        hi = np.array([(by[j].ci_high - by[j].score) / top if j in by else 0 for j in joints])
        ax.bar(x + (k - (n - 1) / 2) * width, vals, width, yerr=[lo, hi], capsize=3, label=label)
    ax.set_xticks(x, joints)
    ax.set_xlabel("joint with clearance (first mechanism's rank order)")
    ax.set_ylabel("score / top score [-]")
    ax.set_title(title or "criticality rankings compared")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    if path is not None:
        save_figure(fig, path)
    return fig
