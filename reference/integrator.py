"""Step a `ReferenceSystem` with a scipy `OdeSolver`, locating every contact onset and end.

The loop drives a scipy `OdeSolver` (LSODA by default) one step at a time through its
public interface (`step`, `dense_output`, `t_old`, `t`, `y`, `step_size`):

  * Contact state is a mode per contact point (a clearance joint's journal, a slider's
    corner): free, or in contact with the approach speed delta_dot^- recorded at onset. The
    right-hand side applies a force only in contact mode, so a step that crosses an onset is
    smooth free flight; the crossing is then located on the step's dense output
    (`clearance.reference.events`), the step is cut there and the solver restarts in the new
    mode with the last step size. No impact can be stepped over and delta_dot^- is exact to
    the tolerance. Points that switch at the same instant switch together: at a located
    switch every other free point already touching and approaching (delta >= 0,
    delta_dot > 0) starts its impact there, and every other point in contact already clear
    and receding (delta <= 0, delta_dot < 0) ends it (a level slider lands on two corners
    at once).
  * Output samples on a uniform grid come from the dense output of the step holding them.
  * Coordinate projection (optional) restarts the solver after any step whose constraint
    drift exceeds the position or velocity tolerance.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate

from clearance.reference.events import find_mode_change, gap
from clearance.reference.system import ReferenceSystem, SingularConstraintsError

__all__ = ["Trajectory", "IntegrationFailure", "integrate_system", "METHODS"]

METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
"""scipy `solve_ivp` methods the loop accepts."""


class IntegrationFailure(RuntimeError):
    """The integration stopped early; ``trajectory`` holds what was computed.

    Attributes:
        time: time of the failure [s].
        joint: clearance joint concerned, or None.
        trajectory: the `Trajectory` up to the last good output sample.
    """

    def __init__(self, message: str, *, time: float, joint: str | None, trajectory: Trajectory):
        super().__init__(message)
        self.time, self.joint, self.trajectory = time, joint, trajectory


@dataclass
class Trajectory:
    """Raw solution on the output grid (centre-of-mass coordinates).

    Attributes:
        times: (n,) [s].
        z, zd: (n, nq) coordinates and velocities.
        vin: (n, n_contacts) approach speed of the impact active at each sample [m/s], 0
            where a joint is free.
        work: (n, n_drives) work done by each drive since t = 0 [J], or None.
        onsets: contact onsets as (time [s], joint index, approach speed [m/s]).
        ends: contact ends as (time [s], joint index).
        n_rhs: right-hand-side evaluations of the integration.
        n_steps: accepted steps.
        n_restarts: solver restarts (events and projections).
        n_projections: coordinate projections.
        wall_time_s: wall time of the integration [s].
    """

    times: np.ndarray
    z: np.ndarray
    zd: np.ndarray
    vin: np.ndarray
    work: np.ndarray | None
    onsets: list[tuple[float, int, float]] = field(default_factory=list)
    ends: list[tuple[float, int]] = field(default_factory=list)
    n_rhs: int = 0
    n_steps: int = 0
    n_restarts: int = 0
    n_projections: int = 0
    wall_time_s: float = 0.0


def integrate_system(
    system: ReferenceSystem,
    z0: np.ndarray,
    zd0: np.ndarray,
    duration: float,
    *,
    output_interval: float,
    rtol: float,
    atol: np.ndarray,
    method: str = "LSODA",
    projection: tuple[float, float] | None = None,
    track_work: bool = False,
    max_penetration: Sequence[float] | None = None,
    progress: Callable[[float], None] | None = None,
) -> Trajectory:
    """Integrate from (z0, zd0) at t = 0 for ``duration`` seconds.

    Args:
        system: the equations of motion.
        z0, zd0: initial centre-of-mass coordinates and velocities (nq,).
        duration: simulated time [s] > 0.
        output_interval: output grid spacing [s].
        rtol: relative tolerance.
        atol: (2 nq,) absolute tolerances of (z, zd).
        method: a name from `METHODS`.
        projection: (position [m, rad], velocity [m/s, rad/s]) drift tolerances: after
            any step whose constraint residual exceeds them, project and restart; None for
            no projection.
        track_work: also integrate the work of each drive.
        max_penetration: per contact point, penetration [m] treated as divergence.
        progress: called with the time reached [s] after each output sample.

    Returns:
        The `Trajectory`.

    Raises:
        IntegrationFailure: solver failure, non-finite state, penetration beyond the limit
            or a singular constraint Jacobian; carries the partial trajectory.
    """
    t_start = time.perf_counter()
    nq, nc, nd = system.nq, len(system.contacts), len(system.drives)
    grid = output_interval * np.arange(int(math.floor(duration / output_interval * (1 + 1e-12))) + 1)
    n_out = len(grid)
    ny = 2 * nq + (nd if track_work else 0)
    tol = np.concatenate([atol, np.full(ny - 2 * nq, 1e100)])
    out_y = np.empty((n_out, ny))
    out_vin = np.zeros((n_out, nc))
    traj = Trajectory(grid, np.empty((0, nq)), np.empty((0, nq)), np.empty((0, nc)), None)  # set in finish
    count = [0]
    limits = list(max_penetration) if max_penetration is not None else [math.inf] * nc
    solver_cls = getattr(integrate, method)

    y = np.concatenate([z0, zd0, np.zeros(ny - 2 * nq)])
    vin = [0.0] * nc
    geo = [gap(system, k, y) for k in range(nc)]
    for k, (delta, ddot, _) in enumerate(geo):  # a journal already in penetration at t = 0
        if delta > 0:
            vin[k] = max(ddot, system.min_approach_speed)
            traj.onsets.append((0.0, k, vin[k]))
    out_y[0], out_vin[0] = y, vin
    n_done, t, h = 1, 0.0, None
    t_end = float(grid[-1])

    def finish() -> Trajectory:
        traj.times = grid[:n_done]
        traj.z, traj.zd = out_y[:n_done, :nq], out_y[:n_done, nq : 2 * nq]
        traj.vin = out_vin[:n_done]
        traj.work = out_y[:n_done, 2 * nq :] if track_work else None
        traj.n_rhs = count[0]
        traj.wall_time_s = time.perf_counter() - t_start
        return traj

    def fail(msg: str, tf: float, joint: str | None) -> IntegrationFailure:
        return IntegrationFailure(msg, time=tf, joint=joint, trajectory=finish())

    while t < t_end:
        seg_vin = tuple(vin)

        def fun(tt: float, yy: np.ndarray, _v: tuple[float, ...] = seg_vin) -> np.ndarray:
            count[0] += 1
            return system.rhs(tt, yy, _v)

        try:
            first = None if h is None else min(h, t_end - t)
            solver = solver_cls(fun, t, y, t_end, rtol=rtol, atol=tol, first_step=first)
        except SingularConstraintsError as exc:
            raise fail(str(exc), t, None) from None
        traj.n_restarts += 1
        restart = False
        while solver.status == "running" and not restart:
            try:
                with np.errstate(invalid="ignore", over="ignore"):  # rejected trial stages
                    message = solver.step()
            except SingularConstraintsError as exc:
                raise fail(str(exc), solver.t, None) from None
            if solver.status == "failed":
                raise fail(
                    f"the {method} solver failed at t = {solver.t:.9g} s ({message})", solver.t, _deepest(system, geo)
                )
            traj.n_steps += 1
            t0s, t1s, y1 = solver.t_old, solver.t, solver.y
            if not np.all(np.isfinite(y1)):
                raise fail(f"non-finite state at t = {t1s:.9g} s", t1s, _deepest(system, geo))
            geo1 = [gap(system, k, y1) for k in range(nc)]
            dense = _Dense(solver)
            event = None
            for k in range(nc):
                te = find_mode_change(system, k, dense, t0s, t1s, geo[k], geo1[k], vin[k] > 0)
                if te is not None and (event is None or te < event[0]):
                    event = (te, k)
            t_cut = event[0] if event else t1s
            # output samples in (t0s, t_cut]
            j1 = n_done
            while j1 < n_out and grid[j1] <= t_cut:
                j1 += 1
            if j1 > n_done:
                ys = dense()(grid[n_done:j1])
                out_y[n_done:j1] = ys.T
                out_vin[n_done:j1] = vin
                n_done = j1
                if progress is not None:
                    progress(float(grid[n_done - 1]))
            if event:
                te, k = event
                y = dense()(te) if te < t1s else y1.copy()
                geo = [gap(system, i, y) for i in range(nc)]
                for i in range(nc):
                    delta, ddot, _ = geo[i]
                    if vin[i] > 0 and (i == k or (delta <= 0.0 and ddot < 0.0)):
                        vin[i] = 0.0
                        traj.ends.append((te, i))
                    elif vin[i] == 0.0 and (i == k or (delta >= 0.0 and ddot > 0.0)):
                        vin[i] = max(ddot, system.min_approach_speed)
                        traj.onsets.append((te, i, vin[i]))
                t, h, restart = te, solver.step_size, True
            else:
                t, y, geo = t1s, y1, geo1
            for k, (delta, _, _) in enumerate(geo):
                if delta > limits[k]:
                    cj = system.contacts[k]
                    raise fail(
                        f"penetration {delta:.3g} m at joint '{cj.name}' exceeds the limit "
                        f"{limits[k]:.3g} m at t = {t:.9g} s",
                        t,
                        cj.name,
                    )
            if projection and system.n_constraints and not restart:
                z, zd = y[:nq], y[nq : 2 * nq]
                phi, _, phit = system.rows.evaluate(t, z.tolist())
                vel = system.rows.G @ zd + np.array(phit)
                if max(map(abs, phi)) > projection[0] or np.max(np.abs(vel)) > projection[1]:
                    y = y.copy()
                    y[:nq], y[nq : 2 * nq] = system.project(t, z, zd)
                    traj.n_projections += 1
                    geo = [gap(system, i, y) for i in range(nc)]
                    h, restart = solver.step_size, True
    return finish()


class _Dense:
    """The current step's dense output, built on first use (DOP853 spends 3 calls on it, LSODA none)."""

    def __init__(self, solver: integrate.OdeSolver) -> None:
        self.solver = solver
        self.sol: integrate.DenseOutput | None = None

    def __call__(self) -> integrate.DenseOutput:
        if self.sol is None:
            self.sol = self.solver.dense_output()
        return self.sol


def _deepest(system: ReferenceSystem, geo: Sequence[tuple[float, float, float]]) -> str | None:
    """The clearance joint of deepest penetration, or None without clearance joints."""
    if not geo:
        return None
    k = int(np.argmax([g[0] for g in geo]))
    return system.contacts[k].name
