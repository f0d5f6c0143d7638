"""64 worlds of gymnasium's pusher, each with its own backlash at every actuated hinge, at 2 ms.

    python examples/randomised_backlash.py [--worlds 64] [--seconds 10] [--threads 2]

What a training loop over randomised dynamics does with play, in four steps:

1. the pusher (gymnasium's ``pusher.xml``; ``pip install gymnasium``) at a 2 ms step gets
   backlash at its seven actuated hinges (`clearance.retrofit.add_backlash`): a motor side, a
   load side and a band of +-b between them, closed by a tendon limit (stock MJCF);
2. `clearance.retrofit.randomised_play.randomise_play` copies the compiled model once per
   world and draws each world's bands (b from 1' to 10') and stops (stiffness and damping from
   half to twice the model's own), refusing before any draw a range whose stop would be unstable
   at 2 ms;
3. `clearance.run.world_batch.step_worlds` steps every world together in one `mujoco.rollout`
   call under the same sinusoidal drive (`SineControl`: half of each control range at 1 Hz);
4. the worlds differ as drawn: the tool tip's spread across worlds and each world's widest
   opening of its shoulder band are printed, with the wall time.

The stop here is MuJoCo's own tendon limit as the two-hinge recipe writes it (``stop="recipe"``):
at 2 ms that is what runs, and it is soft (the load sinks past b; benchmarks/backlash_recipe.md).
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from clearance.retrofit import Backlash, SineControl, add_backlash
from clearance.retrofit.motion import control_signal
from clearance.retrofit.randomised_play import PlayDistribution, PlayWorlds, Uniform, randomise_play, stop_spring
from clearance.run.world_batch import WorldBatch, step_worlds

STEP = 0.002
"""The robot's own time step [s]."""

BAND_ARCMIN = (1.0, 10.0)
"""Range of each band's half-width b [arc-minutes]."""

STOP_SCALE = (0.5, 2.0)
"""Range of each stop's stiffness and damping, as factors of the model's own."""

TIP = "tips_arm"
"""The pusher's tool tip (a body)."""


def pusher_path() -> Path:
    """gymnasium's pusher.xml (found without importing gymnasium)."""
    spec = importlib.util.find_spec("gymnasium")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("gymnasium is not installed: pip install gymnasium")
    return Path(next(iter(spec.submodule_search_locations))) / "envs" / "mujoco" / "assets" / "pusher.xml"


def backlashed_pusher() -> mujoco.MjModel:
    """The pusher at `STEP` with a tool-tip position sensor and 5' of backlash at every actuated hinge."""
    spec = mujoco.MjSpec.from_file(str(pusher_path()))
    spec.option.timestep = STEP
    spec.add_sensor(name="tip", type=mujoco.mjtSensor.mjSENS_FRAMEPOS, objtype=mujoco.mjtObj.mjOBJ_XBODY, objname=TIP)
    model = spec.compile()
    hinges = [model.joint(int(model.actuator_trnid[k, 0])).name for k in range(model.nu)]
    band = Backlash.from_arcmin(5.0, stop="recipe")
    return add_backlash(spec, {hinge: band for hinge in hinges}).model


def worlds_of(model: mujoco.MjModel, n_worlds: int, seed: int = 0) -> PlayWorlds:
    """``n_worlds`` copies of ``model`` with their bands and stops drawn (module docstring)."""
    lo, hi = (math.radians(a / 60.0) for a in BAND_ARCMIN)
    plan = {}
    for t in range(model.ntendon):
        name = model.tendon(t).name
        if name.endswith("__backlash"):
            k, b = stop_spring(model, t)
            plan[name[len("clr_") : -len("__backlash")]] = PlayDistribution(
                size=Uniform(lo, hi),
                stiffness=Uniform(STOP_SCALE[0] * k, STOP_SCALE[1] * k, log=True),
                damping=Uniform(STOP_SCALE[0] * b, STOP_SCALE[1] * b, log=True),
            )
    return randomise_play(model, n_worlds=n_worlds, backlash=plan, seed=seed)


@dataclass(frozen=True)
class Outcome:
    """What one batch did: the worlds, their run, and the tool tip's spread across worlds [m]."""

    worlds: PlayWorlds
    batch: WorldBatch
    tip_spread: float


def run(n_worlds: int = 64, seconds: float = 10.0, threads: int = 2, seed: int = 0) -> Outcome:
    """Build, randomise and step the worlds; the tip's spread is its RMS distance from the worlds' mean."""
    model = backlashed_pusher()
    worlds = worlds_of(model, n_worlds, seed)
    steps = int(round(seconds / STEP))
    control = control_signal(model, SineControl(), np.arange(steps) * STEP)[None]
    batch = step_worlds(worlds.models, control=control, nthread=threads)
    adr = int(model.sensor_adr[model.sensor("tip").id])
    tip = batch.sensordata[:, :, adr : adr + 3]
    spread = float(np.sqrt(np.mean(np.sum((tip - tip.mean(axis=0)) ** 2, axis=2))))
    return Outcome(worlds, batch, spread)


def main(argv: list[str] | None = None) -> int:
    """Run the example and print what the worlds did."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=64, help="how many worlds (default: 64)")
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per world (default: 10)")
    parser.add_argument("--threads", type=int, default=2, help="rollout threads (default: 2)")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    out = run(args.worlds, args.seconds, args.threads)
    total = time.perf_counter() - t0
    model, w = out.worlds.models[0], out.worlds
    shoulder = next(i for i, t in enumerate(w.tendons) if t.hinge == "r_shoulder_pan_joint")
    load, motor = model.joint("r_shoulder_pan_joint").qposadr[0], model.joint("r_shoulder_pan_joint__motor").qposadr[0]
    qpos = out.batch.qpos(model)
    widest = np.abs(qpos[:, :, load] - qpos[:, :, motor]).max(axis=1)
    print(f"{args.worlds} worlds x {args.seconds:g} s at {STEP * 1e3:g} ms, {out.batch.nthread} threads")
    print(
        f"rollout {out.batch.wall_time:.2f} s; with building and drawing {total:.2f} s (load {os.getloadavg()[0]:.2f})"
    )
    print(f"tool tip's spread across worlds (RMS over the run): {out.tip_spread * 1e3:.3f} mm")
    print("world  shoulder b [']  its widest opening [']  stop K [N m/rad]")
    for k in range(min(args.worlds, 6)):
        b = math.degrees(w.size[k, shoulder]) * 60
        print(f"{k:5d}  {b:14.2f}  {math.degrees(widest[k]) * 60:22.2f}  {w.stiffness[k, shoulder]:16.4g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
