"""Round trip on the slider-crank: the retrofitted ideal twin against the native clearance run.

    python benchmarks/retrofit_round_trip.py [--out benchmarks/retrofit_round_trip.md]

Retrofits the ring-free ideal twin's crank_rod hinge (the same clearance, bearing, material,
segments and 2 µs step as the native model with clearance at crank_rod, calibrated ring),
runs both for 5 ms, and writes the first impact times and the orbit gap |e_a - e_b| / c over
growing windows; beside it the native model against itself at half the step (how far two
discretizations of the same model drift apart), and the retrofit with the native model's own
contact parameters (what the separate calibrations account for).
"""

from __future__ import annotations

import argparse
import dataclasses
import platform
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from clearance.builders import slider_crank
from clearance.options import ContactParameters, ModelOptions
from clearance.results import SimulationResult, atomic_write_text
from clearance.retrofit import ControlTable, RadialPlay, RetrofitOptions, retrofit, write_retrofit
from clearance.run.preparation import prepare
from clearance.run.retrofitted import load_retrofitted, simulate_retrofitted
from clearance.run.simulation import simulate_prepared

DURATION = 5e-3
WINDOWS = (0.3e-3, 0.5e-3, 0.8e-3, 1.0e-3, 1.5e-3, 2e-3, 3e-3, 5e-3)


def _retrofitted(native_contact: ContactParameters | None) -> tuple[SimulationResult, float]:
    mech = slider_crank(clearance_at=("crank_rod",))
    options = ModelOptions(contact_mode="calibrated")
    ideal = prepare(mech.ideal_twin(), options)
    spec = mujoco.MjSpec.from_string(ideal.to_xml())
    clearance = mech.joint("crank_rod").require_clearance()
    drive = ControlTable(np.array([0.0]), ideal.model.key_ctrl[:1], "the crank's speed set point")
    if native_contact is not None:
        import clearance.retrofit.pipeline as pipeline
        from clearance.retrofit.contact import PlayContact

        pipeline.play_contact = lambda *a, **k: PlayContact(native_contact)  # type: ignore[assignment]
    r = retrofit(
        spec,
        {"crank_rod": RadialPlay(dataclasses.replace(clearance, journal_link=None))},
        RetrofitOptions(
            segments=104, timestep=options.timestep, control=drive, sizing_duration=0.012, accept_inaccurate=True
        ),
    )
    with tempfile.TemporaryDirectory() as d:
        write_retrofit(r, d)
        return simulate_retrofitted(load_retrofitted(d), drive, DURATION), r.hinges[
            "crank_rod"
        ].contact.parameters.stiffness


def _gaps(a: SimulationResult, e_b: np.ndarray, c: float) -> list[float]:
    gap = np.hypot(*(a.joints["crank_rod"].eccentricity - e_b).T) / c
    return [float(gap[a.times <= w].max()) for w in WINDOWS]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--out", default=str(Path(__file__).with_suffix(".md")))
    args = p.parse_args()
    t0 = time.time()
    mech = slider_crank(clearance_at=("crank_rod",))
    native = prepare(mech, ModelOptions(contact_mode="calibrated"))
    a = simulate_prepared(native, duration=DURATION)
    half = simulate_prepared(prepare(mech, ModelOptions(contact_mode="calibrated", timestep=1e-6)), duration=DURATION)
    c = mech.joint("crank_rod").require_clearance().radial_clearance
    meta = native.metadata["contact"]["crank_rod"]
    native_contact = ContactParameters(
        meta["stiffness_per_row"], meta["damping_per_row"], source="native", impedance_rise=meta["impedance_rise"]
    )
    own, own_k = _retrofitted(None)
    same, _ = _retrofitted(native_contact)
    ja = a.joints["crank_rod"]

    def first(r: SimulationResult) -> float:
        return float(r.times[np.argmax(r.joints["crank_rod"].penetration > 0)])

    rows = [
        ("retrofit, its own calibration", first(own), _gaps(a, own.joints["crank_rod"].eccentricity, c)),
        ("retrofit, the native contact parameters", first(same), _gaps(a, same.joints["crank_rod"].eccentricity, c)),
        ("native at half the step (1 µs)", first(half), _gaps(a, half.joints["crank_rod"].eccentricity[::2], c)),
    ]
    lines = [
        "# Round trip on the slider-crank: retrofitted ideal twin against the native clearance run",
        "",
        f"Command: `python benchmarks/retrofit_round_trip.py`. Machine: {platform.machine()}; MuJoCo "
        f"{mujoco.__version__}; {time.time() - t0:.0f} s.",
        "",
        "Clearance at crank_rod (c = 0.5 mm, R_B = 10 mm, steel, e = 0.9, LN), 5000 rpm, calibrated ring of 104 "
        "segments, h = 2 µs for both. The retrofit gives the ring-free ideal twin's crank_rod hinge the same play; "
        "the twin closes the loop with a `connect` at rod_slider, the native model cuts it at crank_rod. Native "
        f"first impact {first(a) * 1e3:.3f} ms; native ring stiffness per row {meta['stiffness_per_row']:.4g}, the "
        f"retrofit's own fit {own_k:.4g}.",
        "",
        "Gap: max |e - e_native| / c over [0, T].",
        "",
        "| against the native run | first impact [ms] | " + " | ".join(f"T = {w * 1e3:g} ms" for w in WINDOWS) + " |",
        "|---|---|" + "---|" * len(WINDOWS),
    ]
    for name, t_first, gaps in rows:
        lines.append(f"| {name} | {t_first * 1e3:.3f} | " + " | ".join(f"{g:.1%}" for g in gaps) + " |")
    imp = np.nonzero(np.diff((ja.penetration > 0).astype(int)) == 1)[0]
    lines += [
        "",
        f"Native impact starts [ms]: {', '.join(f'{t * 1e3:.3f}' for t in a.times[imp + 1][:10])}.",
        "",
        "## Reading",
        "",
        "The first impact falls on the same step. The orbits agree within 2 % of c through the first two impacts "
        "(0.8 ms) and part from about 1 ms on; the native model against itself at half the step parts the same "
        "way a little later, so past about 1.5 ms the orbit of this motion is not predictable to 5 % of c by any "
        "discretization: the 5 ms window of the goal is beyond that horizon. Giving the retrofit the native "
        "contact parameters does not close the gap, so it is the models' structure (the soft `connect` closing "
        "the twin's loop, coordinates in which each integrator's error falls differently), not the calibration.",
        "",
    ]
    atomic_write_text(args.out, "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
