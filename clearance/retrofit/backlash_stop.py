"""The stops at the ends of each backlash band: the effective inertia, the impact speeds, the fit.

For each band (the fixed tendon q_load - q_motor of `clearance.retrofit.backlash`) on the
model with its motor bodies added:

- the effective inertia along the band, J = 1/(J_t M⁻¹ J_tᵀ) with the tendon's Jacobian J_t and
  the mass matrix M at the model's reference pose (qpos0): the link's inertia and the motor's
  armature (the rotor's reflected inertia) in series, with whatever the rest of the model
  couples to them; and its range over `POSE_SAMPLES` poses drawn in the joints' ranges (the
  time step is chosen at the lightest, and the fitted stop is checked against the law at the
  lightest and the heaviest);
- the closing speed the stop is fitted around, unless given: the speed at which the motor,
  pushed from rest by its actuators' largest torque, takes up the whole band 2b while the load
  stands, v = sqrt(2 · 2b · a) with a the band's acceleration per that torque (M⁻¹ along the
  band). Where the actuators' torque is unbounded (no control or force range) the speed is
  `FALLBACK_IMPACT_SPEED`, and the record says so;
- for a 'calibrated' stop, the time step (`torsional_stop.stop_timestep`, the smallest over
  the bands) and the fit of the tendon limit's solreflimit and solimplimit to the mesh law over
  a decade of closing speeds (`torsional_stop.fit_stop`) at that step and the model's
  integrator. An 'exact' stop (the law itself, in the compiled plugin) needs no fit but the
  same time step rule. A 'recipe' stop keeps MuJoCo's default limit and the model's step.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.contact_calibration.torsional_stop import (
    MeshLaw,
    StopRow,
    TorsionalStop,
    fit_stop,
    stop_at,
    stop_solimp,
    stop_solref,
    stop_speeds,
    stop_timestep,
)
from clearance.retrofit.play import Backlash
from clearance.retrofit.poses import random_pose

__all__ = [
    "FALLBACK_IMPACT_SPEED",
    "POSE_SAMPLES",
    "Band",
    "BandStop",
    "band_inertia",
    "calibrate_stops",
    "impact_speed",
    "pose_inertias",
    "stop_note",
]

FALLBACK_IMPACT_SPEED = 1.0
"""Closing speed [rad/s] a stop is fitted around where the actuators' torque is unbounded."""

POSE_SAMPLES = 64
"""Poses (besides qpos0) the effective inertia along each band is sampled at: every hinge and
slide uniform in its range (an unlimited hinge over a turn; free, ball and unlimited slide
joints at qpos0), each motor at its load's angle; seeded, so a retrofit is reproducible."""


@dataclass(frozen=True)
class Band:
    """Where one band sits in the compiled model.

    Attributes:
        tendon: the band's tendon id. load_dof, motor_dof: the two hinges' dofs.
        actuators: ids of the actuators on the motor hinge. backlash: what was asked.
    """

    tendon: int
    load_dof: int
    motor_dof: int
    actuators: tuple[int, ...]
    backlash: Backlash


@dataclass(frozen=True)
class BandStop:
    """The stop of one band.

    Attributes:
        kind: 'calibrated', 'recipe' or 'exact'.
        inertia: effective inertia J along the band at the reference pose [kg m^2].
        invweight: the tendon's inverse weight Â at qpos0 (MuJoCo's ``tendon_invweight0``) [1/(kg m^2)].
        impact_speed: the closing speed fitted around [rad/s].
        speed_source: how ``impact_speed`` was found.
        fit: the fitted stop (None for 'recipe' and 'exact').
        solref: solreflimit emitted (None: MuJoCo's default).
        solimp: solimplimit emitted (None: MuJoCo's default).
        inertia_range: (lightest, heaviest) effective inertia over the sampled poses [kg m^2].
        pose_rows: the fitted stop against the law at the impact speed at the lightest and the
            heaviest pose (empty for 'recipe' and 'exact').
    """

    kind: str
    inertia: float
    invweight: float
    impact_speed: float
    speed_source: str
    fit: TorsionalStop | None
    solref: tuple[float, float] | None
    solimp: tuple[float, float, float, float, float] | None
    inertia_range: tuple[float, float] = (0.0, 0.0)
    pose_rows: tuple[StopRow, ...] = ()


def _band_jacobian(model: mujoco.MjModel, band: Band) -> np.ndarray:
    """J_t of the band's tendon q_load - q_motor: +1 on the load dof, -1 on the motor dof."""
    jac = np.zeros(model.nv)
    jac[band.load_dof], jac[band.motor_dof] = 1.0, -1.0
    return jac


def _inverse_mass_along(model: mujoco.MjModel, band: Band) -> np.ndarray:
    """M⁻¹ J_tᵀ at qpos0 for the band's tendon."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    out = np.zeros(model.nv)
    mujoco.mj_solveM(model, data, out.reshape(1, -1), _band_jacobian(model, band).reshape(1, -1))
    return out


def pose_inertias(model: mujoco.MjModel, bands: Mapping[str, Band]) -> dict[str, tuple[float, float]]:
    """Hinge -> (lightest, heaviest) effective inertia along its band over qpos0 and `POSE_SAMPLES` poses."""
    rng = np.random.default_rng(0)
    data = mujoco.MjData(model)
    motors = [
        (int(model.jnt_qposadr[model.dof_jntid[b.load_dof]]), int(model.jnt_qposadr[model.dof_jntid[b.motor_dof]]))
        for b in bands.values()
    ]
    jacs = [_band_jacobian(model, b) for b in bands.values()]
    seen = np.zeros((POSE_SAMPLES + 1, len(jacs)))
    x = np.zeros((1, model.nv))
    for i in range(POSE_SAMPLES + 1):
        if i:
            random_pose(model, rng, data.qpos)
        else:
            data.qpos[:] = model.qpos0
        for load, motor in motors:
            data.qpos[motor] = data.qpos[load]
        mujoco.mj_forward(model, data)
        for k, jac in enumerate(jacs):
            mujoco.mj_solveM(model, data, x, jac.reshape(1, -1))
            seen[i, k] = 1.0 / float(jac @ x[0])
    return {name: (float(seen[:, k].min()), float(seen[:, k].max())) for k, name in enumerate(bands)}


def band_inertia(model: mujoco.MjModel, band: Band) -> float:
    """Effective inertia along the band, 1/(J_t M⁻¹ J_tᵀ) at qpos0 [kg m^2]."""
    x = _inverse_mass_along(model, band)
    return 1.0 / float(x[band.load_dof] - x[band.motor_dof])


def _actuator_torque(model: mujoco.MjModel, k: int) -> float | None:
    """Largest torque actuator ``k`` applies on its joint [N m]; None where unbounded.

    Its force range where it has one, else its fixed gain times its largest control (a motor) or
    its control range's span (a servo, whose bias subtracts the position: its largest error).
    """
    gear = abs(float(model.actuator_gear[k, 0]))
    force = math.inf
    if model.actuator_forcelimited[k]:
        force = float(np.max(np.abs(model.actuator_forcerange[k])))
    if (
        model.actuator_ctrllimited[k]
        and int(model.actuator_gaintype[k]) == int(mujoco.mjtGain.mjGAIN_FIXED)
        and int(model.actuator_dyntype[k]) == int(mujoco.mjtDyn.mjDYN_NONE)
    ):
        lo, hi = (float(x) for x in model.actuator_ctrlrange[k])
        # a motor: gain x the largest control; a servo (a bias): gain x the control range's span, its largest error
        servo = int(model.actuator_biastype[k]) != int(mujoco.mjtBias.mjBIAS_NONE)
        force = min(force, abs(float(model.actuator_gainprm[k, 0])) * (hi - lo if servo else max(abs(lo), abs(hi))))
    return gear * force if math.isfinite(force) else None


def impact_speed(model: mujoco.MjModel, band: Band) -> tuple[float, str]:
    """(closing speed [rad/s], how it was found) the band's stop is fitted around (module docstring)."""
    if band.backlash.impact_speed is not None:
        return band.backlash.impact_speed, "given"
    torques = [_actuator_torque(model, k) for k in band.actuators]
    if any(t is None for t in torques) or not torques:
        return FALLBACK_IMPACT_SPEED, f"{FALLBACK_IMPACT_SPEED:g} rad/s (the actuators' torque is unbounded)"
    torque = float(sum(t for t in torques if t is not None))
    accel = torque * abs(float(_inverse_mass_along(model, band)[band.motor_dof]))
    if not accel > 0:
        return FALLBACK_IMPACT_SPEED, f"{FALLBACK_IMPACT_SPEED:g} rad/s (the actuators' torque is zero)"
    v = math.sqrt(4.0 * band.backlash.half_width * accel)
    return v, f"the band 2b crossed from rest under the actuators' largest torque {torque:.4g} N m"


def calibrate_stops(model: mujoco.MjModel, bands: Mapping[str, Band]) -> tuple[float, dict[str, BandStop]]:
    """(time step [s], hinge -> its stop) for the bands of ``model`` (module docstring).

    Raises:
        StopStabilityError: a calibrated stop needs a step below the smallest allowed, or its
            fit is unstable at the step.
    """
    laws = {
        name: MeshLaw(b.backlash.mesh_stiffness, b.backlash.restitution, b.backlash.mesh_exponent)
        for name, b in bands.items()
    }
    inertia = {name: band_inertia(model, b) for name, b in bands.items()}
    ranges = pose_inertias(model, bands)
    speeds = {name: impact_speed(model, b) for name, b in bands.items()}
    step = float(model.opt.timestep)
    for name, b in bands.items():
        if b.backlash.stop in ("calibrated", "exact"):
            top = float(stop_speeds(speeds[name][0])[-1])
            step = min(step, stop_timestep(laws[name], ranges[name][0], float(model.opt.timestep), top))
    out: dict[str, BandStop] = {}
    for name, b in bands.items():
        speed, source = speeds[name]
        invweight = float(model.tendon_invweight0[b.tendon])
        if b.backlash.stop != "calibrated":
            kind = b.backlash.stop
            out[name] = BandStop(kind, inertia[name], invweight, speed, source, None, None, None, ranges[name])
            continue
        fit = fit_stop(
            laws[name],
            inertia=inertia[name],
            half_width=b.backlash.half_width,
            speeds=stop_speeds(speed),
            timestep=step,
            integrator=int(model.opt.integrator),
        )
        solref = stop_solref(fit.stiffness, fit.damping, invweight)
        poses = tuple(stop_at(fit, j, speed) for j in ranges[name])
        out[name] = BandStop(
            "calibrated", inertia[name], invweight, speed, source, fit, solref, stop_solimp(), ranges[name], poses
        )
    return step, out


def stop_note(stop: BandStop) -> str:
    """One line on a band's stop (for notes and reports)."""
    if stop.kind == "exact":
        return (
            "the mesh law itself, exact (compiled plugin clearance.backlash_stop; effective inertia "
            f"{stop.inertia:.4g} kg m^2)"
        )
    if stop.fit is None:
        return f"MuJoCo's default stop (the recipe, not calibrated; effective inertia {stop.inertia:.4g} kg m^2)"
    worst = max(max(abs(r.peak_torque_err), abs(r.restitution_err)) for r in stop.fit.rows)
    return (
        f"stop calibrated to K = {stop.fit.law.stiffness:.4g} N m/rad, e = {stop.fit.law.restitution:g} at J = "
        f"{stop.inertia:.4g} kg m^2 over {stop.fit.speeds[0]:.3g}..{stop.fit.speeds[-1]:.3g} rad/s (worst error "
        f"{100 * worst:.2f} %)"
    )
