"""Fit a backlash stop (a tendon limit on q_load - q_motor) to the gear mesh's impact law.

The stop at either end of a dead band of half-width b is MuJoCo's soft limit constraint on the
fixed tendon q_load - q_motor. The law it is fitted to is Lankarani–Nikravesh in angular form,
T = K δⁿ [1 + 3(1 − cₑ²)/4 · δ̇/δ̇⁻] with δ = |q_load − q_motor| − b (`laws.mesh_torque`), for
the user's torsional mesh stiffness K and restitution cₑ, at the effective inertia J along the
band (1/(J M⁻¹ Jᵀ) with the tendon's Jacobian: the link's and the rotor's inertia in series).

As the ring's fit (`clearance.contact_calibration.fit`) does, the same impact runs in a MuJoCo
scene (one hinge of inertia J against the tendon limit, the model's time step and integrator)
and in the 1-DOF reference (`impact.simulate_impact` under the law), over a decade of closing
speeds; `scipy.optimize.least_squares` fits the stop's stiffness K̂ [N m/rad] and damping
B̂ [N m s/rad] to the residuals

    (T̂/T_law − 1)/0.05, (ê/e_law − 1)/0.05

(peak torque and restitution, each error over its 5 % goal; e_law is the law's own impact
restitution, not cₑ), at two onset phases within a step. The stop is emitted in direct mode,
solreflimit = (−K̂ Â, −B̂ Â) with Â the tendon's inverse weight at qpos0 (MuJoCo's
``tendon_invweight0``), and a small constant impedance, solimplimit = (d, d, 0.001, 0.5, 2)
with d = `STOP_IMPEDANCE`: the limit is then a penalty spring-damper K̂ r + B̂ ṙ that does not
depend on the pose (docs/mujoco_notes.md, "Contact as a force law"), and the actuator's push
reaches it only in the share d.

Why two numbers suffice: with the gear mesh's n = 1 both the law and a linear spring-damper
scale exactly with the closing speed (penetration ∝ speed, the duration fixed), so peak
torque over speed and restitution are the same at every speed; the fit checks it over the
decade. With n ≠ 1 the law's stiffness changes with penetration and one K̂ cannot follow it
over a decade; the rows say how far it misses.

Pose: the fit is at the effective inertia of the reference pose. The stop is a penalty
spring-damper whatever the pose, but the inertia along the band changes with the pose, and the
rebound of a linear damper changes with it (the law's does not): measured on the reacher's elbow
stop, the restitution is 5 % low at half the inertia fitted at and 5 % high at twice it, 9 %
high at 4.7 times it, the peak torque within 5 % (`stop_at` gives it for any inertia).

Time step: the stop's frequency ω = sqrt(K/J) (`laws.mesh_omega`) is kept at ω h ≤ `OMEGA_H`:
measured at the reacher's elbow inertia (K = 1e4 N m/rad, cₑ = 0.8, Euler and RK4), the fitted
stop is within 0.4 % of the law at ω h = 0.1 and the onset phase moves it by 0.6 %; at 0.2, 0.7 %
and 1.2 %; the flywheel of tests/test_backlash_stop.py checks the 5 % goal. `stop_timestep`
lowers a model's step to that, and refuses below `MIN_TIMESTEP`. The fitted
spring-damper is then checked for the explicit step's stability, ω̂ h < 2 and
h²ω̂² + 2hβ̂ < 4 (`StopStabilityError` otherwise), as the ring's `check_stability` does.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from clearance.checks import positive
from clearance.contact_calibration import laws

__all__ = [
    "GOAL",
    "MIN_TIMESTEP",
    "OMEGA_H",
    "PHASES",
    "STOP_IMPEDANCE",
    "MeshLaw",
    "StopRow",
    "StopStabilityError",
    "TorsionalStop",
    "fit_stop",
    "law_stop_impact",
    "scene_stop_impact",
    "stop_scene",
    "stop_at",
    "stop_solimp",
    "stop_solref",
    "stop_speeds",
    "stop_timestep",
]

GOAL = 0.05
"""Accuracy goal of the fitted stop: peak torque and restitution within 5 % of the law's."""

OMEGA_H = 0.1
"""Largest ω h [-] of the stop at the time step (ω = sqrt(K/J)): about 30 steps per impact."""

MIN_TIMESTEP = 1e-7
"""Smallest time step [s] the stop may ask for; a stiffer stop or a lighter band is refused."""

STOP_IMPEDANCE = 1e-3
"""Constant impedance d of the stop's solimplimit [-]: small, so the limit is a penalty
spring-damper and only this share of the actuator's push goes through the constraint."""

PHASES = (0.25, 0.75)
"""Onset phases the fit runs each speed at: where, as a fraction of a step, the band closes."""


class StopStabilityError(ValueError):
    """The stop cannot be simulated accurately or stably at an allowed time step."""


@dataclass(frozen=True)
class MeshLaw:
    """The gear mesh's impact law at one hinge (`laws.mesh_torque`).

    Attributes:
        stiffness: torsional mesh stiffness K [N m/rad^n].
        restitution: coefficient of restitution cₑ [-] of the law.
        exponent: n [-] (`laws.GEAR_MESH_EXPONENT` = 1).
    """

    stiffness: float
    restitution: float
    exponent: float = laws.GEAR_MESH_EXPONENT

    def __post_init__(self) -> None:
        laws.mesh_torque(1e-6, 0.0, 1.0, stiffness=self.stiffness, restitution=self.restitution, exponent=self.exponent)


@dataclass(frozen=True)
class StopRow:
    """The fitted stop against the law at one closing speed (worst of `PHASES`).

    Attributes:
        speed: closing speed [rad/s].
        law_peak_torque: the law's peak torque [N m].
        law_restitution: the law's restitution [-].
        peak_torque: the stop's peak torque [N m] (the phase with the larger error).
        restitution: the stop's restitution [-] (likewise).
        peak_torque_err: peak torque / the law's − 1 [-].
        restitution_err: restitution / the law's − 1 [-].
    """

    speed: float
    law_peak_torque: float
    law_restitution: float
    peak_torque: float
    restitution: float
    peak_torque_err: float
    restitution_err: float


@dataclass(frozen=True)
class TorsionalStop:
    """A fitted backlash stop and how well it follows the law.

    Attributes:
        law: the mesh law fitted to.
        inertia: effective inertia J along the band [kg m^2].
        timestep: the time step fitted at [s].
        integrator: MuJoCo integrator fitted with (``mjtIntegrator`` value).
        stiffness: the stop's spring K̂ [N m/rad].
        damping: the stop's damper B̂ [N m s/rad].
        speeds: closing speeds fitted over [rad/s].
        rows: accuracy per speed.
        omega_h: ω̂ h of the fitted spring at the time step [-].
        damped_bound: h²ω̂² + 2hβ̂ [-] (< 4 for stability).
        nfev: MuJoCo scene evaluations of the fit.
        wall_time: fit time [s].
    """

    law: MeshLaw
    inertia: float
    timestep: float
    integrator: int
    stiffness: float
    damping: float
    speeds: tuple[float, ...]
    rows: tuple[StopRow, ...]
    omega_h: float
    damped_bound: float
    nfev: int
    wall_time: float

    def meets_goal(self) -> bool:
        """Peak torque and restitution within `GOAL` at every fitted speed."""
        return all(abs(r.peak_torque_err) <= GOAL and abs(r.restitution_err) <= GOAL for r in self.rows)


def stop_solref(stiffness: float, damping: float, invweight: float) -> tuple[float, float]:
    """Direct-mode solref (−K̂ Â, −B̂ Â) of a spring K̂ [N m/rad] and damper B̂ [N m s/rad] on a
    tendon of inverse weight Â [1/(kg m^2)] (its ``tendon_invweight0``)."""
    return (-stiffness * invweight, -damping * invweight)


def stop_solimp() -> tuple[float, float, float, float, float]:
    """The stop's solimplimit: the constant impedance `STOP_IMPEDANCE`."""
    return (STOP_IMPEDANCE, STOP_IMPEDANCE, 0.001, 0.5, 2.0)


def stop_speeds(speed: float, n: int = 5) -> np.ndarray:
    """``n`` log-spaced closing speeds over the decade around ``speed`` [rad/s] (speed/√10 to √10 speed)."""
    v = positive("impact speed", speed, "rad/s")
    return np.geomspace(v / math.sqrt(10.0), v * math.sqrt(10.0), n)


def stop_timestep(law: MeshLaw, inertia: float, timestep: float, top_speed: float) -> float:
    """The time step [s] for the stop: ``timestep``, or below it where ω h > `OMEGA_H`.

    ω = `laws.mesh_omega` at the law's largest penetration at ``top_speed`` [rad/s] (the
    stiffest point of K δⁿ for n >= 1; any point for the gear mesh's n = 1). The lowered step is
    OMEGA_H/ω rounded down to one significant digit.

    Raises:
        StopStabilityError: the step needed is below `MIN_TIMESTEP`.
        ValueError: n < 1 (the stop's stiffness would be unbounded at first touch).
    """
    h = positive("timestep", timestep, "s")
    if law.exponent < 1:
        raise ValueError(f"mesh exponent must be >= 1 (got {law.exponent!r}): K d^n is infinitely stiff at d = 0 below")
    deepest = 1.0 if law.exponent == 1 else law_stop_impact(law, inertia, top_speed)[3]
    omega = laws.mesh_omega(law.stiffness, deepest, inertia, law.exponent)
    if omega * h <= OMEGA_H:
        return h
    need = OMEGA_H / omega
    digit = 10.0 ** math.floor(math.log10(need))
    lowered = math.floor(need / digit) * digit
    if lowered < MIN_TIMESTEP:
        raise StopStabilityError(
            f"the backlash stop (mesh stiffness {law.stiffness:.4g} N m/rad on an effective inertia {inertia:.4g} "
            f"kg m^2: omega = {omega:.4g} rad/s) needs a time step of {need:.3g} s for omega*h <= {OMEGA_H}, below the "
            f"smallest allowed {MIN_TIMESTEP:g} s; give a smaller mesh_stiffness"
        )
    return lowered


def stop_scene(
    inertia: float, half_width: float, solref: Sequence[float], timestep: float, integrator: int
) -> mujoco.MjModel:
    """One hinge of inertia ``inertia`` [kg m^2] inside the band ±``half_width`` [rad] of a tendon
    limit with ``solref`` and `stop_solimp`, no gravity, at ``timestep`` with ``integrator``."""
    spec = mujoco.MjSpec()
    spec.option.timestep = timestep
    spec.option.integrator = integrator
    spec.option.gravity = [0.0, 0.0, 0.0]
    body = spec.worldbody.add_body(
        mass=1.0, inertia=[inertia, inertia, inertia], explicitinertial=True, ipos=[0, 0, 0], iquat=[1, 0, 0, 0]
    )
    body.add_joint(name="q", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0])
    band = spec.add_tendon(name="band", limited=mujoco.mjtLimited.mjLIMITED_TRUE, range=[-half_width, half_width])
    band.wrap_joint("q", 1.0)
    band.solref_limit = list(solref)
    band.solimp_limit = list(stop_solimp())
    return spec.compile()


def scene_stop_impact(model: mujoco.MjModel, speed: float, phase: float, max_steps: int) -> tuple[float, float]:
    """(peak torque [N m], restitution [-]) of the scene's hinge closing on its upper stop at ``speed``.

    The hinge starts ``phase`` of a step's travel short of the stop; the torque is the limit
    row's constraint force after each step; the restitution is the speed after the limit lets
    go over ``speed``.

    Raises:
        RuntimeError: the hinge has not left the stop after ``max_steps``.
    """
    data = mujoco.MjData(model)
    b, h = float(model.tendon_range[0, 1]), float(model.opt.timestep)
    data.qpos[0] = b - phase * speed * h
    data.qvel[0] = speed
    peak, touched = 0.0, False
    for _ in range(max_steps):
        mujoco.mj_step(model, data)
        if data.nefc:
            touched = True
            peak = max(peak, float(data.efc_force[0]))
        if touched and data.qpos[0] < b and data.qvel[0] < 0:
            mujoco.mj_forward(model, data)
            if not data.nefc:
                return peak, -float(data.qvel[0]) / speed
    raise RuntimeError(f"the stop scene did not separate within {max_steps} steps at {speed:g} rad/s")


def law_stop_impact(law: MeshLaw, inertia: float, speed: float) -> tuple[float, float, float, float]:
    """(peak torque [N m], restitution [-], duration [s], largest penetration [rad]) of the law's impact
    at ``speed`` [rad/s]."""
    from clearance.contact_calibration.impact import simulate_impact  # scipy.integrate: on first use

    k, e, n = law.stiffness, law.restitution, law.exponent

    def torque(d: Any, dd: Any, v: float) -> Any:
        return laws.mesh_torque(d, dd, v, stiffness=k, restitution=e, exponent=n)

    imp = simulate_impact(torque, mass=inertia, speed=speed, n_samples=200)
    return imp.peak_force, imp.restitution, imp.duration, imp.max_penetration


def _row(speed: float, ref: tuple[float, float, float, float], err: np.ndarray) -> StopRow:
    """The row at ``speed`` from the law's impact and the (phase, [peak, restitution]) relative errors."""
    worst = [int(np.argmax(np.abs(err[:, q]))) for q in range(2)]
    return StopRow(
        speed,
        ref[0],
        ref[1],
        float(ref[0] * (1 + err[worst[0], 0])),
        float(ref[1] * (1 + err[worst[1], 1])),
        float(err[worst[0], 0]),
        float(err[worst[1], 1]),
    )


def stop_at(stop: TorsionalStop, inertia: float, speed: float) -> StopRow:
    """The fitted stop against the law at another effective inertia [kg m^2] and closing speed [rad/s].

    The stop's spring and damper are a penalty on the band whatever the pose (its impedance is
    small), while the effective inertia along the band changes with the pose; the law's
    restitution does not depend on the inertia and a linear damper's does (its damping ratio
    goes like 1/sqrt(J)), so away from the inertia fitted at the rebound drifts. This says by
    how much (worst of `PHASES`).
    """
    j = positive("inertia", inertia, "kg m^2")
    ref = law_stop_impact(stop.law, j, speed)
    model = stop_scene(j, 1.0, stop_solref(stop.stiffness, stop.damping, 1.0 / j), stop.timestep, stop.integrator)
    steps = int(math.ceil(4 * ref[2] / stop.timestep)) + 20
    out = np.array([scene_stop_impact(model, speed, p, steps) for p in PHASES])
    return _row(speed, ref, out / np.array(ref[:2]) - 1.0)


def fit_stop(
    law: MeshLaw,
    *,
    inertia: float,
    half_width: float,
    speeds: Sequence[float] | np.ndarray,
    timestep: float,
    integrator: int = int(mujoco.mjtIntegrator.mjINT_EULER),
) -> TorsionalStop:
    """Fit the stop's spring K̂ and damper B̂ to ``law`` over ``speeds`` at ``timestep``.

    Args:
        law: the mesh law.
        inertia: effective inertia J along the band [kg m^2].
        half_width: the band's half-width b [rad] (the scene's; the fit does not depend on it).
        speeds: closing speeds [rad/s], >= 2 (`stop_speeds`).
        timestep: time step [s] (`stop_timestep`).
        integrator: the model's integrator.

    Returns:
        The fitted stop with its accuracy per speed.

    Raises:
        StopStabilityError: the fitted stop is unstable at ``timestep``.
        ValueError: bad arguments.
    """
    from scipy.optimize import least_squares  # here, not at import (see fit.reference_impacts)

    t0 = time.perf_counter()
    j = positive("inertia", inertia, "kg m^2")
    b = positive("half_width", half_width, "rad")
    h = positive("timestep", timestep, "s")
    v = np.sort(np.asarray(speeds, dtype=float))
    if v.ndim != 1 or len(v) < 2 or not np.all(np.isfinite(v) & (v > 0)):
        raise ValueError(f"speeds must be >= 2 positive finite closing speeds [rad/s] (got {speeds!r})")
    refs = [law_stop_impact(law, j, float(s)) for s in v]
    max_steps = int(math.ceil(4 * max(r[2] for r in refs) / h)) + 20
    mid = len(v) // 2
    k0 = (refs[mid][0] / v[mid]) ** 2 / j  # the linear spring with the law's peak torque
    loge = math.log(max(min(refs[mid][1], 0.999), 1e-3))
    zeta = -loge / math.sqrt(math.pi**2 + loge**2)  # a linear oscillator's damping ratio for that rebound
    x0 = np.log([k0, max(2 * zeta * math.sqrt(k0 * j), 1e-12 * k0)])
    nfev = 0

    def impacts(x: np.ndarray) -> np.ndarray:
        """(speed, phase, [peak, restitution]) of the scene with stiffness, damping exp(x)."""
        # a band at least stop_at's (1 rad): a narrow one (the zero-play check's 0.1') crossed in one step at a fast
        # closing (UR5e's wrist, 1570 rad/s at 5e-7 s) reached its far stop before the impact separated
        model = stop_scene(j, max(b, 1.0), stop_solref(math.exp(x[0]), math.exp(x[1]), 1.0 / j), h, integrator)
        return np.array([[scene_stop_impact(model, float(s), p, max_steps) for p in PHASES] for s in v])

    target = np.array([[r[0], r[1]] for r in refs])[:, None, :]

    def residuals(x: np.ndarray) -> np.ndarray:
        nonlocal nfev
        nfev += 1
        try:
            out = impacts(x)
        except RuntimeError:
            return np.full(len(v) * len(PHASES) * 2, 1e3)  # did not separate: far off
        return ((out / target - 1.0) / GOAL).ravel()

    sol = least_squares(residuals, x0, method="trf", diff_step=1e-4, xtol=1e-8, ftol=1e-10, max_nfev=60)
    k, c = math.exp(sol.x[0]), math.exp(sol.x[1])
    err = impacts(sol.x) / target - 1.0
    rows = [_row(float(s), refs[i], err[i]) for i, s in enumerate(v)]
    omega_h = math.sqrt(k / j) * h
    bound = omega_h**2 + 2 * h * c / j
    if omega_h >= 2.0 or bound >= 4.0:
        raise StopStabilityError(
            f"the fitted backlash stop (stiffness {k:.4g} N m/rad, damping {c:.4g} N m s/rad on {j:.4g} kg m^2) is "
            f"unstable at time step {h:g} s: omega*h = {omega_h:.3f} (must be < 2), h^2 omega^2 + 2 h beta = "
            f"{bound:.3f} (must be < 4)"
        )
    return TorsionalStop(
        law,
        j,
        h,
        int(integrator),
        k,
        c,
        tuple(float(s) for s in v),
        tuple(rows),
        omega_h,
        bound,
        nfev,
        time.perf_counter() - t0,
    )
