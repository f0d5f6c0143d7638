"""Exact circle-in-circle geometry and contact forces of a revolute clearance joint.

A journal of radius R_J on one link sits in a bearing of radius R_B = R_J + c on the other.
With e the journal centre minus the bearing centre (world frame), d = |e| and n = e / d:

  * penetration delta = d - c, its rate delta_dot = n . e_dot (> 0 approaching);
  * contact points: journal r_J + R_J n and bearing r_B + R_B n; the tangential relative
    velocity v_T is the relative velocity of those material points along t = (-n_y, n_x);
  * force on the journal F = -F_N n + F_T t, applied at the journal contact point; the
    bearing gets -F at its contact point (Lankarani and Nikravesh 1990, Ambrósio 2002: docs/references.md).

F_N follows the joint's `ContactLaw` with the approach speed delta_dot^- recorded at contact
onset; F_T is Ambrosio's friction. A lubricated joint adds its oil film's force
(`clearance.contact_calibration.film.film_scalar`, at every state whatever the contact mode)
at the journal centre, minus it at the bearing centre, with the film's shear torques. The
formulas are evaluated here in plain floats for speed and are tested against
`clearance.contact_calibration.laws`, which is the definition.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

from clearance.contact_calibration.cylindrical_laws import CylinderLaw, cylinder_law, damped_force
from clearance.contact_calibration.film import FilmParameters, film_parameters, film_scalar
from clearance.contact_calibration.laws import bearing_stiffness, hysteresis_factor
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw, Joint

__all__ = [
    "ContactJoint",
    "LawPoint",
    "contact_joints",
    "law_terms",
    "check_thresholds",
    "normal_force_scalar",
    "friction_scalar",
    "film_at",
]

_HERTZ, _CHI, _IMPACT = 0, 1, 2


class LawPoint(Protocol):
    """What the scalar laws read of a contact: a clearance joint or a slider's corner (SI)."""

    @property
    def stiffness(self) -> float: ...  # K [N/m^n]
    @property
    def exponent(self) -> float: ...  # n [-]
    @property
    def kind(self) -> int: ...  # 0 Hertz, 1 K delta^n (1 + chi delta_dot / v-), 2 IMPACT
    @property
    def chi(self) -> float: ...  # hysteresis factor [-]
    @property
    def mu(self) -> float: ...  # friction coefficient [-]
    @property
    def v0(self) -> float: ...  # Ambrosio's no-friction speed [m/s]
    @property
    def v1(self) -> float: ...  # Ambrosio's full-friction speed [m/s]
    @property
    def c_max(self) -> float: ...  # IMPACT damping [N s/m]
    @property
    def d_max(self) -> float: ...  # IMPACT full-damping depth [m]


def check_thresholds(v0: float, v1: float) -> None:
    """Refuse Ambrosio thresholds unless 0 <= v0 < v1 [m/s] (both finite).

    Raises:
        ValueError: naming both values.
    """
    if not (math.isfinite(v0) and math.isfinite(v1) and 0 <= v0 < v1):
        raise ValueError(f"friction thresholds must satisfy 0 <= v0 < v1 [m/s] (got {v0!r}, {v1!r})")


def law_terms(
    law: ContactLaw, restitution: float, joint: str, c_max: float | None, d_max: float | None
) -> tuple[int, float, float, float]:
    """(kind, chi, c_max, d_max) of a normal law as the scalar force evaluates it.

    Args:
        law: the joint's law.
        restitution: its c_e.
        joint: joint name (for the message).
        c_max, d_max: IMPACT parameters [N s/m, m], required for IMPACT only.

    Raises:
        ValueError: an IMPACT joint without c_max >= 0 and d_max > 0.
    """
    if law is ContactLaw.IMPACT:
        if c_max is None or d_max is None or not (c_max >= 0 and d_max > 0):
            raise ValueError(
                f"joint '{joint}' uses the IMPACT law: give impact_c_max >= 0 [N s/m] and "
                f"impact_d_max > 0 [m] (got {c_max!r}, {d_max!r})"
            )
        return _IMPACT, 0.0, float(c_max), float(d_max)
    if law is ContactLaw.HERTZ:
        return _HERTZ, 0.0, 0.0, 0.0
    return _CHI, hysteresis_factor(law, restitution), 0.0, 0.0


@dataclass(frozen=True)
class ContactJoint:
    """A clearance joint prepared for the equations of motion (all SI).

    Attributes:
        name: joint name.
        journal_link, bearing_link: link names (bearing may be ground).
        ij, ib: indices of the journal and bearing links among moving links (-1: ground).
        sj, sb: journal and bearing centres relative to their link's centre of mass, in the
            link frame [m].
        clearance: the joint's `Clearance`.
        c, rj, rb: radial clearance, journal and bearing radii [m].
        stiffness: K [N/m^n] (`laws.bearing_stiffness`).
        exponent: n [-].
        kind: 0 Hertz, 1 K delta^n (1 + chi delta_dot / v-), 2 IMPACT.
        chi: hysteresis factor of the law [-].
        mu, v0, v1: friction coefficient and Ambrosio thresholds [m/s].
        c_max, d_max: IMPACT damping [N s/m] and full-damping depth [m] (0 if unused).
        cylinder: a cylindrical law's constants (`cylindrical_laws.cylinder_law`, its force
            with ``chi``), or None: the force is ``kind``'s from ``stiffness``, ``exponent``.
    """

    name: str
    journal_link: str
    bearing_link: str
    ij: int
    ib: int
    sj: tuple[float, float]
    sb: tuple[float, float]
    clearance: Clearance
    c: float
    rj: float
    rb: float
    stiffness: float
    exponent: float
    kind: int
    chi: float
    mu: float
    v0: float
    v1: float
    c_max: float
    d_max: float
    cylinder: CylinderLaw | None = None

    @property
    def penetration_limit(self) -> float:
        """Default penetration treated as divergence [m]: 5 % of the bearing radius, or a
        cylindrical law's deepest penetration δ* if shallower (beyond it the law gives no force)."""
        limit = 0.05 * self.rb
        return limit if self.cylinder is None else min(limit, self.cylinder.max_penetration)

    def evaluate(self, zl: Sequence[float], zdl: Sequence[float], vin: float) -> tuple[float, ...]:
        """`evaluate_contact` of this joint."""
        return evaluate_contact(self, zl, zdl, vin)


def contact_joints(
    joints: Sequence[Joint],
    index: Mapping[str, int],
    rel: Callable[[str, str], tuple[float, float]],
    *,
    v0: float,
    v1: float,
    c_max: float | None,
    d_max: float | None,
) -> list[ContactJoint]:
    """Prepare every clearance joint of ``joints`` (declaration order).

    Args:
        joints: all joints; ideal ones are skipped.
        index: link name -> moving-link index (-1 for ground).
        rel: (link, point) -> point relative to the link's centre of mass [m].
        v0, v1: Ambrosio's friction thresholds [m/s], 0 <= v0 < v1.
        c_max, d_max: IMPACT parameters, required if a joint uses the IMPACT law.

    Raises:
        ValueError: bad thresholds, an IMPACT joint without c_max and d_max, or a
            clearance that names no journal link.
    """
    check_thresholds(v0, v1)
    out = []
    for j in joints:
        cl = j.clearance
        if cl is None:
            continue
        jl = cl.journal_link
        if jl is None:
            raise ValueError(f"joint '{j.name}': its clearance names no journal link (a Mechanism resolves it)")
        if jl == j.link_a:
            bl, sj, sb = j.link_b, rel(j.link_a, j.point_a), rel(j.link_b, j.point_b)
        else:
            bl, sj, sb = j.link_a, rel(j.link_b, j.point_b), rel(j.link_a, j.point_a)
        kind, chi, cm, dm = law_terms(cl.law, cl.restitution, j.name, c_max, d_max)
        out.append(
            ContactJoint(
                name=j.name,
                journal_link=jl,
                bearing_link=bl,
                ij=index[jl],
                ib=index[bl],
                sj=sj,
                sb=sb,
                clearance=cl,
                c=cl.radial_clearance,
                rj=cl.journal_radius,
                rb=cl.bearing_radius,
                stiffness=bearing_stiffness(cl),
                exponent=1.5,
                kind=kind,
                chi=chi,
                mu=cl.friction,
                v0=float(v0),
                v1=float(v1),
                c_max=cm,
                d_max=dm,
                cylinder=cylinder_law(cl) if cl.law in CYLINDRICAL_LAWS else None,
            )
        )
    return out


def normal_force_scalar(cj: LawPoint, delta: float, delta_dot: float, vin: float) -> float:
    """Normal force [N] >= 0 of ``cj``'s law at penetration delta [m], rate delta_dot [m/s].

    ``vin`` is the approach speed at onset [m/s] (> 0). Zero for delta <= 0.
    """
    if delta <= 0.0:
        return 0.0
    n = cj.exponent
    if n == 1.5:
        f = cj.stiffness * delta * math.sqrt(delta)  # overflows to inf, never raises
    else:
        try:
            f = cj.stiffness * delta**n
        except OverflowError:  # a rejected trial stage far outside the physics
            return math.inf
    if cj.kind == _CHI:
        f *= 1.0 + cj.chi * delta_dot / vin
    elif cj.kind == _IMPACT:
        z = delta / cj.d_max
        step = 1.0 if z >= 1.0 else z * z * (3.0 - 2.0 * z)
        f += cj.c_max * step * delta_dot
    return f if f > 0.0 else 0.0


def friction_scalar(cj: LawPoint, fn: float, vt: float) -> float:
    """Ambrosio friction F_T [N] along t for normal force fn [N], tangential speed vt [m/s]."""
    if cj.mu == 0.0 or fn == 0.0:
        return 0.0
    a = abs(vt)
    if a <= cj.v0:
        return 0.0
    cd = 1.0 if a >= cj.v1 else (a - cj.v0) / (cj.v1 - cj.v0)
    return -cj.mu * cd * fn * (1.0 if vt > 0 else -1.0)


def evaluate_contact(cj: ContactJoint, zl: Sequence[float], zdl: Sequence[float], vin: float) -> tuple[float, ...]:
    """Geometry and force of one joint at centre-of-mass coordinates (plain floats).

    Args:
        cj: the joint.
        zl, zdl: coordinates and velocities (nq,) [m, rad, m/s, rad/s].
        vin: approach speed of the current impact [m/s], or 0 when not in contact mode
            (then no force acts whatever the penetration).

    Returns:
        (ex, ey, edx, edy, delta, delta_dot, v_t, fx, fy, mj, mb, fn, ft): eccentricity and
        its world-frame rate [m, m/s], penetration [m] and rate [m/s], tangential velocity
        [m/s], force on the journal (world) [N], moments on journal and bearing links about
        their centres of mass [N m], normal and friction force [N].
    """
    i, k = cj.ij, cj.ib
    if i >= 0:
        th, w = zl[3 * i + 2], zdl[3 * i + 2]
        c, s = math.cos(th), math.sin(th)
        ajx, ajy = c * cj.sj[0] - s * cj.sj[1], s * cj.sj[0] + c * cj.sj[1]
        px, py = zl[3 * i] + ajx, zl[3 * i + 1] + ajy
        vx, vy, wj = zdl[3 * i] - w * ajy, zdl[3 * i + 1] + w * ajx, w
    else:
        ajx, ajy = px, py = cj.sj
        vx = vy = wj = 0.0
    if k >= 0:
        th, w = zl[3 * k + 2], zdl[3 * k + 2]
        c, s = math.cos(th), math.sin(th)
        abx, aby = c * cj.sb[0] - s * cj.sb[1], s * cj.sb[0] + c * cj.sb[1]
        qx, qy = zl[3 * k] + abx, zl[3 * k + 1] + aby
        ux, uy, wb = zdl[3 * k] - w * aby, zdl[3 * k + 1] + w * abx, w
    else:
        abx, aby = qx, qy = cj.sb
        ux = uy = wb = 0.0
    ex, ey, edx, edy = px - qx, py - qy, vx - ux, vy - uy
    d = math.hypot(ex, ey)
    delta = d - cj.c
    ddot = vt = fx = fy = mj = mb = fn = ft = 0.0
    if d > 0.0:
        nx, ny = ex / d, ey / d
        ddot = nx * edx + ny * edy
        # tangential relative velocity of the contact points along t = (-ny, nx)
        vt = -ny * edx + nx * edy + wj * cj.rj - wb * cj.rb
        if vin > 0.0 and delta > 0.0:
            if cj.cylinder is None:
                fn = normal_force_scalar(cj, delta, ddot, vin)
            else:
                fn = damped_force(cj.cylinder, cj.chi, delta, ddot, vin)
            ft = friction_scalar(cj, fn, vt)
            fx, fy = -fn * nx - ft * ny, -fn * ny + ft * nx
            rjx, rjy = ajx + cj.rj * nx, ajy + cj.rj * ny
            rbx, rby = abx + cj.rb * nx, aby + cj.rb * ny
            mj = rjx * fy - rjy * fx
            mb = -(rbx * fy - rby * fx)
    film = film_at(cj, ex, ey, edx, edy, wj, wb)
    if film is not None:
        gx, gy, tj, tb = film
        fx, fy = fx + gx, fy + gy
        mj += ajx * gy - ajy * gx + tj
        mb += -(abx * gy - aby * gx) + tb
    return ex, ey, edx, edy, delta, ddot, vt, fx, fy, mj, mb, fn, ft


def film_at(
    cj: ContactJoint, ex: float, ey: float, edx: float, edy: float, wj: float, wb: float
) -> tuple[float, float, float, float] | None:
    """A lubricated joint's film force and torques at one state (world frame); None for a dry joint.

    Args:
        cj: the joint.
        ex, ey: eccentricity e, journal centre minus bearing centre [m].
        edx, edy: its rate ė [m/s] (world frame, as `evaluate_contact` computes it).
        wj, wb: angular velocities of the journal's and the bearing's links [rad/s].

    Returns:
        (F_x, F_y, T_J, T_B) of `clearance.contact_calibration.film.film_scalar`: the film force on
        the journal [N] in world axes and the shear torques on journal and bearing [N m]; e's rate
        enters as seen from the bearing (ė − ω_B z × e) and the spin as the journal's relative to
        the bearing.
    """
    film = _film(cj.clearance)
    if film is None:
        return None
    return film_scalar(film, ex, ey, edx + wb * ey, edy - wb * ex, wj - wb)


@functools.cache
def _film(clearance: Clearance) -> FilmParameters | None:
    """The film of a lubricated joint's clearance (None for a dry one), prepared once."""
    lub = clearance.lubrication
    if lub is None or clearance.bearing_length is None:
        return None
    return film_parameters(
        lub,
        journal_radius=clearance.journal_radius,
        bearing_length=clearance.bearing_length,
        clearance=clearance.radial_clearance,
    )
