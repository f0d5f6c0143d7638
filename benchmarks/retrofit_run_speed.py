"""Steps per second of a retrofitted model's run against its unmodified twin at the same step.

    python benchmarks/retrofit_run_speed.py [--out benchmarks/retrofit_run_speed.md]

gymnasium's reacher and pusher, every hinge given a polymer bushing (c = 0.2 mm, R_B = 10 mm,
E = 2.4 GPa), in the ring mode (nominal contact parameters: the calibrated ring has the same
geoms and pairs, so it steps as fast) and in the compiled exact mode; each run
(`clearance.run.retrofitted.simulate_retrofitted`, as `clearance run --model` does it) and its
twin's for 0.2 s under the sizing sinusoid at the retrofit's step, wall time of the stepping
and the readout of every row together.
"""

from __future__ import annotations

import argparse
import importlib.util
import platform
import tempfile
import time
from pathlib import Path

import mujoco

from clearance.model import Material
from clearance.results import atomic_write_text
from clearance.retrofit import RadialPlay, RetrofitOptions, SineControl, retrofit, write_retrofit
from clearance.run.retrofitted import load_retrofitted, simulate_retrofitted

DURATION = 0.2
POLYMER = Material(2.4e9, 0.4)


def _assets() -> Path:
    spec = importlib.util.find_spec("gymnasium")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("gymnasium is not installed (pip install -e '.[test]')")
    return Path(next(iter(spec.submodule_search_locations))) / "envs" / "mujoco" / "assets"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--out", default=str(Path(__file__).with_suffix(".md")))
    args = p.parse_args()
    t0 = time.time()
    rows = []
    for name in ("reacher", "pusher"):
        path = _assets() / f"{name}.xml"
        spec = mujoco.MjSpec.from_file(str(path))
        model = spec.compile()
        hinges = [
            mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
            for j in range(model.njnt)
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
        ]
        play = RadialPlay.make(2e-4, 0.01, bearing_material=POLYMER, journal_material=POLYMER)
        for mode in ("nominal", "exact"):
            r = retrofit(
                spec,
                dict.fromkeys(hinges, play),
                RetrofitOptions(contact_mode=mode, measure_speed=False, accept_inaccurate=True),
            )
            with tempfile.TemporaryDirectory() as d:
                write_retrofit(r, d, source_dir=path.parent)
                loaded = load_retrofitted(d)
                res = simulate_retrofitted(loaded, SineControl(), DURATION)
                twin = simulate_retrofitted(loaded, SineControl(), DURATION, twin=True)
            a, b = res.metadata["steps_per_second"], twin.metadata["steps_per_second"]
            ring = "ring" if mode == "nominal" else "exact (plugin)"
            segs = sorted({h.sizing.segments for h in r.hinges.values()})
            rows.append(
                f"| {name} | {len(hinges)} | {ring} | {f'{segs[0]}–{segs[-1]}' if mode == 'nominal' else '–'} "
                f"| {r.timestep:g} | {a:,.0f} | {b:,.0f} | {b / a:.2f} |"
            )
    lines = [
        "# Runs of retrofitted models against their unmodified twins at the same step",
        "",
        f"Command: `python benchmarks/retrofit_run_speed.py`. Machine: {platform.machine()}; MuJoCo "
        f"{mujoco.__version__}; {time.time() - t0:.0f} s in all.",
        "",
        f"Every hinge with a polymer bushing; {DURATION:g} s of motion under the sizing sinusoid, each model at the "
        "retrofit's step (the twin's own is 10 ms); steps/s of the whole run (rollout chunks and the readout of "
        "every row: sensors, body poses).",
        "",
        "| model | hinges | contact | segments | step [s] | retrofitted steps/s | twin steps/s | cost per step |",
        "|---|---|---|---|---|---|---|---|",
        *rows,
        "",
        "## Reading",
        "",
        "Cost per step: how many times longer one step of the retrofitted model's run takes than one of the "
        "twin's at the same step. The ring's hundreds of segment pairs per bearing cost most of it; the compiled "
        "exact contact (one plugin instance per hinge, no pairs) costs a fraction. The twin's own 10 ms step is "
        "a further 2,000-5,000x fewer steps per simulated second (benchmarks/retrofit_speed.md).",
        "",
    ]
    atomic_write_text(args.out, "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
