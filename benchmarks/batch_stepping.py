"""Does batched MuJoCo stepping pay for sweeps on this machine?

Usage:  python benchmarks/batch_stepping.py [--points 8] [--revolutions 10] [--timestep-us 5]
                                           [--out benchmarks/batch_stepping.md]

A clearance sweep of the default slider-crank (c = 0.1 ... 0.5 mm at rod_slider, 5000 rpm,
nominal contact, a fixed ring of 144 segments so that every point's model has the same size
signature, h = 5 µs, 10 revolutions per point) is stepped four ways, on the same prepared
models and initial states:

  A. one `mujoco.rollout` call per point, one after another, one thread (what a sweep
     worker does for each point);
  B. one `mujoco.rollout` call with the list of all models, one thread;
  C. the same list with two threads (two MjData);
  D. a spawn process pool with two workers, each preparing and stepping its points as A
     (what `clearance sweep` does), timed end to end (pool start-up included).

A, B and C time the stepping only; the preparation (MjSpec build, compile, sizing) is timed
separately, once per point. Each of A-C is the best of two. Results are compared to the
last bit between A, B and C (same models, same states: they must agree exactly).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import mujoco
import numpy as np
from _states import (
    keyframe_state,  # benchmarks/_states.py (scripts run from benchmarks/)
)
from _tables import write_keeping_reading
from mujoco import rollout

from clearance.builders import rpm, slider_crank
from clearance.options import ModelOptions
from clearance.run.preparation import prepare


def _options(h: float) -> ModelOptions:
    return ModelOptions(timestep=h, segments=144, contact_mode="nominal")


def _point(clearance: float, h: float, nstep: int) -> float:
    """Prepare and step one point as a sweep worker does; returns its final slider x [m]."""
    prepared = prepare(slider_crank(radial_clearance=clearance), _options(h))
    state, ctrl = keyframe_state(prepared.model)
    states, _ = rollout.rollout(
        prepared.model, mujoco.MjData(prepared.model), state[None], np.tile(ctrl, (1, 1, 1)), nstep=nstep
    )
    return float(states[0, -1, 1])


def _best(f, repeats: int = 2) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=8)
    ap.add_argument("--revolutions", type=float, default=10.0)
    ap.add_argument("--timestep-us", type=float, default=5.0)
    ap.add_argument("--out", default=str(Path(__file__).with_suffix(".md")))
    args = ap.parse_args(argv)
    h = args.timestep_us * 1e-6
    nstep = int(round(args.revolutions * 2 * np.pi / rpm(5000) / h))
    clearances = np.linspace(0.1e-3, 0.5e-3, args.points)
    load0 = os.getloadavg()[0]

    t0 = time.perf_counter()
    prepared = [prepare(slider_crank(radial_clearance=float(c)), _options(h)) for c in clearances]
    t_prep = time.perf_counter() - t0
    models = [p.model for p in prepared]
    init = [keyframe_state(p.model) for p in prepared]
    states0 = np.stack([s for s, _ in init])
    ctrl = np.stack([c for _, c in init])[:, None, :]

    def one_by_one():
        return np.stack(
            [
                rollout.rollout(m, mujoco.MjData(m), s[None], c[None], nstep=nstep)[0][0]
                for m, s, c in zip(models, states0, ctrl)
            ]
        )

    def batched(nthread: int):
        datas = [mujoco.MjData(models[0]) for _ in range(nthread)]
        return rollout.rollout(models, datas, states0, ctrl, nstep=nstep)[0]

    t_a, s_a = _best(one_by_one)
    t_b, s_b = _best(lambda: batched(1))
    t_c, s_c = _best(lambda: batched(2))
    same = bool(np.array_equal(s_a, s_b) and np.array_equal(s_a, s_c))

    t0 = time.perf_counter()
    with ProcessPoolExecutor(2, mp_context=get_context("spawn")) as pool:
        final = list(pool.map(_point, [float(c) for c in clearances], [h] * len(clearances), [nstep] * len(clearances)))
    t_d = time.perf_counter() - t0
    same_pool = bool(np.array_equal(np.asarray(final), s_a[:, -1, 1]))
    load1 = os.getloadavg()[0]

    steps = nstep * len(clearances)
    rows = [
        ("A. one rollout call per point, 1 thread", t_a, t_prep + t_a),
        ("B. one rollout call, list of models, 1 thread", t_b, t_prep + t_b),
        ("C. one rollout call, list of models, 2 threads", t_c, t_prep + t_c),
        ("D. spawn pool, 2 workers, prepare + step per point", None, t_d),
    ]
    lines = [
        "# Batched MuJoCo stepping for sweeps: measured",
        "",
        f"Command: `python benchmarks/batch_stepping.py --points {args.points} --revolutions {args.revolutions:g} "
        f"--timestep-us {args.timestep_us:g}`",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPUs, MuJoCo {mujoco.__version__}; measured "
        f"{datetime.date.today().isoformat()}; load average (1 min) {load0:.1f} before, {load1:.1f} after.",
        "",
        f"{args.points} points of a clearance sweep of the default slider-crank (c = "
        f"{clearances[0] * 1e3:.2g} … {clearances[-1] * 1e3:.2g} mm, 5000 rpm, nominal contact, N = 144 fixed so every "
        f"model has the same size signature), h = {args.timestep_us:g} µs, {nstep:,} steps per point "
        f"({steps:,} in all). Preparation (build, compile, sizing) of the {args.points} models: "
        f"{t_prep:.2f} s on one core.",
        "",
        "| way | stepping [s] | steps/s | with preparation [s] | speed-up against A (with preparation) |",
        "|---|---:|---:|---:|---:|",
    ]
    for name, t_step, t_all in rows:
        step_cells = f"{t_step:.2f} | {steps / t_step:,.0f}" if t_step is not None else "– | –"
        lines.append(f"| {name} | {step_cells} | {t_all:.2f} | {(t_prep + t_a) / t_all:.2f}× |")
    lines += [
        "",
        f"A, B and C give bit-identical states: {same}. The pool's final slider positions equal A's: {same_pool}.",
        "",
    ]
    print(write_keeping_reading(args.out, "\n".join(lines) + "\n"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
