"""Exact-LN contact inside MuJoCo: the law's force imposed on the ring's contact rows.

Each step is split (docs/mujoco_notes.md, "Exact LN inside MuJoCo"): `mj_step1` builds the
contacts; the journal's penetration δ = |e| − c and rate δ̇ = e·ė/|e| come from its
eccentricity e in the bearing (exact circle geometry, not the polygon); the law gives one
force F(δ, δ̇, δ̇⁻), with δ̇⁻ recorded at the first step of each contact; F is shared among
the ring's active rows (minimum-norm non-negative row forces whose net force on the journal
is −F e/|e|; per-row LN would sum to the wrong law, roughly δ²: docs/mujoco_notes.md); then each row's
``efc_aref`` is set so that MuJoCo's solver returns exactly those row forces, and
`mj_step2` integrates.

For a soft constraint with regulariser R the solver's row forces f satisfy
(A + R) f = aref − J a₀ (A = J M⁻¹ Jᵀ, a₀ the unconstrained acceleration) while they are
non-negative, so aref = (A + R) f* + J a₀ gives f = f* exactly. The simpler aref = R f*
errs by the rows' coupling through A: measured −0.7 % of the net force at δ = 5 µm (7 rows)
and −2.1 % at 70 µm (23 rows), N = 144, impedance 1e-3. Loop-closure equality rows are
solved together with the contact rows (`impose_exact_ln`), so they react to the LN force
as to any contact force; other inequality constraints (joint limits, friction) are not.

The force is computed from the state at the start of each step, so its damping term is
explicit. A contact recorded at a low approach speed (a grazing onset, or a journal in
contact at t = 0, both at the floor) has a damping χ K δ^1.5 / δ̇⁻ that can exceed the
step's limit (damping · h / effective mass < 2); the force then chatters from step to step.
Measured on the default slider-crank started 10 µm into its bearing under its 2.7 kN load:
chatter at h = 1 µs, smooth and within 0.4 % of the reference solver at 0.5 µs.

Pair margins are raised to the polygon's largest gap so that a row exists whenever the
exact circles touch. Frictionless pairs only (condim 1). The step loop runs in Python, so
this mode is much slower than `mujoco.rollout` (see benchmarks/calibration_accuracy.md).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.contact_calibration.laws import (
    MIN_APPROACH_SPEED,
    bearing_stiffness,
    hysteresis_factor,
)
from clearance.contact_calibration.scene_impact import (
    SceneImpact,
    _crossing,
    _peak,
    onset_radius,
)
from clearance.mjcf.bearing import RingGeometry
from clearance.mjcf.probe import ring_scene
from clearance.model import Clearance, ContactLaw
from clearance.options import ContactParameters, ModelOptions

__all__ = [
    "ExactLNContact",
    "crossing_speed",
    "impose_exact_ln",
    "step_exact_ln",
    "ExactLNRun",
    "ExactLNStepError",
    "exact_ln_impact",
    "polygon_margin",
    "ExactLNCost",
    "exact_ln_cost",
]


def polygon_margin(ring: RingGeometry) -> float:
    """Largest radial gap [m] between the bearing circle and the ring's first contact."""
    psi = np.linspace(0.0, 2 * math.pi / ring.segments, 9)
    return max(onset_radius(ring, float(p)) for p in psi) - ring.radial_clearance


def crossing_speed(delta0: float, rate0: float, rate1: float, h: float) -> float:
    """Speed [m/s] at which δ crossed 0 during a step, at constant acceleration over it.

    Args:
        delta0: penetration at the start of the step [m] (<= 0: not in contact).
        rate0, rate1: δ̇ at the start and the end of the step [m/s].
        h: the step [s].

    Returns:
        sqrt(rate0² − 2 a delta0) with a = (rate1 − rate0)/h, kept between rate0 and rate1
        (the speed at any instant of a step at constant acceleration lies between them).
    """
    a = (rate1 - rate0) / h
    v = math.sqrt(max(rate0 * rate0 - 2.0 * a * delta0, 0.0))
    return min(max(v, min(rate0, rate1)), max(rate0, rate1))


class ExactLNContact:
    """Imposes the LN force of one clearance joint on its contact rows, step by step.

    Call `apply` between `mujoco.mj_step1` and `mujoco.mj_step2`.

    Args:
        model: compiled model; its pairs with the journal geom are this joint's rows
            (their margins are raised in place to cover the polygon gap).
        clearance: the joint's clearance (law, K, cₑ, radii).
        ring: the joint's ring geometry.
        journal_geom: name of the journal geom.
        bearing_site: name of a site at the bearing centre, or None for a bearing fixed at
            the world origin (the one-bearing scene).

    Attributes:
        min_approach_speed: floor [m/s] on the recorded approach speed
            (`MIN_APPROACH_SPEED`, the reference solver's default).

    Raises:
        ValueError: the law is IMPACT, or a pair has friction (condim > 1).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        clearance: Clearance,
        ring: RingGeometry,
        *,
        journal_geom: str,
        bearing_site: str | None = None,
    ) -> None:
        if clearance.law is ContactLaw.IMPACT:
            raise ValueError("exact-LN mode needs a law with a restitution (not IMPACT)")
        self.jg = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, journal_geom)
        if self.jg < 0:
            raise ValueError(f"no geom named {journal_geom!r}")
        self.site = -1 if bearing_site is None else mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, bearing_site)
        pairs = np.flatnonzero((model.pair_geom1 == self.jg) | (model.pair_geom2 == self.jg))
        if np.any(model.pair_dim[pairs] != 1):
            raise ValueError("exact-LN mode supports frictionless pairs (condim 1) only")
        model.pair_margin[pairs] = 1.5 * polygon_margin(ring) + 1e-3 * ring.radial_clearance
        self.c = clearance.radial_clearance
        self.k = bearing_stiffness(clearance)
        self.chi = hysteresis_factor(clearance.law, clearance.restitution)
        self.min_approach_speed = MIN_APPROACH_SPEED
        self.timestep = float(model.opt.timestep)
        self.approach: float | None = None
        self.last_force = 0.0
        self.last_penetration = -math.inf
        self.last_rate = 0.0

    def _kinematics(self, model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_GEOM, self.jg, vel, 0)
        p, v = data.geom_xpos[self.jg, :2].copy(), vel[3:5].copy()
        if self.site >= 0:
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_SITE, self.site, vel, 0)
            p -= data.site_xpos[self.site, :2]
            v -= vel[3:5]
        return p, v

    def force(self, delta: float, rate: float) -> float:
        """The law's force [N] at δ [m], δ̇ [m/s], updating the contact onset state.

        The first call with δ > 0 is the onset. Its approach speed δ̇⁻ is the speed at the
        crossing δ = 0 inside the last step (`crossing_speed`), as the reference solver
        records it at its located onset event, not the speed one step later: at a grazing
        onset under load the journal gains up to a·h in that step, several times the
        approach speed itself (0.026 m/s recorded against 0.020 m/s at the crossing,
        measured on the slider-crank at c = 0.1 mm, h = 1 µs). A journal that starts in
        contact has no crossing: δ̇⁻ = δ̇ then. Either way δ̇⁻ is at least
        ``min_approach_speed``, as in the reference solver.
        """
        if delta <= 0:
            self.approach = None
            return 0.0
        if self.approach is None:
            v = rate
            if math.isfinite(self.last_penetration) and self.last_penetration <= 0:
                v = crossing_speed(self.last_penetration, self.last_rate, rate, self.timestep)
            self.approach = max(v, self.min_approach_speed)
        return max(self.k * delta**1.5 * (1.0 + self.chi * rate / self.approach), 0.0)

    def targets(self, model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """This joint's contact rows and the row forces [N] that carry the LN force.

        Updates the onset state, ``last_force`` [N] and ``last_penetration`` [m].

        Returns:
            (rows, forces): efc indices and non-negative forces, both shape (m,).
        """
        e, ed = self._kinematics(model, data)
        r = float(np.hypot(*e))
        u = e / r if r > 0 else np.array([1.0, 0.0])
        delta = r - self.c
        rate = float(u @ ed)
        f_ln = self.force(delta, rate)
        self.last_force, self.last_penetration, self.last_rate = f_ln, delta, rate
        con = data.contact
        geom = con.geom
        mine = ((geom[:, 0] == self.jg) | (geom[:, 1] == self.jg)) & (con.efc_address >= 0)
        if not np.any(mine):
            return np.zeros(0, dtype=int), np.zeros(0)
        rows = con.efc_address[mine]
        sign = np.where(geom[mine, 1] == self.jg, 1.0, -1.0)  # force on the journal per unit row force
        s = (con.frame[mine, :2] * sign[:, None]).T  # (2, m)
        f, *_ = np.linalg.lstsq(s, -f_ln * u, rcond=1e-10)  # minimum-norm sharing
        f = np.maximum(f, 0.0)
        radial = float(-(s @ f) @ u)
        f = f * (f_ln / radial) if radial > 0 else np.zeros_like(f)
        return rows, f

    def apply(self, model: mujoco.MjModel, data: mujoco.MjData) -> float:
        """Impose this joint alone (see `impose_exact_ln`); returns the LN force [N]."""
        impose_exact_ln(model, data, [self])
        return self.last_force


def _dense_jacobian(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    nv = model.nv
    if mujoco.mj_isSparse(model):
        jac = np.zeros((data.nefc, nv))
        mujoco.mju_sparse2dense(jac, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind)
        return jac
    return data.efc_J[: data.nefc * nv].reshape(data.nefc, nv)


def impose_exact_ln(model: mujoco.MjModel, data: mujoco.MjData, contacts: list[ExactLNContact]) -> np.ndarray:
    """Set ``efc_aref`` of every exact-LN joint's rows; call between mj_step1 and mj_step2.

    With c the contact rows (target forces f*) and e the equality rows (always active,
    their aref left as MuJoCo computed it), the solver's optimality conditions
    (A + R) f = aref − J a₀ give f_e = (A_ee + R_e)⁻¹(b_e − A_ec f*) and then
    aref_c = (A_cc + R_c) f* + A_ce f_e + J_c a₀, so the contact rows carry exactly f*
    and the loop closures react to them as they would to any contact force.

    Args:
        model: the model.
        data: its data after `mujoco.mj_step1`.
        contacts: the joints in exact-LN mode.

    Returns:
        (len(contacts),) LN force of each joint [N].
    """
    parts = [c.targets(model, data) for c in contacts]
    forces = np.array([c.last_force for c in contacts])
    rows = np.concatenate([p[0] for p in parts]).astype(int)
    if not len(rows):
        return forces
    fc = np.concatenate([p[1] for p in parts])
    jac = _dense_jacobian(model, data)
    eq = np.flatnonzero(data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    allr = np.concatenate([rows, eq])
    j = jac[allr]
    minv_jt = np.zeros((len(allr), model.nv))
    mujoco.mj_solveM(model, data, minv_jt, j)
    a = j @ minv_jt.T + np.diag(data.efc_R[allr])
    mujoco.mj_fwdActuation(model, data)
    mujoco.mj_fwdAcceleration(model, data)
    ja0 = j @ data.qacc_smooth
    m = len(rows)
    aref = a[:m, :m] @ fc + ja0[:m]
    if len(eq):
        b_e = data.efc_aref[eq] - ja0[m:]
        f_e = np.linalg.solve(a[m:, m:], b_e - a[m:, :m] @ fc)
        aref += a[:m, m:] @ f_e
    data.efc_aref[rows] = aref
    return forces


@dataclass(frozen=True)
class ExactLNRun:
    """States and readings of `step_exact_ln`.

    Attributes:
        qpos: (nstep, nq) after each step.
        qvel: (nstep, nv) after each step.
        sensordata: (nstep, nsensordata) at the start of each step (rollout alignment).
        force: (nstep, n_joints) LN force imposed during each step [N].
        penetration: (nstep, n_joints) exact-circle penetration at the start of each step [m].
    """

    qpos: np.ndarray
    qvel: np.ndarray
    sensordata: np.ndarray
    force: np.ndarray
    penetration: np.ndarray


class ExactLNStepError(RuntimeError):
    """An exact-LN step raised a MuJoCo warning or gave a non-finite state.

    Attributes:
        step: index of the failing step.
        reason: what went wrong, for messages.
        partial: the `ExactLNRun` of the steps before it (all good).
    """

    def __init__(self, message: str, *, step: int, reason: str, partial: ExactLNRun) -> None:
        super().__init__(message)
        self.step, self.reason, self.partial = step, reason, partial


def step_exact_ln(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    contacts: list[ExactLNContact],
    nstep: int,
    *,
    ctrl: np.ndarray | None = None,
) -> ExactLNRun:
    """Step ``nstep`` times with exact-LN contact (the Python counterpart of rollout).

    Args:
        model: the model (its exact-LN joints' pairs frictionless).
        data: the data, at the initial state; advanced in place.
        contacts: the joints in exact-LN mode.
        nstep: number of steps.
        ctrl: controls, (nu,) held during the run or (nstep, nu) one row per step
            (default: leave data.ctrl).

    Returns:
        The run's states, sensors, LN forces and penetrations.

    Raises:
        ExactLNStepError: a MuJoCo warning or a non-finite state; it names the step and
            carries the run before it.
    """
    per_step = ctrl if ctrl is not None and np.ndim(ctrl) == 2 else None
    if ctrl is not None and per_step is None:
        data.ctrl[:] = ctrl
    qpos = np.zeros((nstep, model.nq))
    qvel = np.zeros((nstep, model.nv))
    sens = np.zeros((nstep, model.nsensordata))
    force = np.zeros((nstep, len(contacts)))
    pen = np.zeros((nstep, len(contacts)))
    warn0 = int(data.warning.number.sum())
    for i in range(nstep):
        if per_step is not None:
            data.ctrl[:] = per_step[i]
        mujoco.mj_step1(model, data)
        force[i] = impose_exact_ln(model, data, contacts)
        pen[i] = [c.last_penetration for c in contacts]
        mujoco.mj_step2(model, data)
        qpos[i], qvel[i], sens[i] = data.qpos, data.qvel, data.sensordata
        fired = (
            [mujoco.mjtWarning(k).name for k in range(mujoco.mjtWarning.mjNWARNING.value) if data.warning[k].number]
            if int(data.warning.number.sum()) > warn0
            else []
        )
        finite = bool(np.all(np.isfinite(data.qvel)) and np.all(np.isfinite(data.sensordata)))
        if fired or not finite:
            reason = (f"MuJoCo raised warnings {fired}" if fired else "") + (
                (" and " if fired else "") + "the state became non-finite (NaN or Inf)" if not finite else ""
            )
            partial = ExactLNRun(qpos[:i], qvel[:i], sens[:i], force[:i], pen[:i])
            raise ExactLNStepError(
                f"exact-LN run failed at step {i} (t = {data.time:.6g} s): {reason}",
                step=i,
                reason=reason,
                partial=partial,
            )
    return ExactLNRun(qpos, qvel, sens, force, pen)


@dataclass(frozen=True)
class ExactLNCost:
    """Speed of the exact-LN step loop against `mujoco.rollout` on the same scene.

    Attributes:
        exact_steps_per_s: Python step loop with `ExactLNContact` [steps/s].
        rollout_steps_per_s: `mujoco.rollout` with calibrated-style fixed parameters.
        ratio: rollout / exact [-].
    """

    exact_steps_per_s: float
    rollout_steps_per_s: float
    ratio: float


def _scene(clearance: Clearance, ring: RingGeometry, options: ModelOptions, mass: float) -> mujoco.MjModel:
    # The rows' own stiffness/damping are replaced by efc_aref each step; any value works.
    return ring_scene(ring, options, ContactParameters(1.0, 0.0, "exact_ln"), mass=mass)


def exact_ln_impact(
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    *,
    mass: float,
    speed: float,
    direction: float = 0.0,
    max_steps: int | None = None,
) -> SceneImpact:
    """A radial impact in the one-bearing scene with exact-LN contact.

    The journal starts two steps before the exact circles touch, moving at ``speed``
    along ``direction``, and is stepped until it leaves the clearance circle.

    Args:
        clearance: the joint's clearance (law, K, cₑ).
        ring: ring geometry.
        options: model options (time step, geoms, impedance).
        mass: journal (effective) mass [kg].
        speed: approach speed v [m/s] > 0.
        direction: impact direction ψ [rad] in the bearing frame.
        max_steps: step limit (default: 20 Hertz contact durations).

    Returns:
        The impact; penetration and duration use the exact circle (δ = |e| − c).

    Raises:
        RuntimeError: no separation within ``max_steps``.
    """
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be positive and finite (got {speed!r} m/s)")
    model = _scene(clearance, ring, options, mass)
    contact = ExactLNContact(model, clearance, ring, journal_geom="ring__journal")
    data = mujoco.MjData(model)
    h = options.timestep
    u = np.array([math.cos(direction), math.sin(direction)])
    data.qpos[:2] = (clearance.radial_clearance - 2 * speed * h) * u
    data.qvel[:2] = speed * u
    d_hertz = (1.25 * mass * speed**2 / contact.k) ** 0.4
    n = max_steps or int(20 * 2.94 * d_hertz / speed / h) + 10
    delta, force, vel = [], [], []
    for _ in range(n):
        mujoco.mj_step1(model, data)
        force.append(contact.apply(model, data))
        delta.append(contact.last_penetration)
        mujoco.mj_step2(model, data)
        vel.append(float(data.qvel[:2] @ u))
        if len(delta) > 3 and delta[-1] <= 0 and max(delta) > 0 and delta[-2] > 0:
            break
    else:
        raise RuntimeError(f"no separation within {n} steps at v = {speed:g} m/s")
    dl, fl = np.array(delta), np.array(force)
    on = int(np.argmax(dl > 0))
    off = len(dl) - 1
    t_on = (on - 1 + _crossing(dl[on - 1], dl[on])) * h
    t_off = (off - 1 + _crossing(dl[off - 1], dl[off])) * h
    return SceneImpact(
        speed=float(speed),
        direction=float(direction),
        times=np.arange(len(dl)) * h - t_on,
        penetration=dl,
        force=fl,
        peak_force=_peak(fl)[0],
        max_penetration=_peak(dl)[0],
        duration=t_off - t_on,
        restitution=-vel[-1] / speed,
    )


def exact_ln_cost(
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    *,
    mass: float,
    params: ContactParameters,
    load: float = 1000.0,
    nstep: int = 20000,
) -> ExactLNCost:
    """Measure steps/s of the exact-LN loop and of `mujoco.rollout` on the scene.

    Both run ``nstep`` steps, one thread, with the journal pressed into the ring by a
    constant ``load`` [N] (as a gravity field on the journal) so that contact rows are
    active throughout: the contact-heavy case, where exact-LN costs most.
    """
    import mujoco.rollout

    model = _scene(clearance, ring, options, mass)
    contact = ExactLNContact(model, clearance, ring, journal_geom="ring__journal")
    model.opt.gravity[:] = [load / mass, 0.0, 0.0]
    data = mujoco.MjData(model)
    data.qvel[:2] = [0.0, 0.3]
    t0 = time.perf_counter()
    for _ in range(nstep):
        mujoco.mj_step1(model, data)
        contact.apply(model, data)
        mujoco.mj_step2(model, data)
    exact = nstep / (time.perf_counter() - t0)
    fixed = ring_scene(ring, options, params, mass=mass)
    fixed.opt.gravity[:] = [load / mass, 0.0, 0.0]
    d2 = mujoco.MjData(fixed)
    d2.qvel[:2] = [0.0, 0.3]
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.zeros(mujoco.mj_stateSize(fixed, spec))
    mujoco.mj_getState(fixed, d2, s0, spec)
    t0 = time.perf_counter()
    mujoco.rollout.rollout(fixed, d2, s0[None], nstep=nstep)
    roll = nstep / (time.perf_counter() - t0)
    return ExactLNCost(exact, roll, roll / exact)
