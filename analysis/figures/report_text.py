"""The report's paragraphs and tables that draw nothing: the start-up window, the response
table, the lag, the deviation statistics' rows and the energy balance.

Numbers are written for people (`clearance.units.format_quantity`: each in the unit its size
calls for). Used by `clearance.analysis.figures.report`.
"""

from __future__ import annotations

import numpy as np

from clearance.analysis.figures.report_sections import Window
from clearance.analysis.metrics.lag import OutputLag
from clearance.analysis.metrics.response import window_peaks
from clearance.analysis.metrics.statistics import DeviationStatistics
from clearance.results import ENERGY_TERMS, SimulationResult
from clearance.units import format_quantity

__all__ = ["deviation_rows", "energy_section", "lag_lines", "q", "response_table", "startup_lines"]


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


def q(v: float, unit: str) -> str:
    """``v`` with its unit, four significant digits in the unit its size calls for (`format_quantity`)."""
    return format_quantity(v, unit, digits=4)


def response_table(result: SimulationResult, ideal: SimulationResult, keys: list[str], window: Window) -> list[str]:
    """The response table: each key's min and max with their times, start-up and steady state apart.

    Args:
        result: run with clearance.
        ideal: its ideal twin's run.
        keys: the output, then its ``_vel`` and ``_acc`` where present.
        window: the start-up window.

    Returns:
        Markdown lines (header, rule, one row per key and window).
    """
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
                f"| {key} | {name} | {q(p.min_value, u)} | {q(p.min_time, 's')} | {q(p.max_value, u)} | "
                f"{q(p.max_time, 's')} | {q(p.ideal_min, u)} | {q(p.ideal_max, u)} | "
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
        f"({q(lag.window[0], 's')} to {q(lag.window[1], 's')}), searched within ±{q(lag.bound, 's')} "
        f"(an eighth of the period) on a {lag.resolution * 1e3:.2g} ms grid: **{lag.lag * 1e3:.3g} ms**{unc}; "
        f"positive means later than the ideal. Each signal alone: {per}. {verdict}",
        "",
    ]


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


def deviation_rows(st: DeviationStatistics, unit: str) -> list[tuple[str, str]]:
    """(label, value with its unit) of each deviation statistic, in `_DEVIATION_LABELS`' order.

    Args:
        st: the statistics.
        unit: the output's SI unit (``m`` or ``rad``).
    """
    rows = []
    for key, value in st.as_dict().items():
        label, kind = _DEVIATION_LABELS.get(key, (key, None))
        if kind is None:
            rows.append((label, _g(value) if isinstance(value, float) else str(value)))
        else:
            rows.append((label, q(value, unit if kind == "out" else kind)))
    return rows
