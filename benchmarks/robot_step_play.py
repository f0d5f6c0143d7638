"""Backlash at the robot's step against the fine-step exact model: end effector, rebound, impacts, cost.

Arms: the flywheel of benchmarks/backlash_recipe.py, gymnasium's reacher and pusher, robosuite's Panda and
UR5e (from robosuite's start pose) as their files stand and as robosuite runs them (`as_robosuite_runs_it`:
the joint armature, friction loss and damping robosuite's RobotModel adds on loading). For each arm and
robot step (1 and 2 ms), the smallest band represented at every actuated hinge
at that step (`robot_step.smallest_common_band`, as benchmarks/robot_step_feasibility.md finds
it; an arm with none up to 10 degrees gets a row saying so) is given to every actuated hinge
twice: closed by the step-limited stop at the robot's step (`clearance retrofit --robot-step`),
and by the exact stop (the gear mesh's law in the compiled plugin) at its own fine step. Each
runs beside its unmodified twin at its own step, under the sizing motion (`SineControl()`) and
under a second control the fit and the region never saw (`unseen_control`: two sinusoids at
0.43 and 1.7 Hz per actuator, other phases). The end effector (the first site of the deepest body, or the body) deviates from
the twin by |x - x_twin|; its mean, RMS and 95th percentile over the samples at the robot's step
are compared (robot step / exact - 1; the issue's goal: within 10 % under the unseen control).
Rebound: the median over a model's impacts of the band's opening rate at the release over its
closing rate at the onset (closings above 1e-3 rad/s); impacts per second over all bands. Cost:
wall time per simulated second of the robot-step model alone against the unmodified model at
the same step (5 simulated seconds, best of 3 alternating runs; the issue's goal 1.5x).

Writes ``benchmarks/robot_step_play.md`` (the text from ``## Reading`` on is kept).

    python benchmarks/robot_step_play.py [--duration S] [--trajectories K] [--arms NAME ...] [--out FILE]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from clearance.retrofit import Backlash, ControlTable, SineControl
from clearance.retrofit.backlash import BacklashRetrofit, add_backlash
from clearance.retrofit.motion import control_signal, initial_data
from clearance.retrofit.robot_step import add_robot_step_backlash, smallest_common_band

sys.path.insert(0, str(Path(__file__).parent))
from _gym import gym_model
from _tables import write_keeping_reading
from backlash_recipe import FLYWHEEL, _band_torques, _stop_sensors
from retrofit_corpus import CORPUS, START, model_path

OUT = Path(__file__).with_suffix(".md")
COMMAND = "python benchmarks/robot_step_play.py"
STEPS_MS = (1.0, 2.0)
STATS = ("mean", "RMS", "p95")
COST_SECONDS = 5.0
"""Simulated seconds each cost run steps (under `SineControl()`)."""
BLOCKS_PER_SECOND = 1
"""Batch-means blocks per simulated second (one period of the 1 Hz sizing motion)."""
"""Simulated seconds each cost run steps (under `SineControl()`)."""


def arms() -> list[tuple[str, mujoco.MjSpec]]:
    """(name, spec) of each arm; robosuite's from robosuite's start pose (a keyframe), where installed."""
    out = [
        ("flywheel", mujoco.MjSpec.from_string(FLYWHEEL)),
        ("reacher", mujoco.MjSpec.from_file(str(gym_model("reacher")))),
        ("pusher", mujoco.MjSpec.from_file(str(gym_model("pusher")))),
    ]
    for name in ("panda", "ur5e"):
        try:
            spec = mujoco.MjSpec.from_file(str(model_path(*CORPUS[name])))
        except SystemExit as err:
            print(f"{name}: skipped ({err})")
            continue
        spec.add_key(name="start", qpos=list(START[name]))
        out.append((name, spec))
        out.append((f"{name} as robosuite runs it", as_robosuite_runs_it(spec)))
    return out


def as_robosuite_runs_it(spec: mujoco.MjSpec) -> mujoco.MjSpec:
    """A copy of a robosuite arm with the joint defaults robosuite's ``RobotModel`` gives it when it loads it
    (robosuite 1.5.2, robosuite/models/robots/robot_model.py: armature 5/(i+1) kg m^2 on the i-th joint,
    frictionloss and damping 0.1 where the file sets none; read here as 'where the file's value is 0')."""
    out = spec.copy()
    for i, joint in enumerate(out.joints):
        joint.armature = 5.0 / (i + 1) if joint.armature == 0 else joint.armature
        joint.frictionloss = 0.1 if joint.frictionloss == 0 else joint.frictionloss
        damping = np.array(joint.damping, dtype=float)
        if not damping.any():
            damping.flat[0] = 0.1  # the linear coefficient
            joint.damping = damping
    return out


def actuated(spec: mujoco.MjSpec) -> list[str]:
    """The hinges the model's actuators drive."""
    m = spec.copy().compile()
    return [m.joint(int(m.actuator_trnid[k, 0])).name for k in range(m.nu)]


def unseen_control(model: mujoco.MjModel, duration: float, seed: int = 0) -> ControlTable:
    """Two sinusoids per actuator (0.43 and 1.7 Hz; 35 % and 25 % of the control half-range; phases 1.3 k and
    0.7 k^2, plus 2.4 s and 1.1 s for another ``seed``), sampled every 10 ms: a motion the fit and the region
    never saw."""
    t = np.arange(0.0, duration + 0.01, 0.01)
    k = np.arange(model.nu)[None, :]
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    wave = 0.35 * np.sin(2 * np.pi * 0.43 * t[:, None] + 1.3 * k + 2.4 * seed) + 0.25 * np.sin(
        2 * np.pi * 1.7 * t[:, None] + 0.7 * k**2 + 1.1 * seed
    )
    return ControlTable(t, mid[None, :] + half[None, :] * wave, "unseen two-sine control")


def end_effector(twin: mujoco.MjModel, model: mujoco.MjModel) -> tuple[str, int, int]:
    """('site' or 'body', its id in ``model``, in ``twin``): the first site of the twin's deepest body (the last
    link of the longest chain), or the body itself where it has none; found in ``model`` by name (the motor
    bodies move the ids)."""
    depth = np.zeros(twin.nbody, dtype=int)
    for b in range(1, twin.nbody):
        depth[b] = depth[twin.body_parentid[b]] + 1
    body = int(np.argmax(depth))
    sites = [s for s in range(twin.nsite) if twin.site_bodyid[s] == body]
    if sites:
        return "site", int(model.site(twin.site(sites[0]).name).id), sites[0]
    return "body", int(model.body(twin.body(body).name).id), body


@dataclass
class Run:
    """A model beside its twin: the end effector's deviation at the sample times, rebounds, impacts."""

    deviation: np.ndarray
    rebound: float
    impacts: int
    steps: int
    wall: float


def run(
    model: mujoco.MjModel, twin: mujoco.MjModel, control: SineControl | ControlTable, duration: float, sample_dt: float
) -> Run:
    """``model`` and ``twin`` at ``model``'s step for ``duration`` [s]; the deviation sampled every ``sample_dt``."""
    h = float(model.opt.timestep)
    twin.opt.timestep = h
    n = int(round(duration / h))
    u = control_signal(model, control, np.arange(n) * h)
    samples = {int(round(k * sample_dt / h)) for k in range(1, int(round(duration / sample_dt)) + 1)}
    hinges = [model.tendon(t).name for t in range(model.ntendon) if model.tendon(t).name.endswith("__backlash")]
    tendons = [int(model.tendon(t).id) for t in hinges]
    sensors = _stop_sensors(model, [t.removeprefix("clr_").removesuffix("__backlash") for t in hinges])
    kind, ee_m, ee_t = end_effector(twin, model)
    d, dt = initial_data(model), initial_data(twin)
    closing: list[float | None] = [None] * len(tendons)
    rebounds: list[float] = []
    impacts, dev = 0, []
    t0 = time.perf_counter()
    for i in range(1, n + 1):
        d.ctrl[:] = u[i - 1]
        dt.ctrl[:] = u[i - 1]
        mujoco.mj_step(model, d)
        mujoco.mj_step(twin, dt)
        rows = _band_torques(d, tendons, sensors)
        for k, t in enumerate(tendons):
            rate = abs(float(d.ten_velocity[t]))
            if k in rows:
                if closing[k] is None:
                    closing[k] = rate
                    impacts += 1
            elif closing[k] is not None:
                c = closing[k]
                if c is not None and c > 1e-3:
                    rebounds.append(rate / c)
                closing[k] = None
        if i in samples:
            x, xt = (d.site_xpos, dt.site_xpos) if kind == "site" else (d.xpos, dt.xpos)
            dev.append(float(np.linalg.norm(x[ee_m] - xt[ee_t])))
    return Run(
        np.array(dev), float(np.median(rebounds)) if rebounds else math.nan, impacts, n, time.perf_counter() - t0
    )


def stats(x: np.ndarray) -> tuple[float, float, float]:
    """(mean, RMS, 95th percentile) of ``x``."""
    return float(np.mean(x)), float(np.sqrt(np.mean(x * x))), float(np.percentile(x, 95))


def spread(x: np.ndarray, blocks: int) -> np.ndarray:
    """Batch-means standard error of (mean, RMS, p95) of ``x``: the statistic per block of whole seconds, the
    standard deviation over the blocks over sqrt(blocks)."""
    per = np.array([stats(b) for b in np.array_split(x, blocks)])
    return per.std(axis=0, ddof=1) / math.sqrt(blocks)


def ensemble_row(
    name: str,
    step_ms: float,
    band: float,
    coarse: BacklashRetrofit,
    exact: BacklashRetrofit,
    duration: float,
    trajectories: int,
) -> str:
    """A row of the mean statistics over ``trajectories`` unseen controls (seeds 0..K-1), with twice the standard
    error of the difference over the trajectories."""
    h = step_ms * 1e-3
    pairs = []
    for seed in range(trajectories):
        control = unseen_control(coarse.model, duration, seed)
        pairs.append(
            (
                stats(run(coarse.model, coarse.twin, control, duration, h).deviation),
                stats(run(exact.model, exact.twin, control, duration, h).deviation),
            )
        )
    c, e = (np.array([p[i] for p in pairs]) for i in (0, 1))
    err = c.mean(axis=0) / e.mean(axis=0) - 1
    both = 2 * np.hypot(c.std(axis=0, ddof=1), e.std(axis=0, ddof=1)) / math.sqrt(trajectories) / e.mean(axis=0)
    return (
        f"| {name} | {step_ms:g} | {band:g}' | unseen x {trajectories} (mean) | "
        + " / ".join(f"{1e3 * x:.3g}" for x in c.mean(axis=0))
        + " | "
        + " / ".join(f"{1e3 * x:.3g}" for x in e.mean(axis=0))
        + " | "
        + " / ".join(f"{100 * x:+.0f} %" for x in err)
        + " | "
        + " / ".join(f"{100 * x:.0f} %" for x in both)
        + " (over the trajectories) | | | | |"
    )


def cost(model: mujoco.MjModel, twin: mujoco.MjModel, step: float) -> tuple[float, float]:
    """Wall time per simulated second [s] of ``model`` and of ``twin`` at ``step`` (best of 3 alternating)."""
    best = [math.inf, math.inf]
    for _ in range(3):
        for j, m in enumerate((model, twin)):
            m.opt.timestep = step
            n = int(round(COST_SECONDS / step))
            u = control_signal(m, SineControl(), np.arange(n) * step)
            d = initial_data(m)
            t0 = time.perf_counter()
            for i in range(n):
                d.ctrl[:] = u[i]
                mujoco.mj_step(m, d)
            best[j] = min(best[j], (time.perf_counter() - t0) / COST_SECONDS)
    return best[0], best[1]


def rows_for(name: str, spec: mujoco.MjSpec, step_ms: float, duration: float, trajectories: int) -> list[str]:
    """The table's rows of one arm at one step."""
    hinges = actuated(spec)
    h = step_ms * 1e-3
    probe = add_robot_step_backlash(spec, {j: Backlash.from_arcmin(10) for j in hinges}, robot_step=h, refuse=False)
    band = smallest_common_band(probe.sizing, probe.stop)
    if band is None:
        fastest = max(b.closing_speed for b in probe.bands.values())
        return [
            f"| {name} | {step_ms:g} | none up to 600' (fastest closing {fastest:.3g} rad/s at 10') | - | - | - | - | - "
            "| - | - | - | - |"
        ]
    coarse = add_robot_step_backlash(spec, {j: Backlash.from_arcmin(band) for j in hinges}, robot_step=h)
    exact = add_backlash(spec, {j: Backlash.from_arcmin(band, stop="exact") for j in hinges})
    lines = []
    for label, control in (("sizing", SineControl()), ("unseen", unseen_control(coarse.retrofit.model, duration))):
        c = run(coarse.retrofit.model, coarse.retrofit.twin, control, duration, h)
        e = run(exact.model, exact.twin, control, duration, h)
        sc, se = stats(c.deviation), stats(e.deviation)
        err = [x / y - 1 for x, y in zip(sc, se, strict=True)]
        blocks = max(2, int(round(duration * BLOCKS_PER_SECOND)))
        both = 2 * np.hypot(spread(c.deviation, blocks), spread(e.deviation, blocks)) / np.array(se)
        lines.append(
            f"| {name} | {step_ms:g} | {band:g}' | {label} | "
            + " / ".join(f"{1e3 * x:.3g}" for x in sc)
            + " | "
            + " / ".join(f"{1e3 * x:.3g}" for x in se)
            + " | "
            + " / ".join(f"{100 * x:+.0f} %" for x in err)
            + " | "
            + " / ".join(f"{100 * x:.0f} %" for x in both)
            + f" | {c.rebound:.3f} / {e.rebound:.3f} | {c.impacts / duration:.0f} / {e.impacts / duration:.0f} | "
            f"{exact.model.opt.timestep:.2g} | {e.wall:.1f} |"
        )
        print(lines[-1], flush=True)
    if trajectories > 1:
        lines.append(ensemble_row(name, step_ms, band, coarse.retrofit, exact, duration, trajectories))
        print(lines[-1], flush=True)
    mine, plain = cost(coarse.retrofit.model, coarse.retrofit.twin, h)
    lines.append(
        f"| {name} | {step_ms:g} | {band:g}' | cost | robot step {mine:.3f} s, unmodified {plain:.3f} s per simulated "
        f"second: {mine / plain:.2f}x | | | | | | | |"
    )
    print(lines[-1], flush=True)
    return lines


def main() -> None:
    """Run every arm at every step and write the table."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, default=6.0, help="seconds of each motion (default 6)")
    p.add_argument(
        "--trajectories",
        type=int,
        default=1,
        help="unseen controls per row (seeds 0..K-1); K > 1 adds a row of their mean statistics (default 1)",
    )
    p.add_argument("--arms", nargs="+", default=None, help="only these arms (default: all)")
    p.add_argument("--out", type=Path, default=OUT, help=f"the table (default {OUT.name} beside this script)")
    args = p.parse_args()
    load = os.getloadavg()
    t0 = time.perf_counter()
    head = [
        "# Backlash at the robot's step against the fine-step exact model",
        "",
        "```",
        COMMAND,
        "```",
        "",
        f"{time.strftime('%Y-%m-%d')}; MuJoCo {mujoco.__version__}; load average at the start {load[0]:.2f} "
        f"{load[1]:.2f} {load[2]:.2f} (2 cores shared: wall times are indicative). {args.duration:g} s of each "
        "motion; mesh law K = 1e4 N m/rad, e = 0.8 (the defaults); every actuated hinge given the arm's smallest "
        "band represented at the step.",
        "",
        "End-effector deviation from the twin [mm] as mean / RMS / p95 over the samples at the robot's step; "
        "robot step against exact; error = robot step / exact - 1; spread: twice the combined batch-means standard "
        "error of the two runs' statistics (blocks of 1 s, one period of the sizing motion), over the exact "
        "statistic: the sampling scatter a difference of this length has.",
        "",
        "| arm | step [ms] | band | control | robot step: mean / RMS / p95 [mm] | exact: mean / RMS / p95 [mm] | "
        "error | spread: 2 SE of the difference | rebound (robot step / exact) | impacts per s (robot step / exact) | "
        "exact step [s] | exact run + twin [s] |",
        "|---|---:|---:|---|---|---|---|---|---|---|---:|---:|",
    ]
    body = []
    for name, spec in arms():
        if args.arms is not None and name not in args.arms:
            continue
        for step_ms in STEPS_MS:
            body += rows_for(name, spec, step_ms, args.duration, args.trajectories)
    tail = ["", f"Whole run {time.perf_counter() - t0:.0f} s."]
    command = " ".join([COMMAND, *sys.argv[1:]])
    head[3] = command
    write_keeping_reading(args.out, "\n".join(head + body + tail) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
