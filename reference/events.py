"""Contact onset and end of a contact point (a clearance joint or a slider's corner) within one step.

Within a step the solver's dense output gives the state at any time; the penetration
delta(t) of each contact point is a derived scalar (a journal: |e(t)| - c; a slider's corner:
its depth beyond its guide line). A free point changes mode where delta becomes > 0
(onset); a point in contact where delta becomes < 0 (end).

Strategy (no impact may be stepped over, yet most steps cost nothing):

1. Reach test (no dense output): over a step of length h delta changes by at most
   D = 2 h max(r(t0), r(t1)) (factor 2: speeds change within a step), r a bound on its rate
   (a journal: |e_dot|; a corner: its speed across the guide, sliding along it excluded), so
   delta stays below (delta0 + delta1 + D) / 2 and above (delta0 + delta1 - D) / 2. If the
   wall cannot be reached, there is nothing to look for.
2. Scan: otherwise the step is cut into n sub-intervals over which the journal travels at
   most c / 4; delta and delta_dot are taken from the dense output at their ends and a
   cubic Hermite bounds delta inside each (its error ~ (c/4)^4 / (384 c^3) << c). The
   first sub-interval whose cubic comes within a margin of the wall is examined on the
   dense output (bounded scalar maximisation where the ends do not bracket a root).
3. Root: brentq on the dense output to ~1e-16 s.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import brentq, minimize_scalar

from clearance.reference.contact import ContactJoint
from clearance.reference.corner_contact import corner_gap, corner_gaps_many
from clearance.reference.system import ReferenceSystem

__all__ = ["gap", "gap_many", "hermite_extreme", "find_mode_change"]

_MAX_SUB = 512  # sub-intervals per step at most

_Column = np.ndarray | float
"""A quantity over many states (ndarray) or, for the ground, one constant."""


def gap(system: ReferenceSystem, k: int, y: np.ndarray) -> tuple[float, float, float]:
    """(delta [m], delta_dot [m/s], rate bound [m/s]) of contact point k in state y.

    The rate bound is |e_dot| for a journal and, for a slider's corner, its speed across the
    guide (`clearance.reference.corner_contact.corner_gaps_many`).
    """
    nq = system.nq
    cp = system.contacts[k]
    if not isinstance(cp, ContactJoint):
        return corner_gap(cp, y[:nq].tolist(), y[nq : 2 * nq].tolist())
    r = cp.evaluate(y[:nq].tolist(), y[nq : 2 * nq].tolist(), 0.0)
    return r[4], r[5], math.hypot(r[2], r[3])


def gap_many(system: ReferenceSystem, k: int, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(delta, delta_dot) of contact point k for states ys of shape (ny, n), vectorised."""
    cj, nq = system.contacts[k], system.nq
    if not isinstance(cj, ContactJoint):
        delta, ddot, _ = corner_gaps_many(cj, nq, ys)
        return delta, ddot

    def centre(i: int, s: tuple[float, float]) -> tuple[_Column, _Column, _Column, _Column]:
        if i < 0:
            return s[0], s[1], 0.0, 0.0
        th, w = ys[3 * i + 2], ys[nq + 3 * i + 2]
        c, sn = np.cos(th), np.sin(th)
        ax, ay = c * s[0] - sn * s[1], sn * s[0] + c * s[1]
        return ys[3 * i] + ax, ys[3 * i + 1] + ay, ys[nq + 3 * i] - w * ay, ys[nq + 3 * i + 1] + w * ax

    px, py, vx, vy = centre(cj.ij, cj.sj)
    qx, qy, ux, uy = centre(cj.ib, cj.sb)
    ex, ey, edx, edy = px - qx, py - qy, vx - ux, vy - uy
    d = np.hypot(ex, ey)
    with np.errstate(invalid="ignore", divide="ignore"):
        ddot = np.where(d > 0, (ex * edx + ey * edy) / d, 0.0)
    return d - cj.c, ddot


def hermite_extreme(p0: float, p1: float, m0: float, m1: float, want_max: bool) -> float:
    """Max (or min) over s in [0, 1] of the cubic Hermite with end values p, slopes m (per s)."""
    a = 6 * p0 + 3 * m0 - 6 * p1 + 3 * m1  # p'(s) = a s^2 + b s + c
    b = -6 * p0 - 4 * m0 + 6 * p1 - 2 * m1
    c = m0
    cands = [0.0, 1.0]
    if a != 0.0:
        disc = b * b - 4 * a * c
        if disc >= 0:
            r = math.sqrt(disc)
            cands += [(-b + r) / (2 * a), (-b - r) / (2 * a)]
    elif b != 0.0:
        cands.append(-c / b)
    vals = []
    for s in cands:
        if 0.0 <= s <= 1.0:
            s2, s3 = s * s, s * s * s
            vals.append((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1)
    return max(vals) if want_max else min(vals)


def find_mode_change(
    system: ReferenceSystem,
    k: int,
    dense: Callable[[], Callable[[ArrayLike], np.ndarray]],
    t0: float,
    t1: float,
    g0: tuple[float, float, float],
    g1: tuple[float, float, float],
    in_contact: bool,
) -> float | None:
    """First time in (t0, t1] at which contact point k changes mode, or None.

    Args:
        system: the system.
        k: contact point index.
        dense: returns the step's dense output (built on first call only).
        t0, t1: step start and end [s].
        g0, g1: `gap` at the step ends.
        in_contact: current mode of the joint.
    """
    c = system.contacts[k].c
    h = t1 - t0
    travel = 2.0 * h * max(g0[2], g1[2])
    sign = -1.0 if in_contact else 1.0  # "triggered" means sign * delta > 0
    if sign * (g0[0] + g1[0]) + travel < -2e-9 * c and sign * g1[0] <= 0:
        return None
    n = min(max(int(math.ceil(4.0 * travel / c)), 1), _MAX_SUB)
    sub = travel / n
    margin = 100.0 * sub**4 / (384.0 * c**3) + 1e-9 * c
    sol = dense()
    ts = np.linspace(t0, t1, n + 1)
    if n > 1:
        dl, dd = gap_many(system, k, sol(ts[1:-1]))
        deltas = np.concatenate([[g0[0]], dl, [g1[0]]]) * sign
        rates = np.concatenate([[g0[1]], dd, [g1[1]]]) * sign
    else:
        deltas, rates = np.array([g0[0], g1[0]]) * sign, np.array([g0[1], g1[1]]) * sign

    def g(tt: float) -> float:
        return sign * gap(system, k, sol(tt))[0]

    dt = ts[1] - ts[0]
    for i in range(n):
        a, b = float(ts[i]), float(ts[i + 1])
        if deltas[i + 1] > 0:
            if deltas[i] >= 0:  # restarted exactly at a root (rounding): cut at the sample
                return b
            return float(brentq(g, a, b, xtol=1e-16, rtol=1e-14))
        ext = hermite_extreme(deltas[i], deltas[i + 1], dt * rates[i], dt * rates[i + 1], True)
        if ext > -margin:
            best = minimize_scalar(
                lambda tt: -g(tt), bounds=(a, b), method="bounded", options={"xatol": 1e-6 * (b - a)}
            )
            if -best.fun > 0:
                tm = float(best.x)
                return float(brentq(g, a, tm, xtol=1e-16, rtol=1e-14)) if deltas[i] < 0 else tm
    return None
