"""Markdown report of a run (and optionally a bifurcation diagram and a criticality ranking).

`write_report` computes the analyses of this package on a result and its ideal twin,
draws their figures next to the report and writes ``report.md`` (atomically) with the
tables and relative image links.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from clearance.analysis.chaos.poincare import (
    classify_poincare,
    phase_portrait,
    poincare_from_result,
    quantity_series,
)
from clearance.analysis.figures import analysis_figures as figures
from clearance.analysis.figures import plots
from clearance.analysis.metrics.response import compare_response, contact_modes
from clearance.analysis.metrics.statistics import deviation_statistics, drive_period
from clearance.analysis.sweeps.bifurcation import BifurcationDiagram
from clearance.analysis.sweeps.criticality import CriticalityRanking, ranking_markdown
from clearance.results import ENERGY_TERMS, SimulationResult, atomic_write_text

__all__ = ["write_report", "joint_sections", "energy_section"]


def _clearance_of(result: SimulationResult, joint: str) -> float:
    """Radial clearance c [m] from the samples: |e| - penetration = c at every sample."""
    jr = result.joints[joint]
    return float(np.median(np.hypot(jr.eccentricity[:, 0], jr.eccentricity[:, 1]) - jr.penetration))


def _section(result: SimulationResult, names: list[str], period: float, skip: float) -> np.ndarray:
    """(K, len(names)) Poincaré points at t = kT of the drive, from ``skip`` after the start on."""
    ts, pts = poincare_from_result(result, names, period=period)
    return pts[ts >= result.times[0] + skip]


def joint_sections(result: SimulationResult, *, skip: float | None = None) -> dict[str, np.ndarray]:
    """Each clearance joint's Poincaré section, as `write_report` computes and draws it.

    Args:
        result: a run.
        skip: start-up transient [s]; default one drive period.

    Returns:
        joint name -> (K, 2) journal-centre eccentricity [m] in the bearing frame, sampled at
        t = kT of the drive (T the drive period) from ``skip`` on; K may be 0.
    """
    period = drive_period(result)
    skip = period if skip is None else skip
    return {j: _section(result, [f"{j}.ex", f"{j}.ey"], period, skip) for j in result.joints}


def _g(v: float) -> str:
    return f"{v:.4g}"


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
) -> Path:
    """Analyse a run against its ideal twin and write ``<out_dir>/report.md`` with figures.

    Args:
        out_dir: folder for the report and its PNGs (created).
        result: run with clearance.
        ideal: run of the ideal twin (same time step and drive).
        output: output analysed (default: the first position output).
        skip: start-up transient [s] for statistics and sections; default one drive period.
        title: report title (default from the mechanism name).
        bifurcation: a diagram to include.
        ranking: a criticality ranking to include.

    Returns:
        Path of ``report.md``.

    Raises:
        KeyError: unknown output.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    positions = [k for k in result.outputs if not k.endswith(("_vel", "_acc"))]
    output = output or positions[0]
    period = drive_period(result)
    skip = period if skip is None else skip
    angular = "angle" in output
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
        if key in md:
            lines.append(f"| {key} | {md[key]} |")
    lines.append(
        f"| simulated time | {result.times[-1] * 1e3:.4g} ms ({result.times[-1] / period:.3g} drive periods) |"
    )
    lines.append("")

    lines += ["## Response against the ideal mechanism", ""]
    plots.plot_response(result, ideal, output, angular=angular, path=out / "response_vs_ideal.png")
    lines += ["![response](response_vs_ideal.png)", ""]
    lines += [
        "| quantity | lag [ms] | max | at [ms] | min | at [ms] | ideal max | ideal min | peak ratio |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for key in (output, f"{output}_vel", f"{output}_acc"):
        if key not in result.outputs:
            continue
        c = compare_response(result, ideal, key, skip=skip)
        p, p0 = c.peaks, c.ideal_peaks
        lines.append(
            f"| {key} | {c.lag * 1e3:.4g} | {_g(p.max_value)} | {p.max_time * 1e3:.4g} | {_g(p.min_value)} | "
            f"{p.min_time * 1e3:.4g} | {_g(p0.max_value)} | {_g(p0.min_value)} | {c.peak_ratio:.3g} |"
        )
    lines += [
        "",
        "Values in SI units (m, m/s, m/s² or rad, rad/s, rad/s²); lag > 0: the output is later "
        "than the ideal one (cross-correlation peak).",
        "",
    ]

    lines += ["## Deviation statistics", ""]
    st = deviation_statistics(result, ideal, output, skip=skip)
    figures.plot_deviation(result, ideal, output, st, path=out / "deviation.png")
    lines += ["| statistic | value |", "|---|---:|"]
    lines += [f"| {k} | {_g(v) if isinstance(v, float) else v} |" for k, v in st.as_dict().items()]
    lines += [
        "",
        f"Window from t = {st.window_start * 1e3:.4g} ms (start-up transient skipped). Samples are "
        "autocorrelated: compare p-values between runs, not as absolute levels.",
        "",
        "![deviation](deviation.png)",
        "",
    ]

    if result.joints:
        lines += ["## Contact at the clearance joints", ""]
        modes = [contact_modes(result, j) for j in result.joints]
        plots.plot_contact_force(result, path=out / "contact_force.png")
        figures.plot_contact_modes(result, modes, path=out / "contact_modes.png")
        lines += [
            "| joint | dominant mode | free flight | impact | continuous | events | impulse [N s] | peak force [N] "
            "| p95 force [N] | impacts |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for m in modes:
            f = {k.value: v for k, v in m.fractions.items()}
            lines.append(
                f"| {m.joint} | {m.dominant.value} | {f['free_flight']:.1%} | {f['impact']:.1%} | "
                f"{f['continuous_contact']:.1%} | {len(m.events)} | {m.impulse:.4g} | "
                f"{m.summary.peak_force:.4g} | {m.summary.p95_force:.4g} | {m.summary.impacts} |"
            )
        thr = modes[0].continuous_after * 1e3
        lines += [
            "",
            f"A contact event (penetration > 0 without a break) lasting at least {thr:.3g} ms (5 % of the "
            "drive period) is continuous contact, a shorter one an impact.",
            "",
            "![contact force](contact_force.png)",
            "",
            "![contact modes](contact_modes.png)",
            "",
        ]
        for j in result.joints:
            plots.plot_orbit(result, j, _clearance_of(result, j), path=out / f"orbit_{j}.png")
            lines += [f"![orbit {j}](orbit_{j}.png)", ""]

    lines += energy_section(result)

    lines += ["## Phase portraits and Poincaré sections", ""]
    sections = [(output, f"{output}_vel")] + [(f"{j}.ex", f"{j}.ey") for j in result.joints]
    lines += ["| section | points | regime | period | divergence | correlation dim. |", "|---|---:|---|---:|---:|---:|"]
    # figures written by this call only: an earlier report in the same folder may have left others
    phase_pngs, poincare_pngs = [], []
    for k, names in enumerate(sections):
        pts = _section(result, list(names), period, skip)
        if len(pts) == 0:
            continue
        after = result.times >= result.times[0] + skip
        vals = np.column_stack([quantity_series(result, n)[after] for n in names])
        scale = float(np.sqrt(np.mean(np.sum((vals - vals.mean(axis=0)) ** 2, axis=1))))
        cl = classify_poincare(pts, scale=scale)
        lines.append(
            f"| {names[0]} / {names[1]} | {cl.n_points} | {cl.regime.value} | {cl.period} | "
            f"{cl.divergence:.3g} | {cl.correlation_dimension:.3g} |"
        )
        if names[1].endswith("_vel"):
            figures.plot_phase_portrait(phase_portrait(result, names[0]), section=pts, path=out / f"phase_{k}.png")
            phase_pngs.append((k, f"phase_{k}.png"))
        else:
            figures.plot_poincare(pts, names, cl, trajectory=vals, path=out / f"poincare_{k}.png")
            poincare_pngs.append((k, f"poincare_{k}.png"))
    lines += [
        "",
        "Regime criterion: `clearance.analysis.chaos.poincare` (distinct points within 1 % of the motion's RMS "
        "size, then nearest-neighbour divergence of the section map). Few periods give few points: the "
        "regime of a short run is indicative only.",
        "",
    ]
    lines += [f"![section {k}]({name})" for k, name in phase_pngs + poincare_pngs]
    lines.append("")

    if bifurcation is not None:
        figures.plot_bifurcation(bifurcation, path=out / "bifurcation.png")
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
        figures.plot_criticality(ranking, path=out / "criticality.png")
        lines += ["## Joint criticality", "", ranking_markdown(ranking), "![criticality](criticality.png)", ""]
    path = out / "report.md"
    atomic_write_text(path, "\n".join(lines))
    return path
