"""The speed cost of a retrofit: steps per second of each model at its own time step.

Both models run from their first keyframe under the same control (the sizing motion's), stepped by
`mujoco.rollout` (no Python per step), for about `MIN_WALL` seconds of wall time each
after a short warm-up. The cost of simulating one second of the model's motion is the
ratio of the two models' simulated seconds per wall second: the retrofitted model pays
for its smaller time step and for its contact pairs.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

from clearance.retrofit.motion import control_signal, fired_warnings, initial_data
from clearance.retrofit.play import ControlTable, SineControl

__all__ = ["MIN_WALL", "Clock", "Speed", "SpeedCost", "measure_speed", "run_controlled"]

MIN_WALL = 0.3
"""Wall time each model is stepped for when measuring its speed [s]."""


@dataclass(frozen=True)
class Speed:
    """Stepping speed of one model.

    Attributes:
        steps: steps timed.
        wall: their wall time [s].
        timestep: the model's time step [s].
    """

    steps: int
    wall: float
    timestep: float

    @property
    def steps_per_second(self) -> float:
        """Steps per wall second."""
        return self.steps / self.wall

    @property
    def realtime(self) -> float:
        """Simulated seconds per wall second."""
        return self.steps_per_second * self.timestep


@dataclass(frozen=True)
class SpeedCost:
    """Speeds of the unmodified and the retrofitted model, each at its own step."""

    unmodified: Speed
    retrofitted: Speed

    @property
    def per_step(self) -> float:
        """How many times longer one step of the retrofitted model takes."""
        return self.unmodified.steps_per_second / self.retrofitted.steps_per_second

    @property
    def per_simulated_second(self) -> float:
        """How many times longer one simulated second of the retrofitted model takes."""
        return self.unmodified.realtime / self.retrofitted.realtime


@dataclass
class ControlledRun:
    """A rollout under a control.

    Attributes:
        states: (n, nstate) full-physics states after each step.
        sensordata: (n, nsensordata) sensor values at each step.
        data: the data the rollout stepped (its warning counters are the run's).
        wall: wall time of the rollout [s].
    """

    states: np.ndarray
    sensordata: np.ndarray
    data: mujoco.MjData
    wall: float

    @property
    def warnings(self) -> dict[str, int]:
        """MuJoCo warnings the run raised (name -> count)."""
        return fired_warnings(self.data)


def run_controlled(
    model: mujoco.MjModel, control: SineControl | ControlTable, nstep: int, *, start: float = 0.0
) -> ControlledRun:
    """Step ``model`` ``nstep`` times from its first keyframe under ``control`` (times from ``start``)."""
    data = initial_data(model)
    kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, kind))
    mujoco.mj_getState(model, data, state, kind)
    times = start + np.arange(nstep) * model.opt.timestep
    ctrl = control_signal(model, control, times) if model.nu else None
    t0 = time.perf_counter()
    states, sens = rollout.rollout(model, data, state[None], None if ctrl is None else ctrl[None], nstep=nstep)
    wall = time.perf_counter() - t0
    return ControlledRun(states[0], sens[0], data, wall)


def measure_speed(model: mujoco.MjModel, control: SineControl | ControlTable, *, min_wall: float = MIN_WALL) -> Speed:
    """Steps per second of ``model`` at its own step (about ``min_wall`` s of stepping, after a warm-up)."""
    pilot = run_controlled(model, control, 200)
    rate = 200 / max(pilot.wall, 1e-9)
    n = int(min(max(rate * min_wall, 200), 5_000_000))
    run = run_controlled(model, control, n)
    return Speed(n, run.wall, float(model.opt.timestep))


class Clock:
    """Wall time per named phase, summed over its entries (``with clock("phase"): ...``)."""

    def __init__(self) -> None:
        self.times: dict[str, float] = {}

    @contextlib.contextmanager
    def __call__(self, phase: str) -> Iterator[None]:
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.times[phase] = self.times.get(phase, 0.0) + time.perf_counter() - t0
