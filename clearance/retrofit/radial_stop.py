"""Radial play at the robot's own time step: the journal held within c by a tendon limit, no ring.

Geometry. The retrofit's slides before a hinge let the journal's centre move in the bearing
plane; the sites ``clr_<hinge>__bearing`` and ``clr_<hinge>__journal`` sit at the two centres
(`clearance.retrofit.insertion`). A spatial tendon from the bearing's site to the journal's,
``clr_<hinge>__radial`` (`play_tendons.play_tendon_name`), has length |e|, the eccentricity's
size; limited to [0, c] its upper limit is a circle-in-circle stop in MuJoCo's constraint
solver, with no geoms and no collision. The limit's row pushes along the line of centres
e/|e|, as the bearing's normal force does. Near |e| = 0 the tendon's direction is undefined
(MuJoCo takes the world's x axis for a zero-length tendon), but the limit is inactive there:
it acts only at |e| >= c. Its lower limit at 0 never acts (MuJoCo activates it at a length
below 0). The one place the zero length shows is the tendon's inverse weight at qpos0
(``tendon_invweight0``, computed with the journal centred): along the world's x axis, so 0 for
a bearing plane normal to x. The stop is therefore written in MuJoCo's standard form, which
does not divide by it (below).

The stop. At a robot's step (1-10 ms) the bearing's contact (a Hertz-type K of 1e9-1e10
N/m^1.5) cannot be resolved; the stop is the step-limited stop of
`clearance.retrofit.step_stop`: spring frequency ω̂ = 1/(2 h) whatever the inertia along the
line of centres (impedance 0.99), its damping ratio fitted so that its rebound and its
impulse per impact are those of the bearing's law at the hinge's effective mass and closing
speed (`exact_bearing_impact`: the law's own impact, `clearance.contact_calibration.impact`,
integrated without a step: what the compiled exact contact computes at µs steps).

What it does not carry. No friction: a tendon limit has no tangential row, so the journal
slides round its bearing freely (the exact contact's Ambrosio friction, and the friction
torque it puts on the hinge, are absent: with the default friction 0 nothing is lost). No
Hertz stiffening: the stop's force is linear in the penetration, its duration fixed by ω̂
(about π/ω̂ = 2π h, 100-1000 times the exact impact's), and its penetration p h v (p about 1.9)
where the exact bearing's is µm: a journal pressed by a steady load sits (1 - d) a/ω̂² past c
(d = 0.99, a the load over the effective mass) and chatters there by a few a h² (a one-sided limit:
each step off it the load moves the journal a h²; measured at most 2 % of c on a hanging pendulum).
So the stop keeps each impact's momentum exchange (rebound, impulse) and the clearance's geometry,
not its force history.

Where it represents the play. The journal meets the stop at about the speed it gains
crossing the clearance under the hinge's peak load, v = sqrt(2 a c) (a = peak load over the
lightest effective mass: `clearance.retrofit.sizing`); the stop represents c where its deepest
penetration p h v + (1 - d) a/ω̂² is at most `step_stop.MAX_PENETRATION` (20 %) of c. Since v
grows like sqrt(c), that gives a smallest clearance per step (`smallest_clearance`, about
2 a (p h / 0.2)^2) and a largest step per clearance (`step_stop.largest_step` at that v);
outside, the request is refused naming both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from clearance.checks import positive
from clearance.model import Clearance
from clearance.options import ContactParameters
from clearance.retrofit.insertion import PlayElements, add_eccentricity_sensor
from clearance.retrofit.play import RetrofitError
from clearance.retrofit.play_tendons import PlayKind, play_tendon_name
from clearance.retrofit.sizing import PlaySizing
from clearance.retrofit.step_stop import (
    MAX_PENETRATION,
    STEP_IMPEDANCE,
    ExactImpact,
    StepStop,
    fit_to_impact,
    largest_step,
)

__all__ = [
    "ROBOT_STEP_SOURCE",
    "RadialStop",
    "add_radial_stop",
    "exact_bearing_impact",
    "fit_radial_stop",
    "radial_stop_force_name",
    "smallest_clearance",
    "stop_parameters",
]

ROBOT_STEP_SOURCE = "robot step: tendon-limit stop (step_stop), damping fitted to the law's rebound"
"""The contact source of a hinge with radial play at the robot's step."""


@dataclass(frozen=True)
class RadialStop:
    """The step-limited radial stop of one hinge, and where it represents the play.

    Attributes:
        hinge: the hinge.
        clearance: c [m], the tendon's upper limit (copied from the request, never fitted).
        acceleration: a = peak load / lightest effective mass along the line of centres [m/s^2].
        closing_speed: v = sqrt(2 a c) [m/s], the speed the stop is checked at.
        effective_mass: the median effective mass along the line of centres [kg] (the law's
            impact is at it; the stop itself does not depend on it).
        stop: the fitted step-limited stop (ω̂, ζ, rebound and impulse against the law's).
    """

    hinge: str
    clearance: float
    acceleration: float
    closing_speed: float
    effective_mass: float
    stop: StepStop

    @property
    def penetration(self) -> float:
        """Deepest penetration past c [m]: p h v at the closing speed plus the steady share (1 - d) a/ω̂²."""
        return self.stop.penetration * self.closing_speed + _steady(self.stop, self.acceleration)

    @property
    def smallest_clearance(self) -> float:
        """Smallest c [m] the stop represents at its step (`smallest_clearance`)."""
        return smallest_clearance(self.stop, self.acceleration)

    @property
    def largest_step(self) -> float:
        """Largest step [s] at which the stop represents this c at its closing speed (`step_stop.largest_step`)."""
        return largest_step(self.stop, self.clearance, self.closing_speed)


def _steady(stop: StepStop, acceleration: float) -> float:
    """Penetration past the limit under a steady push ``acceleration`` [m]: (1 - d) a / ω̂²."""
    return (1.0 - STEP_IMPEDANCE) * acceleration / stop.omega**2


def smallest_clearance(stop: StepStop, acceleration: float) -> float:
    """Smallest c [m] with p h sqrt(2 a c) + (1 - d) a/ω̂² <= `MAX_PENETRATION` c (module docstring).

    With x = sqrt(c): `MAX_PENETRATION` x² - p h sqrt(2 a) x - s = 0, s the steady share.

    Args:
        stop: the fitted step-limited stop (its penetration per closing speed p h [s]).
        acceleration: a [m/s^2], > 0.
    """
    a = positive("acceleration", acceleration, "m/s^2")
    q = stop.penetration * math.sqrt(2.0 * a)
    s = _steady(stop, a)
    x = (q + math.sqrt(q * q + 4.0 * MAX_PENETRATION * s)) / (2.0 * MAX_PENETRATION)
    return x * x


def exact_bearing_impact(clearance: Clearance, *, mass: float, speed: float) -> ExactImpact:
    """The bearing law's impact of ``mass`` [kg] closing at ``speed`` [m/s] (no load, no friction).

    The law's own 1-DOF impact (`contact_calibration.impact.clearance_impact`, integrated to its
    tolerance, no step): rebound its restitution, impulse over m v = 1 + rebound (a free impact's
    momentum balance).
    """
    from clearance.contact_calibration.impact import clearance_impact  # scipy: on first use

    imp = clearance_impact(clearance, mass=mass, speed=speed)
    return ExactImpact(imp.restitution, 1.0 + imp.restitution, 0.0)


def fit_radial_stop(
    hinge: str, clearance: Clearance, sizing: PlaySizing, *, timestep: float, integrator: int
) -> RadialStop:
    """Fit ``hinge``'s step-limited radial stop at ``timestep``, refusing a clearance it cannot represent.

    Args:
        hinge: the hinge's name (for messages).
        clearance: its play's physics (c, the law the rebound is fitted to).
        sizing: its sizing (peak load, effective mass range, `clearance.retrofit.sizing`).
        timestep: the robot's step h [s].
        integrator: the model's integrator (``mjtIntegrator`` value).

    Returns:
        The fitted stop.

    Raises:
        RetrofitError: c below the smallest clearance the step represents, naming it and the
            largest step for c.
    """
    c = clearance.radial_clearance
    a = sizing.peak_load / sizing.effective_mass_range[0]
    v = math.sqrt(2.0 * a * c)
    exact = exact_bearing_impact(clearance, mass=sizing.effective_mass, speed=v)
    m = sizing.effective_mass
    stop = RadialStop(hinge, c, a, v, m, fit_to_impact(exact, timestep=timestep, integrator=integrator))
    if stop.penetration > MAX_PENETRATION * c:
        raise RetrofitError(
            f"hinge '{hinge}': radial clearance {c * 1e6:.4g} um cannot be represented at the robot's step "
            f"{timestep * 1e3:g} ms (the stop would sink {stop.penetration / c:.0%} of c at {v:.3g} m/s, "
            f"allowed {MAX_PENETRATION:.0%}): give a clearance of at least {stop.smallest_clearance * 1e6:.4g} um "
            f"or a step of at most {stop.largest_step * 1e3:.3g} ms",
            hinge=hinge,
        )
    return stop


def stop_parameters(stop: RadialStop) -> ContactParameters:
    """The stop as a spring-damper at the median effective mass m: K = m ω̂² [N/m], B = 2 ζ ω̂ m [N s/m]
    (what a report lists; the written stop is mass-normalised, the same ω̂ and ζ at every pose)."""
    s, m = stop.stop, stop.effective_mass
    return ContactParameters(m * s.omega**2, 2.0 * s.dampratio * s.omega * m, source=ROBOT_STEP_SOURCE)


def radial_stop_force_name(hinge: str) -> str:
    """Name of the sensor reading ``hinge``'s stop force (the tendon limit's, [N])."""
    return f"{play_tendon_name(hinge, PlayKind.RADIAL)}_force"


def add_radial_stop(
    spec: mujoco.MjSpec, elements: PlayElements, stop: RadialStop, default: mujoco.MjsDefault
) -> mujoco.MjsTendon:
    """Add ``stop`` to the hinge of ``elements``: its tendon, the eccentricity and stop-force sensors.

    The tendon runs from the bearing's site to the journal's, limited to [0, c], with the stop's
    solref (timeconst, dampratio) and constant-impedance solimp; fills ``elements``' sensors
    (eccentricity, then the stop's force).
    """
    tendon = spec.add_tendon(
        default=default,
        name=play_tendon_name(elements.hinge, PlayKind.RADIAL),
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        range=[0.0, stop.clearance],
    )
    tendon.wrap_site(elements.bearing_site)
    tendon.wrap_site(elements.journal_site)
    tendon.solref_limit = list(stop.stop.solref)
    tendon.solimp_limit = list(stop.stop.solimp)
    ecc = add_eccentricity_sensor(spec, elements)
    force = spec.add_sensor(
        name=radial_stop_force_name(elements.hinge),
        type=mujoco.mjtSensor.mjSENS_TENDONLIMITFRC,
        objtype=mujoco.mjtObj.mjOBJ_TENDON,
        objname=tendon.name,
    )
    elements.sensors = [ecc.name, force.name]
    return tendon
