"""Figures and the report section of a run with backlash: the angle in the band, the stop's torque.

``backlash_<hinge>.png`` per backlashed hinge (`plot_backlash`): above, q_load - q_motor in
arc-minutes with the band's ends +-b; below, the stop's torque with each impact's onset
marked. `backlash_section` gives the report's lines (a table of `BacklashSummary` and the
figures).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from clearance.analysis.figures.canvas import draw_series, new_figure, save_png
from clearance.analysis.metrics.backlash_impacts import BacklashSummary
from clearance.results import SimulationResult

__all__ = ["ARCMIN", "backlash_section", "plot_backlash"]

ARCMIN = math.pi / 10800
"""One arc-minute [rad]."""


def plot_backlash(result: SimulationResult, summary: BacklashSummary, *, path: str | Path | None = None) -> Figure:
    """The backlash angle and the stop's torque of one hinge over the run.

    Args:
        result: the run (outputs ``backlash/<hinge>/angle`` and ``/torque``).
        summary: the hinge's `BacklashSummary` (band, impacts, peak).
        path: PNG path to save to.
    """
    hinge = summary.hinge
    t = result.times * 1e3
    angle = result.outputs[f"backlash/{hinge}/angle"] / ARCMIN
    torque = result.outputs[f"backlash/{hinge}/torque"]
    fig = new_figure(10, 5.5)
    gs = fig.add_gridspec(2, 1, left=0.09, right=0.98, top=0.9, bottom=0.1, hspace=0.12)
    a1 = fig.add_subplot(gs[0, 0])
    a2 = fig.add_subplot(gs[1, 0], sharex=a1)
    b = summary.half_width / ARCMIN
    draw_series(a1, t, angle, style={"lw": 0.8, "color": "C0", "label": "q_load - q_motor"}, reach=(-b, b))
    for v, lab in ((b, f"band ends ±{b:.3g}'"), (-b, None)):
        a1.axhline(v, color="k", ls="--", lw=0.9, label=lab)
    a1.set_ylabel("backlash angle [arcmin]")
    a1.legend(loc="upper right", fontsize=8)
    a1.grid(alpha=0.3)
    a1.tick_params(labelbottom=False)
    draw_series(a2, t, torque, style={"lw": 0.8, "color": "C3", "label": "stop torque"})
    engaged = torque > 0
    onsets = np.flatnonzero(np.concatenate([engaged[:1], engaged[1:] & ~engaged[:-1]]))
    if len(onsets):
        a2.plot(t[onsets], torque[onsets], "v", ms=4, color="k", label=f"impact onsets ({len(onsets)})")
    a2.set_xlabel("time [ms]")
    a2.set_ylabel("stop torque [N m]")
    a2.legend(loc="upper right", fontsize=8)
    a2.grid(alpha=0.3)
    fig.suptitle(
        f"backlash at {hinge}: {summary.impacts} impacts, peak stop torque {summary.peak_torque:.4g} N m "
        f"at {summary.peak_torque_time * 1e3:.4g} ms",
        fontsize=11,
    )
    if path is not None:
        save_png(fig, path)
    return fig


def backlash_section(out: str | Path, result: SimulationResult, rows: list[BacklashSummary]) -> list[str]:
    """The report's lines on the backlashed hinges, with their figures written into ``out`` ([] for none).

    Args:
        out: the run's folder (exists).
        result: the run with the backlash outputs.
        rows: each hinge's `BacklashSummary` (`backlash_summaries`).
    """
    if not rows:
        return []
    lines = [
        "## Backlash at the actuated hinges",
        "",
        "Backlash angle q_load - q_motor (the dead band's tendon); an impact is an onset of the stop's torque (the "
        "tendon limit's constraint torque for a calibrated or recipe stop, the mesh law's torque from the "
        "`clearance.backlash_stop` plugin for an exact stop; `retrofit.md` says which) at either end of the band.",
        "",
        "| hinge | b [arcmin] | angle range [arcmin] | impacts (+b / -b) | peak stop torque [N m] | at [ms] "
        "| at the stop |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r.hinge} | {r.half_width / ARCMIN:.4g} | [{r.min_angle / ARCMIN:.4g}, {r.max_angle / ARCMIN:.4g}] "
            f"| {r.impacts} ({r.impacts_upper} / {r.impacts_lower}) | {r.peak_torque:.4g} "
            f"| {r.peak_torque_time * 1e3:.4g} | {r.at_stop:.1%} |"
        )
    lines.append("")
    for r in rows:
        name = f"backlash_{r.hinge}.png"
        plot_backlash(result, r, path=Path(out) / name)
        lines += [f"![backlash at {r.hinge}]({name})", ""]
    return lines
