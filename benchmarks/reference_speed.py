"""Reference solver speed and accuracy: wall time per crank revolution, RHS evaluations,
integrator choice, stabilisation drift and tolerance sensitivity.

Usage (writes the Markdown table committed as benchmarks/reference_speed.md):

    python benchmarks/reference_speed.py --out benchmarks/reference_speed.md

Scenarios: the default slider-crank (c = 0.5 mm, 5000 rpm, LN c_e = 0.9, mu = 0, no
gravity) and the same at 200 rpm with gravity 9.81 m/s^2. Times are wall-clock seconds of
`run_reference` (integration and output assembly), one run at a time.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from datetime import UTC, datetime

import numpy as np
import scipy

from clearance.builders import rpm, slider_crank
from clearance.reference import run_reference


def _period(mech) -> float:
    return mech.drive_period


def _run(mech, duration, repeat: int = 1, **kw):
    """(result, best wall time [s], best CPU time [s]) over ``repeat`` runs, one at a time."""
    walls, cpus = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = run_reference(mech, duration, **kw)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return res, min(walls), min(cpus)


def _energy_residual(res) -> float:
    e = res.metadata["energy"]
    kin, pot, grav = (np.array(e[k]) for k in ("kinetic", "contact_potential", "gravity_potential"))
    work = np.array(res.metadata["drive_work"]).sum(axis=1)
    return float(np.max(np.abs(kin + pot - kin[0] - pot[0] - work + grav - grav[0])) / kin.max())


def _header(*cols: str) -> list[str]:
    return ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]


def speed_table(revs: float) -> list[str]:
    rows = _header(
        "scenario",
        "revolutions",
        "wall [s]",
        "wall / rev [s]",
        "CPU / rev [s]",
        "RHS evals / rev",
        "steps / rev",
        "impacts / rev",
        "peak force [N]",
    )
    slow = slider_crank(crank_speed=rpm(200), gravity=9.81)
    for label, mech, n in (
        ("default: 5000 rpm, no gravity", slider_crank(), revs),
        ("200 rpm, gravity 9.81", slow, max(revs / 3, 1)),
    ):
        res, wall, cpu = _run(mech, n * _period(mech), repeat=3)
        md = res.metadata
        rows.append(
            f"| {label} | {n:g} | {wall:.2f} | {wall / n:.2f} | {cpu / n:.2f} | "
            f"{md['n_rhs'] / n:.0f} | "
            f"{md['n_steps'] / n:.0f} | {md['impacts']['rod_slider'] / n:.1f} | "
            f"{res.joints['rod_slider'].force_magnitude.max():.4g} |"
        )
    return rows


def method_table() -> list[str]:
    mech = slider_crank()
    period = _period(mech)
    horizon = 1.5e-3  # first impacts, before runs separate (docs/references.md, "The default scenario, measured")
    ref, _, _ = _run(mech, horizon, rtol=1e-12, method="DOP853", output_interval=1e-6)
    f_ref = ref.joints["rod_slider"].force_magnitude
    on_ref = np.array(ref.metadata["contact_onsets"]["rod_slider"])
    rows = _header(
        "method",
        "rtol",
        "wall / rev [s]",
        "CPU / rev [s]",
        "RHS evals / rev",
        "steps / rev",
        "onset time error [s]",
        "approach speed error",
        "force error, first impact",
        "force error, 1.5 ms",
    )
    first = int(0.5e-3 / 1e-6)
    for method in ("LSODA", "DOP853", "RK45", "Radau", "BDF"):
        for rtol in (1e-9, 1e-10):
            res, _, _ = _run(mech, horizon, rtol=rtol, method=method, output_interval=1e-6)
            err = np.abs(res.joints["rod_slider"].force_magnitude - f_ref) / f_ref.max()
            on = np.array(res.metadata["contact_onsets"]["rod_slider"])
            n = min(len(on), len(on_ref))
            dt_on = np.max(np.abs(on[:n, 0] - on_ref[:n, 0]))
            dv_on = np.max(np.abs(on[:n, 1] - on_ref[:n, 1]) / on_ref[:n, 1])
            full, wall, cpu = _run(mech, period, repeat=3, rtol=rtol, method=method)
            md = full.metadata
            rows.append(
                f"| {method} | {rtol:g} | {wall:.2f} | {cpu:.2f} | {md['n_rhs']:.0f} | "
                f"{md['n_steps']:.0f} | {dt_on:.1e} | {dv_on:.1e} | "
                f"{err[:first].max():.1e} | {err.max():.1e} |"
            )
    return rows


def stabilisation_table(revs: float) -> list[str]:
    rows = _header(
        "scenario",
        "stabilisation",
        "max closure violation [m]",
        "energy residual (c_e = 1)",
        "projections",
        "CPU / rev [s]",
    )
    for label, speed, g, n in (("5000 rpm", 5000, 0.0, revs), ("200 rpm, gravity", 200, 9.81, max(revs / 3, 1))):
        mech = slider_crank(crank_speed=rpm(speed), gravity=g, restitution=1.0)
        for stab in ("baumgarte", "projection", "none"):
            res, _, cpu = _run(mech, n * _period(mech), stabilisation=stab, track_work=True)
            rows.append(
                f"| {label}, {n:g} rev | {stab} | {res.closure_violation.max():.2e} | "
                f"{_energy_residual(res):.1e} | {res.metadata['n_projections']} | {cpu / n:.2f} |"
            )
    return rows


def drift_table() -> list[str]:
    rows = _header(
        "run", "method", "stabilisation", "closure, first 10 % [m]", "closure, last 10 % [m]", "projections", "CPU [s]"
    )
    period = 2 * math.pi / rpm(5000)
    for label, mech, revs in (
        ("ideal slider-crank, 100 rev", slider_crank(clearance_at=()), 100),
        ("default scenario, 10 rev", slider_crank(), 10),
    ):
        for method in ("LSODA", "DOP853"):
            for stab in ("none", "baumgarte", "projection"):
                res, _, cpu = _run(mech, revs * period, method=method, stabilisation=stab, output_interval=1e-4)
                cv = res.closure_violation
                k = len(cv) // 10
                rows.append(
                    f"| {label} | {method} | {stab} | {cv[:k].max():.1e} | {cv[-k:].max():.1e} | "
                    f"{res.metadata['n_projections']} | {cpu:.2f} |"
                )
    return rows


def tolerance_table() -> list[str]:
    mech = slider_crank()
    rows = _header("rtol", "first-impact peak force [N] (1.5 ms, 1 us output)", "change vs previous rtol")
    prev = None
    for rtol in (1e-8, 1e-9, 1e-10, 1e-11):
        res, _, _ = _run(mech, 1.5e-3, rtol=rtol, output_interval=1e-6)
        peak = res.joints["rod_slider"].force_magnitude.max()
        change = "" if prev is None else f"{abs(peak - prev) / peak:.1e}"
        rows.append(f"| {rtol:g} | {peak:.6f} | {change} |")
        prev = peak
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--revolutions", type=float, default=3.0, help="revolutions at 5000 rpm (default 3)")
    ap.add_argument("--out", help="write the Markdown report here (default: print)")
    args = ap.parse_args(argv)
    cmd = "python benchmarks/reference_speed.py " + " ".join(sys.argv[1:] if argv is None else argv)
    lines = [
        "# Reference solver speed",
        "",
        f"Command: `{cmd.strip()}`",
        "",
        f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; Python "
        f"{platform.python_version()}, NumPy {np.__version__}, SciPy {scipy.__version__}; "
        f"{datetime.now(UTC):%Y-%m-%d %H:%M} UTC. Measured on a "
        "shared machine with other work running: expect +-30 % scatter in wall times.",
        "",
        "Defaults: LSODA, rtol 1e-9, coordinate projection, output every 1e-5 s. Wall and CPU",
        "times are the best of 3 runs (CPU time is less sensitive to other load).",
        "",
        "## Wall time per crank revolution",
        "",
        *speed_table(args.revolutions),
        "",
        "## Integrator choice",
        "",
        "Default scenario. Wall time, calls and steps over one revolution; errors over the first",
        "1.5 ms (before runs separate) against DOP853 at rtol 1e-12: contact onset times and",
        "approach speeds (max over the onsets), contact force (max |error| / peak) over the first",
        "impact (0-0.5 ms) and over 1.5 ms.",
        "",
        *method_table(),
        "",
        "## Constraint drift: Baumgarte (alpha = beta = 5 1/s) against coordinate projection",
        "",
        "Largest ideal-joint closure error over the first and the last tenth of long runs",
        "(5000 rpm, rtol 1e-9):",
        "",
        *drift_table(),
        "",
        "Energy balance with c_e = 1, mu = 0 (residual |E - E0 - W_drive - W_gravity| / max T):",
        "",
        *stabilisation_table(args.revolutions),
        "",
        "## Tolerance sensitivity of the first-impact peak (default scenario)",
        "",
        *tolerance_table(),
        "",
        "## Choices made from these tables",
        "",
        "- Integrator: LSODA (Adams, switching to BDF where stiff). At rtol 1e-9 it places",
        "  contact onsets and approach speeds more accurately than DOP853 at 1e-9 or 1e-10,",
        "  in fewer calls and about the same time; the implicit Radau and BDF cost 3-5x more.",
        "- Stabilisation: coordinate projection. Baumgarte with alpha = beta = 5 1/s (the values of",
        "  Flores and Ambrósio 2004) has a 0.2 s time constant, slow against a 12 ms revolution: it only",
        "  slows the drift. Projection bounds the closure error at ~2e-9 m with a handful of",
        "  projections per run, at the same cost. Energy balances are alike for all three.",
        "",
    ]
    text = "\n".join(lines)
    if args.out:
        with open(args.out, "w", encoding="utf-8") as fh:
            fh.write(text)
    print(text)


if __name__ == "__main__":
    main()
