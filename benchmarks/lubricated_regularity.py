"""Is the lubricated slider-crank regular? Its reference run against runs started 1 nm and 1 um off.

The scenario is builders/scenarios/lubricated_slider_crank.toml (oil film at the rod-slider joint).
The slider, which holds the bearing, is moved along x at t = 0 by 1 nm and by 1 um; over 3
revolutions the spread is max |x - x_base| of the slider divided by max |x_base - x_ideal| (the
clearance's whole effect on the output), as for the dry c = 0.1 mm case. Beside it, each run's
minimum film thickness, largest eccentricity ratio and peak joint force. Writes
lubricated_regularity.md next to this file.

    python benchmarks/lubricated_regularity.py
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from clearance.builders.scenario import load_scenario
from clearance.reference import run_reference
from clearance.reference.run import simulate_system
from clearance.reference.system import ReferenceSystem

HERE = Path(__file__).resolve().parent
SCENARIO = HERE.parent / "builders" / "scenarios" / "lubricated_slider_crank.toml"
DURATION = 0.036  # 3 revolutions at 5000 rpm
SHIFTS = (1e-9, 1e-6)


def _run(mech, shift: float):  # type: ignore[no-untyped-def]
    if not shift:
        return run_reference(mech, DURATION)
    system = ReferenceSystem(mech)
    q0, qd0 = system.initial_state()
    q0[3 * system.link_names.index("slider")] += shift  # the bearing sits on the slider
    return simulate_system(system, q0, qd0, DURATION)


def main() -> None:
    mech = load_scenario(SCENARIO)
    joint = mech.clearance_joints[0]
    c = joint.require_clearance().radial_clearance
    t0 = time.perf_counter()
    base = _run(mech, 0.0)
    ideal = run_reference(mech.ideal_twin(), DURATION)
    effect = float(np.max(np.abs(base.outputs["slider_x"] - ideal.outputs["slider_x"])))
    rows = []
    for shift in (0.0, *SHIFTS):
        res = base if not shift else _run(mech, shift)
        jr = res.joints[joint.name]
        e = np.hypot(jr.eccentricity[:, 0], jr.eccentricity[:, 1])
        diff = np.abs(res.outputs["slider_x"] - base.outputs["slider_x"])
        last = res.times >= DURATION * 2 / 3
        rows.append(
            (
                shift,
                diff.max() / effect,
                diff[last].max() / effect,
                c - e.max(),
                e.max() / c,
                float(jr.force_magnitude.max()),
            )
        )
    wall = time.perf_counter() - t0
    lines = [
        "# Is the lubricated slider-crank regular?",
        "",
        f"`python benchmarks/lubricated_regularity.py` ({wall:.1f} s on 2 cores shared with other work, "
        f"load {os.getloadavg()[0]:.1f}). Scenario `builders/scenarios/lubricated_slider_crank.toml`: "
        f"c = {c * 1e6:.0f} um, 3 revolutions at 5000 rpm, reference solver at its defaults (rtol 1e-9). "
        "Spread: max |x - x_base| of the slider over the run / max |x_base - x_ideal| "
        f"(= {effect * 1e6:.3f} um, the clearance's whole effect on the output).",
        "",
        "| start shifted by | spread, whole run | spread, 3rd revolution | minimum film thickness | "
        "largest eccentricity ratio | peak joint force |",
        "|---|---|---|---|---|---|",
    ]
    for shift, whole, third, hmin, eps, peak in rows:
        label = "0 (base)" if not shift else f"{shift * 1e9:g} nm"
        lines.append(f"| {label} | {whole:.2e} | {third:.2e} | {hmin * 1e6:.3f} um | {eps:.4f} | {peak:.1f} N |")
    lines += [
        "",
        "Reading: the whole-run spread includes the start's own offset (1 nm and 1 um are "
        f"{1e-9 / effect:.1e} and {1e-6 / effect:.2f} of the effect). A regular case keeps the offset's "
        "effect bounded and shrinking; compare the 3rd revolution's spread with those ratios.",
    ]
    (HERE / "lubricated_regularity.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
