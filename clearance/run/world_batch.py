"""Many worlds of one structure stepped together: one `mujoco.rollout` call, no Python per step.

The worlds are copies of one compiled model whose fields differ (the randomised play of
`clearance.retrofit.randomised_play`, or any other per-model values MuJoCo reads at each step);
`mujoco.rollout` steps them over a pool of ``nthread`` threads, each world from its own initial
state under its own controls.

A world that fails stops where it fails: MuJoCo's rollout holds a world's state from its first
warning on (a non-finite or huge acceleration; MuJoCo may have reset it to its start), so its
time stops advancing. `step_worlds` finds such worlds from the time column (and any non-finite
row) and refuses the batch, naming them and the time their failing step began.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

from clearance.checks import of_type
from clearance.retrofit.motion import initial_data

__all__ = ["WorldBatch", "WorldFailure", "initial_states", "step_worlds"]

_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS


class WorldFailure(RuntimeError):
    """Worlds of a batch that stopped (MuJoCo warned and held their state).

    Attributes:
        worlds: indices of the worlds that stopped. times: the simulated time each stopped at [s].
    """

    def __init__(self, message: str, *, worlds: tuple[int, ...], times: tuple[float, ...]) -> None:
        super().__init__(message)
        self.worlds = worlds
        self.times = times


@dataclass
class WorldBatch:
    """What a batch of worlds did.

    Attributes:
        state: (n_worlds, n_steps, nstate) full-physics state after each step (MuJoCo's
            ``mjSTATE_FULLPHYSICS``: time, qpos, qvel, act, ...).
        sensordata: (n_worlds, n_steps, nsensordata) sensors at each step.
        timestep: the step [s]. wall_time: the rollout's wall time [s]. nthread: threads used.
    """

    state: np.ndarray
    sensordata: np.ndarray
    timestep: float
    wall_time: float
    nthread: int

    def qpos(self, model: mujoco.MjModel) -> np.ndarray:
        """(n_worlds, n_steps, nq) joint positions, read from the state rows."""
        return self.state[:, :, 1 : 1 + model.nq]


def initial_states(models: Sequence[mujoco.MjModel]) -> np.ndarray:
    """(n_worlds, nstate) each world's state at its model's first keyframe (qpos0 where it has none)."""
    out = np.empty((len(models), mujoco.mj_stateSize(models[0], _STATE)))
    for k, model in enumerate(models):
        data = initial_data(model)
        mujoco.mj_forward(model, data)
        mujoco.mj_getState(model, data, out[k], _STATE)
    return out


def step_worlds(
    models: Sequence[mujoco.MjModel],
    *,
    control: np.ndarray,
    initial_state: np.ndarray | None = None,
    nthread: int | None = None,
) -> WorldBatch:
    """Step every world of ``models`` together for as many steps as ``control`` has rows.

    Args:
        models: the worlds, compiled models of one structure (`PlayWorlds.models`).
        control: (n_worlds or 1, n_steps, nu) the actuators' controls at each step.
        initial_state: (n_worlds or 1, nstate) full-physics start states; None: each model's
            first keyframe (`initial_states`).
        nthread: threads; None: as many as the machine's cores, at most one per world.

    Returns:
        The worlds' states and sensors at every step.

    Raises:
        WrongTypeError: ``models`` not a sequence of MjModel (also a ValueError).
        ValueError: before any step, for an empty batch, models of different structure, or a
            control or state of the wrong shape (each named with the shape expected).
        WorldFailure: worlds whose state stopped (MuJoCo warned), named with their times.
    """
    of_type("models", models, Sequence, "a sequence of compiled mujoco.MjModel (PlayWorlds.models)")
    if not models:
        raise ValueError("models must hold at least one world (got an empty sequence)")
    for k, model in enumerate(models):
        of_type(f"models[{k}]", model, mujoco.MjModel, "a compiled mujoco.MjModel")
    first = models[0]
    signature = (first.nq, first.nv, first.nu, first.na, first.nsensordata, first.ntendon, first.nbody)
    for k, model in enumerate(models):
        if (model.nq, model.nv, model.nu, model.na, model.nsensordata, model.ntendon, model.nbody) != signature:
            raise ValueError(f"models[{k}] has another structure than models[0] (nq, nv, nu, ...): one model, copied")
    n = len(models)
    ctrl = np.asarray(control, dtype=float)
    if ctrl.ndim != 3 or ctrl.shape[0] not in (1, n) or ctrl.shape[2] != first.nu or ctrl.shape[1] < 1:
        raise ValueError(f"control must have shape ({n} or 1, n_steps >= 1, {first.nu}) (got {ctrl.shape})")
    start = initial_states(models) if initial_state is None else np.asarray(initial_state, dtype=float)
    nstate = mujoco.mj_stateSize(first, _STATE)
    if start.ndim != 2 or start.shape[0] not in (1, n) or start.shape[1] != nstate:
        raise ValueError(f"initial_state must have shape ({n} or 1, {nstate}) (got {start.shape})")
    threads = min(n, os.cpu_count() or 1) if nthread is None else nthread
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise ValueError(f"nthread must be an integer >= 1 (got {nthread!r})")
    datas = [mujoco.MjData(first) for _ in range(threads)]
    t0 = time.perf_counter()
    state, sens = rollout.rollout(list(models), datas, start, ctrl)
    wall = time.perf_counter() - t0
    h = np.array([float(m.opt.timestep) for m in models])
    steps = np.arange(1, ctrl.shape[1] + 1)
    expected = np.broadcast_to(start[:, :1], (n, 1)) + h[:, None] * steps[None, :]
    stalled = np.abs(state[:, :, 0] - expected) > 0.5 * h[:, None]
    stalled |= ~np.isfinite(state).all(axis=2)
    bad = tuple(int(k) for k in np.nonzero(stalled.any(axis=1))[0])
    if bad:
        # the time a world had reached when its failing step began
        times = tuple(float(expected[k, int(np.argmax(stalled[k]))] - h[k]) for k in bad)
        shown = ", ".join(f"{k} (t = {t:.4g} s)" for k, t in zip(bad[:8], times[:8], strict=True))
        raise WorldFailure(
            f"{len(bad)} of {n} worlds stopped (MuJoCo warned: a non-finite or huge acceleration): worlds {shown}"
            + (" ..." if len(bad) > 8 else ""),
            worlds=bad,
            times=times,
        )
    return WorldBatch(state, sens, float(first.opt.timestep), wall, threads)
