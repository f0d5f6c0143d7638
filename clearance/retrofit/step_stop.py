"""The step-limited stop: a play's end stop at the robot's own time step, and where it represents the play.

A robot's model runs at 1–10 ms. A stop at the end of a band (backlash: q_load − q_motor
within ±b; radial play: a journal's eccentricity within c) can then only be MuJoCo's soft limit
whose spring time constant 1/ω̂ spans at least `STEP_SPAN` steps (MuJoCo's own rule for its
solref time constant, `refsafe`: timeconst >= 2 h), ω̂ = 1/(`STEP_SPAN` h): far softer than a
gear mesh or a bearing (a 1e4 N m/rad mesh on a 1.4e-3 kg m^2 flywheel rings at 2,600 rad/s; a
10 ms step allows 50 rad/s). The stiffness is therefore not a free choice: among stops with the same rebound the
stiffest penetrates least, so the stop is this spring, and its damping is fitted so that its
rebound and its impulse per impact are those of the exact stop at a fine step
(`exact_impact`: the compiled `clearance.backlash_stop` at ω h = `torsional_stop.OMEGA_H`).

The stop is written in MuJoCo's standard form, solref = (timeconst, dampratio) =
(1/(ω̂ ζ), ζ), with a constant impedance d = `STEP_IMPEDANCE` close to 1: MuJoCo then makes the
band's relative acceleration r̈ = −2ζω̂ ṙ − ω̂² r whatever the inertia along the band (the
constraint's regulariser, (1 − d)/d of the inverse weight at qpos0, lets through 1 % of
the push at qpos0 and a few % at a pose several times heavier), so the rebound, the impulse per
closing speed and inertia, and the penetration hold at every pose, which a penalty spring
fitted at one inertia does not (`clearance.contact_calibration.torsional_stop`).

Scale: in units of the step the stop's impact is one dimensionless system (ω̂ h = 1/`STEP_SPAN`,
ζ, the onset's phase within a step), so ζ does not depend on the step, the rebound and
impulse/(J v) do not depend on the speed v or the inertia J, and the deepest penetration is
δ_max = p h v with one number p (`StepStop.penetration`/h, the worst of `PHASES`). The stop
represents a band b where δ_max <= `MAX_PENETRATION` b at the closing speed v:

    b >= p h v / MAX_PENETRATION          (`smallest_band`)
    h <= MAX_PENETRATION b / (p v)        (`largest_step`)

The same arithmetic serves any play whose stop is a 1-DOF band (radial play along its line of
centres, through a tendon); only the exact reference differs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.checks import positive
from clearance.contact_calibration.torsional_stop import OMEGA_H, MeshLaw

__all__ = [
    "MAX_PENETRATION",
    "PHASES",
    "STEP_IMPEDANCE",
    "STEP_SPAN",
    "ExactImpact",
    "StepImpact",
    "StepStop",
    "exact_impact",
    "fit_step_stop",
    "fit_to_impact",
    "largest_step",
    "smallest_band",
    "step_impact",
    "step_omega",
]

STEP_SPAN = 2.0
"""Steps the stop's spring time constant 1/ω̂ spans at least [-] (MuJoCo's refsafe rule, timeconst >= 2 h)."""

MAX_PENETRATION = 0.2
"""Deepest penetration into the stop a band is represented with, as a fraction of its half-width b [-]."""

STEP_IMPEDANCE = 0.99
"""Constant impedance d of the stop's solimp [-]: close to 1, so MuJoCo's soft limit follows its
reference acceleration (pose-independent) and lets 1 - d of the push through."""

PHASES = (0.125, 0.375, 0.625, 0.875)
"""Onset phases an impact is run at: how far into a step, as a fraction of it, the band closes."""

_MOTOR_RATIO = 1e3
"""The exact scene's motor inertia over its load's: the motor stands, the effective inertia is the load's."""


@dataclass(frozen=True)
class ExactImpact:
    """One impact of the exact stop (the law in the compiled plugin) at its fine step.

    Attributes:
        rebound: opening speed after the impact over the closing speed [-].
        impulse: the stop's impulse over the impact divided by J v [-] (1 + rebound for a free impact).
        timestep: the fine step it ran at [s] (0: the law's own impact, integrated without a step).
    """

    rebound: float
    impulse: float
    timestep: float


@dataclass(frozen=True)
class StepImpact:
    """One impact of a step-limited stop at one onset phase.

    Attributes:
        rebound: opening over closing speed [-].
        impulse: the limit's impulse over J v [-].
        penetration: deepest penetration over the closing speed [s] (δ_max / v).
    """

    rebound: float
    impulse: float
    penetration: float


@dataclass(frozen=True)
class StepStop:
    """A step-limited stop fitted at one step, and how it compares with the exact stop.

    Attributes:
        timestep: the step h [s]. integrator: MuJoCo integrator (``mjtIntegrator`` value).
        omega: ω̂ = 1/(`STEP_SPAN` h) [rad/s]. dampratio: ζ fitted [-].
        exact: the exact stop's impact it was fitted to.
        impacts: the stop's impact at each of `PHASES`.
        penetration: worst δ_max / v over `PHASES` [s].
    """

    timestep: float
    integrator: int
    omega: float
    dampratio: float
    exact: ExactImpact
    impacts: tuple[StepImpact, ...]
    penetration: float

    @property
    def solref(self) -> tuple[float, float]:
        """MuJoCo's standard solref (timeconst [s], dampratio [-]) = (1/(ω̂ ζ), ζ)."""
        return (1.0 / (self.omega * self.dampratio), self.dampratio)

    @property
    def solimp(self) -> tuple[float, float, float, float, float]:
        """solimp with the constant impedance `STEP_IMPEDANCE`."""
        return (STEP_IMPEDANCE, STEP_IMPEDANCE, 0.001, 0.5, 2.0)

    @property
    def rebound_error(self) -> float:
        """Worst rebound over `PHASES` / the exact stop's − 1 [-]."""
        return max((i.rebound / self.exact.rebound - 1.0 for i in self.impacts), key=abs)

    @property
    def impulse_error(self) -> float:
        """Worst impulse per impact over `PHASES` / the exact stop's − 1 [-]."""
        return max((i.impulse / self.exact.impulse - 1.0 for i in self.impacts), key=abs)


def step_omega(timestep: float) -> float:
    """ω̂ = 1/(`STEP_SPAN` h) [rad/s], the stiffest stop a step ``timestep`` [s] allows."""
    return 1.0 / (STEP_SPAN * positive("timestep", timestep, "s"))


def exact_impact(law: MeshLaw, *, inertia: float, speed: float) -> ExactImpact:
    """The exact stop's impact: a load of ``inertia`` [kg m^2] closing at ``speed`` [rad/s] on a standing motor.

    Two hinges on one axis closed by the compiled `clearance.backlash_stop` (the gear mesh's law)
    at ω h = `OMEGA_H` with ω = sqrt(K/J); the motor is `_MOTOR_RATIO` times heavier, so the
    effective inertia is the load's.

    Raises:
        clearance.contact_plugin.PluginUnavailableError: the compiled plugin is not installed.
        RuntimeError: the load has not left the stop after many impact durations.
    """
    from clearance.contact_plugin import require
    from clearance.contact_plugin.backlash_stop import add_backlash_stop, sensor_offsets

    require()
    j, v = positive("inertia", inertia, "kg m^2"), positive("speed", speed, "rad/s")
    omega = math.sqrt(law.stiffness / j)
    h = OMEGA_H / omega
    spec = mujoco.MjSpec()
    spec.option.timestep = h
    spec.option.gravity = [0.0, 0.0, 0.0]
    for name, inert in (("load", j), ("motor", _MOTOR_RATIO * j)):
        body = spec.worldbody.add_body(
            name=name, mass=1.0, inertia=[inert] * 3, explicitinertial=True, ipos=[0, 0, 0], iquat=[1, 0, 0, 0]
        )
        body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0])
    b = 1.0
    add_backlash_stop(
        spec,
        name="stop",
        load_joint="load",
        motor_joint="motor",
        half_width=b,
        stiffness=law.stiffness,
        restitution=law.restitution,
        exponent=law.exponent,
    )
    model = spec.compile()
    data = mujoco.MjData(model)
    torque = sensor_offsets(model, "stop")["load_torque"]
    data.qpos[0] = b - 0.5 * v * h
    data.qvel[0] = v
    j_eff = j * _MOTOR_RATIO / (1.0 + _MOTOR_RATIO)
    impulse, touched = 0.0, False
    for _ in range(int(40 * math.pi / OMEGA_H)):
        mujoco.mj_step(model, data)
        t = -float(data.sensordata[torque])  # the stop pushes the load back: -s T with s = +1
        if t > 0:
            touched, impulse = True, impulse + t * h
        elif touched and data.qpos[0] - data.qpos[1] < b:
            rate = float(data.qvel[0] - data.qvel[1])
            return ExactImpact(-rate / v, impulse / (j_eff * v), h)
    raise RuntimeError(f"the exact stop's scene did not separate at {v:g} rad/s")


def _scene(inertia: float, solref: Sequence[float], timestep: float, integrator: int) -> mujoco.MjModel:
    """One hinge of ``inertia`` inside a tendon limit ±1 rad with ``solref`` and `STEP_IMPEDANCE`."""
    spec = mujoco.MjSpec()
    spec.option.timestep = timestep
    spec.option.integrator = integrator
    spec.option.gravity = [0.0, 0.0, 0.0]
    body = spec.worldbody.add_body(
        mass=1.0, inertia=[inertia] * 3, explicitinertial=True, ipos=[0, 0, 0], iquat=[1, 0, 0, 0]
    )
    body.add_joint(name="q", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0])
    band = spec.add_tendon(name="band", limited=mujoco.mjtLimited.mjLIMITED_TRUE, range=[-1.0, 1.0])
    band.wrap_joint("q", 1.0)
    band.solref_limit = list(solref)
    band.solimp_limit = [STEP_IMPEDANCE, STEP_IMPEDANCE, 0.001, 0.5, 2.0]
    return spec.compile()


def step_impact(
    *, dampratio: float, timestep: float, integrator: int, phase: float, inertia: float = 1.0, speed: float = 1.0
) -> StepImpact:
    """The step-limited stop's impact (ω̂ = `step_omega`, ``dampratio``) at one onset ``phase`` in [0, 1).

    Raises:
        RuntimeError: the hinge has not left the stop after many impact durations.
    """
    h, v = positive("timestep", timestep, "s"), positive("speed", speed, "rad/s")
    omega = step_omega(h)
    model = _scene(positive("inertia", inertia, "kg m^2"), (1.0 / (omega * dampratio), dampratio), h, integrator)
    data = mujoco.MjData(model)
    data.qpos[0] = 1.0 - phase * v * h
    data.qvel[0] = v
    impulse, deepest, touched = 0.0, 0.0, False
    for _ in range(int(40 * STEP_SPAN * math.pi) + 20):
        mujoco.mj_step(model, data)
        if data.nefc:
            touched, impulse = True, impulse + float(data.efc_force[0]) * h
        deepest = max(deepest, float(data.qpos[0]) - 1.0)
        if touched and data.qpos[0] < 1.0 and data.qvel[0] < 0:
            mujoco.mj_forward(model, data)
            if not data.nefc:
                return StepImpact(-float(data.qvel[0]) / v, impulse / (inertia * v), deepest / v)
    raise RuntimeError(f"the step-limited stop's scene did not separate (dampratio {dampratio:g})")


def fit_step_stop(law: MeshLaw, *, timestep: float, integrator: int, inertia: float, speed: float) -> StepStop:
    """Fit the step-limited stop's damping ratio to the exact stop's rebound and impulse per impact.

    Args:
        law: the mesh law of the exact stop.
        timestep: the robot's step h [s].
        integrator: the model's integrator (``mjtIntegrator`` value).
        inertia: effective inertia along the band [kg m^2] (the exact stop's impact; the
            step-limited stop does not depend on it).
        speed: closing speed [rad/s] (likewise).

    Returns:
        The fitted stop: ω̂ = `step_omega`, ζ, its impacts at `PHASES` and its worst penetration per speed.

    Raises:
        ValueError: bad arguments. RuntimeError: a scene did not separate.
    """
    exact = exact_impact(law, inertia=inertia, speed=speed)
    return fit_to_impact(exact, timestep=timestep, integrator=integrator)


def fit_to_impact(exact: ExactImpact, *, timestep: float, integrator: int) -> StepStop:
    """Fit the step-limited stop's damping ratio to an exact impact's rebound and impulse per impact.

    `fit_step_stop` for the gear mesh; radial play fits its bearing's law the same way
    (`clearance.retrofit.radial_stop`).

    Args:
        exact: the exact stop's impact (rebound, impulse over the inertia times the closing speed).
        timestep: the robot's step h [s].
        integrator: the model's integrator (``mjtIntegrator`` value).

    Returns:
        The fitted stop: ω̂ = `step_omega`, ζ, its impacts at `PHASES` and its worst penetration per speed.

    Raises:
        ValueError: bad arguments. RuntimeError: a scene did not separate.
    """
    from scipy.optimize import least_squares  # on first use

    h = positive("timestep", timestep, "s")
    target = np.array([exact.rebound, exact.impulse])

    def impacts(x: float) -> list[StepImpact]:
        return [step_impact(dampratio=math.exp(x), timestep=h, integrator=integrator, phase=p) for p in PHASES]

    def residuals(x: np.ndarray) -> np.ndarray:
        got = np.array([[i.rebound, i.impulse] for i in impacts(float(x[0]))])
        return (got / target - 1.0).ravel()

    loge = math.log(max(exact.rebound, 1e-3))
    zeta0 = min(-loge / math.sqrt(math.pi**2 + loge**2), 0.9)  # a linear oscillator's damping ratio for it
    sol = least_squares(residuals, [math.log(zeta0)], bounds=([math.log(1e-4)], [0.0]), xtol=1e-10, ftol=1e-12)
    zeta = math.exp(float(sol.x[0]))
    out = impacts(float(sol.x[0]))
    return StepStop(h, int(integrator), step_omega(h), zeta, exact, tuple(out), max(i.penetration for i in out))


def smallest_band(stop: StepStop, speed: float) -> float:
    """Smallest half-width b [rad] the stop represents at closing speed ``speed`` [rad/s] (module docstring)."""
    return stop.penetration * positive("speed", speed, "rad/s") / MAX_PENETRATION


def largest_step(stop: StepStop, band: float, speed: float) -> float:
    """Largest step [s] at which a step-limited stop represents half-width ``band`` [rad] at ``speed`` [rad/s].

    The penetration per speed scales with the step (module docstring), so this is the fitted
    stop's step times the band over its `smallest_band`.
    """
    return stop.timestep * positive("band", band, "rad") / smallest_band(stop, speed)
