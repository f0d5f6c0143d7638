"""Convergence of every contact mode and law with the time step, against the reference solver.

Usage:  python benchmarks/convergence.py [--out benchmarks/convergence.md] [--cache DIR]
                                         [--laws LAW ...] [--steps-us 5 4 3 2 1 0.5 0.25 0.125]

A numerical treatment is right when its error against the reference shrinks with the step at
its order, on a mechanism. For the exact (compiled) contact and each contact law, with and
without friction (μ = 0 and 0.1), at each step:

* the first impact of the scenarios of `benchmarks/exact_realtime.md` (default slider-crank,
  clearance at crank–rod, 200 rpm with gravity; "μ = 0.1" is the default with friction): peak
  contact-force magnitude, approach speed (the plugin's record against the reference's) and
  onset time (δ crossing 0, interpolated linearly in both), relative errors (onset in ns);
* the c = 0.1 mm slider-crank (5000 rpm, journal centred at t = 0): the slider's error over
  0–14.9 ms, max |x − x_ref| / max |x_ref − x_ideal| (the latter over the 3 revolutions), and
  the same over the whole 3 revolutions (a convergence check: a grazing lift-off at 14.97 ms is
  hypersensitive to the state).

The observed order is the least-squares slope of log error against log step over the steps whose
error exceeds twice the reference's own floor (the same error measure between the reference at
rtol 1e-9 and at 1e-11). The ring modes (calibrated, nominal; LN, no friction) converge to
their fitted model, not to the reference: their c = 0.1 mm window error is given against
themselves at h/4, with their error against the reference (the model error) beside it. Last, the
c = 0.1 mm statistics (impacts per revolution, contact fraction, p95 force; `joint_summary`'s
definitions) of the exact contact at each step against the reference's.

Reference runs are cached in ``--cache`` (a run takes 1–5 s; about 60 are needed).
"""

from __future__ import annotations

import argparse
import platform
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import mujoco
import numpy as np
from _tables import write_keeping_reading  # benchmarks/_tables.py (scripts run from benchmarks/)

from clearance import ModelOptions, simulate
from clearance.analysis.metrics.summary import joint_summary
from clearance.builders import rpm, slider_crank
from clearance.contact_calibration.laws import UnverifiedLawWarning
from clearance.contact_plugin.attributes import sensor_offsets
from clearance.model import CYLINDRICAL_LAWS, ContactLaw, Mechanism
from clearance.reference import ReferenceSystem, run_reference, simulate_system
from clearance.results import SimulationResult
from clearance.run.preparation import exact_contact_name, prepare
from clearance.run.simulation import start_data

DEFAULT_LAWS = [law.value for law in ContactLaw if law is not ContactLaw.IMPACT and law not in CYLINDRICAL_LAWS]
"""The point laws. IMPACT needs C_max and d_max, which a mechanism's `Clearance` does not carry
(simulate refuses it); the cylindrical laws are compared law by law in cylindrical_laws.md."""
STEPS_US = (5.0, 4.0, 3.0, 2.0, 1.0, 0.5, 0.25, 0.125)
RING_STEPS_US = (5.0, 4.0, 3.0, 2.0, 1.0, 0.5)
WINDOW = 14.9e-3  # s: the c = 0.1 mm case is regular before its grazing lift-off at 14.97 ms
FRICTION = 0.1
RTOLS = (1e-9, 1e-11)  # the reference, and the reference of the reference (its floor)
SHIFT = 10e-9  # m: the journal moved along x at t = 0, to measure how sensitive a case is

Builder = Callable[[ContactLaw, float], Mechanism]
SCENARIOS: dict[str, tuple[Builder, float]] = {
    "default": (lambda law, mu: slider_crank(law=law, friction=mu), 0.6e-3),
    "clearance at crank-rod": (lambda law, mu: slider_crank(law=law, friction=mu, clearance_at=("crank_rod",)), 0.6e-3),
    "200 rpm, gravity": (lambda law, mu: slider_crank(law=law, friction=mu, crank_speed=rpm(200), gravity=9.81), 40e-3),
}


def _c01(law: ContactLaw, mu: float) -> Mechanism:
    return slider_crank(radial_clearance=0.1e-3, law=law, friction=mu)


class References:
    """Reference runs, computed once and kept in a folder."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        folder.mkdir(parents=True, exist_ok=True)

    def get(
        self, key: str, mech: Mechanism, duration: float, rtol: float, interval: float, shift: float = 0.0
    ) -> SimulationResult:
        """The reference run of ``mech`` (its journal moved by ``shift`` [m] along x at t = 0)."""
        name = f"{key}_rtol{rtol:g}" + (f"_shift{shift:g}" if shift else "")
        path = self.folder / name.replace(".", "p")  # no dot: the file's suffix follows
        if path.with_suffix(".json").exists():
            return SimulationResult.load(path)
        if shift:
            system = ReferenceSystem(mech)
            q0, qd0 = system.initial_state()
            q0[3 * system.link_names.index("slider")] -= shift  # the journal sits on the slider
            res = simulate_system(system, q0, qd0, duration, output_interval=interval, rtol=rtol)
        else:
            res = run_reference(mech, duration, output_interval=interval, rtol=rtol)
        res.save(path, compress=True)
        return res


def _first_onset(times: np.ndarray, pen: np.ndarray) -> tuple[int, float]:
    """(index of the first row in contact, onset time by linear interpolation [s])."""
    k = int(np.argmax(pen > 0))
    if pen[k] <= 0 or k == 0:
        raise RuntimeError("no impact in the window")
    return k, float(times[k - 1] + (times[k] - times[k - 1]) * pen[k - 1] / (pen[k - 1] - pen[k]))


def _first_impact_reference(ref: SimulationResult, joint: str) -> tuple[float, float, float]:
    """(peak force magnitude [N], approach speed [m/s], onset time [s]) of the first impact."""
    jr = ref.joints[joint]
    k, _ = _first_onset(ref.times, jr.penetration)
    end = k + int(np.argmax(jr.penetration[k:] <= 0))
    t_on, v_in = ref.metadata["contact_onsets"][joint][0]
    return float(jr.force_magnitude[k:end].max()), float(v_in), float(t_on)


def _first_impact_mujoco(mech: Mechanism, h: float, duration: float) -> tuple[float, float, float]:
    """The same from the exact contact's sensor rows at step ``h``."""
    prepared = prepare(mech, ModelOptions(contact_mode="exact", timestep=h))
    model = prepared.model
    data = start_data(model)  # the run's own start (velocities at -h/2)
    state = np.empty(mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    nstep = int(round(duration / h))
    _, sens = mujoco.rollout.rollout(model, data, state[None], data.ctrl.copy()[None, None], nstep=nstep)
    sens = sens[0]
    o = sensor_offsets(model, exact_contact_name(mech.clearance_joints[0].name))
    pen = sens[:, o["penetration"]]
    force = np.hypot(sens[:, o["normal_force"]], sens[:, o["tangential_force"]])
    k, t_on = _first_onset(np.arange(nstep) * h, pen)
    end = k + int(np.argmax(pen[k:] <= 0))
    return float(force[k:end].max()), float(sens[k, o["approach_speed"]]), t_on


def _slider_error(run: SimulationResult, ref: SimulationResult, effect: float) -> tuple[float, float]:
    """(window error, whole-run error) of the slider against ``ref``, in units of ``effect``."""
    t = ref.times
    keep = t <= run.times[-1]  # a row held past the run's end would read the slider's speed as error
    x = np.interp(t[keep], run.times, run.outputs["slider_x"])
    err = np.abs(x - ref.outputs["slider_x"][keep]) / effect
    return float(err[t[keep] <= WINDOW].max()), float(err.max())


def observed_order(steps: Sequence[float], errors: Sequence[float], floor: float) -> float:
    """Least-squares slope of log error against log step over the errors above twice ``floor``
    (NaN with fewer than two)."""
    pts = [(h, e) for h, e in zip(steps, errors) if np.isfinite(e) and abs(e) > 2 * floor]
    if len(pts) < 2:
        return float("nan")
    hs, es = np.array(pts).T
    return float(np.polyfit(np.log(hs), np.log(np.abs(es)), 1)[0])


def _pct(x: float) -> str:
    return "—" if not np.isfinite(x) else f"{100 * x:+.3f} %"


def _law_section(law: ContactLaw, steps: Sequence[float], refs: References, effect: float) -> list[str]:
    """A law's table: first impacts and the c = 0.1 mm errors at each step, with and without friction."""
    cols: dict[str, list[float]] = {}
    floors: dict[str, float] = {}
    sensitivity: dict[str, tuple[float, float]] = {}
    for mu in (0.0, FRICTION):
        tag = "μ = 0" if mu == 0 else f"μ = {mu:g}"
        peak, speed, onset = [], [], []
        fl_peak = fl_speed = fl_onset = 0.0
        per_scenario = []
        for name, (build, dur) in SCENARIOS.items():
            mech = build(law, mu)
            joint = mech.clearance_joints[0].name
            key = f"{law.value}_mu{mu:g}_{name.replace(' ', '_').replace(',', '')}"
            interval = 1e-7 if dur < 1e-3 else 1e-6
            r9, r11 = (_first_impact_reference(refs.get(key, mech, dur, rt, interval), joint) for rt in RTOLS)
            fl_peak = max(fl_peak, abs(r9[0] / r11[0] - 1))
            fl_speed = max(fl_speed, abs(r9[1] / r11[1] - 1))
            fl_onset = max(fl_onset, abs(r9[2] - r11[2]))
            per_scenario.append((mech, dur, r11))
        for h in steps:
            worst = [0.0, 0.0, 0.0]
            for mech, dur, (rp, rv, rt) in per_scenario:
                p, v, t = _first_impact_mujoco(mech, h * 1e-6, dur)
                for i, e in enumerate((p / rp - 1, v / rv - 1, t - rt)):
                    worst[i] = e if abs(e) > abs(worst[i]) else worst[i]
            peak.append(worst[0])
            speed.append(worst[1])
            onset.append(worst[2])
        cols[f"peak {tag}"], floors[f"peak {tag}"] = peak, fl_peak
        cols[f"v_in {tag}"], floors[f"v_in {tag}"] = speed, fl_speed
        cols[f"onset {tag}"], floors[f"onset {tag}"] = onset, fl_onset
        mech = _c01(law, mu)
        key = f"{law.value}_mu{mu:g}_c01"
        dur = 3 * (mech.drive_period or 0.0)
        ref9, ref11 = (refs.get(key, mech, dur, rt, 1e-6) for rt in RTOLS)
        win_floor, whole_floor = _slider_error(ref9, ref11, effect)
        moved = refs.get(key, mech, dur, RTOLS[1], 1e-6, shift=SHIFT)
        sensitivity[tag] = _slider_error(moved, ref11, effect)
        win, whole = [], []
        for h in steps:
            try:
                run = simulate(
                    mech, duration=dur + h * 1e-6, options=ModelOptions(contact_mode="exact", timestep=h * 1e-6)
                )
                w, a = _slider_error(run, ref11, effect)
            except Exception as err:  # a step the contact refuses or a run that diverges: a row says so
                print(f"  {law.value} {tag} h = {h:g} us: {type(err).__name__}: {err}")
                w = a = float("nan")
            win.append(w)
            whole.append(a)
        cols[f"c = 0.1 mm, 0–14.9 ms, {tag}"], floors[f"c = 0.1 mm, 0–14.9 ms, {tag}"] = win, win_floor
        cols[f"c = 0.1 mm, whole run, {tag}"], floors[f"c = 0.1 mm, whole run, {tag}"] = whole, whole_floor
    names = list(cols)
    lines = [
        f"### {law.value}",
        "",
        "| h [µs] | " + " | ".join(names) + " |",
        "|---|" + "---|" * len(names),
    ]
    for i, h in enumerate(steps):
        cells = [f"{1e9 * cols[n][i]:+.1f} ns" if n.startswith("onset") else _pct(cols[n][i]) for n in names]
        lines.append(f"| {h:g} | " + " | ".join(cells) + " |")
    floor_cells = [f"{1e9 * floors[n]:.2g} ns" if n.startswith("onset") else f"{100 * floors[n]:.2g} %" for n in names]
    lines.append("| reference floor | " + " | ".join(floor_cells) + " |")
    orders = [observed_order(steps, cols[n], floors[n]) for n in names]
    lines.append("| observed order | " + " | ".join("—" if not np.isfinite(o) else f"{o:.2f}" for o in orders) + " |")
    lines.append("")
    lines.append(
        "Sensitivity of the c = 0.1 mm case under this law (the reference against itself with the journal moved "
        f"{SHIFT * 1e9:g} nm at t = 0): "
        + "; ".join(
            f"{tag}: {100 * w:.2g} % over 0–14.9 ms, {100 * a:.2g} % over the run"
            for tag, (w, a) in sensitivity.items()
        )
        + ". Where it is not small against the errors above, the case is not regular under the law and its "
        "pointwise error cannot converge at these steps."
    )
    lines.append("")
    return lines


def _ring_section(steps: Sequence[float], refs: References, effect: float) -> list[str]:
    mech = _c01(ContactLaw.LANKARANI_NIKRAVESH, 0.0)
    dur = 3 * (mech.drive_period or 0.0)
    ref = refs.get("lankarani_nikravesh_mu0_c01", mech, dur, RTOLS[1], 1e-6)
    lines = [
        "## The ring modes against themselves (LN, μ = 0, c = 0.1 mm)",
        "",
        "| mode | h [µs] | 0–14.9 ms against itself at h/4 | whole run against itself at h/4 | "
        "0–14.9 ms against the reference (model error) | wall [s] |",
        "|---|---|---|---|---|---|",
    ]
    notes = []
    for mode in ("calibrated", "nominal"):
        selves = []
        for h in steps:
            c0 = time.perf_counter()
            try:
                runs = [
                    simulate(mech, duration=dur + s * 1e-6, options=ModelOptions(contact_mode=mode, timestep=s * 1e-6))
                    for s in (h, h / 4)
                ]
                own_w, own_a = _slider_error(runs[0], runs[1], effect)
                model_w, _ = _slider_error(runs[0], ref, effect)
            except Exception as err:
                print(f"  {mode} h = {h:g} us: {type(err).__name__}: {err}")
                own_w = own_a = model_w = float("nan")
            selves.append(own_w)
            lines.append(
                f"| {mode} | {h:g} | {_pct(own_w)} | {_pct(own_a)} | {_pct(model_w)} | {time.perf_counter() - c0:.1f} |"
            )
        order = observed_order(steps, selves, 0.0)
        lines.append(f"| {mode} | observed order | {order:.2f} | | | |")
        fine = ModelOptions(contact_mode=mode, timestep=steps[-1] / 4 * 1e-6)
        runs = [
            simulate(mech, duration=dur + fine.timestep, options=fine, initial_eccentricity=e)
            for e in (None, {"rod_slider": (SHIFT, 0.0)})
        ]
        w, a = _slider_error(runs[1], runs[0], effect)
        notes.append(
            f"{mode}: {100 * w:.2g} % over 0–14.9 ms and {100 * a:.2g} % over the run at {fine.timestep * 1e6:g} µs"
        )
    lines.append("")
    lines.append(
        f"Sensitivity of each ring model (itself with the journal moved {SHIFT * 1e9:g} nm at t = 0): "
        + "; ".join(notes)
        + "."
    )
    lines.append("")
    return lines


def _statistics_section(steps: Sequence[float], refs: References) -> list[str]:
    mech = _c01(ContactLaw.LANKARANI_NIKRAVESH, 0.0)
    period = mech.drive_period or 0.0
    ref = refs.get("lankarani_nikravesh_mu0_c01", mech, 3 * period, RTOLS[1], 1e-6)
    s_ref = joint_summary(ref, "rod_slider")
    lines = [
        "## Statistics of the c = 0.1 mm run (exact, LN, μ = 0), 3 revolutions",
        "",
        "| h [µs] | impacts per revolution | contact fraction | p95 force [N] |",
        "|---|---|---|---|",
        f"| reference | {s_ref.impacts / 3:.2f} | {s_ref.contact_fraction:.4f} | {s_ref.p95_force:.1f} |",
    ]
    for h in steps:
        run = simulate(mech, duration=3 * period, options=ModelOptions(contact_mode="exact", timestep=h * 1e-6))
        s = joint_summary(run, "rod_slider")
        lines.append(f"| {h:g} | {s.impacts / 3:.2f} | {s.contact_fraction:.4f} | {s.p95_force:.1f} |")
    lines.append("")
    return lines


def _slider_section() -> list[str]:
    """The compiled slider-guide contact's order on the published slider-crank with play in its guide
    (`translational_clearance_mujoco.convergence_rows`: its first episode, 0-20 ms)."""
    import translational_clearance_mujoco as guide  # benchmarks/translational_clearance_mujoco.py

    from clearance.builders.scenario import load_scenario

    return [
        "## The slider in its guide (the compiled slider-guide contact)",
        "",
        "The Flores, Leine and Glocker (2010) slider-crank with play in its guide "
        f"(`{guide.SCENARIO.relative_to(Path(__file__).resolve().parents[1])}`), the exact contact against the "
        "reference over its first episode (0-20 ms): the largest |across - reference's| / c of the slider's path "
        "across the guide, the first impact's peak corner force (relative) and the tilt rate at 4 ms (relative); "
        "its own reference floor (rtol 1e-9 against 1e-11) and observed order as above.",
        "",
        *guide.convergence_rows(load_scenario(guide.SCENARIO)),
        "",
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    ap.add_argument("--out", default="benchmarks/convergence.md")
    ap.add_argument("--cache", default=str(Path.home() / ".cache" / "clearance" / "convergence"))
    ap.add_argument("--laws", nargs="+", default=DEFAULT_LAWS)
    ap.add_argument("--steps-us", type=float, nargs="+", default=list(STEPS_US))
    args = ap.parse_args()
    warnings.simplefilter("ignore", UnverifiedLawWarning)  # Hu-Guo: its table row says [recalled]
    t0 = time.perf_counter()
    refs = References(Path(args.cache))
    mech = _c01(ContactLaw.LANKARANI_NIKRAVESH, 0.0)
    dur = 3 * (mech.drive_period or 0.0)
    ideal = refs.get("ideal_c01", mech.ideal_twin(), dur, RTOLS[1], 1e-6)
    ref = refs.get("lankarani_nikravesh_mu0_c01", mech, dur, RTOLS[1], 1e-6)
    effect = float(
        np.max(np.abs(ref.outputs["slider_x"] - np.interp(ref.times, ideal.times, ideal.outputs["slider_x"])))
    )
    body: list[str] = ["## The exact contact, law by law", ""]
    for name in args.laws:
        print(f"law {name}", flush=True)
        body += _law_section(ContactLaw(name), args.steps_us, refs, effect)
    print("rings", flush=True)
    body += _ring_section(RING_STEPS_US, refs, effect)
    print("statistics", flush=True)
    body += _statistics_section(args.steps_us, refs)
    print("slider in its guide", flush=True)
    body += _slider_section()
    head = [
        "# Convergence with the time step: every contact mode and law against the reference",
        "",
        f"Command: `python benchmarks/convergence.py{'' if args.laws == DEFAULT_LAWS else ' --laws ' + ' '.join(args.laws)}`. "
        f"Machine: {platform.machine()}, Python {platform.python_version()}; "
        f"written {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {time.perf_counter() - t0:.0f} s.",
        "",
        "Errors are relative (peak force, approach speed v_in) or in ns (onset time); each first-impact column is the "
        "worst of the three scenarios (default; clearance at crank–rod; 200 rpm with gravity), the μ = 0.1 columns "
        'hold the exact_realtime scenario "μ = 0.1" (the default with friction). The c = 0.1 mm columns are '
        f"max |x − x_ref| / max |x_ref − x_ideal| (= {effect * 1e6:.2f} µm, over 3 revolutions) of the slider over "
        "0–14.9 ms and over the whole run. The reference floor is the same measure between the reference at rtol "
        "1e-9 and at 1e-11; the observed order is fitted over the steps whose error exceeds twice that floor.",
        "",
    ]
    write_keeping_reading(args.out, "\n".join(head + body))


if __name__ == "__main__":
    main()
