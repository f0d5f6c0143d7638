"""The cylindrical (conformal) contact laws of a pin in a hole: force curves and the default scenario.

Usage:  python benchmarks/cylindrical_laws.py [--out benchmarks/cylindrical_laws.md]
                                              [--laws LAW ...] [--no-mujoco]

* Figure ``cylindrical_laws.png``: the elastic force against penetration of each cylindrical
  law at c = 0.01, 0.1 and 0.5 mm (steel, R_B = 10 mm, L = 20 mm), with the point-contact
  Hertz force K δ^1.5 of the other laws (`laws.bearing_stiffness`) for comparison; a curve ends
  at the law's deepest penetration δ* where it has one.
* The force of each law at 0.1, 1 and 10 µm (c = 0.1 mm, L = 20 mm, steel) and its
  provenance ([checked] against DyS's formulas run by hand, or [recalled]).
* The default scenario (slider-crank, c = 0.5 mm, 5000 rpm, cₑ = 0.9, μ = 0; L = 2 R_B = 20 mm)
  under each law, Lankarani–Nikravesh first: the reference solver's first impact (onset, peak
  force, peak penetration, impulse; `analysis.metrics.accuracy.first_impact`) and statistics
  over 3 revolutions (impacts per revolution, contact fraction, p95 and peak force;
  `joint_summary`); then MuJoCo's compiled exact contact at the default step against it (the
  first impact's peak-force error, the statistics' errors) and its cost per step relative to
  LN's, each law timed in the same run as LN (best of 3, 3 revolutions, preparation apart).
  A law the compiled contact does not know yet is refused by `clearance run` in one line
  (`contact_plugin.attributes.require_compiled_law`); its MuJoCo cells say so, and fill in
  once the compiled port adds the law.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from _tables import write_keeping_reading  # benchmarks/_tables.py (scripts run from benchmarks/)

from clearance import ModelOptions, simulate
from clearance.analysis.metrics.accuracy import first_impact
from clearance.analysis.metrics.summary import joint_summary
from clearance.builders import slider_crank
from clearance.contact_calibration.cylindrical_laws import cylinder_law, elastic
from clearance.contact_calibration.laws import UnverifiedLawWarning, bearing_stiffness
from clearance.contact_plugin.attributes import require_compiled_law
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw
from clearance.reference import run_reference
from clearance.run.preparation import prepare
from clearance.run.simulation import simulate_prepared

LAWS = [ContactLaw.LANKARANI_NIKRAVESH, *sorted(CYLINDRICAL_LAWS, key=list(ContactLaw).index)]
CHECKED = {ContactLaw.JOHNSON, ContactLaw.RADZIMOVSKY, ContactLaw.LIU, ContactLaw.PEREIRA}
CLEARANCES = (0.01e-3, 0.1e-3, 0.5e-3)
LENGTH = 0.02
JOINT = "rod_slider"
REVOLUTIONS = 3


def _clearance(law: ContactLaw, c: float) -> Clearance:
    return Clearance(c, 0.01, law=law, bearing_length=LENGTH)


def figure(path: Path) -> None:
    """Force against penetration at each clearance of `CLEARANCES`."""
    fig, axes = plt.subplots(1, len(CLEARANCES), figsize=(13, 4.4), sharey=True)
    deltas = np.geomspace(1e-9, 1e-4, 400)
    for ax, c in zip(axes, CLEARANCES):
        k = bearing_stiffness(_clearance(ContactLaw.LANKARANI_NIKRAVESH, c))
        ax.loglog(deltas * 1e6, k * deltas**1.5, "k--", lw=1.2, label="Hertz K δ^1.5 (point laws)")
        for law in LAWS[1:]:
            try:
                cyl = cylinder_law(_clearance(law, c))
            except ValueError:
                continue  # Pereira outside its fitted clearances
            d = deltas[deltas < cyl.max_penetration]
            (line,) = ax.loglog(d * 1e6, elastic(cyl, d), lw=1.3, label=law.value)
            if math.isfinite(cyl.max_penetration) and cyl.max_penetration <= deltas[-1]:
                ax.plot(cyl.max_penetration * 1e6, elastic(cyl, cyl.max_penetration), "o", color=line.get_color(), ms=4)
        ax.set_title(f"c = {c * 1e3:g} mm")
        ax.set_xlabel("penetration δ [µm]")
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("elastic force F [N] (L = 20 mm, steel)")
    axes[0].set_ylim(1e-2, 1e7)
    axes[-1].legend(fontsize=7, loc="lower right")
    fig.suptitle("Cylindrical contact laws of a pin in a hole: force against penetration (dots: δ*, beyond it refused)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _force_table() -> list[str]:
    pen = (1e-7, 1e-6, 1e-5)
    lines = [
        "## Force at 0.1, 1 and 10 µm (c = 0.1 mm, L = 20 mm, steel)",
        "",
        "| law | F(0.1 µm) [N] | F(1 µm) [N] | F(10 µm) [N] | δ* [µm] | provenance |",
        "|---|---|---|---|---|---|",
    ]
    k = bearing_stiffness(_clearance(ContactLaw.LANKARANI_NIKRAVESH, 1e-4))
    lines.append(
        "| Hertz K δ^1.5 (point laws) | "
        + " | ".join(f"{k * d**1.5:.4g}" for d in pen)
        + " | — | [checked] (the point laws' stiffness) |"
    )
    for law in LAWS[1:]:
        cyl = cylinder_law(_clearance(law, 1e-4))
        star = f"{cyl.max_penetration * 1e6:.4g}" if math.isfinite(cyl.max_penetration) else "none"
        how = "[checked] against DyS within 1e-15" if law in CHECKED else "[recalled], warns"
        lines.append(f"| {law.value} | " + " | ".join(f"{elastic(cyl, d):.4g}" for d in pen) + f" | {star} | {how} |")
    return [*lines, ""]


def _cost_per_step(law: ContactLaw, duration: float, h: float) -> float:
    """Best of 3 wall seconds per step of the default scenario under ``law``, preparation apart."""
    prepared = prepare(slider_crank(law=law), ModelOptions(contact_mode="exact", timestep=h))
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        simulate_prepared(prepared, duration=duration)
        best = min(best, time.perf_counter() - t0)
    return best / round(duration / h)


def _rel(a: float, b: float) -> str:
    return f"{a / b - 1:+.2%}"


def scenario_table(laws: list[ContactLaw], mujoco: bool) -> list[str]:
    """The default scenario under each law: reference, and MuJoCo's exact contact against it."""
    base = slider_crank()
    period = base.drive_period or 0.0
    duration = REVOLUTIONS * period
    h = ModelOptions(contact_mode="exact").timestep
    ref_lines = [
        f"## The default scenario under each law: reference solver, {REVOLUTIONS} revolutions",
        "",
        "| law | first onset [ms] | first peak [N] | first δ_max [µm] | first impulse [N s] | impacts/rev "
        "| contact fraction | p95 force [N] | peak force [N] | run [s] |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    mj_lines = [
        f"## MuJoCo's exact contact at the default step ({h * 1e6:g} µs) against the reference",
        "",
        "| law | first peak | impacts/rev | contact fraction | p95 force | cost per step / LN's |",
        "|---|---|---|---|---|---|",
    ]
    ln_cost = math.nan
    refusal = ""
    for law in laws:
        mech = slider_crank(law=law)
        t0 = time.perf_counter()
        ref = run_reference(mech, duration, output_interval=1e-6)
        wall = time.perf_counter() - t0
        fi, s = first_impact(ref, JOINT), joint_summary(ref, JOINT)
        assert fi is not None
        ref_lines.append(
            f"| {law.value} | {fi.onset * 1e3:.4f} | {fi.peak_force:.5g} | {fi.max_penetration * 1e6:.4g} | "
            f"{fi.impulse:.4g} | {s.impacts / REVOLUTIONS:.2f} | {s.contact_fraction:.4f} | {s.p95_force:.4g} | "
            f"{s.peak_force:.5g} | {wall:.1f} |"
        )
        if not mujoco:
            continue
        try:
            require_compiled_law(law, JOINT)
        except ValueError as err:
            refusal = refusal or str(err)
            mj_lines.append(f"| {law.value} | refused: not compiled yet | | | | |")
            continue
        run = simulate(mech, duration=duration, options=ModelOptions(contact_mode="exact"))
        fm, sm = first_impact(run, JOINT), joint_summary(run, JOINT)
        assert fm is not None
        if law is ContactLaw.LANKARANI_NIKRAVESH:
            ln_cost = _cost_per_step(law, duration, h)
            cost = 1.0
        else:  # timed in the same run as LN: LN again, then the law
            ln_again = _cost_per_step(ContactLaw.LANKARANI_NIKRAVESH, duration, h)
            cost = _cost_per_step(law, duration, h) / ln_again
        mj_lines.append(
            f"| {law.value} | {_rel(fm.peak_force, fi.peak_force)} | {_rel(sm.impacts, s.impacts)} | "
            f"{_rel(sm.contact_fraction, s.contact_fraction)} | {_rel(sm.p95_force, s.p95_force)} | {cost:.3f} |"
        )
    out = [*ref_lines, ""]
    if mujoco:
        note = f"LN's own cost: {ln_cost * 1e6:.3g} µs per step." if math.isfinite(ln_cost) else ""
        if refusal:
            note += f" A law not compiled yet is refused by `clearance run` in one line: `{refusal}`."
        out += [*mj_lines, "", note.strip(), ""]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    ap.add_argument("--out", default="benchmarks/cylindrical_laws.md")
    ap.add_argument("--laws", nargs="+", default=[law.value for law in LAWS], choices=[law.value for law in LAWS])
    ap.add_argument("--no-mujoco", action="store_true", help="the reference side only")
    args = ap.parse_args()
    warnings.simplefilter("ignore", UnverifiedLawWarning)  # the tables say which laws are [recalled]
    laws = [ContactLaw(v) for v in args.laws]
    t0 = time.perf_counter()
    load0 = os.getloadavg()[0]
    out = Path(args.out)
    png = out.with_suffix(".png")
    figure(png)
    body = [*_force_table(), *scenario_table(laws, not args.no_mujoco)]
    load1 = os.getloadavg()[0]
    laws_arg = "" if args.laws == [law.value for law in LAWS] else " --laws " + " ".join(args.laws)
    head = [
        "# Cylindrical contact laws of a pin in a hole",
        "",
        f"Command: `python benchmarks/cylindrical_laws.py{laws_arg}{' --no-mujoco' if args.no_mujoco else ''}` "
        f"({time.perf_counter() - t0:.0f} s on {platform.processor() or platform.machine()}, load average "
        f"{load0:.1f} at the start and {load1:.1f} at the end on {os.cpu_count()} cores). Figure: "
        f"[{png.name}]({png.name}).",
        "",
        f"![force against penetration]({png.name})",
        "",
    ]
    write_keeping_reading(out, "\n".join(head + body))


if __name__ == "__main__":
    main()
