"""The report of a retrofitted model's run: contact statistics, orbits, contact force, site deviation.

``report.md`` beside the run's arrays, with ``orbit_<hinge>.png`` per retrofitted hinge
(`plot_orbit`), ``contact_force.png`` (`plot_contact_force`) and, for the site asked for,
``site_deviation_<axis>.png`` per coordinate that moves (`plot_deviation`). The statistics
cover the whole run (a model driven by controls has no drive period to skip) unless a
start-up window is given.
"""

from __future__ import annotations

from pathlib import Path

from clearance.analysis.figures.backlash_figures import backlash_section
from clearance.analysis.figures.deviation_figure import plot_deviation
from clearance.analysis.figures.plots import plot_contact_force, plot_orbit
from clearance.analysis.metrics.backlash_impacts import backlash_summaries
from clearance.analysis.metrics.response import contact_modes
from clearance.analysis.metrics.site_deviation import SiteDeviation
from clearance.analysis.metrics.summary import JointSummary
from clearance.results import SimulationResult, atomic_write_text

__all__ = ["REPORT_FILE", "write_model_report"]

REPORT_FILE = "report.md"


def write_model_report(
    out: str | Path,
    result: SimulationResult,
    twin: SimulationResult,
    rows: list[JointSummary],
    deviation: SiteDeviation | None,
    *,
    continuous_after: float,
    startup: float = 0.0,
    stopped: str | None = None,
) -> Path:
    """Write ``report.md`` and its figures into ``out``; returns the report's path.

    Args:
        out: the run's folder (exists).
        result: the retrofitted model's run (``metadata['radial_clearance']`` per hinge).
        twin: the unmodified model's run.
        rows: the hinges' contact statistics (`clearance.analysis.metrics.summary.summarise`).
        deviation: the chosen site's deviation, or None.
        continuous_after: a contact longer than this is continuous, shorter an impact [s]
            (a mechanism's run takes 5 % of its drive period).
        startup: start-up window [s] shaded in the figures and skipped by the steady statistics.
        stopped: the error that stopped the run early, or None.
    """
    out = Path(out)
    meta = result.metadata
    h = meta.get("timestep", float("nan"))
    lines = [
        f"# Run of a retrofitted model: {meta.get('retrofit', '')}",
        "",
        f"- model: `{meta.get('mechanism', '')}`, its unmodified twin run beside it at the same step and controls",
        f"- drive: {meta.get('drive', '')}",
        f"- simulated {result.times[-1] - result.times[0] + h:.4g} s at h = {h:g} s (the model's own step "
        f"{meta.get('original_timestep', float('nan')):g} s); "
        + (f"{meta.get('contact_mode', '')} ring bearings" if result.joints else "no radial play"),
        f"- {meta.get('steps_per_second', 0) or 0:.3g} steps/s "
        f"(twin {twin.metadata.get('steps_per_second', 0) or 0:.3g})",
    ]
    if result.joints:
        lines.append("- planar play only: each journal moves in the plane normal to its hinge axis, it cannot tilt")
    if stopped:
        lines += ["", f"**The run stopped early:** {stopped}"]
    lines.append("")
    if result.joints:
        lines += [
            "## Contact at the retrofitted hinges",
            "",
            "| hinge | impacts | peak force [N] | at [ms] | p95 force [N] | in contact | max penetration [µm] |",
            "|---|---|---|---|---|---|---|",
        ]
    for r in rows:
        lines.append(
            f"| {r.joint} | {r.impacts} | {r.peak_force:.4g} | {r.peak_force_time * 1e3:.4g} | {r.p95_force:.4g} "
            f"| {r.contact_fraction:.1%} | {r.max_penetration * 1e6:.3g} |"
        )
    if rows:
        lines.append("")
    clearances = meta.get("radial_clearance", {})
    for hinge in result.joints:
        name = f"orbit_{hinge}.png"
        plot_orbit(result, hinge, float(clearances[hinge]), startup=startup, path=out / name)
        lines += [f"![journal orbit at {hinge}]({name})", ""]
    if result.joints:
        modes = [contact_modes(result, j, continuous_after=continuous_after) for j in result.joints]
        plot_contact_force(result, startup=startup, modes=modes, path=out / "contact_force.png")
        lines += ["![contact force](contact_force.png)", ""]
    lines += backlash_section(out, result, backlash_summaries(result))
    if deviation is not None:
        lines += [
            f"## Deviation of {deviation.site} from the unmodified twin",
            "",
            f"Largest distance between the two points: {deviation.max_distance * 1e3:.4g} mm. Per coordinate that "
            "moves (window from t = "
            f"{deviation.times[0] * 1e3:.4g} ms):",
            "",
            "| coordinate | mean [mm] | RMS [mm] | max [mm] | 90 % band ± [mm] | t p-value | F | KS p-value |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for output, s in deviation.axes.items():
            lines.append(
                f"| {output} | {s.mean_deviation * 1e3:.4g} | {s.rms_deviation * 1e3:.4g} | "
                f"{s.max_deviation * 1e3:.4g} | {s.band90 * 1e3:.4g} | {s.t_pvalue:.3g} | {s.f_statistic:.4g} "
                f"| {s.ks_pvalue:.3g} |"
            )
        lines.append("")
        for output, s in deviation.axes.items():
            name = f"site_deviation_{output.rsplit('/', 1)[1]}.png"
            plot_deviation(result, twin, output, s, path=out / name)
            lines += [f"![{output} deviation]({name})", ""]
    path = out / REPORT_FILE
    atomic_write_text(path, "\n".join(lines))
    return path
