"""`simulate`: run a mechanism in MuJoCo with `mujoco.rollout`, no Python per step.

The run is stepped in chunks (bounded memory); after each chunk MuJoCo's warning counters,
non-finite values and every journal's penetration are checked. A run that goes unstable
stops with `SimulationError`, which names the time, the joint (when a journal went beyond
its bound; None when the cause is the model's state as a whole) and a remedy, and carries
the result computed up to the last good step: the rows before the first bad one.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable, Mapping

import mujoco
import numpy as np
from mujoco import rollout

from clearance.checks import finite
from clearance.contact_plugin.onsets import record_closed_contacts
from clearance.model import DriveKind, Mechanism
from clearance.options import ContactParameters, ModelOptions
from clearance.results import SimulationResult
from clearance.run.preparation import PreparedModel, check_run_arguments, prepare
from clearance.run.readout import read_sensors
from clearance.version import __version__

__all__ = [
    "SimulationError",
    "StepFailure",
    "default_duration",
    "model_stepper",
    "simulate",
    "simulate_prepared",
    "start_data",
]

_Stepper = Callable[[np.ndarray, int], tuple[np.ndarray, np.ndarray, mujoco.MjData]]
"""(controls (1 or n, nu), n) -> (states (n, nstate), sensors (n, nsensordata), data) of n steps."""


class SimulationError(RuntimeError):
    """A run diverged.

    Attributes:
        partial: the result up to the last good step (None when there is none).
        time: time of the first bad step [s].
        joint: the clearance joint whose journal went beyond its divergence bound, or None
            when the cause cannot be tied to one joint (a non-finite state, a MuJoCo warning).
    """

    def __init__(
        self,
        message: str,
        partial: SimulationResult | None = None,
        *,
        time: float | None = None,
        joint: str | None = None,
    ) -> None:
        super().__init__(message)
        self.partial = partial
        self.time = time
        self.joint = joint


def default_duration(mechanism: Mechanism, revolutions: float = 3.0) -> float:
    """``revolutions`` periods of the slowest prescribed drive [s] (1 s if none)."""
    period = mechanism.drive_period
    return revolutions * period if period is not None else 1.0


def _controls(mechanism: Mechanism, times: np.ndarray) -> np.ndarray:
    """(len(times), n_drives) actuator controls: drive speed, or torque."""
    out = np.empty((len(times), len(mechanism.drives)))
    for k, d in enumerate(mechanism.drives):
        out[:, k] = d.torque if d.kind is DriveKind.TORQUE else d.rate(times)
    return out


def _constant_controls(mechanism: Mechanism) -> bool:
    return all(d.kind is not DriveKind.MOTION_LAW for d in mechanism.drives)


def simulate(
    mechanism: Mechanism,
    *,
    duration: float | None = None,
    options: ModelOptions | None = None,
    output_interval: float | None = None,
    contact: dict[str, ContactParameters] | None = None,
    progress: bool | Callable[[float], None] = False,
    chunk_steps: int = 100_000,
    initial_eccentricity: Mapping[str, tuple[float, float]] | None = None,
) -> SimulationResult:
    """Simulate a mechanism with clearance joints in MuJoCo.

    Args:
        mechanism: the mechanism.
        duration: simulated time [s]; default 3 periods of the slowest drive.
        options: numerical options (default `ModelOptions()`).
        output_interval: interval of stored rows [s]; default every step. Peaks and event
            statistics should be taken from full-rate data: keep the default for them.
        contact: per-joint contact parameters overriding the contact mode's.
        progress: True for a progress bar on stderr, or a callable receiving the fraction
            done (0..1) after each chunk.
        chunk_steps: steps per `mujoco.rollout` call (memory bound).
        initial_eccentricity: clearance joint name -> (e_x, e_y) [m] journal centre in the
            bearing frame at t = 0 (default: centred). The other coordinates change as
            little as the loop closures and drive angles allow; velocities stay ideal.

    Returns:
        SimulationResult (times, outputs, per-joint eccentricity / penetration / force,
        drive angle / speed / torque, link poses, closure violation, metadata).

    Raises:
        TypeError: an argument of the wrong type (a name for the mechanism, a dict for the
            options), naming it (`clearance.checks.WrongTypeError`, also a ValueError).
        ValueError: bad arguments (before any work).
        AssemblyError: the mechanism cannot be assembled at t = 0.
        TimeStepError: the time step is too large for the contact stiffness.
        SimulationError: the run diverged (partial result attached).
    """
    check_run_arguments(mechanism, options)
    options = options or ModelOptions()
    if duration is None:
        duration = default_duration(mechanism)
    if not finite("duration", duration) > 0:
        raise ValueError(f"duration must be a positive number of seconds (got {duration!r})")
    if output_interval is not None and not (np.isfinite(output_interval) and output_interval > 0):
        raise ValueError(f"output_interval must be > 0 s (got {output_interval!r})")
    if not isinstance(chunk_steps, int) or chunk_steps < 1:
        raise ValueError(f"chunk_steps must be a positive integer (got {chunk_steps!r})")
    _step_count(duration, options.timestep)
    if initial_eccentricity is not None:
        names = {j.name for j in mechanism.clearance_joints}
        for k, v in dict(initial_eccentricity).items():
            if k not in names:
                raise ValueError(
                    f"initial_eccentricity: '{k}' is not a clearance joint (clearance joints: {sorted(names)})"
                )
            if not (len(v) == 2 and all(np.isfinite(x) for x in v)):
                raise ValueError(f"initial_eccentricity['{k}'] must be (e_x, e_y) in metres (got {v!r})")
    prepared = prepare(mechanism, options, contact=contact)
    return simulate_prepared(
        prepared,
        duration=duration,
        output_interval=output_interval,
        progress=progress,
        chunk_steps=chunk_steps,
        initial_eccentricity=initial_eccentricity,
    )


def simulate_prepared(
    prepared: PreparedModel,
    *,
    duration: float,
    output_interval: float | None = None,
    progress: bool | Callable[[float], None] = False,
    chunk_steps: int = 100_000,
    initial_eccentricity: Mapping[str, tuple[float, float]] | None = None,
) -> SimulationResult:
    """Run an already prepared model (see `simulate` for the arguments)."""
    model, mech = prepared.model, prepared.mechanism
    h = model.opt.timestep
    nstep = _step_count(duration, h)
    every = 1 if output_interval is None else max(1, int(round(output_interval / h)))
    qpos0 = _initial_qpos(prepared, initial_eccentricity)
    step = _rollout_stepper(prepared, qpos0)
    constant = _constant_controls(mech)
    bar = _progress(progress, nstep)
    parts: list[SimulationResult] = []
    angles: np.ndarray | None = None  # the links' unwrapped angles in the last full-rate row
    t0 = _time.perf_counter()
    done = 0
    while done < nstep:
        n = min(chunk_steps, nstep - done)
        times = (done + np.arange(n)) * h
        ctrl = _controls(mech, times[:1] if constant else times)
        failure = None
        try:
            states, sens, data = step(ctrl, n)
        except _StepFailure as fail:
            states, sens, data, failure = fail.states, fail.sens, fail.data, fail.reason
        part = read_sensors(prepared, times[: len(sens)], sens, states[: len(sens)], angles_before=angles)
        if len(part):
            angles = part.link_poses[-1, :, 2]
        # a stepper that stopped early has placed its warning at the step: only rows before it came back
        bad = _first_bad(prepared, data, part, states, sens, warnings=failure is None)
        if failure is not None and (bad is None or bad[0] >= len(sens)):
            # the stepper stopped at its first bad step: all rows it returned are good
            bad = (len(sens), None, failure, _remedy(prepared))
        if bad is not None:
            idx, joint, why, remedy = bad
            parts.append(_thin(part.sliced(slice(0, idx)), done, every))
            result = _finish(parts, prepared, t0, nstep_done=done + idx, every=every)
            tb = float(times[min(idx, n - 1)])
            raise SimulationError(
                f"simulation diverged at t = {tb:.6g} s{f' at joint {joint!r}' if joint else ''}: {why}. "
                f"Remedy: {remedy}. The result up to t = {tb:.6g} s is attached as .partial.",
                result,
                time=tb,
                joint=joint,
            )
        parts.append(_thin(part, done, every))
        done += n
        bar(done)
    bar(None)
    return _finish(parts, prepared, t0, nstep_done=nstep, every=every)


def _step_count(duration: float, h: float) -> int:
    """Steps of ``h`` [s] in ``duration`` [s], at least one."""
    nstep = int(round(duration / h))
    if nstep < 1:
        raise ValueError(f"duration must be at least half a time step ({h / 2:g} s; got {duration!r} s)")
    return nstep


def _thin(part: SimulationResult, first_step: int, every: int) -> SimulationResult:
    """Rows of a chunk starting at step ``first_step`` whose step index is a multiple of ``every``.

    Thinning each chunk as it comes keeps memory bounded by the stored rows, not the steps.
    """
    return part if every == 1 else part.sliced(slice((-first_step) % every, None, every))


class _StepFailure(Exception):
    """A stepper stopped at its first bad step; carries the rows before it and the reason."""

    def __init__(self, states: np.ndarray, sens: np.ndarray, data: mujoco.MjData, reason: str) -> None:
        super().__init__(reason)
        self.states, self.sens, self.data, self.reason = states, sens, data, reason


def _initial_qpos(prepared: PreparedModel, targets: Mapping[str, tuple[float, float]] | None) -> np.ndarray | None:
    """qpos with journals moved to ``targets`` (None: the keyframe's)."""
    if not targets:
        return None
    from clearance.run.initial_state import offset_journals

    model, mech = prepared.model, prepared.mechanism
    for k, v in targets.items():
        c = mech.joint(k).require_clearance().radial_clearance
        lim = prepared.sizing[k].penetration_limit
        if np.hypot(*v) > c + lim:
            raise ValueError(
                f"initial_eccentricity['{k}'] = {tuple(v)} m puts the journal {np.hypot(*v) - c:.3g} m into its "
                f"bearing, beyond the divergence bound {lim:.3g} m; expected |e| <= c + bound = {c + lim:.4g} m"
            )
    return offset_journals(
        model,
        model.key_qpos[0],
        targets,
        bearings={k: mech.joint(k).require_clearance().radial_clearance for k in targets},
        fixed_joints=[d.joint for d in mech.drives],
    )


def start_data(model: mujoco.MjModel, qpos0: np.ndarray | None = None) -> mujoco.MjData:
    """The state a run starts from: keyframe 0 (``qpos0`` in place of its positions when given),
    its velocities taken back half a step for the semi-implicit integrators.

    MuJoCo's Euler and implicit integrators update velocities first and positions with the new
    velocities, so the velocity they carry into step k is the one of the interval before t_k.
    Starting from the velocities at t = 0 (the keyframe's ideal ones) puts the whole run half a
    step of acceleration off, an error of first order in the step (a journal released under
    gravity met its bearing 94 ns late per µs of step). The start is v0 - (h/2) a0 instead, a0
    MuJoCo's acceleration at the start state, projected (in the metric of M) onto the
    velocities that keep the equality constraints' rows at rest: MuJoCo's constraint rows hold
    J(q_k) v_k at 0, so a velocity along them is no half-step lag but a violation the stiff loop
    closures would throw back. RK4's states are synchronous: it starts from the keyframe's
    velocities.

    Args:
        model: the compiled model (its time step and integrator are the run's).
        qpos0: (nq,) positions in place of the keyframe's, or None.
    """
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    if qpos0 is not None:
        data.qpos[:] = qpos0
    if model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4:
        return data
    # a0 with every force at the state's own rates: RK4's evaluation (the compiled contacts'
    # in-step treatment would give the mean over the coming step instead)
    integrator = model.opt.integrator
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    try:
        mujoco.mj_forward(model, data)
    finally:
        model.opt.integrator = integrator
    record_closed_contacts(model, data)  # a journal starting in contact: δ̇⁻ at the state's rates
    v = data.qvel - 0.5 * model.opt.timestep * data.qacc
    rows = _equality_rows(model, data)
    if len(rows):
        minv_jt = np.empty((len(rows), model.nv))
        mujoco.mj_solveM(model, data, minv_jt, rows)
        v -= minv_jt.T @ np.linalg.solve(rows @ minv_jt.T, rows @ v)
    data.qvel[:] = v
    return data


def _equality_rows(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """(n, nv) the equality constraints' rows of the constraint Jacobian at ``data``'s state."""
    eq = np.flatnonzero(data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    if not len(eq):
        return np.zeros((0, model.nv))
    if mujoco.mj_isSparse(model):
        dense = np.zeros((data.nefc, model.nv))
        mujoco.mju_sparse2dense(dense, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind)
    else:
        dense = data.efc_J[: data.nefc * model.nv].reshape(data.nefc, model.nv)
    rows = dense[eq]
    return rows[np.linalg.norm(rows, axis=1) > 0]  # a planar connect's out-of-plane row is empty


def _rollout_stepper(prepared: PreparedModel, qpos0: np.ndarray | None = None) -> _Stepper:
    """Chunks with `mujoco.rollout` (no Python per step)."""
    return model_stepper(prepared.model, start_data(prepared.model, qpos0))


StepFailure = _StepFailure
"""Raised by a `model_stepper` at its first bad step (attributes states, sens, data, reason)."""


def model_stepper(model: mujoco.MjModel, data: mujoco.MjData) -> _Stepper:
    """Chunks of any model from ``data``'s state with `mujoco.rollout`; a chunk that raises a
    MuJoCo warning stops at its first warning step with `StepFailure` (the rows before it).

    Chunks equal one long rollout bit for bit by construction: each chunk starts from the
    full-physics state and the constraint solver's warm start (``qacc_warmstart``, not part
    of ``mjSTATE_FULLPHYSICS``) that the previous chunk ended with; a rollout given no warm
    start would start every chunk's solver from zero.
    """
    kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, kind))
    mujoco.mj_getState(model, data, state, kind)
    box = {"state": state, "warmstart": data.qacc_warmstart.copy()}

    def step(ctrl: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, mujoco.MjData]:
        start, warm, before = box["state"], box["warmstart"], _warning_count(data)
        states, sens = rollout.rollout(model, data, start[None], ctrl[None], nstep=n, initial_warmstart=warm[None])
        states, sens = states[0], sens[0]
        box["state"], box["warmstart"] = states[-1], data.qacc_warmstart.copy()
        if _warning_count(data) > before and np.isfinite(states).all() and np.isfinite(sens).all():
            # a warning without a non-finite value (a huge acceleration, a full contact
            # buffer) says nothing about when: step the chunk again to find the step
            k, fired = _first_warning_step(model, start, warm, ctrl, n)
            raise _StepFailure(states[:k], sens[:k], data, f"MuJoCo raised warnings {fired}")
        return states, sens, data

    return step


def _warning_count(data: mujoco.MjData) -> int:
    return int(sum(data.warning[i].number for i in range(mujoco.mjtWarning.mjNWARNING.value)))


def _first_warning_step(
    model: mujoco.MjModel, state: np.ndarray, warmstart: np.ndarray, ctrl: np.ndarray, n: int
) -> tuple[int, list[str]]:
    """(index of the first step of a chunk that raises a MuJoCo warning, the warnings' names).

    Replays the chunk from its initial full-physics state and warm start with `mujoco.mj_step`
    (the stepping rollout does; only on this error path). ``ctrl``: (1, nu) held or (n, nu).
    """
    data = mujoco.MjData(model)
    mujoco.mj_setState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    data.qacc_warmstart[:] = warmstart
    for k in range(n):
        data.ctrl[:] = ctrl[min(k, len(ctrl) - 1)]
        mujoco.mj_step(model, data)
        if _warning_count(data):
            break
    fired = [mujoco.mjtWarning(i).name for i in range(mujoco.mjtWarning.mjNWARNING.value) if data.warning[i].number]
    return k, fired


def _remedy(prepared: PreparedModel) -> str:
    h = prepared.options.timestep
    smaller = f"use a smaller time step (now {h:g} s, try {h / 2:g} s)"
    if prepared.built.exact_contact or not prepared.built.rings:
        return smaller
    return f"{smaller} or more bearing segments (ModelOptions(segments=...))"


def _finish(
    parts: list[SimulationResult], prepared: PreparedModel, t0: float, *, nstep_done: int, every: int
) -> SimulationResult:
    res = SimulationResult.concatenate(parts)
    wall = _time.perf_counter() - t0
    mech = prepared.mechanism
    res.metadata = {
        **prepared.metadata,
        "solver": "mujoco",
        "mechanism": mech.name,
        "parameters": dict(mech.parameters),
        "clearance_joints": [j.name for j in mech.clearance_joints],
        "drives": [d.name for d in mech.drives],
        "links": [lk.name for lk in mech.moving_links],
        "steps": nstep_done,
        "output_every_steps": every,
        # 4 significant digits: a wall time is measured to a millisecond or so, not to 1e-17 s
        "wall_time_s": float(f"{wall:.4g}"),
        "steps_per_second": float(f"{nstep_done / wall:.4g}") if wall > 0 else None,
        "mujoco_version": mujoco.__version__,
        "package_version": __version__,
    }
    res.metadata["energy_balance"] = res.energy_balance()
    return res


def _first_bad(
    prepared: PreparedModel,
    data: mujoco.MjData,
    part: SimulationResult,
    states: np.ndarray,
    sens: np.ndarray,
    *,
    warnings: bool = True,
) -> tuple[int, str | None, str, str] | None:
    """(row index, joint or None, reason, remedy) of a chunk's first bad row, or None.

    Rows from the index on are dropped. A row is bad when its journal, or a corner of its
    slider, is beyond the divergence bound (that joint and the corner are named) or its state
    or sensors are not finite (no joint is named: the cause cannot be tied to one). State row i is after step i and
    sensor row i before it, so a step that goes non-finite drops its own row. With
    ``warnings``, MuJoCo warnings the stepper could not place drop the whole chunk.
    """
    n = len(part.times)
    finite = np.isfinite(states[:n]).all(axis=1) & np.isfinite(sens[:n]).all(axis=1)
    first_nan = int(np.argmin(finite)) if not finite.all() else n
    worst: tuple[int, str, float, str] | None = None  # (row, joint, penetration, what) of the first row beyond
    pens = [(name, jr.penetration, "the journal penetrated {} um into its bearing") for name, jr in part.joints.items()]
    pens += [
        (name, sr.corner_penetration[:, k], f"corner {k} of the slider penetrated {{}} um into its guide")
        for name, sr in part.sliders.items()
        for k in range(sr.corner_penetration.shape[1])
    ]
    for name, pen, what in pens:
        over = np.nonzero(pen > prepared.sizing[name].penetration_limit)[0]
        if len(over) and (worst is None or over[0] < worst[0]):
            worst = (int(over[0]), name, float(pen[over[0]]), what)
    remedy = _remedy(prepared)
    if worst is not None and worst[0] <= first_nan:
        lim = prepared.sizing[worst[1]].penetration_limit
        return (
            worst[0],
            worst[1],
            (
                f"{worst[3].format(f'{worst[2] * 1e6:.3g}')}, beyond the bound {lim * 1e6:.3g} um (4 x the Hertz "
                "penetration of the expected hardest impact)"
            ),
            remedy,
        )
    if first_nan < n:
        return first_nan, None, "the state became non-finite (NaN or Inf)", remedy
    fired = [mujoco.mjtWarning(i).name for i in range(mujoco.mjtWarning.mjNWARNING.value) if data.warning[i].number > 0]
    if warnings and fired:
        # a stepper that could not say when: keep only what preceded the chunk
        return 0, None, f"MuJoCo raised warnings {fired} during this chunk", remedy
    return None


def _progress(progress: bool | Callable[[float], None], total: int) -> Callable[[int | None], None]:
    if callable(progress):
        return lambda done: progress(1.0 if done is None else done / total)
    if not progress:
        return lambda done: None
    from clearance.progress import progress_bar

    bar = progress_bar(total, unit="step", desc="simulate", unit_scale=True, leave=False)

    def update(done: int | None) -> None:
        if done is None:
            bar.close()
        else:
            bar.update(done - bar.n)

    return update
