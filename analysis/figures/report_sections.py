"""Sections of the Markdown report on contact and on Poincaré sections, each with its figures.

Both take the run's start-up window (the first period of the slowest prescribed drive in a
report written by ``clearance run``) and keep the start-up apart from the steady state.
Used by `clearance.analysis.figures.report`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from clearance.analysis.chaos.poincare import (
    MIN_SECTION_POINTS,
    classify_poincare,
    phase_portrait,
    poincare_from_result,
    quantity_series,
    section_warning,
)
from clearance.analysis.figures import analysis_figures as figures
from clearance.analysis.figures import plots
from clearance.analysis.figures.drawing import draw
from clearance.analysis.metrics.response import ContactMode, JointContactModes, contact_modes
from clearance.analysis.metrics.summary import JointSummary, joint_summary
from clearance.results import SimulationResult

__all__ = ["Window", "clearance_of", "contact_section", "poincare_section", "section_points"]


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

    def ms(self, a: float, b: float) -> str:
        """'a–b ms' of two times [s]."""
        return f"{a * 1e3:.4g}–{b * 1e3:.4g} ms"


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


def _fmt(v: float, spec: str = ".4g") -> str:
    return "n/a" if not np.isfinite(v) else format(v, spec)


def _column(summary: JointSummary, modes: JointContactModes) -> list[str]:
    """One column of the contact table: a window's statistics of one joint (rows: `_STATISTICS`)."""
    f = modes.fractions
    return [
        _fmt(summary.peak_force),
        _fmt(summary.peak_force_time * 1e3),
        _fmt(summary.p95_force),
        str(summary.impacts),
        f"{summary.contact_fraction:.1%}",
        _fmt(summary.max_penetration * 1e6, ".3g"),
        f"{f[ContactMode.FREE_FLIGHT]:.1%}",
        f"{f[ContactMode.IMPACT]:.1%}",
        f"{f[ContactMode.CONTINUOUS]:.1%}",
        modes.dominant.value.replace("_", " "),
        str(len(modes.events)),
        _fmt(modes.impulse),
    ]


_STATISTICS = (
    "peak force [N]",
    "at [ms]",
    "p95 force, in contact [N]",
    "impacts (contact onsets)",
    "in contact",
    "max penetration [µm]",
    "free flight",
    "impact",
    "continuous contact",
    "dominant mode",
    "contact events starting",
    "impulse [N s]",
)


def _summary(result: SimulationResult, joint: str, sel: np.ndarray, steady: bool, startup: float) -> JointSummary:
    """A window's `JointSummary` of one joint; the steady state's as summary.csv counts it.

    The steady-state impacts, contact fraction and forces are `joint_summary`'s ``steady_*``
    values (an onset needs the sample before it, so a contact running on from the start-up is
    no new impact); the other windows are summarised on their own samples.
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


def contact_section(result: SimulationResult, window: Window, out: Path) -> list[str]:
    """The "Contact at the clearance joints" section; draws contact_force.png, contact_modes.png, orbits.

    Args:
        result: the run (with clearance joints).
        window: its start-up window.
        out: folder of the report.

    Returns:
        The section's Markdown lines: start-up and steady-state statistics side by side.
    """
    joints = list(result.joints)
    t = result.times
    whole = [contact_modes(result, j) for j in joints]
    if window.startup > 0:
        parts = [(f"start-up, {window.ms(window.start, window.split)}", t < window.split, {"end": window.startup})]
        steady = (
            f"steady state, {window.ms(window.split, window.end)}"
            if window.has_steady_state
            else "steady state: none (the run ends in the start-up window)"
        )
        parts.append((steady, t >= window.split, {"skip": window.startup}))
    else:
        parts = [(f"whole run, {window.ms(window.start, window.end)}", np.ones(len(t), bool), {})]
    draw(plots.plot_contact_force, result, startup=window.startup, modes=whole, path=out / "contact_force.png")
    by_part = {label: [contact_modes(result, j, **kw) for j in joints] for label, sel, kw in parts if sel.any()}
    draw(
        figures.plot_contact_modes,
        by_part,
        title=f"{result.metadata.get('mechanism', '')}: share of time in each contact mode, "
        + ", ".join(label.split(",")[0].split(":")[0] for label in by_part),
        path=out / "contact_modes.png",
    )
    head, rule, columns = ["| statistic |"], ["|---|"], []
    for i, j in enumerate(joints):
        for label, sel, kw in parts:
            head.append(f" {j}, {label} |")
            rule.append("---:|")
            if label in by_part and np.count_nonzero(sel) >= 2:
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
    lines += ["".join(head), "".join(rule)]
    lines += [f"| {name} | " + " | ".join(c[i] for c in columns) + " |" for i, name in enumerate(_STATISTICS)]
    thr = whole[0].continuous_after * 1e3 if whole else float("nan")
    lines += [
        "",
        f"A contact event (penetration > 0 without a break) lasting at least {thr:.3g} ms (5 % of the drive "
        "period) is continuous contact, a shorter one an impact; an event is classified over its whole "
        "duration and counted in the window it starts in. Shares are of the window's time.",
        "",
        "![contact force](contact_force.png)",
        "",
        "![contact modes](contact_modes.png)",
        "",
    ]
    for j in joints:
        draw(plots.plot_orbit, result, j, clearance_of(result, j), startup=window.startup, path=out / f"orbit_{j}.png")
        lines += [f"![orbit {j}](orbit_{j}.png)", ""]
    return lines


def poincare_section(result: SimulationResult, output: str, window: Window, period: float, out: Path) -> list[str]:
    """The "Phase portraits and Poincaré sections" section; draws phase_<k>.png and poincare_<k>.png.

    Sections sample t = kT of the drive after the start-up window; a section with fewer than
    `chaos.poincare.MIN_SECTION_POINTS` points is flagged in the table, under it and on its
    figure.

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
    lines += ["| section | points | regime | period | divergence | correlation dim. |", "|---|---:|---|---:|---:|---:|"]
    # figures written by this call only: an earlier report in the same folder may have left others
    pngs: list[tuple[int, str]] = []
    warnings: list[str] = []
    # the trajectory drawn behind a section: the steady state's, or the whole run's when it has none
    after = result.times >= (window.split if window.has_steady_state else window.start)
    for k, names in enumerate(sections):
        ks, pts = section_points(result, list(names), period, window.startup)
        vals = np.column_stack([quantity_series(result, n)[after] for n in names])
        cl = None
        if len(pts):
            scale = float(np.sqrt(np.mean(np.sum((vals - vals.mean(axis=0)) ** 2, axis=1))))
            cl = classify_poincare(pts, scale=scale)
        flag = " (too few)" if len(pts) < MIN_SECTION_POINTS else ""
        lines.append(
            f"| {names[0]} / {names[1]} | {len(pts)}{flag} | "
            + (
                f"{cl.regime.value} | {cl.period} | {cl.divergence:.3g} | {cl.correlation_dimension:.3g} |"
                if cl is not None
                else "n/a | | | |"
            )
        )
        warning = section_warning(len(pts))
        if warning:
            warnings.append(f"{names[0]} / {names[1]}: {warning}")
        if names[1].endswith("_vel"):
            draw(
                figures.plot_phase_portrait, phase_portrait(result, names[0]), section=pts, path=out / f"phase_{k}.png"
            )
            pngs.append((k, f"phase_{k}.png"))
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
                path=out / f"poincare_{k}.png",
            )
            pngs.append((k, f"poincare_{k}.png"))
    lines.append("")
    if warnings:
        lines += [
            f"**Too few drive periods for a regime.** A regime is told from {MIN_SECTION_POINTS} section points "
            "or more (one per drive period after the start-up window); below that the regime column says "
            "little:",
            "",
        ]
        lines += [f"- {w}" for w in warnings]
        lines.append("")
    lines += [
        "Regime criterion: `clearance.analysis.chaos.poincare` (distinct points within 1 % of the motion's RMS "
        "size, then nearest-neighbour divergence of the section map). Points are coloured by their drive period "
        "k (t = kT); the eccentricity sections show the clearance circle.",
        "",
    ]
    lines += [f"![section {k}]({name})" for k, name in pngs]
    lines.append("")
    return lines
