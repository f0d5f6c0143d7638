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
from clearance.analysis.figures.report_sections import (
    Window,
    clearance_of,
    contact_section,
    poincare_section,
    section_points,
)
from clearance.analysis.metrics.lag import OutputLag, joint_lag
from clearance.analysis.metrics.response import window_peaks
from clearance.analysis.metrics.statistics import DeviationStatistics, deviation_statistics, drive_period
from clearance.results import ENERGY_TERMS, SimulationResult, atomic_write_text
from clearance.units import format_quantity

if TYPE_CHECKING:  # types only: the sweeps' modules load only where a diagram or ranking is drawn
    from clearance.analysis.metrics.reactions import ReactionSummary
    from clearance.analysis.sweeps.bifurcation import BifurcationDiagram
    from clearance.analysis.sweeps.criticality import CriticalityRanking


__all__ = ["write_report", "joint_sections", "energy_section", "lag_lines", "reactions_section", "startup_lines"]


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


def _g(v: float) -> str:
    return "n/a" if not np.isfinite(v) else f"{v:.4g}"


def startup_lines(window: Window) -> list[str]:
    """The report's paragraph naming the start-up window and how it is defined.

    Args:
        window: the run's start-up window.

    Returns:
        Markdown lines.
    """
    if window.startup <= 0:
        return [
            "**No start-up window**: the mechanism has no prescribed drive period; every number below is of "
            "the whole run.",
            "",
        ]
    lines = [
        f"**Start-up window**: {window.span(window.start, window.split)}, the first period of the slowest "
        "prescribed drive. The journal is released from the bearing centre and makes its first, largest "
        "impacts in it. Start-up values are taken within it; steady-state values (peaks and peak ratios, "
        "lag, deviation statistics, contact statistics, Poincaré sections) after it.",
        "",
    ]
    if not window.has_steady_state:
        lines += [
            f"**No steady state**: the run ({window.span(window.start, window.end)}) is no longer than its "
            "start-up window; the values below are of the start-up alone. Run at least two drive periods "
            "for steady-state numbers.",
            "",
        ]
    return lines


def _si_unit(key: str, output: str) -> str:
    """The SI unit of an output's position, velocity or acceleration series."""
    base = "rad" if "angle" in output else "m"
    return base + ("/s²" if key.endswith("_acc") else "/s" if key.endswith("_vel") else "")


def _q(v: float, unit: str) -> str:
    return format_quantity(v, unit, digits=4)


def _response_table(result: SimulationResult, ideal: SimulationResult, keys: list[str], window: Window) -> list[str]:
    lines = [
        "| quantity | window | min | at | max | at | ideal min | ideal max | peak ratio |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    if window.startup > 0:
        parts = [("start-up", window.start, window.split), ("steady state", window.split, np.inf)]
    else:
        parts = [("whole run", window.start, np.inf)]
    for key in keys:
        for name, a, b in parts:
            p = window_peaks(result, ideal, key, start=a, end=b)
            if p is None:
                lines.append(f"| {key} | {name} | n/a | | n/a | | n/a | n/a | n/a |")
                continue
            bold = "**" if name == "steady state" else ""
            u = _si_unit(key, keys[0])
            lines.append(
                f"| {key} | {name} | {_q(p.min_value, u)} | {_q(p.min_time, 's')} | {_q(p.max_value, u)} | "
                f"{_q(p.max_time, 's')} | {_q(p.ideal_min, u)} | {_q(p.ideal_max, u)} | "
                f"{bold}{p.peak_ratio:.3g}{bold} |"
            )
    return lines


def lag_lines(lag: OutputLag) -> list[str]:
    """The report's paragraph on the output's lag behind the ideal output (`metrics.lag.joint_lag`).

    Args:
        lag: the estimate.

    Returns:
        Markdown lines.
    """
    head = (
        f"**Lag** of {lag.output} behind the ideal output: one estimate from displacement, velocity and "
        "acceleration together (least squares, each signal weighted by the inverse of its own misfit; "
        "`clearance.analysis.metrics.lag`)"
    )
    if not np.isfinite(lag.lag):
        return [f"{head}: not estimated: {lag.note}.", ""]
    unc = f" ± {lag.uncertainty * 1e3:.2g} ms (standard error over the periods)" if np.isfinite(lag.uncertainty) else ""
    per = ", ".join(f"{k} {v * 1e3:.3g} ms" for k, v in lag.per_signal.items())
    verdict = "Resolved." if lag.resolved else f"**Not resolved**: {lag.note}."
    return [
        f"{head}, over the steady state's {lag.periods} whole drive period{'s' if lag.periods != 1 else ''} "
        f"({_q(lag.window[0], 's')} to {_q(lag.window[1], 's')}), searched within ±{_q(lag.bound, 's')} "
        f"(an eighth of the period) on a {lag.resolution * 1e3:.2g} ms grid: **{lag.lag * 1e3:.3g} ms**{unc}; "
        f"positive means later than the ideal. Each signal alone: {per}. {verdict}",
        "",
    ]


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


def energy_section(result: SimulationResult) -> list[str]:
    """Markdown lines of the report's "Energy balance" section.

    Args:
        result: a run; its energy series (`SimulationResult.energy`) may be empty.

    Returns:
        The section's lines: each term's change over the run [J], the residual at the end and
        its largest magnitude against the largest energy exchanged, or a line saying why there
        is no balance.
    """
    lines = ["## Energy balance", ""]
    balance = result.energy_balance()
    if balance is None:
        return lines + ["The run carries no energy series (its model had no energy meter).", ""]
    lines += ["| term | change over the run [J] |", "|---|---:|"]
    lines += [f"| {k} | {_g(v)} |" for k, v in balance["change_J"].items() if k in ENERGY_TERMS]
    if balance["residual_J"] is None:
        return lines + [
            "",
            f"No residual: the solver does not record {', '.join(balance['missing'])}.",
            "",
        ]
    rel = balance["residual_relative"]
    lines += [
        f"| **residual** | {_g(balance['residual_J'])} |",
        "",
        f"Largest |residual| over the run: {_g(balance['residual_max_abs_J'])} J, "
        f"{'n/a' if rel is None else f'{rel:.2%}'} of the largest energy exchanged ({_g(balance['scale_J'])} J, "
        "the largest range of any term). Residual = Δkinetic + Δgravity_potential + Δcontact_potential − the works "
        "done on the mechanism (drive, equality, contact rows, other rows, dampers) + dissipated_work; it is "
        "the integrator's energy error, first order in the time step. kinetic includes the speed drives' "
        "armature. A ring bearing's stored energy is in contact_work (its contact_potential is 0); "
        "compiled_contact_work is a check (−Δcontact_potential − dissipated_work), not a term.",
        "",
    ]
    return lines


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
    span = f"{'steady state' if steady else 'whole run'}, {_q(st.window_start, 's')}–{_q(st.window_end, 's')}"
    lines += [f"| statistic of d = {output} − ideal ({span}) | value |", "|---|---:|"]
    unit = "rad" if "angle" in output else "m"  # as the response figure tells an angle from a position
    lines += [f"| {label} | {text} |" for label, text in _deviation_rows(st, unit)]
    lines += [
        "",
        f"Window from t = {_q(st.window_start, 's')}: {what}. Samples are autocorrelated: compare p-values "
        "between runs, not as absolute levels.",
        "",
        "![deviation](deviation.png)",
        "",
    ]
    return lines


_DEVIATION_LABELS = {
    "n": ("samples", None),
    "window_start": ("window start", "s"),
    "window_end": ("window end", "s"),
    "mean_deviation": ("mean deviation (mean of the absolute d)", "out"),
    "mean_signed_deviation": ("mean signed deviation (mean of d)", "out"),
    "rms_deviation": ("RMS deviation", "out"),
    "max_deviation": ("largest absolute deviation", "out"),
    "band90": ("90 % tolerance band (90th percentile of the absolute d)", "out"),
    "band90_low": ("5th percentile of d", "out"),
    "band90_high": ("95th percentile of d", "out"),
    "t_statistic": ("paired t statistic", None),
    "t_pvalue": ("paired t-test p-value", None),
    "f_statistic": ("variance ratio F = var(y) / var(ideal)", None),
    "f_pvalue": ("F-test p-value", None),
    "ks_statistic": ("Kolmogorov–Smirnov distance", None),
    "ks_pvalue": ("Kolmogorov–Smirnov p-value", None),
}
"""Each deviation statistic's label in the report, and its unit ("out": the output's own)."""


def _deviation_rows(st: DeviationStatistics, unit: str) -> list[tuple[str, str]]:
    """(label, value with its unit) of each deviation statistic, in `_DEVIATION_LABELS`' order."""
    rows = []
    for key, value in st.as_dict().items():
        label, kind = _DEVIATION_LABELS.get(key, (key, None))
        if kind is None:
            rows.append((label, _g(value) if isinstance(value, float) else str(value)))
        else:
            rows.append((label, _q(value, unit if kind == "out" else kind)))
    return rows


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
    lines += _response_table(result, ideal, keys, window)
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
    if result.joints:
        lines += contact_section(result, window, out)
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
