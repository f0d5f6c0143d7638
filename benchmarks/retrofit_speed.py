"""Retrofit of gymnasium's arms: the time the retrofit takes, and what the play costs a run.

Usage:  python benchmarks/retrofit_speed.py [--out benchmarks/retrofit_speed.md]

Every hinge of gymnasium's reacher.xml (planar two-link arm, RK4) and pusher.xml (seven-joint
arm, geom density) gets radial play, calibrated ring, segments by the ripple rule, time step
by the stability rule, with two materials:

  * steel: the defaults of `clearance retrofit` (c = 0.1 mm, R_B = 10 mm, E = 207 GPa);
  * polymer bushing: c = 0.2 mm, R_B = 10 mm, E = 2.4 GPa, nu = 0.4.

Each case is retrofitted twice in a fresh calibration cache: cold (every bearing fitted) and
warm (the stored fits reused). The table gives the wall time of each phase of the warm run
(the spec edit and its compiles, the goal being under 2 s for the seven-joint arm; the sizing
motion, the effective masses, the segment rule) and the contact parameters of both runs
(the fits, then their reuse). Speed: steps per second of the unmodified and the retrofitted
model, each at its own time step under the sizing sinusoid, best of 3 (`measure_speed`), and
the cost of one simulated second. Timings on a machine shared with other work vary: the load
average is written beside the table.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import tempfile
import time
from pathlib import Path

import mujoco
from _gym import gym_model

from clearance.model import Material
from clearance.results import atomic_write_text
from clearance.retrofit import RadialPlay, RetrofitOptions, retrofit
from clearance.retrofit.speed import measure_speed

CASES = {
    "steel": dict(radial_clearance=1e-4, bearing_radius=0.01),
    "polymer bushing": dict(
        radial_clearance=2e-4,
        bearing_radius=0.01,
        bearing_material=Material(2.4e9, 0.4),
        journal_material=Material(2.4e9, 0.4),
    ),
}


def _hinges(spec: mujoco.MjSpec) -> list[str]:
    m = spec.compile()
    return [
        mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
        for j in range(m.njnt)
        if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(Path(__file__).with_suffix(".md")))
    args = ap.parse_args()
    started = time.perf_counter()
    load = os.getloadavg()[0]
    rows, speed_rows, notes = [], [], []
    for model_name in ("reacher", "pusher"):
        path = gym_model(model_name)
        for case, kw in CASES.items():
            with tempfile.TemporaryDirectory() as cache:
                os.environ["CLEARANCE_CACHE_DIR"] = cache
                runs = []
                for _ in range(2):  # cold, then warm
                    spec = mujoco.MjSpec.from_file(str(path))
                    plays = {h: RadialPlay.make(**kw) for h in _hinges(spec)}
                    runs.append(retrofit(spec, plays, RetrofitOptions(accept_inaccurate=True)))
            cold, warm = runs
            t = warm.timings
            segs = sorted({h.sizing.segments for h in warm.hinges.values()})
            rows.append(
                f"| {model_name} | {case} | {len(warm.hinges)} | {warm.timestep:g} | "
                f"{segs[0]}–{segs[-1]} | {t['spec edit and compiles']:.2f} | {t['sizing motion']:.2f} | "
                f"{t['effective masses']:.2f} | {t['segment rule']:.2f} | {cold.timings['contact parameters']:.1f} "
                f"/ {t['contact parameters']:.2f} | {warm.wall_time:.2f} |"
            )
            u = max(
                (measure_speed(warm.twin, warm.options.control) for _ in range(3)), key=lambda s: s.steps_per_second
            )
            m = max(
                (measure_speed(warm.model, warm.options.control) for _ in range(3)), key=lambda s: s.steps_per_second
            )
            speed_rows.append(
                f"| {model_name} | {case} | {u.timestep:g} | {u.steps_per_second:,.0f} | {m.timestep:g} | "
                f"{m.steps_per_second:,.0f} | {u.steps_per_second / m.steps_per_second:.1f} | "
                f"{u.realtime / m.realtime:,.0f} | {m.realtime:.3g} |"
            )
            notes += [f"{model_name}, {case}: {n}" for n in warm.notes]
            print(rows[-1], speed_rows[-1], sep="\n", flush=True)
    when = datetime.date.today().isoformat()
    text = "\n".join(
        [
            "# Retrofit of gymnasium's arms: time of the retrofit and speed cost",
            "",
            "Command: `python benchmarks/retrofit_speed.py`",
            f"Machine: {platform.machine()}, load average {load:.1f} at the start; MuJoCo {mujoco.__version__}; "
            f"measured {when} in {time.perf_counter() - started:.0f} s.",
            "",
            "Every hinge with radial play, calibrated ring (contact fitted to Lankarani-Nikravesh at each bearing's "
            "effective mass), segments by the ripple rule, time step by the stability rule (omega*h <= 0.2). "
            "Steel: c = 0.1 mm, R_B = 10 mm, E = 207 GPa (the command's defaults); polymer bushing: c = 0.2 mm, "
            "R_B = 10 mm, E = 2.4 GPa, nu = 0.4.",
            "",
            "## Time of the retrofit [s]",
            "",
            "Phases of the second (warm) run; contact parameters: first run (every bearing fitted) / second run "
            "(stored fits reused). Goal: spec edit and compiles under 2 s for the seven-joint arm.",
            "",
            "| model | bearing | hinges | time step [s] | segments | spec edit and compiles | sizing motion "
            "| effective masses | segment rule | contact parameters (fit / reuse) | total (warm) |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            "## Speed cost",
            "",
            "Each model at its own time step under the sizing sinusoid, best of 3. Cost: how many times longer one "
            "step, and one simulated second, of the retrofitted model takes.",
            "",
            "| model | bearing | step [s] | steps/s | retrofitted step [s] | retrofitted steps/s | cost per step "
            "| cost per simulated second | retrofitted simulated s per wall s |",
            "|---|---|---|---|---|---|---|---|---|",
            *speed_rows,
            "",
            "## Notes of the runs",
            "",
            *([f"- {n}" for n in notes] or ["None."]),
            "",
        ]
    )
    atomic_write_text(args.out, text)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
