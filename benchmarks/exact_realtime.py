"""Accurate and real time at one step: the compiled exact contact's first impacts and cost per step.

Usage:  python benchmarks/exact_realtime.py [--out benchmarks/exact_realtime.md] [--steps-us 1 2 3 5]

For each time step: the first-impact peak contact force of the four scenarios of the issue
(default slider-crank; clearance at crank-rod; mu = 0.1; 200 rpm with gravity) against the
reference solver (0.6 ms at 5000 rpm, the first 40 ms at 200 rpm), and the cost of the default
scenario per crank revolution at 5000 rpm (one thread, model preparation apart, stepping and
readout included: `simulate_prepared` over 3 revolutions, best of 3; CPU time and wall time),
against the 12 ms of one revolution in real time. The calibrated ring at 2 us (the previous
default) runs in the same call for comparison.
"""

from __future__ import annotations

import argparse
import platform
import time

from _tables import write_keeping_reading  # benchmarks/_tables.py (scripts run from benchmarks/)

from clearance import ModelOptions
from clearance.builders import rpm, slider_crank
from clearance.reference import run_reference
from clearance.run.preparation import prepare
from clearance.run.simulation import simulate_prepared

SCENARIOS = {
    "default": (slider_crank(), 0.6e-3),
    "clearance at crank-rod": (slider_crank(clearance_at=("crank_rod",)), 0.6e-3),
    "mu = 0.1": (slider_crank(friction=0.1), 0.6e-3),
    "200 rpm, gravity": (slider_crank(crank_speed=rpm(200), gravity=9.81), 40e-3),
}
REAL_TIME_PER_REV = 60.0 / 5000.0  # s of simulated time in one revolution at 5000 rpm


def _peak(result: object, joint: str) -> float:
    return float(result.joints[joint].force_magnitude.max())  # type: ignore[attr-defined]


def _cost_per_rev(options: ModelOptions, revolutions: float = 3.0, repeat: int = 3) -> tuple[float, float]:
    """(best CPU, best wall) seconds per revolution of the default scenario, preparation apart."""
    mech = slider_crank()
    prepared = prepare(mech, options)
    period = mech.drive_period or 1.0
    best_cpu = best_wall = float("inf")
    for _ in range(repeat):
        c0, w0 = time.process_time(), time.perf_counter()
        simulate_prepared(prepared, duration=revolutions * period)
        best_cpu = min(best_cpu, (time.process_time() - c0) / revolutions)
        best_wall = min(best_wall, (time.perf_counter() - w0) / revolutions)
    return best_cpu, best_wall


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    ap.add_argument("--out", default="benchmarks/exact_realtime.md")
    ap.add_argument("--steps-us", type=float, nargs="+", default=[1.0, 2.0, 3.0, 5.0])
    args = ap.parse_args()
    refs = {}
    for name, (mech, t) in SCENARIOS.items():
        joint = mech.clearance_joints[0].name
        refs[name] = _peak(run_reference(mech, t, output_interval=1e-6), joint)
    settings = [("exact", h * 1e-6) for h in args.steps_us] + [("calibrated", 2e-6)]
    rows = []
    for mode, h in settings:
        opts = ModelOptions(contact_mode=mode, timestep=h)
        errs = []
        for name, (mech, t) in SCENARIOS.items():
            joint = mech.clearance_joints[0].name
            from clearance import simulate

            errs.append(_peak(simulate(mech, duration=t, options=opts), joint) / refs[name] - 1.0)
        cpu, wall = _cost_per_rev(opts)
        rows.append((mode, h, errs, cpu, wall))
    head = " | ".join(SCENARIOS)
    lines = [
        "# The compiled exact contact: accurate and real time at one step",
        "",
        f"Command: `python benchmarks/exact_realtime.py --steps-us {' '.join(f'{s:g}' for s in args.steps_us)}`. "
        f"Machine: {platform.machine()}, Python {platform.python_version()}; "
        f"written {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.",
        "",
        "First-impact peak contact force against the reference solver (relative error), and the cost of the "
        "default scenario per crank revolution at 5000 rpm (one thread, stepping and readout, model preparation "
        f"apart; best of 3 runs of 3 revolutions). Real time is {REAL_TIME_PER_REV * 1e3:g} ms per revolution.",
        "",
        f"| mode | h [µs] | {head} | worst | CPU per rev [ms] | wall per rev [ms] | × real time (wall) |",
        "|---|---|" + "---|" * len(SCENARIOS) + "---|---|---|---|",
    ]
    for mode, h, errs, cpu, wall in rows:
        cells = " | ".join(f"{100 * e:+.2f} %" for e in errs)
        worst = max(abs(e) for e in errs)
        lines.append(
            f"| {mode} | {h * 1e6:g} | {cells} | {100 * worst:.2f} % | {cpu * 1e3:.2f} | {wall * 1e3:.2f} | "
            f"{REAL_TIME_PER_REV / wall:.2f} |"
        )
    lines.append("")
    write_keeping_reading(args.out, "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
