"""The lubricated journal in the exact contact against the reference solver, and what the film costs.

Five parts, written to lubricated_bearing.md next to this file:

1. The committed lubricated slider-crank (builders/scenarios/lubricated_slider_crank.toml: oil film
   at the rod-slider joint, c = 10 um, 5000 rpm; regular: benchmarks/lubricated_regularity.md),
   3 revolutions, MuJoCo's exact contact at 5, 3, 2 and 1 us against the reference solver (rtol
   1e-9, output every 1 us): minimum film thickness, largest eccentricity ratio, peak film force,
   peak bearing force, and the slider's deviation from the reference, max |x - x_ref| over the
   run / max |x_ref - x_ideal| (the clearance's whole effect on the slider).
2. Through the transition into dry contact: the same slider-crank with the film at the crank-rod
   joint and a tenth of the oil's viscosity (0.003 Pa s), so that the journal closes the film,
   passes the transition thickness and presses into the bearing under the dry law; the same
   columns plus the largest overlap and the share of the run in dry contact.
3. Dry against lubricated at the same clearance: the scenario and the same mechanism without oil
   (c = 10 um, dry Lankarani-Nikravesh), exact contact at the default step: peak bearing force
   over the run and after the first revolution, contact, the slider's deviation from the ideal
   twin (the reference's), and the two orbits side by side (lubricated_bearing_orbits.png).
4. Two lubricated joints: the scenario's bearing and oil at both of the slider-crank's rod joints
   (one revolution) and at the seven-bar press's A and C (0.2 s), reference against the exact
   contact at 3, 1 and 0.5 us (each film's in-step treatment sees its own joint alone).
5. Cost per step: the runs of part 3, alternately, best of 3 (wall time of `simulate_prepared`:
   the stepping and the readout, the preparation apart).

    nice -n 10 python benchmarks/lubricated_bearing.py
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

import numpy as np

from clearance import ModelOptions, simulate
from clearance.analysis.figures.comparison_figures import OrbitPanel, plot_orbit_panels
from clearance.analysis.metrics.film import film_summary
from clearance.builders import seven_bar_press
from clearance.builders.scenario import load_scenario, loads_scenario
from clearance.model import Mechanism
from clearance.reference import run_reference
from clearance.results import SimulationResult
from clearance.run.preparation import prepare
from clearance.run.simulation import SimulationError, simulate_prepared

HERE = Path(__file__).resolve().parent
SCENARIO = HERE.parent / "builders" / "scenarios" / "lubricated_slider_crank.toml"
STEPS = (5e-6, 3e-6, 2e-6, 1e-6)
DEFAULT_STEP = 3e-6
REVOLUTIONS = 3
OUTPUT = "slider_x"
JOINT = "rod_slider"
FIGURE = "lubricated_bearing_orbits.png"


def _thin_oil_at_crank_rod() -> Mechanism:
    text = SCENARIO.read_text().replace("viscosity_pa_s = 0.03", "viscosity_pa_s = 0.003")
    return loads_scenario(text.replace('clearance_at = ["rod_slider"]', 'clearance_at = ["crank_rod"]'))


def _two_films() -> list[tuple[str, Mechanism, float]]:
    """(name, mechanism, duration [s]) of the cases with two lubricated joints: the scenario's
    slider-crank with the film at both of the rod's joints (one revolution), and the seven-bar press
    with the scenario's bearing and oil at its two clearance joints A and C (0.2 s, a tenth of its
    2 s revolution)."""
    text = SCENARIO.read_text().replace('clearance_at = ["rod_slider"]', 'clearance_at = ["crank_rod", "rod_slider"]')
    scenario = load_scenario(SCENARIO)
    cl = scenario.joint(JOINT).require_clearance()
    press = seven_bar_press(
        radial_clearance=cl.radial_clearance,
        bearing_radius=cl.bearing_radius,
        bearing_length=cl.bearing_length,
        lubrication=cl.lubrication,
    )
    period = scenario.drive_period or 0.0
    return [("slider-crank, crank_rod and rod_slider", loads_scenario(text), period), ("press, A and C", press, 0.2)]


def _joints_cell(res: SimulationResult) -> str:
    """Each joint's peak bearing force and minimum film thickness, in one table cell."""
    return "; ".join(
        f"{j}: {jr.force_magnitude.max():.1f} N, h_min {-jr.penetration.max() * 1e6:.3f} µm"
        for j, jr in res.joints.items()
    )


def _two_film_rows() -> list[str]:
    """The two-film cases: the reference, then the exact contact at 3, 1 and 0.5 us (or where it diverged)."""
    rows = []
    for name, mech, duration in _two_films():
        ref = run_reference(mech, duration, output_interval=1e-5)
        rows.append(f"| {name} | reference (rtol 1e-9) | {_joints_cell(ref)} |")
        for h in (3e-6, 1e-6, 0.5e-6):
            try:
                run = simulate(mech, duration=duration, options=ModelOptions(contact_mode="exact", timestep=h))
                cell = _joints_cell(run)
            except SimulationError as err:
                cell = f"diverged at t = {(err.time or 0.0) * 1e3:.3f} ms (at {err.joint})"
            rows.append(f"| {name} | exact, {h * 1e6:g} µs | {cell} |")
    return rows


def _dry(mech: Mechanism) -> Mechanism:
    """The same mechanism without oil: every clearance kept, its lubrication removed."""
    joints = tuple(
        dataclasses.replace(j, clearance=dataclasses.replace(j.clearance, lubrication=None))
        if j.clearance is not None
        else j
        for j in mech.joints
    )
    return dataclasses.replace(mech, joints=joints)


def _numbers(res: SimulationResult, joint: str, period: float) -> dict[str, float]:
    s = film_summary(res, joint)
    force = res.joints[joint].force_magnitude
    return {
        "late": float(force[res.times >= period].max()),
        "h_min": s.min_film_thickness,
        "eps": s.max_eccentricity_ratio,
        "film": s.peak_film_force,
        "peak": float(force.max()),
        "peak_time": float(res.times[int(np.argmax(force))]),
        "dry": s.dry_fraction,
    }


def _deviation(res: SimulationResult, ref: SimulationResult, effect: float) -> float:
    return float(np.max(np.abs(res.outputs[OUTPUT] - _on(res, ref)))) / effect


def _rel(a: float, b: float) -> str:
    return f"{(a - b) / abs(b):+.2%}"


def _comparison(mech: Mechanism, joint: str, duration: float) -> tuple[list[str], dict[str, float], SimulationResult]:
    """The comparison table's rows (reference first, then each step), the default step's errors
    and the reference's ideal twin (for the deviations)."""
    t0 = time.perf_counter()
    ref = run_reference(mech, duration, output_interval=1e-6, rtol=1e-9)
    ref_wall = time.perf_counter() - t0
    ideal = run_reference(mech.ideal_twin(), duration, output_interval=1e-6, rtol=1e-9)
    effect = float(np.max(np.abs(ref.outputs[OUTPUT] - _on(ref, ideal))))
    period = mech.drive_period or 0.0
    r = _numbers(ref, joint, period)
    rows = [
        f"| reference (rtol 1e-9) | {r['h_min'] * 1e6:.4f} µm | {r['eps']:.4f} | {r['film']:.1f} N | "
        f"{r['peak']:.1f} N | {r['late']:.1f} N | {r['dry']:.1%} | — | {ref_wall:.1f} s |"
    ]
    errors: dict[str, float] = {}
    for h in STEPS:
        t0 = time.perf_counter()
        run = simulate(mech, duration=duration, options=ModelOptions(contact_mode="exact", timestep=h))
        wall = time.perf_counter() - t0
        m = _numbers(run, joint, period)
        dev = _deviation(run, ref, effect)
        rows.append(
            f"| exact, {h * 1e6:g} µs | {m['h_min'] * 1e6:.4f} µm ({_rel(m['h_min'], r['h_min'])}) | "
            f"{m['eps']:.4f} ({_rel(m['eps'], r['eps'])}) | {m['film']:.1f} N ({_rel(m['film'], r['film'])}) | "
            f"{m['peak']:.1f} N ({_rel(m['peak'], r['peak'])}) | {m['late']:.1f} N ({_rel(m['late'], r['late'])}) | "
            f"{m['dry']:.1%} | {dev:.2e} | {wall:.1f} s |"
        )
        if h == DEFAULT_STEP:
            errors = {k: (m[k] - r[k]) / abs(r[k]) for k in ("h_min", "eps", "film", "peak", "late")} | {"dev": dev}
    rows.append(f"\nThe clearance's whole effect on the slider, max |x_ref − x_ideal|: {effect * 1e6:.3f} µm.")
    errors["ref_peak_time"] = r["peak_time"]
    return rows, errors, ideal


def _on(run: SimulationResult, other: SimulationResult) -> np.ndarray:
    """``other``'s slider position at ``run``'s times (linear; both sampled every 1 us or more often)."""
    return np.interp(run.times, other.times, other.outputs[OUTPUT])


def _timed(duration: float) -> tuple[list[str], dict[str, SimulationResult]]:
    """Cost per step, lubricated against dry, alternately, best of 3 (wall time of `simulate_prepared`
    per step: the stepping and the readout, preparation apart); the last run of each."""
    options = ModelOptions(contact_mode="exact", timestep=DEFAULT_STEP)
    mech = load_scenario(SCENARIO)
    cases = {"lubricated": prepare(mech, options), "dry": prepare(_dry(mech), options)}
    best = {k: np.inf for k in cases}
    runs: dict[str, SimulationResult] = {}
    steps = round(duration / DEFAULT_STEP)
    for _ in range(3):
        for name, prepared in cases.items():
            t0 = time.perf_counter()
            runs[name] = simulate_prepared(prepared, duration=duration)
            best[name] = min(best[name], (time.perf_counter() - t0) / steps)
    rows = [f"| {k} | {steps} | {best[k] * 1e6:.3f} µs |" for k in cases]
    rows.append(f"| lubricated / dry | | {best['lubricated'] / best['dry']:.3f} |")
    return rows, runs


def _dry_against_lubricated(runs: dict[str, SimulationResult], ideal: SimulationResult, period: float) -> list[str]:
    """The table of the same mechanism dry and lubricated at the default step, and the orbit figure."""
    rows = []
    for name, run in runs.items():
        jr = run.joints[JOINT]
        force = jr.force_magnitude
        later = run.times >= period
        d = run.outputs[OUTPUT] - _on(run, ideal)
        touching = jr.penetration > 0
        onsets = int(np.count_nonzero(touching[1:] & ~touching[:-1]) + touching[0])
        rows.append(
            f"| {name} | {force.max():.1f} N | {force[later].max():.1f} N | {jr.penetration.max() * 1e6:+.3f} µm | "
            f"{touching.mean():.1%} | {onsets} | {np.abs(d).max() * 1e6:.3f} µm | {np.sqrt(np.mean(d**2)) * 1e6:.3f} µm |"
        )
    c = load_scenario(SCENARIO).joint(JOINT).require_clearance().radial_clearance
    plot_orbit_panels(
        [
            OrbitPanel(runs["dry"], JOINT, c, "dry (Lankarani–Nikravesh)"),
            OrbitPanel(runs["lubricated"], JOINT, c, "lubricated (short-bearing film, 0.03 Pa s)"),
        ],
        title=f"{JOINT} journal centre, 3 revolutions at 5000 rpm, exact contact at {DEFAULT_STEP * 1e6:g} µs",
        path=HERE / FIGURE,
    )
    return rows


def main() -> None:
    start = time.perf_counter()
    load = os.getloadavg()[0]
    mech = load_scenario(SCENARIO)
    period = mech.drive_period or 0.0
    duration = REVOLUTIONS * period
    head = (
        "| run | minimum film thickness | largest ε = \\|e\\|/c | peak film force | peak bearing force | "
        "after the 1st revolution | in dry contact | slider deviation / effect | wall time |"
    )
    rule = "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    lubricated, err, ideal = _comparison(mech, JOINT, duration)
    transition, err_t, _ = _comparison(_thin_oil_at_crank_rod(), "crank_rod", duration)
    cost, runs = _timed(duration)
    two = _two_film_rows()
    against = _dry_against_lubricated(runs, ideal, period)
    wall = time.perf_counter() - start
    lines = [
        "# The lubricated journal in the exact contact against the reference",
        "",
        f"`nice -n 10 python benchmarks/lubricated_bearing.py` ({wall:.0f} s on 2 cores shared with other work; "
        f"load average {load:.1f} at the start, {os.getloadavg()[0]:.1f} at the end). Unless a section says "
        f"otherwise, {REVOLUTIONS} revolutions at 5000 rpm (36 ms) each; in brackets each number's difference from the reference's. The film force "
        "is `JointResult.film_force` (the compiled contact's sensor; the reference's film at each sample's "
        "state); the bearing force the joint's whole contact force (film and dry law). Slider deviation: "
        "max |x − x_ref| over the run / max |x_ref − x_ideal|.",
        "",
        "## The lubricated slider-crank (oil film at the rod–slider joint)",
        "",
        "`builders/scenarios/lubricated_slider_crank.toml`: c = 10 µm, R = 10 mm, L = 10 mm, 0.03 Pa s, "
        "short-bearing film, transition at 1 µm; regular (benchmarks/lubricated_regularity.md), so compared "
        "point by point.",
        "",
        head,
        rule,
        *lubricated,
        "",
        f"At the default step ({DEFAULT_STEP * 1e6:g} µs) the minimum film thickness is {err['h_min']:+.2%} and the "
        f"peak bearing force {err['peak']:+.3%} from the reference's (the issue's goal: within 2 %); the peak film "
        f"force {err['film']:+.3%}, the largest eccentricity ratio {err['eps']:+.2%}.",
        "",
        "## Through the transition into dry contact (film at the crank–rod joint, 0.003 Pa s)",
        "",
        "The same slider-crank with the film at the crank–rod joint (its bearing on the crank turns at "
        "5000 rpm) and a tenth of the viscosity: the journal closes the film, passes the transition thickness "
        "(1 µm, where the film's coefficients are held) and presses into the bearing under the dry "
        "Lankarani–Nikravesh law (negative film thickness: the overlap). Not checked for regularity: the "
        "deviation column is a pointwise comparison that a chaotic case would not support.",
        "",
        head,
        rule,
        *transition,
        "",
        f"At the default step: largest overlap {err_t['h_min']:+.2%}, peak bearing force {err_t['peak']:+.3%} "
        f"(after the first revolution {err_t['late']:+.3%}), peak film force {err_t['film']:+.3%} from the "
        f"reference's. The whole run's peak (the reference's at {err_t['ref_peak_time'] * 1e3:.3f} ms) is the "
        "film's answer to the start, a journal released centred in a bearing that turns at 5000 rpm, not a "
        "contact. The overlap does not converge on the reference's as the step shrinks: the dry law's damping "
        "(Lankarani–Nikravesh, inversely proportional to the approach speed at onset) is set by the speed at "
        "which the journal reaches the wall through the film, a slow gliding approach of a few mm/s that the "
        "compiled contact takes from its step's rates at the crossing and the reference locates exactly, and "
        "the overlap moves with it from step to step.",
        "",
        "## Dry against lubricated at the same clearance",
        "",
        f"The scenario and the same mechanism without oil (c = 10 µm at the rod–slider joint, dry "
        f"Lankarani–Nikravesh, restitution 0.9, no friction), exact contact at {DEFAULT_STEP * 1e6:g} µs. "
        "Deviation: the slider's x − x_ideal against the reference's ideal twin. Peak force after the first "
        "revolution: the journal starts centred, so the first revolution holds the start-up.",
        "",
        "| run | peak bearing force | after the 1st revolution | max penetration (−: film thickness) | "
        "in dry contact | contact onsets | max \\|x − x_ideal\\| | RMS x − x_ideal |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
        *against,
        "",
        f"![orbits, dry against lubricated]({FIGURE})",
        "",
        "## Two lubricated joints",
        "",
        "The compiled contact integrates each film's stiff damping with its own joint's response over the "
        "step (the 2×2 in-step treatment of each joint alone); two films coupled through the links they "
        "share are each held fixed in the other's step. Below: the scenario's bearing and oil at two joints "
        "at once, the slider-crank over one revolution (12 ms), the press (crank 2 at π rad/s, gravity) over "
        "0.2 s, a tenth of its revolution. Each cell: every joint's peak bearing force and minimum film "
        "thickness (negative: dry overlap). A run that diverged, or one whose peak stands far above the "
        "reference's, is a case the per-joint treatment does not carry at that step.",
        "",
        "| case | run | joints |",
        "|---|---|---|",
        *two,
        "",
        "## Cost per step: lubricated against dry",
        "",
        f'The dry and the lubricated run of "Dry against lubricated", {REVOLUTIONS} revolutions at '
        f"{DEFAULT_STEP * 1e6:g} µs each, run alternately three times; the best wall time per step of each "
        "(`simulate_prepared`: the stepping and the readout, the preparation apart).",
        "",
        "| run | steps | best time per step |",
        "|---|---:|---:|",
        *cost,
        "",
    ]
    (HERE / "lubricated_bearing.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
