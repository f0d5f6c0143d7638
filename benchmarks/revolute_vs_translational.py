"""Revolute against translational play in the same slider-crank at equal clearance.

The catalogue slider-crank (`clearance.builders.slider_crank`: crank 50 mm, rod 120 mm, the
catalogue's speeds) with play at one joint: the rod-slider pin (a revolute clearance joint:
a journal of radius 10 mm in its bearing, radial clearance c) or the slider in its guide (a
translational clearance joint: a 40 by 20 mm block in a guide 2c higher, c on each side). The
same c at both, the exact contact (the compiled plugin), 3 revolutions at the default step.
Which costs the output, the slider's position, more: its deviation from the ideal
mechanism's (mean |dx| per revolution after the first, RMS and largest over the same
window), beside each joint's contact statistics. Each cell is also run at half the step, so
the comparison is shown not to be the step's. Writes revolute_vs_translational.md,
revolute_vs_translational.png and revolute_vs_translational.json (the measures per cell, read
by docs/study/study_report.py) next to this file.

    python benchmarks/revolute_vs_translational.py
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from _clock import clock, since  # benchmarks/_clock.py (scripts run from benchmarks/)
from _tables import write_keeping_reading

from clearance import ModelOptions, simulate
from clearance.analysis.metrics.statistics import deviation_statistics, per_cycle_mean_deviation
from clearance.analysis.metrics.summary import joint_summary
from clearance.builders import slider_crank
from clearance.options import ContactMode
from clearance.results import SimulationResult, atomic_write_text
from clearance.run.simulation import default_duration

HERE = Path(__file__).resolve().parent
JOINTS = ("rod_slider", "slider_guide")
"""The revolute clearance joint (the rod-slider pin) and the translational one (the slider in its guide)."""
CLEARANCES_MM = (0.05, 0.1, 0.25, 0.5)
SPEEDS_RPM = (1000.0, 3000.0, 5000.0)
REVOLUTIONS = 3
OUTPUT = "slider_x"
STIFF_CLEARANCES_MM = (0.1, 0.5)
STIFF_RPM = 5000.0
GUIDE_STIFFNESSES = (1e10, 1e11)
"""The stiffer-guide check: the catalogue's corner stiffness and ten times it [N/m^1.5]."""
FIGURE_CELL = (0.1, 5000.0)
"""The cell whose deviations are drawn over time (c [mm], speed [rpm])."""


def run(
    joint: str, c_mm: float, rpm: float, timestep: float = 0.0, **builder: float
) -> tuple[SimulationResult, SimulationResult]:
    """The run with play at ``joint`` and its ideal twin's (exact contact; 0: the default step)."""
    mech = slider_crank(clearance_at=(joint,), radial_clearance=c_mm * 1e-3, crank_speed=rpm * np.pi / 30, **builder)
    options = ModelOptions(contact_mode=ContactMode.EXACT, timestep=timestep)
    duration = default_duration(mech, REVOLUTIONS)
    return simulate(mech, duration=duration, options=options), simulate(
        mech.ideal_twin(), duration=duration, options=options
    )


def measures(joint: str, rpm: float, res: SimulationResult, ideal: SimulationResult) -> dict[str, float]:
    """Deviation of the output after the first revolution [m], and the joint's steady contact statistics."""
    period = 60.0 / rpm
    cycles = per_cycle_mean_deviation(res, ideal, OUTPUT, period=period, skip=period)
    stats = deviation_statistics(res, ideal, OUTPUT, skip=period)
    s = joint_summary(res, joint, startup=period)
    return {
        "mean": float(cycles.mean()),
        "rms": stats.rms_deviation,
        "max": stats.max_deviation,
        "peak_force": s.steady_peak_force,
        "in_contact": s.steady_contact_fraction,
        "impacts": float(s.steady_impacts),
        "timestep": float(res.metadata["time_step"]),
    }


def main() -> None:
    """Run the grid, write the table and the figure."""
    start, load = clock(), os.getloadavg()[0]
    rows = [
        "| c [mm] | speed [rpm] | play at | mean dev. [µm] | RMS dev. [µm] | max dev. [µm] | mean dev. / c | "
        "same at h/2 | peak force [N] | in contact | impacts |",
        "|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    ratio_rows, ratios, steps, cells = [], {}, set(), []
    for c_mm in CLEARANCES_MM:
        for rpm in SPEEDS_RPM:
            m, m_half = {}, {}
            for joint in JOINTS:
                res, ideal = run(joint, c_mm, rpm)
                m[joint] = measures(joint, rpm, res, ideal)
                h = m[joint]["timestep"]
                steps.add(h)
                half = m_half[joint] = measures(joint, rpm, *run(joint, c_mm, rpm, timestep=h / 2))
                mj = m[joint]
                rows.append(
                    f"| {c_mm:g} | {rpm:g} | {joint} | {mj['mean'] * 1e6:.3g} | {mj['rms'] * 1e6:.3g} | "
                    f"{mj['max'] * 1e6:.3g} | {mj['mean'] / (c_mm * 1e-3):.3f} | "
                    f"{half['mean'] * 1e6:.3g} ({half['mean'] / mj['mean'] - 1:+.1%}) | {mj['peak_force']:.4g} | "
                    f"{mj['in_contact']:.1%} | {mj['impacts']:.0f} |"
                )
            r = m["rod_slider"]["mean"] / m["slider_guide"]["mean"]
            ratios[(c_mm, rpm)] = r
            cells.append({"clearance_mm": c_mm, "rpm": rpm, "at_step": m, "at_half_step": m_half})
            ratio_rows.append(
                f"| {c_mm:g} | {rpm:g} | {r:.3g} | "
                f"{m_half['rod_slider']['mean'] / m_half['slider_guide']['mean']:.3g} | "
                f"{m['rod_slider']['max'] / m['slider_guide']['max']:.3g} |"
            )
            print(f"c = {c_mm:g} mm, {rpm:g} rpm: revolute / translational mean deviation {r:.3g}", flush=True)
    stiff_rows = []
    for c_mm in STIFF_CLEARANCES_MM:
        for k in GUIDE_STIFFNESSES:
            res, ideal = run("slider_guide", c_mm, STIFF_RPM, guide_stiffness=k)
            g = measures("slider_guide", STIFF_RPM, res, ideal)
            pin = next(x["at_step"]["rod_slider"] for x in cells if x["clearance_mm"] == c_mm and x["rpm"] == STIFF_RPM)
            stiff_rows.append(
                f"| {c_mm:g} | {k:.0e} | {g['mean'] / (c_mm * 1e-3):.3f} | {g['max'] / (c_mm * 1e-3):.3f} | "
                f"{res.sliders['slider_guide'].corner_penetration.max() * 1e6:.3g} | {pin['mean'] / g['mean']:.3g} |"
            )
    cpu, wall = since(start)
    figure(ratios)
    step = ", ".join(f"{h * 1e6:g} µs" for h in sorted(steps))
    text = "\n".join(
        [
            "# Revolute against translational play in the slider-crank, at equal clearance",
            "",
            'Generated by `python benchmarks/revolute_vs_translational.py` (the text from "Reading" on is '
            "written by hand).",
            "",
            "The catalogue slider-crank (`slider_crank`: crank 50 mm, rod 120 mm, no gravity, no friction, "
            "Lankarani-Nikravesh law with restitution 0.9) with play at one joint: the rod-slider pin "
            "(`rod_slider`, a revolute clearance joint: journal radius 10 mm, steel on steel) or the slider in "
            "its guide (`slider_guide`, a translational clearance joint: a 40 by 20 mm block, corner "
            "stiffness 1e10 N/m^1.5, c on each side). The same c at both, exact contact (the compiled "
            f"plugin), {REVOLUTIONS} revolutions at the default step ({step}), constant crank speed. The output is "
            "the slider's position `slider_x`: its deviation from the ideal mechanism's over revolutions 2 "
            "and 3 (the first is start-up): the mean over revolutions of the mean |dx| (as `clearance rank` "
            'scores it), the RMS and the largest |dx|. "same at h/2": the mean deviation at half the step '
            "(its change in brackets). Contact statistics are the played joint's, over the same window "
            "(a slider: its deepest corner, the net force on it).",
            "",
            *rows,
            "",
            "## Revolute over translational",
            "",
            "| c [mm] | speed [rpm] | mean dev. ratio | the same at h/2 | max dev. ratio |",
            "|---:|---:|---:|---:|---:|",
            *ratio_rows,
            "",
            f"## A stiffer guide ({STIFF_RPM:g} rpm)",
            "",
            "The guide's corners ten times stiffer (K in N/m^1.5; the journal's Hertz stiffness is 6.6e10 to "
            "2.1e11 from c = 0.5 to 0.05 mm): the guide's play alone, its deviation over c, its corners' deepest "
            "penetration, and the pin's mean deviation (table above) over it.",
            "",
            "| c [mm] | guide K | mean dev. / c | max dev. / c | deepest corner [µm] | pin / guide mean dev. |",
            "|---:|---:|---:|---:|---:|---:|",
            *stiff_rows,
            "",
            "![revolute against translational play](revolute_vs_translational.png)",
            "",
            f"{2 * 2 * len(ratios) + len(stiff_rows)} runs with their ideal twins in {wall:.0f} s wall ({cpu:.0f} s CPU) on 2 "
            f"shared cores, load {load:.1f} at the start.",
            "",
        ]
    )
    write_keeping_reading(HERE / "revolute_vs_translational.md", text)
    # the measures per cell, for docs/study/study.md's section (deviations in m, forces in N)
    atomic_write_text(HERE / "revolute_vs_translational.json", json.dumps({"cells": cells}, indent=1) + "\n")


def figure(ratios: dict[tuple[float, float], float]) -> None:
    """Left: the output's deviation over time at `FIGURE_CELL`; right: the mean-deviation ratio per cell."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.6))
    c_mm, rpm = FIGURE_CELL
    for joint, color in zip(JOINTS, ("C0", "C3"), strict=True):
        res, ideal = run(joint, c_mm, rpm)
        dx = res.outputs[OUTPUT] - np.interp(res.times, ideal.times, ideal.outputs[OUTPUT])
        kind = "revolute (pin)" if joint == "rod_slider" else "translational (guide)"
        ax.plot(res.times * 1e3, dx * 1e6, color=color, lw=0.8, label=f"{joint}: {kind}")
    ax.set(
        xlabel="time [ms]",
        ylabel="slider_x - ideal [µm]",
        title=f"slider-crank, c = {c_mm:g} mm at one joint, {rpm:g} rpm",
    )
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=8)
    for rpm_i, marker in zip(SPEEDS_RPM, ("o", "s", "^"), strict=True):
        bx.plot(CLEARANCES_MM, [ratios[(c, rpm_i)] for c in CLEARANCES_MM], marker=marker, label=f"{rpm_i:g} rpm")
    bx.axhline(1.0, color="0.5", lw=0.8)
    bx.set(
        xscale="log",
        yscale="log",
        xlabel="clearance c [mm] (the same at either joint)",
        ylabel="mean deviation: pin play / guide play",
        title="which costs the output more (> 1: the pin's play)",
    )
    bx.set_xticks(CLEARANCES_MM, [f"{c:g}" for c in CLEARANCES_MM])
    bx.set_yticks([1, 2, 4, 8], ["1", "2", "4", "8"])
    bx.minorticks_off()
    bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "revolute_vs_translational.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
