"""Steps per second and force ripple of the default slider-crank per geom pair and segment count.

Usage:  python benchmarks/segments_speed.py [--timestep-us 2] [--contact-mode calibrated]
                                            [--out benchmarks/segments_speed.md]

For each journal/segment geom pair and N: the default scenario (c = 0.5 mm at rod_slider,
5000 rpm; time step and contact mode the package defaults unless given) is run for one crank
revolution (12 ms) three times on one thread, and the best steps/s is kept (the machine is shared; the best run is the least
disturbed). The force ripple is measured in MuJoCo itself on a one-bearing scene with the
same geoms, N and contact parameters: (max - min) / mean of the radial force over one
segment pitch of journal direction, at the scenario's typical penetration (Hertz
penetration under the median ideal joint load) and at 0.5x / 2x of it.

The table is rewritten; any text from a "## Reading" heading on in the existing file is kept.
"""

from __future__ import annotations

import argparse
import dataclasses
import platform
import time

from _tables import (
    write_keeping_reading,  # benchmarks/_tables.py (scripts run from benchmarks/)
)

from clearance import ModelOptions
from clearance.builders import slider_crank
from clearance.mjcf.probe import measured_ripple, ring_scene
from clearance.run.preparation import prepare
from clearance.run.simulation import simulate_prepared

PAIRS = [("sphere", "sphere"), ("capsule", "capsule"), ("sphere", "box"), ("cylinder", "box")]
SEGMENTS = [36, 72, 144, 288]


def measure(journal: str, segment: str, n: int | None, base: ModelOptions) -> dict:
    mech = slider_crank()
    opts = dataclasses.replace(base, segments=n, journal_geom=journal, segment_geom=segment)
    prep = prepare(mech, opts)
    best = 0.0
    for _ in range(3):
        r = simulate_prepared(prep, duration=0.012)
        best = max(best, r.metadata["steps_per_second"])
    ring = prep.built.rings["rod_slider"]
    scene = ring_scene(ring, opts, prep.contact["rod_slider"])
    d = prep.sizing["rod_slider"].typical_penetration
    rip = [measured_ripple(scene, ring, f * d) for f in (0.5, 1.0, 2.0)]
    return {
        "pair": f"{journal}/{segment}",
        "N": ring.segments,
        "steps_per_s": best,
        "ripple": rip,
        "delta_um": d * 1e6,
        "peak_kN": r.joints["rod_slider"].force_magnitude.max() / 1e3,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--timestep-us", type=float, default=ModelOptions().timestep * 1e6)
    ap.add_argument("--contact-mode", default=ModelOptions().contact_mode.value, choices=("nominal", "calibrated"))
    ap.add_argument("--out", default="benchmarks/segments_speed.md")
    args = ap.parse_args()
    base = ModelOptions(timestep=args.timestep_us * 1e-6, contact_mode=args.contact_mode)
    rows = []
    t0 = time.time()
    default = measure("sphere", "sphere", None, base)
    for j, s in PAIRS:
        for n in SEGMENTS:
            rows.append(measure(j, s, n, base))
            print(rows[-1], flush=True)
    lines = [
        "# Segment count and geom pair: speed and force ripple",
        "",
        f"Command: `python benchmarks/segments_speed.py --timestep-us {args.timestep_us:g} "
        f"--contact-mode {args.contact_mode}`",
        f"Machine: {platform.processor() or platform.machine()}, one thread; measured "
        f"{time.strftime('%Y-%m-%d')} in {time.time() - t0:.0f} s.",
        "",
        f"Default slider-crank (c = 0.5 mm at rod_slider, 5000 rpm, h = {args.timestep_us:g} µs, "
        f"{args.contact_mode} contact), one crank",
        f"revolution. Typical penetration δ = {default['delta_um']:.2f} µm (Hertz under the median ideal joint load).",
        "Ripple = (max − min)/mean of the radial ring force over journal direction, measured in MuJoCo.",
        "",
        "| journal / segment | N | steps/s (best of 3) | ripple at δ/2 | ripple at δ | ripple at 2δ | first-revolution peak force [kN] |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in [default] + rows:
        tag = " (default: ripple rule)" if r is default else ""
        lines.append(
            f"| {r['pair']}{tag} | {r['N']} | {r['steps_per_s']:,.0f} | {r['ripple'][0]:.1%} | {r['ripple'][1]:.1%} | "
            f"{r['ripple'][2]:.1%} | {r['peak_kN']:.1f} |"
        )
    print(write_keeping_reading(args.out, "\n".join(lines) + "\n"))


if __name__ == "__main__":
    main()
