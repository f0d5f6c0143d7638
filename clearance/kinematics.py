"""Planar kinematics of any mechanism in Cartesian coordinates (x, y, theta per moving link).

`ConstraintSystem` (defined in `clearance.constraints`, re-exported here) holds the
holonomic constraints of the ideal joints and the drives (Phi(q, t) = 0), their Jacobian
Phi_q and the acceleration right-hand side gamma, vectorised over the pairs and over any
leading batch axes of q. It serves three users:

  * initial assembly (`assemble`): Newton iteration on the loop closures at the drive
    angles of t = 0, starting from the links' pose guesses so that the branch nearest the
    guesses is found;
  * the ideal-mechanism velocities and accelerations (`velocities`, `accelerations`) and the
    exact ideal kinematics over time (`solve_kinematics`), the baseline of "deviation from
    ideal";
  * the reference solver, which builds the same constraints without the clearance joints
    (``include_clearance=False``) and adds contact forces for them.

Works for any 1- or 2-DOF (any DOF, one drive per DOF) planar linkage of revolute and
prismatic pairs. Singular positions (a loop at a dead point, where the drives no longer
determine the linkage) are detected and reported by `SingularPositionError`.

Coordinates: q = [x_1, y_1, theta_1, x_2, ...] over `Mechanism.moving_links` in order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearance.constraints import ConstraintSystem, _Pair, _rot  # noqa: F401 (re-exported)
from clearance.model import JointType, Mechanism, OutputKind

__all__ = [
    "AssemblyError",
    "SingularPositionError",
    "ConstraintSystem",
    "KinematicsResult",
    "TransmissionAngle",
    "assemble",
    "velocities",
    "accelerations",
    "solve_kinematics",
    "link_point_world",
    "output_kinematics",
    "transmission_angle",
    "singularity_measure",
]

SINGULAR_TOL = 1e-7
"""Default threshold of `singularity_measure` below which a position counts as singular."""


class AssemblyError(ValueError):
    """The mechanism cannot be assembled (non-closable loop or singular position).

    Attributes:
        joint: where the loops cannot be closed, the joint with the largest closure
            residual at the last Newton iterate (None when not known).
        gap: that joint's residual: how far apart its two sides stay [m] (None when not
            known).
    """

    def __init__(self, message: str, *, joint: str | None = None, gap: float | None = None) -> None:
        super().__init__(message)
        self.joint = joint
        self.gap = gap


class SingularPositionError(AssemblyError):
    """The linkage reaches a singular (dead-point) position where the drives no longer
    determine it. ``time`` [s] and ``measure`` (see `singularity_measure`) say where."""

    def __init__(self, message: str, *, time: float, measure: float) -> None:
        super().__init__(message)
        self.time = time
        self.measure = measure


def singularity_measure(mechanism: Mechanism, q: np.ndarray) -> np.ndarray:
    """How far a position is from singular: 1 / cond of the scaled Jacobian, (...,) in (0, 1].

    Args:
        mechanism: the mechanism (clearance joints count as ideal).
        q: coordinates (..., nq).
    """
    return ConstraintSystem(mechanism).singularity_measure(q)


def _newton(cs: ConstraintSystem, q: np.ndarray, t: float, tol: float, max_iter: int) -> tuple[np.ndarray, float, bool]:
    """Damped Newton on Phi(q, t) = 0 from q. Returns (q, max |Phi|, converged)."""
    q = np.array(q, dtype=float)
    res = np.inf
    for _ in range(max_iter):
        f = cs.phi(q, t)
        res = float(np.max(np.abs(f))) if f.size else 0.0
        if res < tol:
            return q, res, True
        try:
            step = np.linalg.solve(cs.jacobian(q), -f)
        except np.linalg.LinAlgError:
            return q, res, False
        if not np.all(np.isfinite(step)):
            return q, res, False
        # damp very large rotation steps so Newton stays on the nearby branch
        big = float(np.max(np.abs(step[2::3]))) if cs.n_links else 0.0
        q = q + min(1.0, 0.5 / max(1e-300, big)) * step
    f = cs.phi(q, t)
    return q, float(np.max(np.abs(f))) if f.size else 0.0, False


def _widest_gap(cs: ConstraintSystem, q: np.ndarray, t: float) -> tuple[str | None, float]:
    """(joint, residual [m]) of the pair whose closure residual at q is largest.

    A revolute pair's residual is its pin gap; a prismatic pair's its offset normal to the
    axis with the angle error times the length scale.
    """
    f = cs.phi(q, t)
    best, gap = None, -1.0
    for k, (name, pair) in enumerate(zip(cs.pair_names, cs.pairs)):
        a, b = f[2 * k], f[2 * k + 1]
        if pair.kind is not JointType.REVOLUTE:
            a = a * cs.length_scale
        g = float(np.hypot(a, b))
        if g > gap:
            best, gap = name, g
    return best, max(gap, 0.0)


def _check_square(cs: ConstraintSystem) -> None:
    if cs.n_constraints != cs.nq:
        raise AssemblyError(
            f"mechanism '{cs.mechanism.name}' has {cs.n_constraints} constraint equations for "
            f"{cs.nq} coordinates: it is not fully determined by its drives"
        )


def _singular_error(cs: ConstraintSystem, t: float, measure: float, what: str) -> SingularPositionError:
    angles = ", ".join(f"{d.name} = {math.degrees(float(d.angle(t))):.3f} deg" for d, _, _ in cs.drives)
    return SingularPositionError(
        f"mechanism '{cs.mechanism.name}' {what} at t = {t:.6g} s ({angles}): a loop reaches "
        f"a dead point (singularity measure {measure:.2e}); change the link lengths so that "
        "every transmission angle stays away from 0 and 180 deg, or limit the drive range",
        time=t,
        measure=measure,
    )


def assemble(
    mechanism: Mechanism,
    t: float = 0.0,
    *,
    q_guess: np.ndarray | None = None,
    tol: float = 1e-12,
    max_iter: int = 50,
    singular_tol: float = SINGULAR_TOL,
) -> np.ndarray:
    """Solve the loop closures for the drive angles at time t (Newton iteration).

    Args:
        mechanism: the mechanism (clearance joints are treated as ideal, journals centred).
        t: time [s] at which the drive angles are taken.
        q_guess: starting coordinates, shape (nq,); default: the links' pose guesses.
        tol: convergence tolerance on max |Phi| [m, rad].
        max_iter: Newton iteration limit.
        singular_tol: positions with `singularity_measure` below this are rejected.

    Returns:
        q: coordinates (nq,) [m, rad].

    Raises:
        AssemblyError: the loops cannot be closed (lengths do not fit).
        SingularPositionError: the assembled position is singular (a dead point).
    """
    cs = ConstraintSystem(mechanism)
    _check_square(cs)
    q0 = (
        np.array([v for lk in mechanism.moving_links for v in lk.pose_guess], dtype=float)
        if q_guess is None
        else np.array(q_guess, dtype=float)
    )
    q, res, ok = _newton(cs, q0, t, tol, max_iter)
    if not ok:
        joint, gap = _widest_gap(cs, q, t)
        where = (
            f"; the largest is at joint '{joint}', whose two sides stay {gap:.3g} m apart" if joint is not None else ""
        )
        raise AssemblyError(
            f"mechanism '{mechanism.name}' cannot be assembled at t = {t:g} s: loop-closure "
            f"residual {res:.3g} after {max_iter} Newton iterations{where} (check that the link "
            "lengths can close every loop at the drive start angles, and the pose guesses)",
            joint=joint,
            gap=gap if joint is not None else None,
        )
    measure = float(cs.singularity_measure(q))
    if measure < singular_tol:
        raise _singular_error(cs, t, measure, "is assembled in a singular position")
    return q


def velocities(mechanism: Mechanism, q: np.ndarray, t: float = 0.0) -> np.ndarray:
    """Ideal-mechanism velocities qd (nq,) [m/s, rad/s] at coordinates q and time t."""
    cs = ConstraintSystem(mechanism)
    return np.linalg.solve(cs.jacobian(q), -cs.phi_t(t))


def accelerations(mechanism: Mechanism, q: np.ndarray, qd: np.ndarray, t: float = 0.0) -> np.ndarray:
    """Ideal-mechanism accelerations qdd (nq,) [m/s^2, rad/s^2]."""
    cs = ConstraintSystem(mechanism)
    return np.linalg.solve(cs.jacobian(q), cs.gamma(q, qd, t))


@dataclass(frozen=True)
class KinematicsResult:
    """Exact ideal kinematics over time.

    Attributes:
        times: (n,) [s].
        q, qd, qdd: (n, nq) coordinates and their derivatives [m, rad, ...].
        outputs: name -> (n,) position [m or rad], plus ``<name>_vel`` and ``<name>_acc``.
        singularity: (n,) `singularity_measure` at each time (1 is best, 0 singular); for
            more than 2048 times only at the continuation points and 2048 evenly spread
            times, NaN elsewhere (use ``np.nanmin``).
    """

    times: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    outputs: dict[str, np.ndarray]
    singularity: np.ndarray | None = None


def _scaled_dev(cs: ConstraintSystem, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """max over coordinates of |a - b| with lengths divided by the length scale, (...,)."""
    d = np.abs(np.asarray(a) - np.asarray(b)).reshape(np.shape(a)[:-1] + (cs.n_links, 3))
    return np.max(np.maximum(d[..., :2].max(axis=-1) / cs.length_scale, d[..., 2]), axis=-1)


def _track(
    cs: ConstraintSystem,
    q: np.ndarray,
    t0: float,
    t1: float,
    max_step: float,
    tol: float,
    singular_tol: float,
) -> np.ndarray:
    """Follow the assembly branch from (q, t0) to t1 by continuation; return q at t1."""
    ts = np.linspace(t0, t1, 9)
    rate = max([float(np.max(np.abs(d.rate(ts)))) for d, _, _ in cs.drives] + [0.0])
    h0 = (t1 - t0) / max(1, math.ceil(rate * (t1 - t0) / max_step - 0.5))
    h, t = h0, t0
    while t < t1:
        tn = min(t1, t + h)
        qd = np.linalg.solve(cs.jacobian(q), -cs.phi_t(t))
        guess = q + qd * (tn - t)
        qn, _, ok = _newton(cs, guess, tn, tol, 30)
        if ok and float(_scaled_dev(cs, qn, guess)) <= 0.5 * max_step:
            # singular positions at the requested times are caught by the caller's check
            q, t, h = qn, tn, min(h0, 2 * h)
            continue
        h /= 2
        if h < 1e-9 * max(h0, 1e-300):
            measure = float(cs.singularity_measure(q))
            raise _singular_error(cs, t, measure, "cannot be continued past this position")
    return q


def _newton_batch(
    cs: ConstraintSystem, q: np.ndarray, t: np.ndarray, tol: float, max_iter: int
) -> tuple[np.ndarray, np.ndarray]:
    """Newton on many (q, t) at once; returns (q, converged mask)."""
    q = q.copy()
    ok = np.zeros(len(q), dtype=bool)
    idx = np.arange(len(q))
    for _ in range(max_iter):
        f = cs.phi(q[idx], t[idx])
        conv = np.max(np.abs(f), axis=-1) < tol
        ok[idx[conv]] = True
        idx, f = idx[~conv], f[~conv]
        if not len(idx):
            break
        try:
            step = np.linalg.solve(cs.jacobian(q[idx]), -f[..., None])[..., 0]
        except np.linalg.LinAlgError:
            break
        big = np.max(np.abs(step[:, 2::3]), axis=-1)
        q[idx] += np.minimum(1.0, 0.5 / np.maximum(big, 1e-300))[:, None] * step
    return q, ok


def solve_kinematics(
    mechanism: Mechanism,
    times: np.ndarray,
    *,
    max_step: float = math.radians(5.0),
    singular_tol: float = SINGULAR_TOL,
    tol: float = 1e-12,
) -> KinematicsResult:
    """Exact ideal kinematics at each time, following the assembly branch of t = times[0].

    The branch is followed by continuation in steps of at most ``max_step`` of drive angle
    (halved where the prediction misses); the remaining times are solved together by
    Newton from Hermite-interpolated guesses.

    Args:
        mechanism: the mechanism (its ideal twin is solved).
        times: (n,) non-decreasing times [s].
        max_step: largest drive-angle step of the continuation [rad].
        singular_tol: positions with `singularity_measure` below this are an error.
        tol: Newton tolerance on max |Phi| [m, rad].

    Returns:
        The kinematics, with the outputs and the singularity measure at each time.

    Raises:
        ValueError: times empty or decreasing.
        AssemblyError: if the mechanism cannot be assembled at times[0].
        SingularPositionError: a singular position (dead point) is reached; the error
            names the time and the drive angles.
    """
    times = np.asarray(times, dtype=float).reshape(-1)
    if not len(times) or np.any(np.diff(times) < 0) or not np.all(np.isfinite(times)):
        raise ValueError("times must be a non-empty, finite, non-decreasing array [s]")
    ideal = mechanism.ideal_twin()
    cs = ConstraintSystem(ideal)
    _check_square(cs)
    n = len(times)
    q = np.empty((n, cs.nq))
    q[0] = assemble(ideal, float(times[0]), tol=tol, singular_tol=singular_tol)
    ang = np.stack([np.asarray(d.angle(times), dtype=float) for d, _, _ in cs.drives], axis=-1)
    path = np.concatenate([[0.0], np.cumsum(np.max(np.abs(np.diff(ang, axis=0)), axis=-1))])
    tracked = [0]
    for i in range(1, n):
        if i == n - 1 or path[i] - path[tracked[-1]] >= max_step:
            q[i] = _track(cs, q[tracked[-1]], times[tracked[-1]], times[i], max_step, tol, singular_tol)
            tracked.append(i)
    tr = np.array(tracked)
    qd_tr = np.linalg.solve(cs.jacobian(q[tr]), -cs.phi_t(times[tr])[..., None])[..., 0]
    untracked = np.ones(n, dtype=bool)
    untracked[tr] = False
    rest = np.flatnonzero(untracked)  # np.setdiff1d's result, without its first call importing numpy.ma (10 ms)
    if len(rest):
        right = np.searchsorted(tr, rest)
        left = right - 1
        iL, iR = tr[left], tr[right]
        h = (times[iR] - times[iL])[:, None]
        s = np.where(h[:, 0] > 0, (times[rest] - times[iL]) / np.where(h[:, 0] > 0, h[:, 0], 1), 0)[:, None]
        guess = (
            (2 * s**3 - 3 * s**2 + 1) * q[iL]
            + (s**3 - 2 * s**2 + s) * h * qd_tr[left]
            + (-2 * s**3 + 3 * s**2) * q[iR]
            + (s**3 - s**2) * h * qd_tr[right]
        )
        sol, ok = _newton_batch(cs, guess, times[rest], tol, 30)
        ok &= _scaled_dev(cs, sol, guess) <= 0.5 * max_step
        q[rest[ok]] = sol[ok]
        for k in np.flatnonzero(~ok):
            i = rest[k]
            q[i] = _track(cs, q[iL[k]], times[iL[k]], times[i], max_step, tol, singular_tol)
    # the measure (an SVD per time) at every time for up to 2048 times, else at the
    # continuation points and an even subsample of 2048 (NaN elsewhere)
    measure = np.full(n, np.nan)
    where = np.arange(n) if n <= 2048 else np.union1d(tr, np.linspace(0, n - 1, 2048).astype(int))
    measure[where] = cs.singularity_measure(q[where])
    bad = np.flatnonzero(measure < singular_tol)
    if len(bad):
        raise _singular_error(cs, float(times[bad[0]]), float(measure[bad[0]]), "reaches a singular position")
    jac = cs.jacobian(q)
    qd = np.linalg.solve(jac, -cs.phi_t(times)[..., None])[..., 0]
    qdd = np.linalg.solve(jac, cs.gamma(q, qd, times)[..., None])[..., 0]
    outputs = output_kinematics(mechanism, q, qd, qdd)
    return KinematicsResult(times, q, qd, qdd, outputs, measure)


def link_point_world(mechanism: Mechanism, q: np.ndarray, link: str, point: tuple[float, float]) -> np.ndarray:
    """World position of a point given in a link frame, for q of shape (..., nq): (..., 2)."""
    if link == mechanism.ground:
        return np.broadcast_to(np.asarray(point, dtype=float), q.shape[:-1] + (2,)).copy()
    i = [lk.name for lk in mechanism.moving_links].index(link)
    x, y, th = q[..., 3 * i], q[..., 3 * i + 1], q[..., 3 * i + 2]
    c, s = np.cos(th), np.sin(th)
    return np.stack([x + c * point[0] - s * point[1], y + s * point[0] + c * point[1]], axis=-1)


def output_kinematics(mechanism: Mechanism, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> dict[str, np.ndarray]:
    """Outputs (position, ``_vel``, ``_acc``) from coordinates of shape (n, nq)."""
    names = [lk.name for lk in mechanism.moving_links]
    out: dict[str, np.ndarray] = {}
    for o in mechanism.outputs:
        if o.link == mechanism.ground:
            raise ValueError(f"output '{o.name}' is on the ground link: it never moves")
        i = names.index(o.link)
        th, w, al = q[:, 3 * i + 2], qd[:, 3 * i + 2], qdd[:, 3 * i + 2]
        if o.kind is OutputKind.ANGLE:
            out[o.name], out[o.name + "_vel"], out[o.name + "_acc"] = th.copy(), w.copy(), al.copy()
            continue
        px, py = mechanism.link(o.link).point(o.require_point())
        c, s = np.cos(th), np.sin(th)
        rp = np.stack([c * px - s * py, s * px + c * py], axis=-1)  # R p
        drp = np.stack([-s * px - c * py, c * px - s * py], axis=-1)  # R' p
        pos = q[:, 3 * i : 3 * i + 2] + rp
        vel = qd[:, 3 * i : 3 * i + 2] + w[:, None] * drp
        acc = qdd[:, 3 * i : 3 * i + 2] + al[:, None] * drp - (w**2)[:, None] * rp
        comp = 0 if o.kind is OutputKind.POSITION_X else 1
        out[o.name], out[o.name + "_vel"], out[o.name + "_acc"] = (
            pos[:, comp],
            vel[:, comp],
            acc[:, comp],
        )
    return out


@dataclass(frozen=True)
class TransmissionAngle:
    """Where a coupler drives a follower: the data to measure one transmission angle.

    The transmission angle mu is the angle at the revolute ``joint`` between the coupler
    line (joint -> ``coupler`` point) and the follower line: joint -> the follower's pivot
    for a rocker, or the normal to the ``guide`` of a slider. 90 deg is best; 0 and 180 deg
    are dead points.

    Attributes:
        joint: revolute joint between the coupler and the follower.
        coupler: (link, point): the coupler link and a second point on it.
        follower: (link, point): the follower link and its pivot (rocker), or None.
        guide: prismatic joint of a slider follower (when ``follower`` is None).
    """

    joint: str
    coupler: tuple[str, str]
    follower: tuple[str, str] | None = None
    guide: str | None = None

    def __post_init__(self) -> None:
        if (self.follower is None) == (self.guide is None):
            raise ValueError(f"transmission angle at '{self.joint}': give follower or guide, not both")


def transmission_angle(mechanism: Mechanism, q: np.ndarray, spec: TransmissionAngle) -> np.ndarray:
    """Transmission angle mu [rad], shape (...,), for coordinates q (..., nq).

    For a rocker mu is in [0, pi]; for a slider it is folded into [0, pi/2] (the guide
    normal has no preferred sign).

    Raises:
        KeyError: unknown joint, link or point.
        ValueError: the coupler link is not a link of the joint.
    """
    q = np.asarray(q, dtype=float)
    jt = mechanism.joint(spec.joint)
    clink, cpoint = spec.coupler
    if clink not in (jt.link_a, jt.link_b):
        raise ValueError(f"transmission angle: '{clink}' is not a link of joint '{spec.joint}'")
    jpoint = jt.point_a if clink == jt.link_a else jt.point_b
    lk = mechanism.link(clink)
    pj = link_point_world(mechanism, q, clink, lk.point(jpoint))
    u = link_point_world(mechanism, q, clink, lk.point(cpoint)) - pj
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    if spec.follower is not None:
        flink, fpoint = spec.follower
        v = link_point_world(mechanism, q, flink, mechanism.link(flink).point(fpoint)) - pj
        v = v / np.linalg.norm(v, axis=-1, keepdims=True)
        return np.arccos(np.clip(np.sum(u * v, axis=-1), -1.0, 1.0))
    assert spec.guide is not None  # TransmissionAngle holds a follower or a guide
    guide = mechanism.joint(spec.guide)
    if guide.link_a == mechanism.ground:
        th = np.zeros(q.shape[:-1])
    else:
        i = [m.name for m in mechanism.moving_links].index(guide.link_a)
        th = q[..., 3 * i + 2]
    ax = np.stack(
        [
            np.cos(th) * guide.axis[0] - np.sin(th) * guide.axis[1],
            np.sin(th) * guide.axis[0] + np.cos(th) * guide.axis[1],
        ],
        axis=-1,
    )
    # angle between the coupler and the guide normal = 90 deg - angle to the guide axis
    return np.arcsin(np.clip(np.abs(np.sum(u * ax, axis=-1)), 0.0, 1.0))
