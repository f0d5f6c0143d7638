"""Calibrated and exact-LN contact against the LN impact reference; exact-LN cost.

    python benchmarks/calibration_accuracy.py [--timestep-us 2] [--out benchmarks/calibration_accuracy.md]

Cases (steel, R_B = 10 mm, LN with cₑ = 0.9, sphere journal / sphere segments, the calibrated
mode's default time step unless --timestep-us is given, implicitfast, impedance 1e-3; segment count by the ripple rule of `prepare`):
  A. the default slider-crank joint (c = 0.5 mm) at its cycle-median effective mass (drive
     locked; the mass `prepare` sizes with), fitted over the default range (impact
     speed/50 .. impact speed), evaluated at 0.1–5 m/s;
  B. the same joint fitted over one decade only (0.3–3 m/s);
  C. c = 0.1 mm (same mechanism), default range.
Then exact-LN at 0.1–5 m/s (worst of three directions) and its speed against
`mujoco.rollout` in sustained contact. Uses a temporary calibration cache (fits are
always fresh). Writes the Markdown table (and prints it).
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np
from _states import (
    keyframe_state,  # benchmarks/_states.py (scripts run from benchmarks/)
)

from clearance.builders import slider_crank
from clearance.contact_calibration import clearance_impact
from clearance.contact_calibration.effective_mass import cycle_effective_mass
from clearance.contact_calibration.exact_ln import exact_ln_cost, exact_ln_impact
from clearance.contact_calibration.fit import GOALS, accuracy_rows, default_speeds
from clearance.contact_calibration.report import accuracy_table
from clearance.contact_calibration.store import calibrate
from clearance.options import ModelOptions
from clearance.run.preparation import prepare

EVAL_SPEEDS = np.geomspace(0.1, 5.0, 8)  # m/s: the range for the default scenario


def _why(a: dict, c: dict) -> str:
    """Why the calibrated mode misses where it does, with this run's numbers (cases A and C)."""

    def worst(info: dict, attr: str) -> float:
        vals = [getattr(r, attr) for r in info["rows"]]
        return vals[int(np.argmax(np.abs(vals)))]

    pa, pc = a["params"], c["params"]
    fa, fc = worst(a, "peak_force_worst"), worst(c, "peak_force_worst")
    ea = [r.restitution_worst for r in a["rows"]]
    return f"""\
Three parameters (per-row stiffness k, damping b and the impedance rise ε) follow LN's peak
force, penetration and duration over the whole range; restitution is what stays off at
its ends:

- Restitution (the one miss, {max(ea):+.4f} at {a["rows"][0].speed:.3g} m/s and {min(ea):+.4f} at
  {a["rows"][-1].speed:.3g} m/s in case A, 1.7 decades of speed): N linear rows sum to a
  Hertz-like spring, but their summed damping grows like sqrt(δ)·δ̇ while LN's grows like
  δ^1.5·δ̇/δ̇⁻ (docs/mujoco_notes.md). The damping-to-spring force ratio is then about
  (b·a/(C·k))·δ̇/δ for the ring against χ·δ̇/δ̇⁻ for LN; with δ_max ∝ v^0.8 the ring's loss
  grows like v^0.2, so one constant b matches LN's 0.913 at one speed only (about 1 m/s here).
  The impedance rise does not change that: a row's damping scales with d(r)/d as its
  stiffness does with (d(r)/d)². A span of about 0.055 in e over 0.1–5 m/s means ±0.027 at
  best even for a fit that only balanced restitution; the goal of 0.02 holds over roughly
  0.3–3 m/s (one decade, case B).
- Peak force (worst {fa * 100:+.2f} % over 0.1–5 m/s in case A, {fc * 100:+.2f} % in case C): the
  ring's static force is close to F ∝ δ^1.5/sqrt(c + δ) (the engaged arc is sqrt(2δ/(c + δ))),
  not K·δ^1.5 with a fixed K, so with constant row stiffness it softens as δ/c grows: F/δ^1.5
  of `ring_force` at c = 0.5 mm, N = 144 falls 8 % from δ = 2 µm to 70 µm. The fit with k
  and b alone (FIT_VERSION 1, constant impedance) traded that against the low speeds and
  missed the top: at 2 µs −6.79 % at 5 m/s (case A, beyond the fitted 4.3 m/s) and −8.17 % at
  1.93 m/s (case C) (calibration_accuracy.md before the impedance rise, and the baseline of
  benchmarks/ring_bounded_try.md).
  The impedance rise makes each row stiffen with its own penetration r, by
  (1 − ε + ε r/c)² against r ≥ c, which undoes the softening: fitted ε = {pa.impedance_rise:.3f} (A),
  {pc.impedance_rise:.3f} (C). k is the row stiffness at full impedance (r ≥ c), so it is larger than a
  constant-impedance fit's: (1 − ε)²·k = {(1 - pa.impedance_rise) ** 2 * pa.stiffness:.4g} N/m at zero depth in
  case A against k = {pa.stiffness:.4g} N/m; the stability check takes each row at its own
  impedance at the divergence bound.
- Penetration and duration stay well inside their goals everywhere measured.

The exact-LN mode below, and the compiled exact contact (`ContactMode.EXACT`), impose the law
itself.
"""


def _misses(rows) -> str:
    """Plain-text list of the goals missed: metric, speeds, largest excess over the goal."""
    out = []
    for name, attr, goal, pct in (
        ("peak force", "peak_force_worst", GOALS["peak_force"], True),
        ("max penetration", "max_penetration_worst", GOALS["max_penetration"], True),
        ("duration", "duration_worst", GOALS["duration"], True),
        ("restitution", "restitution_worst", GOALS["restitution"], False),
    ):
        bad = [(r.speed, getattr(r, attr)) for r in rows if abs(getattr(r, attr)) > goal]
        if bad:
            worst = max(bad, key=lambda b: abs(b[1]))
            val = f"{worst[1] * 100:+.2f} %" if pct else f"{worst[1]:+.4f}"
            lim = f"{goal:.0%}" if pct else f"{goal}"
            out.append(
                f"{name} at {', '.join(f'{v:.3g}' for v, _ in bad)} m/s (worst {val} at "
                f"{worst[0]:.3g} m/s against ±{lim})"
            )
    return "; ".join(out) if out else "none"


TIMESTEP = ModelOptions(contact_mode="calibrated").timestep  # [s]; set from --timestep-us in main


def _case(title: str, mech, *, speeds=None, cycle: bool = False, eval_speeds=EVAL_SPEEDS) -> tuple[str, dict]:
    opts = ModelOptions(timestep=TIMESTEP, contact_mode="calibrated")
    prep = prepare(mech, opts)
    j = mech.clearance_joints[0]
    s, ring = prep.sizing[j.name], prep.built.rings[j.name]
    mass, mrange = s.effective_mass, None
    if cycle:
        em = cycle_effective_mass(prep.model, prep.built, mech)[j.name]
        mass, mrange = em.median, em.valid_range
    fit_speeds = speeds if speeds is not None else default_speeds(s.impact_speed)
    res, _ = calibrate(
        j.clearance, ring, opts, mass=mass, speeds=fit_speeds, mass_range=mrange, max_penetration=s.penetration_limit
    )
    wall = res.wall_time  # the fit's own time (`prepare` may have fitted the case already)
    rows = accuracy_rows(
        j.clearance, ring, opts, res.parameters, mass=mass, speeds=fit_speeds if eval_speeds is None else eval_speeds
    )
    where = (
        f"{fit_speeds[0]:.3g}–{fit_speeds[-1]:.3g} m/s (the fitted speeds)"
        if eval_speeds is None
        else f"{eval_speeds[0]:.3g}–{eval_speeds[-1]:.3g} m/s"
    )
    p = res.parameters
    head = (
        f"### {title}\n\n"
        f"c = {j.clearance.radial_clearance * 1e3:g} mm, N = {ring.segments}, effective mass "
        f"{mass:.4g} kg"
        + (f" (cycle range {mrange[0]:.4g}–{mrange[1]:.4g} kg)" if mrange else " (qpos0)")
        + f"; fitted over {fit_speeds[0]:.3g}–{fit_speeds[-1]:.3g} m/s ({len(fit_speeds)} speeds × 2 "
        f"directions) in {wall:.1f} s ({res.nfev} MuJoCo evaluations): per-row k = {p.stiffness:.5g} N/m, "
        f"b = {p.damping:.5g} N·s/m at full impedance, impedance rise ε = {p.impedance_rise:.3f} (nominal "
        f"{res.initial.stiffness:.5g}, {res.initial.damping:.5g}, constant impedance); "
        f"ω·h = {res.stability.omega_h:.3f} at {res.stability.penetration * 1e6:.0f} µm.\n\n"
        f"At the fitted speeds: {sum(r.meets_goals() for r in res.rows)} of {len(res.rows)} meet all "
        f"goals. At {where}:\n\n"
    )
    tail = f"\nGoals missed: {_misses(rows)}.\n"
    return head + accuracy_table(rows) + tail, {
        "rows": rows,
        "ring": ring,
        "joint": j,
        "mass": mass,
        "opts": opts,
        "params": p,
    }


def _fit_range_check() -> str:
    """The fit range's top speed (an estimate) against the fastest contact onset of a run."""
    from clearance.builders import rpm
    from clearance.run.simulation import simulate

    cases = {
        "default": slider_crank(),
        "c = 0.01 mm": slider_crank(radial_clearance=1e-5),
        "c = 0.1 mm": slider_crank(radial_clearance=1e-4),
        "c = 1 mm": slider_crank(radial_clearance=1e-3),
        "10,000 rpm": slider_crank(crank_speed=rpm(10000)),
        "200 rpm, gravity": slider_crank(crank_speed=rpm(200), gravity=9.81),
    }
    lines = [
        "| scenario | fit range top (estimate) [m/s] | fastest onset in one revolution [m/s] | estimate / measured |",
        "|---|---:|---:|---:|",
    ]
    for name, mech in cases.items():
        opts = ModelOptions(timestep=TIMESTEP, contact_mode="nominal", segments=144)
        prep = prepare(mech, opts)
        r = simulate(mech, duration=2 * math.pi / mech.drives[0].speed, options=opts)
        jr = r.joints["rod_slider"]
        on = jr.penetration > 0
        idx = np.flatnonzero(on[1:] & ~on[:-1]) + 1
        e = jr.eccentricity[idx]
        v = float(np.max((e * jr.eccentricity_rate[idx]).sum(axis=1) / np.hypot(*e.T)))
        est = prep.sizing["rod_slider"].impact_speed
        lines.append(f"| {name} | {est:.3g} | {v:.3g} | {est / v:.2f} |")
    return "\n".join(lines) + "\n"


def _exact(info: dict) -> str:
    j, ring, opts, m = info["joint"], info["ring"], info["opts"], info["mass"]
    lines = ["| v [m/s] | peak F err | δmax err | T err | e − e_LN |", "|---|---|---|---|---|"]
    worst = np.zeros(4)
    for v in EVAL_SPEEDS:
        ref = clearance_impact(j.clearance, mass=m, speed=float(v))
        errs = []
        for frac in (0.0, 0.5, 0.3):
            imp = exact_ln_impact(
                j.clearance, ring, opts, mass=m, speed=float(v), direction=frac * 2 * math.pi / ring.segments
            )
            errs.append(
                [
                    imp.peak_force / ref.peak_force - 1,
                    imp.max_penetration / ref.max_penetration - 1,
                    imp.duration / ref.duration - 1,
                    imp.restitution - ref.restitution,
                ]
            )
        e = np.array(errs)
        w = e[np.argmax(np.abs(e), axis=0), np.arange(4)]
        worst = np.maximum(worst, np.abs(w))
        lines.append(f"| {v:.3g} | {w[0] * 100:+.3f} % | {w[1] * 100:+.3f} % | {w[2] * 100:+.3f} % | {w[3]:+.5f} |")
    cost = exact_ln_cost(j.clearance, ring, opts, mass=m, params=info["params"], load=1000.0, nstep=20000)
    return (
        "\n".join(lines) + "\n\n"
        f"Worst over speeds and directions: peak force {worst[0] * 100:.2f} %, penetration "
        f"{worst[1] * 100:.2f} %, duration {worst[2] * 100:.2f} %, restitution {worst[3]:.5f} "
        f"(relative {worst[3] / 0.913 * 100:.3f} %).\n\n"
        f"Cost (one bearing, journal held in contact by 1000 N, N = {ring.segments}, 20 000 steps, "
        f"one thread): exact-LN Python step loop {cost.exact_steps_per_s:,.0f} steps/s; calibrated "
        f"mode with `mujoco.rollout` {cost.rollout_steps_per_s:,.0f} steps/s; exact-LN is "
        f"{cost.ratio:.1f}× slower.\n"
    )


def _full_cost(nstep: int = 20000) -> str:
    """Steps/s of the whole default slider-crank: rollout (calibrated) against exact-LN."""
    import copy

    import mujoco.rollout

    from clearance.contact_calibration.exact_ln import ExactLNContact, step_exact_ln
    from clearance.options import ContactMode

    prep = prepare(slider_crank(), ModelOptions(contact_mode=ContactMode.CALIBRATED, timestep=TIMESTEP))
    model = prep.model
    data = mujoco.MjData(model)
    s0, ctrl0 = keyframe_state(model)
    ctrl = np.tile(ctrl0, (nstep, 1))[None]
    t0 = time.perf_counter()
    mujoco.rollout.rollout(model, data, s0[None], ctrl, nstep=nstep)
    roll = nstep / (time.perf_counter() - t0)
    ex_model = copy.copy(model)
    j = prep.mechanism.clearance_joints[0]
    contact = ExactLNContact(
        ex_model,
        j.clearance,
        prep.built.rings[j.name],
        journal_geom=f"{j.name}__journal",
        bearing_site=f"{j.name}__bearing",
    )
    d2 = mujoco.MjData(ex_model)
    mujoco.mj_resetDataKeyframe(ex_model, d2, 0)
    t0 = time.perf_counter()
    run = step_exact_ln(ex_model, d2, [contact], nstep)
    exact = nstep / (time.perf_counter() - t0)
    frac = float(np.mean(run.force[:, 0] > 0))
    return (
        f"Whole default slider-crank (N = {prep.built.rings[j.name].segments}, {TIMESTEP * 1e6:g} µs, first "
        f"{nstep * TIMESTEP * 1e3:.0f} ms from the initial keyframe, contact during {frac:.0%} of the steps, one "
        f"thread): calibrated mode with `mujoco.rollout` {roll:,.0f} steps/s; exact-LN "
        f"`step_exact_ln` {exact:,.0f} steps/s ({roll / exact:.1f}× slower).\n"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--timestep-us",
        type=float,
        default=ModelOptions(contact_mode="calibrated").timestep * 1e6,
        help="MuJoCo time step [µs] (default: the calibrated mode's default)",
    )
    ap.add_argument("--out", default=str(Path(__file__).with_suffix(".md")))
    args = ap.parse_args(argv)
    global TIMESTEP
    TIMESTEP = args.timestep_us * 1e-6
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["CLEARANCE_CACHE_DIR"] = tmp
        mech = slider_crank()
        a, info = _case(
            "A. Default joint, default fit range, cycle-median effective mass (as `prepare` sizes it)", mech, cycle=True
        )
        c, _ = _case(
            "B. Default joint, fitted over one decade (0.3–3 m/s)", mech, cycle=True, speeds=np.geomspace(0.3, 3.0, 6)
        )
        d, info_c = _case(
            "C. c = 0.1 mm, default fit range", slider_crank(radial_clearance=0.1e-3), cycle=True, eval_speeds=None
        )
        ex = _exact(info) + "\n" + _full_cost()
        fit_range = _fit_range_check()
    text = (
        "# Contact calibration accuracy\n\n"
        f"Command: `python benchmarks/calibration_accuracy.py --timestep-us {args.timestep_us:g}` "
        f"({time.perf_counter() - t0:.0f} s; time step {args.timestep_us:g} µs; "
        f"MuJoCo {mujoco.__version__}, Python {platform.python_version()}, {platform.machine()}, "
        f"{os.cpu_count()} CPUs).\n\n"
        "Calibrated mode: MuJoCo's ring of N linear rows with fitted per-row stiffness k and damping b "
        "(direct-mode solref) and impedance rise ε (solimp (d(1 − ε), d, c, 0.5, 1): each row's impedance "
        "rises linearly with its penetration from d(1 − ε) to d at the clearance c, so the row force is "
        "(d(r)/d)² k r + (d(r)/d) b ṙ; `FIT_VERSION` 2) against the LN point-mass impact (K of "
        "docs/references.md, same effective mass). Goals: peak force and max penetration within 5 %, "
        "duration within 10 %, restitution within 0.02 of the LN impact's own (0.9132 at cₑ = 0.9). "
        "Cells: mean over the two impact directions (at a segment, between two), worst direction "
        "in brackets; bold = outside the goal.\n\n"
        + a
        + "\n"
        + c
        + "\n"
        + d
        + "\n## Fit range against the impacts of a run\n\n"
        "The fit range's top speed is the speed a journal gains crossing its clearance under the "
        "ideal joint's peak load, sqrt(2 F_peak c / m_eff) (`JointSizing.impact_speed`), known before "
        "any run. Against the fastest contact onset of one revolution (nominal contact, N = 144; the "
        "start-up impact is the fastest, and crosses the clearance under about that load) the "
        "ratio in the last column says how far the fitted range reaches; impacts beyond its top are "
        "extrapolated, which costs peak-force accuracy (tables above: the error grows towards the "
        "range's ends):\n\n"
        + fit_range
        + "\n## Why calibrated mode misses at the ends of the range\n\n"
        + _why(info, info_c)
        + "\n## Exact-LN mode (case A's joint and mass)\n\n"
        "LN imposed on the ring rows each step (Python step loop); worst of three directions "
        "(at a segment, between two, 0.3 pitch). Goal: 1 % on all four.\n\n"
        + ex
        + "\nTimings come from a shared machine and varied between runs (exact-LN 7.5k–21k "
        "steps/s in contact, rollout 100k–216k); compare the ratios, each taken within one run.\n"
    )
    Path(args.out).write_text(text, encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
