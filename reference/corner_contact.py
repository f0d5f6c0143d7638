"""Exact corner geometry and contact forces of a slider with play in its guide.

A prismatic joint with a `TranslationalClearance` holds nothing: its slider (link_b) moves
freely in the plane and each of its four corners may touch the guide's lines (on link_a).
Each corner is one contact point of the reference solver with its own mode and its own
approach speed at onset, as each corner's impact is in Flores, Ambrósio, Claro and
Lankarani (2008). With the guide's centre line through G (the joint's point_a) along the
world direction u_w, its normal n_w (u_w turned by +90 degrees) and s = n_w . (P - G) the
corner P's distance across the centre line:

  * the corner faces the line on its side, sign(s); its penetration is
    delta = |s| - (H/2 + c), exact for any position and tilt, against either line;
  * delta_dot = sign(s) n_w . (P_dot - V), V the velocity of the guide's material point at
    P; the tangential velocity along the guide is v_T = u_w . (P_dot - V);
  * the force on the slider at P is F = -sign(s) F_N n_w + F_T u_w, the guide gets -F at
    the same point (no spurious couple), F_N the joint's `ContactLaw` with the corner's
    approach speed delta_dot^- recorded at onset and F_T Ambrosio's friction
    (`clearance.reference.contact.normal_force_scalar`, `friction_scalar`, tested against
    `clearance.contact_calibration.laws`).

`evaluate_corner` returns the tuple layout of `clearance.reference.contact.evaluate_contact`
(the corner relative to G standing for the eccentricity), so the equations of motion, the
events and the energy treat corners and journals alike.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from clearance.model import Joint
from clearance.reference.contact import check_thresholds, friction_scalar, law_terms, normal_force_scalar
from clearance.translational import CORNERS, TranslationalClearance

__all__ = ["CornerContact", "corner_contacts", "corner_gap", "evaluate_corner", "corner_gaps_many"]


@dataclass(frozen=True)
class CornerContact:
    """One corner of a slider with play, prepared for the equations of motion (all SI).

    Attributes:
        name: joint name.
        corner: corner index 0-3 (`clearance.translational.CORNERS`).
        slider_link, guide_link: link names (guide may be ground).
        ij, ib: indices of the slider and guide links among moving links (-1: ground).
        sk: the corner relative to the slider's centre of mass, slider frame [m].
        sg: the guide's centre-line point (point_a) relative to the guide's centre of mass,
            guide frame [m].
        u, n: the guide's axis and its normal in the guide frame (unit vectors).
        half: H/2 + c [m]: distance of each guide line from the centre line.
        clearance: the joint's `TranslationalClearance`.
        c: its clearance [m].
        stiffness: K [N/m^1.5]; exponent: n = 1.5.
        kind, chi, c_max, d_max: the law's terms (`clearance.reference.contact.law_terms`).
        mu, v0, v1: friction coefficient and Ambrosio thresholds [m/s].
        reach: distance from the slider's centre of mass to the corner [m].
    """

    name: str
    corner: int
    slider_link: str
    guide_link: str
    ij: int
    ib: int
    sk: tuple[float, float]
    sg: tuple[float, float]
    u: tuple[float, float]
    n: tuple[float, float]
    half: float
    clearance: TranslationalClearance
    c: float
    stiffness: float
    exponent: float
    kind: int
    chi: float
    c_max: float
    d_max: float
    mu: float
    v0: float
    v1: float
    reach: float

    @property
    def penetration_limit(self) -> float:
        """Default penetration treated as divergence [m]: the whole clearance c."""
        return self.c

    def evaluate(self, zl: Sequence[float], zdl: Sequence[float], vin: float) -> tuple[float, ...]:
        """`evaluate_corner` of this corner."""
        return evaluate_corner(self, zl, zdl, vin)


def corner_contacts(
    joints: Sequence[Joint],
    index: Mapping[str, int],
    rel: Callable[[str, str], tuple[float, float]],
    offsets: Mapping[str, float],
    *,
    v0: float,
    v1: float,
    c_max: float | None,
    d_max: float | None,
) -> list[CornerContact]:
    """The four corners of every slider with play in ``joints`` (declaration order).

    Args:
        joints: all joints; those without a translational clearance are skipped.
        index: link name -> moving-link index (-1 for ground).
        rel: (link, point) -> point relative to the link's centre of mass [m].
        offsets: joint name -> theta_b - theta_a at assembly [rad] (the slider's zero tilt).
        v0, v1: Ambrosio's friction thresholds [m/s], 0 <= v0 < v1.
        c_max, d_max: IMPACT parameters, required if a joint uses the IMPACT law.

    Raises:
        ValueError: bad thresholds, an IMPACT joint without c_max and d_max.
    """
    check_thresholds(v0, v1)
    out = []
    for j in joints:
        tc = j.translational_clearance
        if tc is None:
            continue
        kind, chi, cm, dm = law_terms(tc.law, tc.restitution, j.name, c_max, d_max)
        u = j.axis
        n = (-u[1], u[0])
        sp = rel(j.link_b, j.point_b)
        co, si = math.cos(-offsets[j.name]), math.sin(-offsets[j.name])
        for k, (fu, fn) in enumerate(CORNERS):
            # the corner in the guide's axes at zero tilt, turned into the slider's frame
            wx = fu * tc.slider_length * u[0] + fn * tc.slider_height * n[0]
            wy = fu * tc.slider_length * u[1] + fn * tc.slider_height * n[1]
            sk = (sp[0] + co * wx - si * wy, sp[1] + si * wx + co * wy)
            out.append(
                CornerContact(
                    name=j.name,
                    corner=k,
                    slider_link=j.link_b,
                    guide_link=j.link_a,
                    ij=index[j.link_b],
                    ib=index[j.link_a],
                    sk=sk,
                    sg=rel(j.link_a, j.point_a),
                    u=u,
                    n=n,
                    half=0.5 * tc.slider_height + tc.clearance,
                    clearance=tc,
                    c=tc.clearance,
                    stiffness=tc.stiffness,
                    exponent=1.5,
                    kind=kind,
                    chi=chi,
                    c_max=cm,
                    d_max=dm,
                    mu=tc.friction,
                    v0=float(v0),
                    v1=float(v1),
                    reach=math.hypot(*sk),
                )
            )
    return out


def _state(cc: CornerContact, zl: Sequence[float], zdl: Sequence[float]) -> tuple[float, ...]:
    """The corner's kinematics: (ax, ay, px, py, gx0, gy0, dx, dy, rx, ry, ux, uy, side, delta,
    delta_dot, v_t, bound); a: the corner from the slider's centre of mass, g0: the guide's
    centre of mass, d: the corner from the centre-line point, r: its velocity relative to the
    guide's material point under it, u: the guide's axis (world), bound: see `corner_gaps_many`."""
    i, k = cc.ij, cc.ib
    th, w = zl[3 * i + 2], zdl[3 * i + 2]
    c, s = math.cos(th), math.sin(th)
    ax, ay = c * cc.sk[0] - s * cc.sk[1], s * cc.sk[0] + c * cc.sk[1]
    px, py = zl[3 * i] + ax, zl[3 * i + 1] + ay
    cvx, cvy = zdl[3 * i], zdl[3 * i + 1]
    if k >= 0:
        th, wg = zl[3 * k + 2], zdl[3 * k + 2]
        c, s = math.cos(th), math.sin(th)
        gx0, gy0 = zl[3 * k], zl[3 * k + 1]
        gx, gy = gx0 + c * cc.sg[0] - s * cc.sg[1], gy0 + s * cc.sg[0] + c * cc.sg[1]
        ux, uy = c * cc.u[0] - s * cc.u[1], s * cc.u[0] + c * cc.u[1]
        # the guide's material points under the corner and under the slider's centre of mass
        vx, vy = zdl[3 * k] - wg * (py - gy0), zdl[3 * k + 1] + wg * (px - gx0)
        cvx -= zdl[3 * k] - wg * (zl[3 * i + 1] - gy0)
        cvy -= zdl[3 * k + 1] + wg * (zl[3 * i] - gx0)
        turn = abs(w - wg)
    else:
        gx0 = gy0 = 0.0
        (gx, gy), (ux, uy) = cc.sg, cc.u
        vx = vy = 0.0
        turn = abs(w)
    nx, ny = -uy, ux
    dx, dy = px - gx, py - gy
    rx, ry = zdl[3 * i] - w * ay - vx, zdl[3 * i + 1] + w * ax - vy
    across = nx * dx + ny * dy
    side = 1.0 if across >= 0.0 else -1.0
    delta = side * across - cc.half
    ddot = side * (nx * rx + ny * ry)
    vt = ux * rx + uy * ry
    bound = abs(nx * cvx + ny * cvy) + turn * cc.reach
    return ax, ay, px, py, gx0, gy0, dx, dy, rx, ry, ux, uy, side, delta, ddot, vt, bound


def corner_gap(cc: CornerContact, zl: Sequence[float], zdl: Sequence[float]) -> tuple[float, float, float]:
    """(delta [m], delta_dot [m/s], rate bound [m/s]) of a corner (see `corner_gaps_many`)."""
    st = _state(cc, zl, zdl)
    return st[13], st[14], st[16]


def evaluate_corner(cc: CornerContact, zl: Sequence[float], zdl: Sequence[float], vin: float) -> tuple[float, ...]:
    """Geometry and force of one corner at centre-of-mass coordinates (plain floats).

    Args:
        cc: the corner.
        zl, zdl: coordinates and velocities (nq,) [m, rad, m/s, rad/s].
        vin: approach speed of the corner's current impact [m/s], or 0 when not in contact
            mode (then no force acts whatever the penetration).

    Returns:
        (dx, dy, rx, ry, delta, delta_dot, v_t, fx, fy, m_slider, m_guide, fn, ft): the corner
        relative to the guide's centre-line point and its velocity relative to the guide's
        material point under it (world) [m, m/s], penetration [m] and rate [m/s], tangential
        velocity along the guide [m/s], force on the slider (world) [N], moments on the slider
        and guide links about their centres of mass [N m], normal and friction force [N].
    """
    ax, ay, px, py, gx0, gy0, dx, dy, rx, ry, ux, uy, side, delta, ddot, vt, _ = _state(cc, zl, zdl)
    if vin <= 0.0 or delta <= 0.0:
        return dx, dy, rx, ry, delta, ddot, vt, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    fn = normal_force_scalar(cc, delta, ddot, vin)
    ft = friction_scalar(cc, fn, vt)
    # the normal n_w is (-uy, ux); the force pushes the corner back across the centre line
    fx, fy = side * fn * uy + ft * ux, -side * fn * ux + ft * uy
    m_slider = ax * fy - ay * fx
    m_guide = -((px - gx0) * fy - (py - gy0) * fx) if cc.ib >= 0 else 0.0
    return dx, dy, rx, ry, delta, ddot, vt, fx, fy, m_slider, m_guide, fn, ft


def corner_gaps_many(cc: CornerContact, nq: int, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(delta, delta_dot, speed bound) of one corner for states ys of shape (ny, n), vectorised.

    The speed bound is the largest rate at which the corner's distance across the guide can
    change for the state's velocities, sliding along the guide excluded: the slider centre
    of mass's speed across the guide relative to it plus the relative turning rate times the
    corner's reach (the reach test of `clearance.reference.events` uses it).

    Args:
        cc: the corner.
        nq: number of coordinates.
        ys: (2 nq or more, n) states (z, zd) as columns.
    """
    i, k = cc.ij, cc.ib
    th, w = ys[3 * i + 2], ys[nq + 3 * i + 2]
    c, s = np.cos(th), np.sin(th)
    ax, ay = c * cc.sk[0] - s * cc.sk[1], s * cc.sk[0] + c * cc.sk[1]
    px, py = ys[3 * i] + ax, ys[3 * i + 1] + ay
    cvx, cvy = ys[nq + 3 * i], ys[nq + 3 * i + 1]
    pvx, pvy = cvx - w * ay, cvy + w * ax
    if k >= 0:
        tg, wg = ys[3 * k + 2], ys[nq + 3 * k + 2]
        cg, sg = np.cos(tg), np.sin(tg)
        gx0, gy0 = ys[3 * k], ys[3 * k + 1]
        gx, gy = gx0 + cg * cc.sg[0] - sg * cc.sg[1], gy0 + sg * cc.sg[0] + cg * cc.sg[1]
        ux, uy = cg * cc.u[0] - sg * cc.u[1], sg * cc.u[0] + cg * cc.u[1]
        gvx, gvy = ys[nq + 3 * k], ys[nq + 3 * k + 1]
        vx, vy = gvx - wg * (py - gy0), gvy + wg * (px - gx0)
        cx, cy = gvx - wg * (ys[3 * i + 1] - gy0), gvy + wg * (ys[3 * i] - gx0)
        turn = np.abs(w - wg)
    else:
        gx, gy = cc.sg
        ux, uy = cc.u
        vx = vy = cx = cy = 0.0
        turn = np.abs(w)
    nx, ny = -uy, ux
    across = nx * (px - gx) + ny * (py - gy)
    side = np.where(across >= 0.0, 1.0, -1.0)
    delta = side * across - cc.half
    ddot = side * (nx * (pvx - vx) + ny * (pvy - vy))
    bound = np.abs(nx * (cvx - cx) + ny * (cvy - cy)) + turn * cc.reach
    return delta, ddot, bound
