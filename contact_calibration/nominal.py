"""Nominal contact parameters of a ring bearing: no fitting, documented formulas.

Stiffness: the per-row stiffness k that makes the ring of N linear rows reproduce the
journal-bearing stiffness K of the clearance-joint literature (docs/references.md: K = 4/(3(sigma_B + sigma_J))
sqrt(R_B R_J / (R_B - R_J))), k = K / C with C the ring coefficient of
`clearance.mjcf.bearing.ring_stiffness_coefficient` (docs/mujoco_notes.md: a ring of linear
rows is already Hertz-like, F ~ delta^1.5). For a cylindrical law K is the Hertz-like
stiffness F_el(delta_ref)/delta_ref^1.5 that gives the law's force at the law impact's peak
penetration delta_ref.

Damping: the constant per-row damping b for which a radial impact of the ring model at a
nominal speed (4 m/s by default) has the same restitution as the LN impact at that speed.
Because the ring's damping grows like sqrt(delta) and LN's like delta^1.5, restitution then
drifts with impact speed; `clearance.contact_calibration` fits better values.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from clearance.contact_calibration.laws import bearing_stiffness
from clearance.mjcf.bearing import (
    RingGeometry,
    ring_damping_coefficient,
    ring_stiffness_coefficient,
)
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw
from clearance.options import ContactParameters

if TYPE_CHECKING:
    from clearance.contact_calibration.impact import ForceLaw, ImpactResult

__all__ = ["NOMINAL_IMPACT_SPEED", "nominal_parameters", "ring_impact"]

NOMINAL_IMPACT_SPEED = 4.0
"""Impact speed [m/s] at which nominal damping matches LN restitution."""


def _ring_law(geom: RingGeometry, k: float, b: float, delta_ref: float) -> ForceLaw:
    """The ring's normal force law: stiffness fitted over 1/20-2 ``delta_ref``, damping at it."""
    c_k = ring_stiffness_coefficient(geom, (delta_ref / 20, delta_ref * 2))
    # ring damping ~ a sqrt(delta): fit a at the reference depth
    a = ring_damping_coefficient(geom, delta_ref) / math.sqrt(delta_ref)

    def force(delta: ArrayLike, delta_dot: ArrayLike, _v: float) -> float | np.ndarray:
        d = np.maximum(delta, 0.0)
        return np.maximum(c_k * k * d**1.5 + b * a * np.sqrt(d) * np.asarray(delta_dot, dtype=float), 0.0)

    return force


def ring_impact(
    geom: RingGeometry, params: ContactParameters, *, mass: float, speed: float, delta_ref: float
) -> ImpactResult:
    """Radial impact of a journal of ``mass`` [kg] at ``speed`` [m/s] on the ring model.

    Returns the `ImpactResult` of the closed-form ring law (no MuJoCo).
    """
    # here, not at import: the impact reference needs scipy.integrate (0.3 s to import), and a
    # calibrated run with its calibration cached never simulates an impact
    from clearance.contact_calibration.impact import simulate_impact

    return simulate_impact(_ring_law(geom, params.stiffness, params.damping, delta_ref), mass=mass, speed=speed)


def nominal_parameters(
    clearance: Clearance,
    geom: RingGeometry,
    *,
    effective_mass: float,
    impact_speed: float = NOMINAL_IMPACT_SPEED,
) -> ContactParameters:
    """Per-row stiffness and damping of a ring bearing (see module docstring).

    Args:
        clearance: the joint's clearance (geometry, materials, restitution, law).
        geom: the ring geometry (segment count and shape).
        effective_mass: mass seen along the contact normal [kg].
        impact_speed: speed at which restitution is matched [m/s].

    Returns:
        ContactParameters with source "nominal".
    """
    from scipy.optimize import brentq  # here, not at import (see ring_impact)

    from clearance.contact_calibration.cylindrical_laws import cylinder_law, elastic
    from clearance.contact_calibration.impact import clearance_impact

    K = bearing_stiffness(clearance)
    ln = (
        clearance_impact(clearance, mass=effective_mass, speed=impact_speed)
        if clearance.law is not ContactLaw.IMPACT
        else None
    )
    delta_ref = ln.max_penetration if ln is not None else (5 * effective_mass * impact_speed**2 / (4 * K)) ** 0.4
    if clearance.law in CYLINDRICAL_LAWS:
        K = elastic(cylinder_law(clearance), delta_ref) / delta_ref**1.5
    c_k = ring_stiffness_coefficient(geom, (delta_ref / 20, delta_ref * 2))
    k = K / c_k
    target = ln.restitution if ln is not None else clearance.restitution
    if target >= 1.0 - 1e-9:
        return ContactParameters(k, 0.0, "nominal")

    def miss(b: float) -> float:
        r = ring_impact(geom, ContactParameters(k, b), mass=effective_mass, speed=impact_speed, delta_ref=delta_ref)
        return r.restitution - target

    # critical damping of the linearised ring at delta_ref bounds the search
    k_t = 1.5 * c_k * k * math.sqrt(delta_ref)
    a = ring_damping_coefficient(geom, delta_ref)
    b_hi = 2 * math.sqrt(k_t * effective_mass) / a
    b = brentq(miss, 0.0, b_hi, xtol=b_hi * 1e-6)
    return ContactParameters(k, b, "nominal")
