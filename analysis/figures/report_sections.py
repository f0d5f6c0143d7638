"""Sections of the Markdown report on contact and on Poincaré sections, each with its figures.

Both take the run's start-up window (the first period of the slowest prescribed drive in a
report written by ``clearance run``) and keep the start-up apart from the steady state.
Used by `clearance.analysis.figures.report`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from clearance.analysis.chaos.poincare import (
    MIN_SECTION_POINTS,
    classify_poincare,
    phase_portrait,
    poincare_from_result,
    quantity_series,
)
from clearance.analysis.figures import analysis_figures as figures
from clearance.analysis.figures.drawing import draw
from clearance.analysis.metrics.response import CONTINUOUS_SHARE, ContactMode, JointContactModes, contact_modes
from clearance.analysis.metrics.statistics import drive_period
from clearance.analysis.metrics.summary import JointSummary, joint_summary
from clearance.results import SimulationResult
from clearance.units import format_quantity, scaled_unit

__all__ = [
    "Window",
    "clearance_of",
    "contact_section",
    "poincare_section",
    "revolutions_for_sections",
    "section_points",
]


@dataclass(frozen=True)
class Window:
    """The start-up window of a run and what follows it.

    Attributes:
        start: the run's first time [s].
        startup: length of the start-up window [s] (0: none).
        end: the run's last time [s].
    """

    start: float
    startup: float
    end: float

    @property
    def split(self) -> float:
        """Time where the steady state starts [s]."""
        return self.start + self.startup

    @property
    def has_steady_state(self) -> bool:
        """Whether samples follow the start-up window (the steady-state numbers exist)."""
        return self.end > self.split

    def span(self, a: float, b: float) -> str:
        """'a–b <unit>' of two times [s], the unit chosen by the larger ('0–12 ms', '2–6 s')."""
        unit, factor = scaled_unit(max(abs(a), abs(b)), "s")
        return f"{a * factor:.4g}–{b * factor:.4g} {unit}"


def clearance_of(result: SimulationResult, joint: str) -> float:
    """Radial clearance c [m] from the samples: |e| - penetration = c at every sample."""
    jr = result.joints[joint]
    return float(np.median(np.hypot(jr.eccentricity[:, 0], jr.eccentricity[:, 1]) - jr.penetration))


def section_points(
    result: SimulationResult, names: list[str], period: float, skip: float
) -> tuple[np.ndarray, np.ndarray]:
    """Poincaré points at t = kT of the drive from ``skip`` after the start on, and their k.

    Args:
        result: a run.
        names: quantity names (`chaos.poincare.quantity_series`), one per column.
        period: drive period T [s].
        skip: start-up window after the run's start [s].

    Returns:
        (k (K,) integers, points (K, len(names))).
    """
    ts, pts = poincare_from_result(result, names, period=period)
    # a millionth of a period of slack: t = T ends a start-up window of one period whether T
    # comes from the mechanism or from the recorded drive speed
    keep = ts >= result.times[0] + skip - 1e-6 * period
    k = np.rint((ts[keep] - result.times[0]) / period).astype(int)
    return k, pts[keep]


def _fmt(v: float, unit: str) -> str:
    return "n/a" if not np.isfinite(v) else format_quantity(v, unit, digits=4)


def _column(summary: JointSummary, modes: JointContactModes) -> list[str]:
    """One column of the contact table: a window's statistics of one joint (rows: `_STATISTICS`)."""
    f = modes.fractions
    return [
        _fmt(summary.peak_force, "N"),
        _fmt(summary.peak_force_time, "s"),
        _fmt(summary.p95_force, "N"),
        str(summary.impacts),
        f"{summary.contact_fraction:.1%}",
        _fmt(summary.max_penetration, "m"),
        f"{f[ContactMode.FREE_FLIGHT]:.1%}",
        f"{f[ContactMode.IMPACT]:.1%}",
        f"{f[ContactMode.CONTINUOUS]:.1%}",
        modes.dominant.value.replace("_", " "),
        str(len(modes.events)),
        _fmt(modes.impulse, "N s"),
    ]


_STATISTICS = (
    "peak force",
    "at",
    "p95 force, in contact",
    "impacts (contact onsets)",
    "in contact",
    "max penetration",
    "free flight",
    "impact",
    "continuous contact",
    "dominant mode",
    "contact events starting",
    "impulse",
)


def _summary(result: SimulationResult, joint: str, sel: slice, steady: bool, startup: float) -> JointSummary:
    """A window's `JointSummary` of one joint; the steady state's as summary.csv counts it.

    The steady-state impacts, contact fraction and forces are `joint_summary`'s ``steady_*``
    values (an onset needs the sample before it, so a contact running on from the start-up is
    no new impact); the other windows are summarised on their own samples (``sel``: their rows,
    a slice, so the result's arrays are viewed, not copied).
    """
    part = joint_summary(result.sliced(sel), joint)
    if not steady:
        return part
    s = joint_summary(result, joint, startup=startup)
    return replace(
        part,
        peak_force=s.steady_peak_force,
        p95_force=s.steady_p95_force,
        impacts=s.steady_impacts,
        contact_fraction=s.steady_contact_fraction,
        max_penetration=s.steady_max_penetration,
    )


_WIDE_TABLE = 4
"""Joint-window columns of the contact table at most; more (three joints and up) turn it to one row each."""


def _contact_table(names: list[tuple[str, str]], columns: list[list[str]]) -> list[str]:
    """The contact statistics: a column per joint and window, or a row each when there are many."""
    if len(columns) <= _WIDE_TABLE:
        lines = ["| statistic |" + "".join(f" {j}, {w} |" for j, w in names), "|---|" + "---:|" * len(names)]
        return lines + [f"| {name} | " + " | ".join(c[i] for c in columns) + " |" for i, name in enumerate(_STATISTICS)]
    lines = ["| joint | window | " + " | ".join(_STATISTICS) + " |", "|---|---|" + "---:|" * len(_STATISTICS)]
    return lines + [f"| {j} | {w} | " + " | ".join(c) + " |" for (j, w), c in zip(names, columns)]


def contact_section(result: SimulationResult, window: Window, out: Path) -> list[str]:
    """The "Contact at the clearance joints" section; draws contact_modes.png, links contact_force.png and orbits.

    Args:
        result: the run (with clearance joints or sliders with play).
        window: its start-up window.
        out: folder of the report.

    Returns:
        The section's Markdown lines: start-up and steady-state statistics side by side.
    """
    joints = [*result.joints, *result.sliders]  # a slider with play: its deepest corner, its net force
    k = int(np.searchsorted(result.times, window.split))  # the first steady-state row
    parts: list[tuple[str, slice, dict[str, float]]]
    if window.startup > 0:
        parts = [(f"start-up, {window.span(window.start, window.split)}", slice(0, k), {"end": window.startup})]
        steady = (
            f"steady state, {window.span(window.split, window.end)}"
            if window.has_steady_state
            else "steady state: none (the run ends in the start-up window)"
        )
        parts.append((steady, slice(k, len(result.times)), {"skip": window.startup}))
    else:
        parts = [(f"whole run, {window.span(window.start, window.end)}", slice(0, len(result.times)), {})]
    rows_in = {label: sel.stop - sel.start for label, sel, _ in parts}
    by_part = {label: [contact_modes(result, j, **kw) for j in joints] for label, _, kw in parts if rows_in[label]}
    draw(
        figures.plot_contact_modes,
        by_part,
        title=f"{result.metadata.get('mechanism', '')}: share of time in each contact mode, "
        + ", ".join(label.split(",")[0].split(":")[0] for label in by_part),
        path=out / "contact_modes.png",
    )
    names, columns = [], []
    for i, j in enumerate(joints):
        for label, sel, kw in parts:
            names.append((j, label))
            if label in by_part and rows_in[label] >= 2:
                columns.append(_column(_summary(result, j, sel, "skip" in kw, window.startup), by_part[label][i]))
            else:
                columns.append(["n/a"] * len(_STATISTICS))
    lines = ["## Contact at the clearance joints", ""]
    if window.startup > 0:
        lines += [
            "Start-up and steady state side by side (the windows of the report's head). A journal released "
            "from the bearing centre makes its first and largest impacts in the start-up window: size parts "
            "from the steady state.",
            "",
        ]
    lines += _contact_table(names, columns)
    thr = CONTINUOUS_SHARE * drive_period(result)
    lines += [
        "",
        f"A contact event (penetration > 0 without a break) lasting at least {format_quantity(thr, 's')} (5 % of "
        "the drive "
        "period) is continuous contact, a shorter one an impact; an event is classified over its whole "
        "duration and counted in the window it starts in. Shares are of the window's time."
        + (
            " A slider with play is in contact while any corner is: its penetration is the deepest corner's, its "
            "force the net contact force on it (its corners and contact cases: the slider section)."
            if result.sliders
            else ""
        ),
        "",
        *(["![contact force](contact_force.png)", ""] if result.joints else []),
        "![contact modes](contact_modes.png)",
        "",
    ]
    for j in result.joints:
        lines += [f"![orbit {j}](orbit_{j}.png)", ""]
    return lines


def revolutions_for_sections(result: SimulationResult, period: float, skip: float) -> int:
    """Drive periods a run needs for `chaos.poincare.MIN_SECTION_POINTS` section points.

    Section points lie at t = kT from the end of the start-up window on, up to the run's last
    sample (one step before its end): the first at k0 = ceil(skip / T), so k0 + MIN - 1 < the
    run's length in periods.

    Args:
        result: the run (its start).
        period: drive period T [s].
        skip: the start-up window [s].

    Returns:
        The smallest whole number of drive periods that gives the minimum.
    """
    k0 = max(0, math.ceil(skip / period - 1e-6)) if period > 0 else 0
    return k0 + MIN_SECTION_POINTS


def poincare_section(result: SimulationResult, output: str, window: Window, period: float, out: Path) -> list[str]:
    """The "Phase portraits and Poincaré sections" section; draws phase_0.png and poincare_<k>.png.

    Sections sample t = kT of the drive after the start-up window, the same instants for every
    quantity. Below `chaos.poincare.MIN_SECTION_POINTS` points no section is drawn or
    classified: the section says how many points the run gives and how many drive periods
    would give the minimum (`revolutions_for_sections`), and only the output's phase portrait
    is drawn. Figures are numbered by section: section 0 is the output's phase portrait
    (``phase_0.png``), section k >= 1 the k-th clearance joint's eccentricity
    (``poincare_<k>.png``); the table and each figure's title name both.

    Args:
        result: the run.
        output: the output analysed (its phase portrait is section 0).
        window: the start-up window.
        period: drive period T [s].
        out: folder of the report.

    Returns:
        The section's Markdown lines.
    """
    sections = [(output, f"{output}_vel")] + [(f"{j}.ex", f"{j}.ey") for j in result.joints]
    lines = ["## Phase portraits and Poincaré sections", ""]
    ks, _ = section_points(result, [output], period, window.startup)
    if len(ks) < MIN_SECTION_POINTS:
        need = revolutions_for_sections(result, period, window.startup)
        have = "no section point" if not len(ks) else f"{len(ks)} (k = {ks[0]}–{ks[-1]})"
        draw(figures.plot_phase_portrait, phase_portrait(result, output), label="section 0", path=out / "phase_0.png")
        return lines + [
            f"**No Poincaré section: too few drive periods.** A section samples the motion once per drive period "
            f"after the start-up window (t = kT), and a regime (periodic, quasi-periodic, chaotic) is told from "
            f"{MIN_SECTION_POINTS} points or more; this run gives {have}. A run of {need} drive periods "
            f"({format_quantity(need * period, 's')}: `clearance run --revolutions {need}`) gives "
            f"{MIN_SECTION_POINTS}. The journal's path is in its orbit figure above; the output's phase portrait "
            "(section 0) follows.",
            "",
            "![section 0: phase portrait](phase_0.png)",
            "",
        ]
    lines += [
        "| section | figure | points | regime | period | divergence | correlation dim. |",
        "|---|---|---:|---|---:|---:|---:|",
    ]
    # figures written by this call only: an earlier report in the same folder may have left others
    pngs: list[tuple[int, str]] = []
    # the trajectory drawn behind a section: the steady state's, or the whole run's when it has none
    after = result.times >= (window.split if window.has_steady_state else window.start)
    for k, names in enumerate(sections):
        ks, pts = section_points(result, list(names), period, window.startup)
        vals = np.column_stack([quantity_series(result, n)[after] for n in names])
        scale = float(np.sqrt(np.mean(np.sum((vals - vals.mean(axis=0)) ** 2, axis=1))))
        cl = classify_poincare(pts, scale=scale)
        name = f"phase_{k}.png" if k == 0 else f"poincare_{k}.png"
        lines.append(
            f"| {k}: {names[0]} / {names[1]} | {name} | {len(pts)} | {cl.regime.value} | {cl.period} | "
            f"{cl.divergence:.3g} | {cl.correlation_dimension:.3g} |"
        )
        if k == 0:
            portrait = phase_portrait(result, names[0])
            draw(figures.plot_phase_portrait, portrait, section=pts, label="section 0", path=out / name)
        else:
            joint = names[0].rpartition(".")[0]
            draw(
                figures.plot_poincare,
                pts,
                names,
                cl,
                trajectory=vals,
                periods=ks,
                clearance=clearance_of(result, joint),
                label=f"section {k}: {joint}",
                path=out / name,
            )
        pngs.append((k, name))
    lines += [
        "",
        "Regime criterion: `clearance.analysis.chaos.poincare` (distinct points within 1 % of the motion's RMS "
        "size, then nearest-neighbour divergence of the section map). Points are coloured by their drive period "
        "k (t = kT); the eccentricity sections show the clearance circle. Section 0 is the output's phase "
        "portrait (phase_0.png), section k the k-th clearance joint's eccentricity (poincare_k.png).",
        "",
    ]
    lines += [f"![section {k}]({name})" for k, name in pngs]
    lines.append("")
    return lines
