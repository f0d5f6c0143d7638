"""Planar kinematics of any mechanism in Cartesian coordinates (x, y, theta per moving link).

`ConstraintSystem` holds the holonomic constraints of the ideal joints and the drives
(Phi(q, t) = 0), their Jacobian Phi_q and the acceleration right-hand side gamma. It serves
three users:

  * initial assembly (`assemble`): Newton iteration on the loop closures at the drive
    angles of t = 0, starting from the links' pose guesses so that the branch nearest the
    guesses is found;
  * the ideal-mechanism velocities and accelerations (`velocities`, `accelerations`) and the
    exact ideal kinematics over time (`solve_kinematics`), the baseline of "deviation from
    ideal";
  * the reference solver, which builds the same constraints without the clearance joints
    (``include_clearance=False``) and adds contact forces for them.

Coordinates: q = [x_1, y_1, theta_1, x_2, ...] over `Mechanism.moving_links` in order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearance.model import DriveKind, JointType, Mechanism, OutputKind

__all__ = [
    "AssemblyError",
    "ConstraintSystem",
    "KinematicsResult",
    "assemble",
    "velocities",
    "accelerations",
    "solve_kinematics",
    "link_point_world",
    "output_kinematics",
]


class AssemblyError(ValueError):
    """The mechanism cannot be assembled (non-closable loop or singular position)."""


def _rot(th: np.ndarray | float) -> np.ndarray:
    c, s = np.cos(th), np.sin(th)
    return np.array([[c, -s], [s, c]])


def _drot(th: float) -> np.ndarray:
    c, s = np.cos(th), np.sin(th)
    return np.array([[-s, -c], [c, -s]])


@dataclass(frozen=True)
class _Pair:
    kind: JointType
    ia: int  # index of link a among moving links, -1 for ground
    ib: int
    pa: np.ndarray
    pb: np.ndarray
    u: np.ndarray  # prismatic: normal to the axis in frame a
    offset: float  # prismatic: theta_b - theta_a


class ConstraintSystem:
    """Constraints Phi(q, t) = 0 of a mechanism's ideal joints and prescribed drives.

    Args:
        mechanism: the mechanism.
        include_clearance: if True (default) clearance joints count as ideal revolute
            joints; if False they are left out (their links are then held by contact).
        include_drives: if True (default) each constant-speed or motion-law drive adds one
            rheonomic row theta_b - theta_a - angle(t) = 0. Torque drives never add a row.
    """

    def __init__(
        self, mechanism: Mechanism, *, include_clearance: bool = True, include_drives: bool = True
    ) -> None:
        self.mechanism = mechanism
        index = {lk.name: i for i, lk in enumerate(mechanism.moving_links)}
        index[mechanism.ground] = -1
        self.index = index
        self.n_links = len(mechanism.moving_links)
        self.nq = 3 * self.n_links
        links = {lk.name: lk for lk in mechanism.links}
        guess = {lk.name: lk.pose_guess for lk in mechanism.links}
        guess[mechanism.ground] = (0.0, 0.0, 0.0)
        self.pairs: list[_Pair] = []
        self.pair_names: list[str] = []
        for j in mechanism.joints:
            if j.clearance is not None and not include_clearance:
                continue
            pa = np.array(links[j.link_a].point(j.point_a))
            pb = np.array(links[j.link_b].point(j.point_b))
            u = np.array([-j.axis[1], j.axis[0]])
            off = guess[j.link_b][2] - guess[j.link_a][2]
            self.pairs.append(_Pair(j.kind, index[j.link_a], index[j.link_b], pa, pb, u, off))
            self.pair_names.append(j.name)
        self.drives = []
        if include_drives:
            for d in mechanism.drives:
                if d.kind is DriveKind.TORQUE:
                    continue
                jt = mechanism.joint(d.joint)
                self.drives.append((d, index[jt.link_a], index[jt.link_b]))
        self.n_constraints = 2 * len(self.pairs) + len(self.drives)

    # -- pose helpers -------------------------------------------------------------------
    @staticmethod
    def _pose(q: np.ndarray, i: int) -> tuple[np.ndarray, float]:
        if i < 0:
            return np.zeros(2), 0.0
        return q[3 * i : 3 * i + 2], float(q[3 * i + 2])

    def phi(self, q: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Constraint residuals Phi(q, t), shape (n_constraints,) [m or rad]."""
        out = np.empty(self.n_constraints)
        k = 0
        for p in self.pairs:
            ra, tha = self._pose(q, p.ia)
            rb, thb = self._pose(q, p.ib)
            if p.kind is JointType.REVOLUTE:
                out[k : k + 2] = ra + _rot(tha) @ p.pa - rb - _rot(thb) @ p.pb
            else:
                d = rb + _rot(thb) @ p.pb - ra - _rot(tha) @ p.pa
                out[k] = thb - tha - p.offset
                out[k + 1] = (_rot(tha) @ p.u) @ d
            k += 2
        for d, ia, ib in self.drives:
            out[k] = self._pose(q, ib)[1] - self._pose(q, ia)[1] - float(d.angle(t))
            k += 1
        return out

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Phi_q, shape (n_constraints, nq)."""
        jac = np.zeros((self.n_constraints, self.nq))
        k = 0
        for p in self.pairs:
            ra, tha = self._pose(q, p.ia)
            rb, thb = self._pose(q, p.ib)
            if p.kind is JointType.REVOLUTE:
                if p.ia >= 0:
                    jac[k : k + 2, 3 * p.ia : 3 * p.ia + 2] = np.eye(2)
                    jac[k : k + 2, 3 * p.ia + 2] = _drot(tha) @ p.pa
                if p.ib >= 0:
                    jac[k : k + 2, 3 * p.ib : 3 * p.ib + 2] = -np.eye(2)
                    jac[k : k + 2, 3 * p.ib + 2] = -_drot(thb) @ p.pb
            else:
                n = _rot(tha) @ p.u
                d = rb + _rot(thb) @ p.pb - ra - _rot(tha) @ p.pa
                if p.ia >= 0:
                    jac[k, 3 * p.ia + 2] = -1.0
                    jac[k + 1, 3 * p.ia : 3 * p.ia + 2] = -n
                    jac[k + 1, 3 * p.ia + 2] = (_drot(tha) @ p.u) @ d - n @ (_drot(tha) @ p.pa)
                if p.ib >= 0:
                    jac[k, 3 * p.ib + 2] = 1.0
                    jac[k + 1, 3 * p.ib : 3 * p.ib + 2] = n
                    jac[k + 1, 3 * p.ib + 2] = n @ (_drot(thb) @ p.pb)
            k += 2
        for _, ia, ib in self.drives:
            if ib >= 0:
                jac[k, 3 * ib + 2] = 1.0
            if ia >= 0:
                jac[k, 3 * ia + 2] = -1.0
            k += 1
        return jac

    def phi_t(self, t: float) -> np.ndarray:
        """Partial time derivative of Phi, shape (n_constraints,)."""
        out = np.zeros(self.n_constraints)
        k = 2 * len(self.pairs)
        for i, (d, _, _) in enumerate(self.drives):
            out[k + i] = -float(d.rate(t))
        return out

    def gamma(self, q: np.ndarray, qd: np.ndarray, t: float) -> np.ndarray:
        """Acceleration right-hand side: Phi_q qdd = gamma, shape (n_constraints,)."""
        out = np.zeros(self.n_constraints)
        k = 0
        for p in self.pairs:
            ra, tha = self._pose(q, p.ia)
            rb, thb = self._pose(q, p.ib)
            va, wa = self._pose(qd, p.ia)
            vb, wb = self._pose(qd, p.ib)
            if p.kind is JointType.REVOLUTE:
                out[k : k + 2] = wa**2 * (_rot(tha) @ p.pa) - wb**2 * (_rot(thb) @ p.pb)
            else:
                n = _rot(tha) @ p.u
                nd = wa * (_drot(tha) @ p.u)
                d = rb + _rot(thb) @ p.pb - ra - _rot(tha) @ p.pa
                dd = vb + wb * (_drot(thb) @ p.pb) - va - wa * (_drot(tha) @ p.pa)
                rest = (
                    -(wa**2) * (n @ d)
                    + 2 * nd @ dd
                    + n @ (-(wb**2) * (_rot(thb) @ p.pb) + wa**2 * (_rot(tha) @ p.pa))
                )
                out[k + 1] = -rest
            k += 2
        for i, (d, _, _) in enumerate(self.drives):
            out[k + i] = float(d.acceleration(t))
        return out


def assemble(
    mechanism: Mechanism,
    t: float = 0.0,
    *,
    q_guess: np.ndarray | None = None,
    tol: float = 1e-12,
    max_iter: int = 50,
) -> np.ndarray:
    """Solve the loop closures for the drive angles at time t (Newton iteration).

    Args:
        mechanism: the mechanism (clearance joints are treated as ideal, journals centred).
        t: time [s] at which the drive angles are taken.
        q_guess: starting coordinates, shape (nq,); default: the links' pose guesses.
        tol: convergence tolerance on max |Phi| [m, rad].
        max_iter: Newton iteration limit.

    Returns:
        q: coordinates (nq,) [m, rad].

    Raises:
        AssemblyError: the loops cannot be closed (lengths do not fit) or the position is
            singular.
    """
    cs = ConstraintSystem(mechanism)
    if cs.n_constraints != cs.nq:
        raise AssemblyError(
            f"mechanism '{mechanism.name}' has {cs.n_constraints} constraint equations for "
            f"{cs.nq} coordinates: it is not fully determined by its drives"
        )
    q = (
        np.array([v for lk in mechanism.moving_links for v in lk.pose_guess], dtype=float)
        if q_guess is None
        else np.array(q_guess, dtype=float)
    )
    res = np.inf
    for _ in range(max_iter):
        f = cs.phi(q, t)
        res = float(np.max(np.abs(f)))
        if res < tol:
            return q
        jac = cs.jacobian(q)
        if np.linalg.cond(jac) > 1e12:
            break
        step = np.linalg.solve(jac, -f)
        # damp very large rotation steps so Newton stays on the nearby branch
        scale = min(1.0, 0.5 / max(1e-300, float(np.max(np.abs(step[2::3])))))
        q = q + scale * step
    raise AssemblyError(
        f"mechanism '{mechanism.name}' cannot be assembled at t = {t:g} s: loop-closure "
        f"residual {res:.3g} after {max_iter} Newton iterations (check that the link lengths "
        "can close every loop at the drive start angles, and the pose guesses)"
    )


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
    """

    times: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    outputs: dict[str, np.ndarray]


def solve_kinematics(mechanism: Mechanism, times: np.ndarray) -> KinematicsResult:
    """Exact ideal kinematics at each time (Newton continued from the previous time).

    Raises:
        AssemblyError: if the mechanism cannot be assembled at some time (e.g. a singular
            position is reached).
    """
    times = np.asarray(times, dtype=float)
    ideal = mechanism.ideal_twin()
    cs = ConstraintSystem(ideal)
    n = len(times)
    q = np.zeros((n, cs.nq))
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    guess = None
    for i, t in enumerate(times):
        qi = assemble(ideal, float(t), q_guess=guess)
        jac = cs.jacobian(qi)
        qdi = np.linalg.solve(jac, -cs.phi_t(float(t)))
        qddi = np.linalg.solve(jac, cs.gamma(qi, qdi, float(t)))
        q[i], qd[i], qdd[i] = qi, qdi, qddi
        # linear prediction of the next guess
        guess = qi if i + 1 >= n else qi + qdi * (times[i + 1] - t)
    outputs = output_kinematics(mechanism, q, qd, qdd)
    return KinematicsResult(times, q, qd, qdd, outputs)


def link_point_world(
    mechanism: Mechanism, q: np.ndarray, link: str, point: tuple[float, float]
) -> np.ndarray:
    """World position of a point given in a link frame, for q of shape (..., nq): (..., 2)."""
    if link == mechanism.ground:
        return np.broadcast_to(np.asarray(point, dtype=float), q.shape[:-1] + (2,)).copy()
    i = [lk.name for lk in mechanism.moving_links].index(link)
    x, y, th = q[..., 3 * i], q[..., 3 * i + 1], q[..., 3 * i + 2]
    c, s = np.cos(th), np.sin(th)
    return np.stack([x + c * point[0] - s * point[1], y + s * point[0] + c * point[1]], axis=-1)


def output_kinematics(
    mechanism: Mechanism, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> dict[str, np.ndarray]:
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
        px, py = mechanism.link(o.link).point(o.point)
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
