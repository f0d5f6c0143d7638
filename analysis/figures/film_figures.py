"""Lubricated joints in a report: the oil film's figure and the report's section.

`plot_film` draws, for one lubricated joint, the minimum film thickness h = c − |e|, the
eccentricity ratio ε = |e|/c and the magnitude of the film force against time, on the
steady-state scale with the start-up window shaded (`time_rows.draw_time_rows`, as the contact
force figure); the journal's path is its orbit figure. `film_section` writes the report's
Markdown section: start-up and steady state side by side (`clearance.analysis.metrics.film`),
whether the film carried the load or ruptured into dry contact, and the figures.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from clearance.analysis.figures.canvas import Trace, save_png
from clearance.analysis.figures.drawing import draw
from clearance.analysis.figures.plots import scale_note, scaled, steady_peak
from clearance.analysis.figures.report_sections import Window
from clearance.analysis.figures.time_rows import Layout, Row, draw_time_rows, head_and_legend, time_axis
from clearance.analysis.metrics.film import FilmSummary, film_summary
from clearance.results import SimulationResult
from clearance.units import format_quantity, scaled_unit

__all__ = ["film_section", "plot_film"]


def plot_film(result: SimulationResult, joint: str, *, startup: float = 0.0, path: str | Path | None = None) -> Figure:
    """Minimum film thickness, eccentricity ratio and film force of a lubricated joint against time.

    Rows (top to bottom): h = c − |e| (a dashed line at 0, where the surfaces touch and the dry
    law takes over), ε = |e|/c, and |F_film|; each on the steady state's scale (after
    ``startup``) with the start-up window shaded, a crowded series drawn as its envelope band and
    a zoom into the steady state beside where the whole run cannot be read. Units by size (µm,
    kN).

    Args:
        result: a run.
        joint: a lubricated clearance joint of it.
        startup: start-up window from the run's start [s] (0: none); also the drive period that
            a zoom shows.
        path: PNG path to save to.

    Returns:
        The figure; its rows' axes are labelled ``film thickness``, ``eccentricity ratio``,
        ``film force``.

    Raises:
        KeyError: no such clearance joint.
        ValueError: the joint carries no film force.
    """
    jr = result.joints[joint]
    force = jr.film_force_magnitude
    if force is None:
        raise ValueError(f"joint {joint!r} carries no film force (a dry joint, or a result saved without it)")
    time = time_axis(result.times)
    t = result.times * time.scale
    h = jr.film_thickness
    h_unit, h_scale = scaled_unit(steady_peak(result.times, h, startup), "m")
    f_unit, f_scale = scaled_unit(steady_peak(result.times, force, startup), "N")
    style = {"color": "C0", "lw": 0.7, "zorder": 2.2}
    rows = [
        Row([Trace(t, scaled(h, h_scale), style)], "film thickness", f"h = c − |e| [{h_unit}]", "m", h_scale, True),
        Row([Trace(t, jr.eccentricity_ratio, style)], "eccentricity ratio", "ε = |e|/c [-]", "-", 1.0, True),
        Row([Trace(t, scaled(force, f_scale), style)], "film force", f"|F_film| [{f_unit}]", "N", f_scale, True),
    ]
    t0 = float(t[0]) if len(t) else 0.0
    layout = Layout(row_height=1.5, top=0.75)
    fig, drawn, _ = draw_time_rows(
        rows, window=(t0, t0 + startup * time.scale), cycle=startup * time.scale, layout=layout, time=time
    )
    drawn[0].main.axhline(0.0, color="k", lw=0.8, ls="--", zorder=2.5, label="h = 0: dry contact below")
    head = f"{result.metadata.get('mechanism', '')}: oil film at {joint}{scale_note(result.times, startup)}"
    head_and_legend(fig, drawn, head, band_colour="C0")
    if path is not None:
        save_png(fig, path)
    return fig


def _q(v: float, unit: str) -> str:
    return "n/a" if not np.isfinite(v) else format_quantity(v, unit, digits=3)


_ROWS = (
    "minimum film thickness h = c − \\|e\\|",
    "at",
    "largest eccentricity ratio ε = \\|e\\|/c",
    "peak film force",
    "at",
    "in dry contact (h < 0)",
)


def _column(s: FilmSummary) -> list[str]:
    """One column of the film table (rows: `_ROWS`)."""
    if not s.samples:
        return ["n/a"] * len(_ROWS)
    return [
        _q(s.min_film_thickness, "m"),
        _q(s.min_film_thickness_time, "s"),
        f"{s.max_eccentricity_ratio:.3g}",
        _q(s.peak_film_force, "N"),
        _q(s.peak_film_force_time, "s"),
        f"{s.dry_fraction:.1%}",
    ]


def film_section(result: SimulationResult, window: Window, out: Path) -> list[str]:
    """The report's "Oil film at the lubricated joints" section; draws ``film_<joint>.png``.

    Args:
        result: the run.
        window: its start-up window (the report's).
        out: folder of the report.

    Returns:
        The section's Markdown lines (none for a run without a lubricated joint).
    """
    joints = [j for j, jr in result.joints.items() if jr.lubricated]
    if not joints:
        return []
    if window.startup > 0:
        parts = [(f"start-up, {window.span(window.start, window.split)}", -np.inf, window.split)]
        if window.has_steady_state:
            parts.append((f"steady state, {window.span(window.split, window.end)}", window.split, np.inf))
    else:
        parts = [(f"whole run, {window.span(window.start, window.end)}", -np.inf, np.inf)]
    names, columns, whole = [], [], []
    for j in joints:
        whole.append(film_summary(result, j))
        for label, a, b in parts:
            names.append(f"{j}, {label}")
            columns.append(_column(film_summary(result, j, since=a, until=b)))
        draw(plot_film, result, j, startup=window.startup, path=out / f"film_{j}.png")
    lines = ["## Oil film at the lubricated joints", ""]
    lines += ["| statistic | " + " | ".join(names) + " |", "|---|" + "---:|" * len(names)]
    lines += [f"| {row} | " + " | ".join(c[i] for c in columns) + " |" for i, row in enumerate(_ROWS)]
    lines.append("")
    for s in whole:
        c = format_quantity(s.clearance, "m", digits=3)
        if s.film_carried_the_load:
            lines.append(
                f"- {s.joint}: the oil film carried the load over the whole run: the journal came no closer than "
                f"{_q(s.min_film_thickness, 'm')} to the bearing (ε at most {s.max_eccentricity_ratio:.3g}; "
                f"c = {c}); its contact force above is the film's alone."
            )
        else:
            lines.append(
                f"- {s.joint}: the film ruptured: the journal went through the film into dry contact in "
                f"{s.dry_fraction:.1%} of the samples (overlap up to {_q(-s.min_film_thickness, 'm')}, c = {c}), "
                "where the joint's dry contact law acted beside the film; its contact force above is the sum."
            )
    lines += [
        "",
        "The film force is the oil's pressure on the journal (`JointResult.film_force`): from the compiled "
        "contact's sensor in a MuJoCo run, evaluated at each sample's state in a reference run. The journal's "
        "path is its orbit figure above.",
        "",
    ]
    lines += [f"![oil film {j}](film_{j}.png)" for j in joints]
    lines.append("")
    return lines
