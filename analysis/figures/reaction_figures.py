"""Joint reactions in a report: the figure of every joint's load over time and the report's section.

`plot_reactions` draws, per joint, the magnitude of its reaction force (the force its link_a
exerts on its link_b) and, per drive, its torque with its sign, for the run and its ideal
twin, on the steady-state scale with the start-up window shaded, its excursions beyond that
scale marked at the edge and the largest one named above the row (no start-up panels: axes
dominate a figure's drawing time), and a zoom into the steady state beside where the whole run
cannot be read. `reaction_section` writes the report's
Markdown section: whole-run and steady-state peaks side by side, the per-cycle spread and the
load factor against the ideal twin (`clearance.analysis.metrics.reactions`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from clearance.analysis.figures.canvas import Trace, save_png
from clearance.analysis.figures.plots import on_times, scale_note, scaled, steady_peak
from clearance.analysis.figures.time_rows import Layout, Row, band_legend_entry, draw_time_rows, time_axis
from clearance.analysis.metrics.reactions import ReactionSummary, reaction_magnitudes, summarise_reactions
from clearance.results import SimulationResult
from clearance.units import format_quantity, scaled_unit

__all__ = ["plot_reactions", "reaction_section"]

_ONE_COLUMN = 10
"""Rows in one column at most: more joints and drives than this go into two columns."""


def plot_reactions(
    result: SimulationResult,
    ideal: SimulationResult | None = None,
    *,
    startup: float = 0.0,
    path: str | Path | None = None,
) -> Figure:
    """Reaction magnitude of every joint and the signed torque of every drive against time, the ideal twin beside.

    Args:
        result: a run with joint reactions.
        ideal: its ideal twin's run (drawn in grey), or None.
        startup: start-up window from the run's start [s] (0: none; the scale is the whole run's);
            also the drive period that a zoom shows. The largest start-up excursion beyond the
            steady-state scale is named above its row.
        path: PNG path to save to.

    Returns:
        The figure: one row per joint and drive, its axes labelled with the name; a zoom into
        the steady state beside each where the whole run cannot be read
        (`time_rows.draw_time_rows`). Units are chosen by each row's steady peak.

    Raises:
        ValueError: the result has no joint reactions (a result saved before they existed).
    """
    if not result.joint_reactions:
        raise ValueError("the result has no joint reactions (saved before they existed): rerun it")
    series = _signed(result)
    ideal_series = _signed(ideal) if ideal is not None else {}
    time = time_axis(result.times)
    t_ms = result.times * time.scale
    rows = []
    for name, y in series.items():
        drive = name not in result.joint_reactions
        si = "N m" if drive else "N"
        unit, scale = scaled_unit(steady_peak(result.times, y, startup), si)
        traces = []
        if name in ideal_series and ideal is not None:
            y0 = scaled(on_times(result.times, ideal.times, ideal_series[name]), scale)
            style = {"color": "0.5", "lw": 1.8, "label": "ideal twin", "zorder": 2.0}
            traces.append(Trace(t_ms, y0, style, marks_clipping=False))
        run = {"color": "C0" if drive else "C3", "lw": 0.7, "label": "run", "zorder": 2.2}
        traces.append(Trace(t_ms, scaled(y, scale), run))
        what = "torque" if drive else "|F|"
        rows.append(Row(traces, name, f"{name} {what} [{unit}]", si, scale, include_zero=not drive))
    groups = 1 if len(rows) <= _ONE_COLUMN else 2
    layout = Layout(
        row_height=1.5 if len(rows) <= 6 else 1.25,
        main_width=6.4 if groups == 1 else 5.0,
        top=0.85,
        groups=groups,
        startup_panels=False,
    )
    t0 = float(t_ms[0]) if len(t_ms) else 0.0
    window = (t0, t0 + startup * time.scale)
    fig, drawn, _ = draw_time_rows(rows, window=window, cycle=startup * time.scale, layout=layout, time=time)
    handles, names = drawn[0].main.get_legend_handles_labels()
    if any(d.band for d in drawn):
        handles.append(band_legend_entry())
        names.append(handles[-1].get_label())
    drawn[0].main.legend(handles, names, loc="upper right", fontsize=7)
    h = fig.get_figheight()
    fig.text(
        0.02,
        1 - 0.22 / h,
        f"{result.metadata.get('mechanism', '')}: joint reactions and drive torques{scale_note(result.times, startup)}",
        fontsize=10,
        va="center",
    )
    fig.text(
        0.02,
        1 - 0.45 / h,
        "joints: |F|, the magnitude of the force of the joint's first link on its second; drives: the torque, signed",
        fontsize=8,
        va="center",
        color="0.3",
    )
    if path is not None:
        save_png(fig, path)
    return fig


def _signed(result: SimulationResult) -> dict[str, np.ndarray]:
    """`reaction_magnitudes` with each drive's torque signed, as the drive applies it [N m]."""
    out = reaction_magnitudes(result)
    drives = [name for name in out if name not in result.joint_reactions]
    for k, name in enumerate(drives):
        out[name] = result.drive_torque[:, k]
    return out


def _fmt(value: float, unit: str) -> str:
    return "–" if not np.isfinite(value) else format_quantity(value, unit)


def _ms(t: float) -> str:
    return "–" if not np.isfinite(t) else format_quantity(t, "s")


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
