"""The report of a retrofitted model's run: contact statistics, orbits, contact force, site deviation.

``report.md`` beside the run's arrays, with ``orbit_<hinge>.png`` per retrofitted hinge
(`plot_orbit`), ``contact_force.png`` (`plot_contact_force`) and, for the site asked for,
``site_deviation_<axis>.png`` per coordinate that moves (`plot_deviation`; ``site_deviation_base_<axis>.png``
in a floating base's frame). Contact statistics over the whole run and over the steady state
after the start-up window; the deviation over the steady state; whether it is the play's or
chaos (the twin against itself nudged by rounding).
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
from clearance.run.sensitivity import CHAOS_SHARE, Sensitivity, is_chaos

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
    frame_deviation: SiteDeviation | None = None,
    sensitivity: Sensitivity | None = None,
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
        frame_deviation: the site's deviation in its floating base's frame, or None (a fixed base).
        sensitivity: the twin against itself started a rounding-size nudge off (`clearance.run.sensitivity`),
            or None: says whether the deviation is the play's or chaos.
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
        + (_bearings(meta.get("contact_mode", "")) if result.joints else "no radial play"),
        f"- start-up window: the first {startup * 1e3:.4g} ms (the journals start centred: their first drop is in it); "
        "the steady-state statistics start after it",
        f"- rows: {meta.get('rows', 'every step')}; the contact statistics are taken at every step",
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
            "| hinge | window | impacts | peak force [N] | at [ms] | p95 force [N] | in contact "
            "| max penetration [µm] |",
            "|---|---|---|---|---|---|---|---|",
        ]
    for r in rows:
        lines.append(
            f"| {r.joint} | whole run | {r.impacts} | {r.peak_force:.4g} | {r.peak_force_time * 1e3:.4g} "
            f"| {r.p95_force:.4g} | {r.contact_fraction:.1%} | {r.max_penetration * 1e6:.3g} |"
        )
        if r.has_steady_state:
            lines.append(
                f"| {r.joint} | after {startup * 1e3:.4g} ms | {r.steady_impacts} | {r.steady_peak_force:.4g} | "
                f"| {r.steady_p95_force:.4g} | {r.steady_contact_fraction:.1%} | {r.steady_max_penetration * 1e6:.3g} |"
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
    for dev in (deviation, frame_deviation):
        if dev is not None:
            lines += _deviation_section(out, result, twin, dev, frame_deviation is not None)
    if sensitivity is not None and deviation is not None:
        lines += _sensitivity_section(sensitivity, max(d.max_distance for d in (deviation, frame_deviation) if d))
    path = out / REPORT_FILE
    atomic_write_text(path, "\n".join(lines))
    return path


def _bearings(mode: str) -> str:
    """How the report names the bearings of a contact mode."""
    return "exact contact (the compiled plugin, no ring)" if mode == "exact" else f"{mode} ring bearings"


def _deviation_section(
    out: Path, result: SimulationResult, twin: SimulationResult, dev: SiteDeviation, floating: bool
) -> list[str]:
    """The deviation table and figures of one frame (the world's or the floating base's)."""
    window = f"window from t = {dev.times[0] * 1e3:.4g} ms" if dev.times[0] > result.times[0] else "the whole run"
    if dev.frame is not None:
        title = f"## Deviation of {dev.site} from the twin in the frame of its floating base {dev.frame}"
        note = (
            f"Each run's point read in its own base's frame: how the limb moves on the body, without where the base "
            f"went. Largest distance: {dev.max_distance * 1e3:.4g} mm. Per coordinate that moves ({window}):"
        )
    else:
        title = f"## Deviation of {dev.site} from the unmodified twin"
        note = f"Largest distance between the two points: {dev.max_distance * 1e3:.4g} mm. " + (
            "The model has a floating base: in the world frame this includes where the base went (the next section "
            "reads it in the base's frame). "
            if floating
            else ""
        )
        note += f"Per coordinate that moves ({window}):"
    lines = [
        title,
        "",
        note,
        "",
        "| coordinate | mean |d| [mm] | mean d [mm] | RMS [mm] | max [mm] | 90 % band ± [mm] | t p-value | F "
        "| KS p-value |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for output, s in dev.axes.items():
        lines.append(
            f"| {output} | {s.mean_deviation * 1e3:.4g} | {s.mean_signed_deviation * 1e3:.4g} "
            f"| {s.rms_deviation * 1e3:.4g} | {s.max_deviation * 1e3:.4g} | {s.band90 * 1e3:.4g} | {s.t_pvalue:.3g} "
            f"| {s.f_statistic:.4g} | {s.ks_pvalue:.3g} |"
        )
    lines.append("")
    for output, s in dev.axes.items():
        frame = "" if dev.frame is None else "base_"
        name = f"site_deviation_{frame}{output.rsplit('/', 1)[1]}.png"
        plot_deviation(result, twin, output, s, path=out / name)
        lines += [f"![{output} deviation]({name})", ""]
    return lines


def _sensitivity_section(sensitivity: Sensitivity, deviation: float) -> list[str]:
    """Whether the deviation is the play's or chaos (`clearance.run.sensitivity`)."""
    chaos = is_chaos(sensitivity, deviation)
    verdict = (
        f"**chaos rather than play**: the twin alone moves {CHAOS_SHARE:.0%} of the deviation or more when its start "
        "moves by rounding, so the deviation above cannot be put down to the play"
        if chaos
        else f"the play's: the twin alone stays below {CHAOS_SHARE:.0%} of it"
    )
    return [
        "## Chaos or play",
        "",
        f"The unmodified twin run again from a start {sensitivity.perturbation:g} rad or m off (every hinge and slide "
        f"coordinate) moves {sensitivity.site} by up to {sensitivity.max_distance * 1e3:.4g} mm against the retrofit's "
        f"{deviation * 1e3:.4g} mm: the deviation is {verdict}.",
        "",
    ]
