"""Joint reactions in a report: the figure of every joint's load over time and the report's section.

`plot_reactions` draws, per joint, the magnitude of its reaction force (the force its link_a
exerts on its link_b) and, per drive, the magnitude of its torque, for the run and its ideal
twin, on the steady-state scale with the start-up window shaded, its excursions beyond that
scale marked at the edge and the largest one written in the panel (one axes per series, no
side panels: axes dominate a figure's drawing time). `reaction_section` writes the report's
Markdown section: whole-run and steady-state peaks side by side, the per-cycle spread and the
load factor against the ideal twin (`clearance.analysis.metrics.reactions`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from clearance.analysis.figures.canvas import Trace, draw_steady_scaled, envelope, new_figure, save_png
from clearance.analysis.figures.plots import force_unit
from clearance.analysis.metrics.reactions import ReactionSummary, reaction_magnitudes, summarise_reactions
from clearance.results import SimulationResult

__all__ = ["plot_reactions", "reaction_section"]

_MAX_ROWS = 6
"""Panels per column: more joints than this go into two columns."""


def plot_reactions(
    result: SimulationResult,
    ideal: SimulationResult | None = None,
    *,
    startup: float = 0.0,
    path: str | Path | None = None,
) -> Figure:
    """Reaction magnitude of every joint and drive against time, the ideal twin beside.

    Args:
        result: a run with joint reactions.
        ideal: its ideal twin's run (drawn in grey), or None.
        startup: start-up window from the run's start [s] (0: none; the scale is the whole run's).
            The largest start-up excursion beyond the steady-state scale is written in its panel.
        path: PNG path to save to.

    Returns:
        The figure: one axes per joint and drive, labelled with its name.

    Raises:
        ValueError: the result has no joint reactions (a result saved before they existed).
    """
    if not result.joint_reactions:
        raise ValueError("the result has no joint reactions (saved before they existed): rerun it")
    mags = reaction_magnitudes(result)
    ideal_mags = reaction_magnitudes(ideal) if ideal is not None else {}
    names = list(mags)
    t_ms = result.times * 1e3
    t0 = float(t_ms[0]) if len(t_ms) else 0.0
    window = (t0, t0 + startup * 1e3)
    rows, units = [], []
    for name in names:
        drive = name not in result.joint_reactions
        steady = mags[name][t_ms >= window[1]] if startup > 0 else mags[name]
        peak = float(np.nanmax(steady, initial=0.0)) if len(steady) else 0.0
        unit, scale = ("N m", 1.0) if drive else force_unit(peak)
        units.append(unit)
        traces = []
        if ideal is not None and name in ideal_mags:
            y0 = np.interp(result.times, ideal.times, ideal_mags[name]) * scale
            traces.append(Trace(t_ms, y0, {"color": "0.55", "lw": 1.6, "label": "ideal twin"}, marks_clipping=False))
        colour = "C0" if drive else "C3"
        traces.append(Trace(t_ms, mags[name] * scale, {"color": colour, "lw": 0.7, "label": "run"}))
        rows.append(traces)
    ncols = 1 if len(names) <= _MAX_ROWS else 2
    nrows = math.ceil(len(names) / ncols)
    fig = new_figure(9.0 if ncols == 1 else 14.0, 1.0 + 1.55 * nrows)
    h = fig.get_figheight()
    gs = fig.add_gridspec(
        nrows,
        ncols,
        left=0.09 if ncols == 1 else 0.06,
        right=0.98,
        top=1 - 0.7 / h,
        bottom=0.5 / h,
        hspace=0.38,
        wspace=0.22,
    )
    first = None
    for i, (name, traces, unit) in enumerate(zip(names, rows, units)):
        r, c = i % nrows, i // nrows
        ax = fig.add_subplot(gs[r, c], sharex=first)
        first = first or ax
        if startup > 0:
            lim, clipped = draw_steady_scaled(ax, traces, window, label="start-up" if r == 0 else None)
            if clipped:
                worst = max(clipped, key=lambda k: abs(k.peak))
                value = f"{worst.peak:.0f}" if abs(worst.peak) >= 1e3 else f"{worst.peak:.3g}"
                ax.set_title(
                    f"start-up peak {value} {unit} at {worst.peak_time:.3g} ms (off this scale)",
                    loc="left",
                    fontsize=7,
                    pad=2,
                    color="0.3",
                )
        else:
            for tr in traces:
                ax.plot(*envelope(tr.x, tr.y), **tr.style)
        ax.set_label(name)
        kind = "torque" if name not in result.joint_reactions else "|F|"
        ax.set_ylabel(f"{name} {kind} [{unit}]", fontsize=8)
        ax.tick_params(labelsize=8)
        ax.grid(alpha=0.3)
        if r == nrows - 1 or i == len(names) - 1:
            ax.set_xlabel("time [ms]", fontsize=9)
        else:
            ax.tick_params(labelbottom=False)
        if i == 0:
            ax.legend(loc="upper right", fontsize=7)
    scale_note = "; y-scale of the steady state" if startup > 0 else ""
    title = (
        f"{result.metadata.get('mechanism', '')}: joint reactions (force of each joint's first link on its second) "
        f"and drive torques{scale_note}"
    )
    fig.text(0.5, 1 - 0.35 / h, title, fontsize=10, ha="center", va="center")
    if path is not None:
        save_png(fig, path)
    return fig


def _fmt(value: float, unit: str) -> str:
    if not np.isfinite(value):
        return "–"
    if unit == "N" and abs(value) >= 1e3:
        return f"{value / 1e3:.3g} kN"
    return f"{value:.4g} {unit}"


def _ms(t: float) -> str:
    return "–" if not np.isfinite(t) else f"{t * 1e3:.3g} ms"


def reaction_section(
    result: SimulationResult,
    ideal: SimulationResult | None = None,
    *,
    startup: float = 0.0,
    period: float | None = None,
    figure: str | None = None,
    rows: list[ReactionSummary] | None = None,
) -> list[str]:
    """The report's Markdown section on joint reactions and drive torques.

    Args:
        result: a run with joint reactions.
        ideal: its ideal twin's run (its peaks and the load factor), or None.
        startup: the start-up window [s] every statistic of the report uses (the first period of
            the slowest drive); 0 for none.
        period: cycle length for the per-cycle peaks [s] (default: ``startup``).
        figure: file name of the `plot_reactions` figure to link, or None.
        rows: the summaries when already computed (`summarise_reactions` with the same window).

    Returns:
        Markdown lines (a ``##`` heading, a paragraph, a table).
    """
    out = ["## Joint reactions", ""]
    if not result.joint_reactions:
        return out + ["This result carries no joint reactions (it was saved before they existed).", ""]
    if rows is None:
        rows = summarise_reactions(result, ideal, startup=startup, period=period)
    steady = startup > 0 and any(r.has_steady_state for r in rows)
    out.append(
        "The reaction of each joint is the force its first link exerts on its second (the second "
        "link receives it, the first the opposite), in N; a clearance joint's is its contact force. "
        "Drive torques are in N m."
    )
    if startup > 0 and not steady:
        out.append(
            f"The run ({_ms(float(result.times[-1]))}) is no longer than the start-up window "
            f"(the first drive period, {_ms(startup)}): there are no steady-state values; run longer."
        )
    elif steady:
        out.append(
            f"Steady state: after the start-up window (the first drive period, {_ms(startup)}); cycle "
            "peaks: the peak in each whole period after it (mean, smallest to largest)."
        )
    out.append("")
    ideal_cols = ideal is not None
    head = ["joint", "peak (whole run)", "at"]
    if steady:
        head += ["steady peak", "at", "steady p95", "cycle peaks"]
    if ideal_cols:
        head += ["ideal twin steady peak" if steady else "ideal twin peak"]
        if steady:
            head += ["steady / ideal"]
    out += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        name = r.name if r.kind == "joint" else f"{r.name} (drive torque)"
        cells = [name, _fmt(r.peak, r.unit), _ms(r.peak_time)]
        if steady:
            cycles = (
                f"{_fmt(r.cycle_peak_mean, r.unit)} ({_fmt(r.cycle_peak_min, r.unit)} to "
                f"{_fmt(r.cycle_peak_max, r.unit)}, {r.cycles} periods)"
                if r.cycles
                else "–"
            )
            cells += [_fmt(r.steady_peak, r.unit), _ms(r.steady_peak_time), _fmt(r.steady_p95, r.unit), cycles]
        if ideal_cols:
            cells.append(_fmt(r.ideal_steady_peak if steady else r.ideal_peak, r.unit))
            if steady:
                cells.append("–" if not np.isfinite(r.steady_peak_ratio) else f"{r.steady_peak_ratio:.3g}")
        out.append("| " + " | ".join(cells) + " |")
    out.append("")
    if figure:
        out += [f"![joint reactions]({figure})", ""]
    return out
