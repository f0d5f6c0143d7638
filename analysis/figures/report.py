"""Markdown report of a run (and optionally a bifurcation diagram and a criticality ranking).

`write_report` computes the analyses of this package on a result and its ideal twin,
draws their figures next to the report and writes ``report.md`` (atomically) with the
tables and relative image links.

One start-up window serves every number and figure of the report: the first period of the
slowest prescribed drive (``skip``, as ``clearance run`` passes `Mechanism.drive_period`).
The report names it; start-up values (within it) and steady-state values (after it) are
given side by side; a run no longer than the window says so instead of giving steady-state
numbers.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from clearance.analysis.figures import analysis_figures as figures
from clearance.analysis.figures import plots
from clearance.analysis.figures.deviation_figure import plot_deviation
from clearance.analysis.figures.drawing import draw, figures_in_parallel, start_child
from clearance.analysis.figures.film_figures import film_section
from clearance.analysis.figures.report_sections import (
    Window,
    clearance_of,
    contact_section,
    poincare_section,
    section_points,
)
from clearance.analysis.figures.report_text import deviation_rows, q, response_table
from clearance.analysis.figures.report_text import energy_section as energy_section
from clearance.analysis.figures.report_text import lag_lines as lag_lines
from clearance.analysis.figures.report_text import startup_lines as startup_lines
from clearance.analysis.metrics.lag import joint_lag
from clearance.analysis.metrics.statistics import deviation_statistics, drive_period
from clearance.results import SimulationResult, atomic_write_text
from clearance.units import format_quantity

if TYPE_CHECKING:  # types only: the sweeps' modules load only where a diagram or ranking is drawn
    from clearance.analysis.metrics.reactions import ReactionSummary
    from clearance.analysis.sweeps.bifurcation import BifurcationDiagram
    from clearance.analysis.sweeps.criticality import CriticalityRanking


__all__ = ["write_report", "joint_sections", "energy_section", "lag_lines", "reactions_section", "startup_lines"]
# energy_section, lag_lines and startup_lines live in report_text; re-exported here where users found them


def joint_sections(result: SimulationResult, *, skip: float | None = None) -> dict[str, np.ndarray]:
    """Each clearance joint's Poincaré section, as `write_report` computes and draws it.

    Args:
        result: a run.
        skip: start-up window [s]; default one drive period.

    Returns:
        joint name -> (K, 2) journal-centre eccentricity [m] in the bearing frame, sampled at
        t = kT of the drive (T the drive period) from ``skip`` on; K may be 0.
    """
    period = drive_period(result)
    skip = period if skip is None else skip
    return {j: section_points(result, [f"{j}.ex", f"{j}.ey"], period, skip)[1] for j in result.joints}


def reactions_section(
    result: SimulationResult,
    ideal: SimulationResult,
    window: Window,
    out: Path,
    rows: list[ReactionSummary] | None = None,
) -> list[str]:
    """The report's "Joint reactions" section (the bearing load at every joint).

    The section of `reaction_section` with the report's start-up window, linking
    ``joint_reactions.png`` (`plot_reactions`, which `write_report` draws).

    Args:
        result: a run with joint reaction series (``SimulationResult.joint_reactions``).
        ideal: its ideal twin's run.
        window: its start-up window.
        out: the report's folder.
        rows: the summaries when already computed (`summarise_reactions` with the same window).

    Returns:
        The section's Markdown lines.
    """
    from clearance.analysis.figures.reaction_figures import reaction_section
    from clearance.analysis.metrics.reactions import summarise_reactions

    if rows is None:
        rows = summarise_reactions(result, ideal, startup=window.startup)
    return reaction_section(result, ideal, startup=window.startup, figure="joint_reactions.png", rows=rows)


def _deviation_lines(
    result: SimulationResult, ideal: SimulationResult, output: str, window: Window, out: Path
) -> list[str]:
    lines = ["## Deviation statistics", ""]
    skip = window.startup if window.has_steady_state else 0.0
    try:
        st = deviation_statistics(result, ideal, output, skip=skip)
    except ValueError as err:  # fewer than 3 samples in the window
        return lines + [f"No deviation statistics: {err}.", ""]
    draw(plot_deviation, result, ideal, output, st, path=out / "deviation.png")
    steady = window.has_steady_state and window.startup > 0
    what = "the steady state (the start-up window skipped)" if steady else "the whole run (no steady state)"
    span = f"{'steady state' if steady else 'whole run'}, {q(st.window_start, 's')}–{q(st.window_end, 's')}"
    lines += [f"| statistic of d = {output} − ideal ({span}) | value |", "|---|---:|"]
    unit = "rad" if "angle" in output else "m"  # as the response figure tells an angle from a position
    lines += [f"| {label} | {text} |" for label, text in deviation_rows(st, unit)]
    lines += [
        "",
        f"Window from t = {q(st.window_start, 's')}: {what}. Samples are autocorrelated: compare p-values "
        "between runs, not as absolute levels.",
        "",
        "![deviation](deviation.png)",
        "",
    ]
    return lines


def write_report(
    out_dir: str | Path,
    result: SimulationResult,
    ideal: SimulationResult,
    *,
    output: str | None = None,
    skip: float | None = None,
    title: str | None = None,
    bifurcation: BifurcationDiagram | None = None,
    ranking: CriticalityRanking | None = None,
    processes: int = 1,
    reactions: list[ReactionSummary] | None = None,
) -> Path:
    """Analyse a run against its ideal twin and write ``<out_dir>/report.md`` with figures.

    Args:
        out_dir: folder for the report and its PNGs (created).
        result: run with clearance.
        ideal: run of the ideal twin (same time step and drive).
        output: output analysed (default: the first position output).
        skip: the start-up window [s]: the first period of the slowest prescribed drive
            (`Mechanism.drive_period`; 0 for a mechanism without one); default one period of
            the result's first drive.
        title: report title (default from the mechanism name).
        bifurcation: a diagram to include.
        ranking: a criticality ranking to include.
        processes: 2 draws the figures in this process and a forked child at once
            (`clearance.analysis.figures.drawing`); 1 draws them here, one after the other.
        reactions: the joint-reaction summaries when already computed with the same window
            (`summarise_reactions`), else computed here.

    Returns:
        Path of ``report.md``.

    Raises:
        KeyError: unknown output.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    positions = [k for k in result.outputs if not k.endswith(("_vel", "_acc"))]
    output = output or positions[0]
    if output not in result.outputs:
        raise KeyError(f"output {output!r} not in the result (have {positions})")
    period = drive_period(result)
    window = Window(float(result.times[0]), period if skip is None else skip, float(result.times[-1]))
    with figures_in_parallel(processes):
        lines = _report_lines(out, result, ideal, output, window, period, title, bifurcation, ranking, reactions)
    path = out / "report.md"
    atomic_write_text(path, "\n".join(lines))
    return path


def _time_figures(
    out: Path, result: SimulationResult, ideal: SimulationResult, output: str, window: Window, reactions: bool
) -> None:
    """Queue the figures that need none of the report's numbers: response, contact force, orbits, reactions."""
    draw(
        plots.plot_response,
        result,
        ideal,
        output,
        angular="angle" in output,
        startup=window.startup,
        path=out / "response_vs_ideal.png",
    )
    if result.joints:
        draw(plots.plot_contact_force, result, startup=window.startup, path=out / "contact_force.png")
    for j in result.joints:
        draw(plots.plot_orbit, result, j, clearance_of(result, j), startup=window.startup, path=out / f"orbit_{j}.png")
    if reactions:
        from clearance.analysis.figures.reaction_figures import plot_reactions

        draw(plot_reactions, result, ideal, startup=window.startup, path=out / "joint_reactions.png")


def _report_lines(
    out: Path,
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    window: Window,
    period: float,
    title: str | None,
    bifurcation: BifurcationDiagram | None,
    ranking: CriticalityRanking | None,
    reactions: list[ReactionSummary] | None = None,
) -> list[str]:
    """The report's Markdown lines; its figures are handed to `draw`."""
    md = result.metadata
    lines = [f"# {title or md.get('mechanism', 'run')}: response with clearance", ""]
    lines += ["| item | value |", "|---|---|"]
    for key in (
        "mechanism",
        "solver",
        "time_step",
        "integrator",
        "segments",
        "journal_geom",
        "segment_geom",
        "contact_mode",
        "wall_time_s",
        "mujoco_version",
    ):
        if key in md and md[key] not in (None, "", {}, []):  # e.g. no ring segments in the exact mode
            value = md[key]
            if key in ("time_step", "wall_time_s") and isinstance(value, (int, float)):
                value = format_quantity(float(value), "s")  # 3 µs, 12.3 s: not 3e-06 nor 17 digits
            lines.append(f"| {key} | {value} |")
    lines.append(
        f"| simulated time | {format_quantity(float(result.times[-1]), 's', digits=4)} "
        f"({result.times[-1] / period:.3g} drive periods) |"
    )
    lines.append(f"| start-up window | {window.span(window.start, window.split)} |")
    lines.append("")
    lines += startup_lines(window)
    has_reactions = bool(getattr(result, "joint_reactions", None))
    _time_figures(out, result, ideal, output, window, has_reactions)
    sections = poincare_section(result, output, window, period, out)  # a few points: cheap
    start_child()  # the figures so far are drawn while the numbers below are computed

    lines += ["## Response against the ideal mechanism", ""]
    lines += ["![response](response_vs_ideal.png)", ""]
    keys = [k for k in (output, f"{output}_vel", f"{output}_acc") if k in result.outputs]
    lines += response_table(result, ideal, keys, window)
    lines += [
        "",
        "Each value in the unit its size calls for (mm, m/s, km/s², ...); peak ratio = max |y| / max |y_ideal| "
        "over the same window. The figure is scaled to the steady state; triangles at an edge mark start-up "
        "samples beyond it, shown at full scale beside. A series too dense for its pixels is drawn as the band "
        "of each pixel column's smallest and largest sample with the column means as its line (every peak "
        "stays); where the whole run cannot be read, a zoom into the steady state (its span shaded orange) comes "
        "beside it.",
        "",
    ]
    lines += lag_lines(joint_lag(result, ideal, output, startup=window.startup))

    lines += _deviation_lines(result, ideal, output, window, out)
    if result.joints or result.sliders:
        lines += contact_section(result, window, out)
    if result.joints:
        lines += film_section(result, window, out)  # lubricated joints: the film beside the orbits
    if result.sliders:  # sliders with play: position and tilt in the guide, contact cases
        from clearance.analysis.figures.slider_figures import slider_section

        lines += slider_section(result, out)
    if has_reactions:  # the joint reactions' section, where the result has them
        lines += reactions_section(result, ideal, window, out, reactions)
    lines += energy_section(result)
    lines += sections

    if bifurcation is not None:
        draw(figures.plot_bifurcation, bifurcation, path=out / "bifurcation.png")
        counts = {r: bifurcation.regimes.count(r) for r in dict.fromkeys(bifurcation.regimes)}
        lines += [
            "## Bifurcation diagram",
            "",
            f"{len(bifurcation.values)} points over {bifurcation.parameter}; regimes: {counts}.",
            "",
            "![bifurcation](bifurcation.png)",
            "",
        ]
    if ranking is not None:
        draw(figures.plot_criticality, ranking, path=out / "criticality.png")
        from clearance.analysis.sweeps.criticality import ranking_markdown

        lines += ["## Joint criticality", "", ranking_markdown(ranking), "![criticality](criticality.png)", ""]
    return lines
