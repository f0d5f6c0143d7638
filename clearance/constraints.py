"""Holonomic constraints of a planar mechanism in Cartesian coordinates (x, y, theta per link).

`ConstraintSystem` (re-exported by `clearance.kinematics`) evaluates the constraints of the
ideal joints and the drives, Phi(q, t) = 0, their Jacobian Phi_q, Phi_t and the
acceleration right-hand side gamma, vectorised over the pairs and over any leading batch
axes of q. Coordinates: q = [x_1, y_1, theta_1, x_2, ...] over `Mechanism.moving_links`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearance.model import Drive, DriveKind, JointType, Mechanism

__all__ = ["ConstraintSystem"]


def _rot(th: np.ndarray | float) -> np.ndarray:
    c, s = np.cos(th), np.sin(th)
    return np.array([[c, -s], [s, c]])


@dataclass(frozen=True)
class _Pair:
    kind: JointType
    ia: int  # index of link a among moving links, -1 for ground
    ib: int
    pa: np.ndarray
    pb: np.ndarray
    u: np.ndarray  # prismatic: normal to the axis in frame a
    offset: float  # prismatic: theta_b - theta_a


class _Held:
    """A torque drive seen by kinematics: its joint at the start angle turning at its initial speed."""

    def __init__(self, name: str, angle: float, speed: float = 0.0) -> None:
        self.name = name
        self.start_angle = angle
        self.speed = speed

    def angle(self, t: ArrayLike) -> NDArray[np.float64]:
        return self.start_angle + self.speed * np.asarray(t, dtype=float)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        return self.speed + 0.0 * np.asarray(t, dtype=float)

    def acceleration(self, t: ArrayLike) -> NDArray[np.float64]:
        return 0.0 * np.asarray(t, dtype=float)


class ConstraintSystem:
    """Constraints Phi(q, t) = 0 of a mechanism's ideal joints and prescribed drives.

    Rows: two per pair in joint order (revolute: x and y of the pin gap; prismatic: the
    relative angle and the offset normal to the axis), then one per drive. Every method
    accepts q of shape (nq,) or (..., nq) and t scalar or broadcastable to the batch shape.

    Args:
        mechanism: the mechanism.
        include_clearance: if True (default) clearance joints count as ideal joints (a
            radial clearance as a revolute, a slider with play as a prismatic); if False they
            are left out (their links are then held by contact).
        include_drives: if True (default) each constant-speed or motion-law drive adds one
            rheonomic row theta_b - theta_a - angle(t) = 0, and each torque drive a row
            holding its joint at the drive's start angle, turning at its initial speed (so a
            torque-driven mechanism assembles in the pose its start angles give, with the
            velocities its initial speeds give). The reference solver,
            which applies torque drives as torques, builds its system without them.
    """

    def __init__(self, mechanism: Mechanism, *, include_clearance: bool = True, include_drives: bool = True) -> None:
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
            if j.has_play and not include_clearance:
                continue
            pa = np.array(links[j.link_a].point(j.point_a))
            pb = np.array(links[j.link_b].point(j.point_b))
            u = np.array([-j.axis[1], j.axis[0]])
            off = guess[j.link_b][2] - guess[j.link_a][2]
            self.pairs.append(_Pair(j.kind, index[j.link_a], index[j.link_b], pa, pb, u, off))
            self.pair_names.append(j.name)
        # (drive or held torque drive, index of link a, index of link b; -1 for ground) per drive row
        self.drives: list[tuple[Drive | _Held, int, int]] = []
        if include_drives:
            for d in mechanism.drives:
                jt = mechanism.joint(d.joint)
                law = _Held(d.name, d.start_angle, d.initial_speed) if d.kind is DriveKind.TORQUE else d
                self.drives.append((law, index[jt.link_a], index[jt.link_b]))
        self.n_constraints = 2 * len(self.pairs) + len(self.drives)
        self.length_scale = _length_scale(mechanism)
        # vectorised tables; the ground is the extra link block n_links (always at rest)
        g = self.n_links

        def table(kind: JointType) -> tuple[np.ndarray, ...]:
            ks = [k for k, p in enumerate(self.pairs) if p.kind is kind]
            ps = [self.pairs[k] for k in ks]
            return (
                np.array([2 * k for k in ks], dtype=int),
                np.array([g if p.ia < 0 else p.ia for p in ps], dtype=int),
                np.array([g if p.ib < 0 else p.ib for p in ps], dtype=int),
                np.array([p.pa for p in ps], dtype=float).reshape(-1, 2),
                np.array([p.pb for p in ps], dtype=float).reshape(-1, 2),
                np.array([p.u for p in ps], dtype=float).reshape(-1, 2),
                np.array([p.offset for p in ps], dtype=float),
            )

        self._rev = table(JointType.REVOLUTE)
        self._pri = table(JointType.PRISMATIC)
        self._drv_rows = 2 * len(self.pairs) + np.arange(len(self.drives), dtype=int)
        self._drv_ia = np.array([g if ia < 0 else ia for _, ia, _ in self.drives], dtype=int)
        self._drv_ib = np.array([g if ib < 0 else ib for _, _, ib in self.drives], dtype=int)
        # flat indices of the Jacobian's constant (+-1) and pose-dependent entries
        w = self.nq + 3
        rr, ra, rb = self._rev[:3]
        pr, pa_, pb_ = self._pri[:3]
        dr, da_, db_ = self._drv_rows, self._drv_ia, self._drv_ib
        const = [
            (rr * w + 3 * ra, 1.0),
            ((rr + 1) * w + 3 * ra + 1, 1.0),
            (rr * w + 3 * rb, -1.0),
            ((rr + 1) * w + 3 * rb + 1, -1.0),
            (pr * w + 3 * pa_ + 2, -1.0),
            (pr * w + 3 * pb_ + 2, 1.0),
            (dr * w + 3 * db_ + 2, 1.0),
            (dr * w + 3 * da_ + 2, -1.0),
        ]
        self._jac_const_idx = np.concatenate([i for i, _ in const])
        self._jac_const_val = np.concatenate([np.full(len(i), v) for i, v in const])
        self._jac_var_idx = np.concatenate(
            [rr * w + 3 * ra + 2, (rr + 1) * w + 3 * ra + 2, rr * w + 3 * rb + 2, (rr + 1) * w + 3 * rb + 2]
            + [(pr + 1) * w + 3 * x + k for x in (pa_, pb_) for k in range(3)]
        ).astype(int)
        # every link-frame vector that the rows rotate, in one table: (link block, vector) for
        # the revolute pairs' a and b points, then the prismatic pairs' a and b points and axis
        # normals; `_rotated` turns them all with one cosine and sine per link
        pri_a, pri_b = self._pri[1], self._pri[2]
        self._rot_link = np.concatenate([ra, rb, pri_a, pri_b, pri_a]).astype(int)
        self._rot_vec = np.concatenate(
            [self._rev[3], self._rev[4], self._pri[3], self._pri[4], self._pri[5]], axis=0
        ).reshape(-1, 2)
        nr, npr = len(rr), len(pr)
        self._rot_at = np.cumsum([0, nr, nr, npr, npr, npr])

    def _ext(self, q: np.ndarray) -> np.ndarray:
        """q (..., nq) -> poses (..., n_links + 1, 3) with the ground block appended."""
        q = np.asarray(q, dtype=float)
        z = np.zeros(q.shape[:-1] + (3,))
        return np.concatenate([q, z], axis=-1).reshape(q.shape[:-1] + (self.n_links + 1, 3))

    def _rotated(self, pose: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """R(theta) v and dR/dtheta(theta) v of every vector of the rotation table, (..., k, 2) per
        group: revolute a, revolute b, prismatic a, prismatic b, prismatic normal.

        The same operations as `_rotate` and `_rotate_d`, with one cosine and sine per link.
        """
        th = pose[..., 2]
        c, s = np.cos(th)[..., self._rot_link], np.sin(th)[..., self._rot_link]
        px, py = self._rot_vec[:, 0], self._rot_vec[:, 1]
        rot = np.empty(c.shape + (2,))
        rot[..., 0] = c * px - s * py
        rot[..., 1] = s * px + c * py
        drot = np.empty(c.shape + (2,))
        drot[..., 0] = -s * px - c * py
        drot[..., 1] = c * px - s * py
        at = self._rot_at
        return (
            [rot[..., at[k] : at[k + 1], :] for k in range(5)],
            [drot[..., at[k] : at[k + 1], :] for k in range(5)],
        )

    def phi(self, q: np.ndarray, t: float | np.ndarray = 0.0) -> np.ndarray:
        """Constraint residuals Phi(q, t), shape (..., n_constraints) [m or rad]."""
        pose = self._ext(q)
        out = np.empty(pose.shape[:-2] + (self.n_constraints,))
        (ra_p, rb_p, pa_p, pb_p, n_p), _ = self._rotated(pose)
        rows, ia, ib = self._rev[:3]
        if len(rows):
            res = pose[..., ia, :2] + ra_p - pose[..., ib, :2] - rb_p
            out[..., rows], out[..., rows + 1] = res[..., 0], res[..., 1]
        rows, ia, ib, pa, pb, u, off = self._pri
        if len(rows):
            tha, thb = pose[..., ia, 2], pose[..., ib, 2]
            d = pose[..., ib, :2] + pb_p - pose[..., ia, :2] - pa_p
            out[..., rows] = thb - tha - off
            out[..., rows + 1] = np.sum(n_p * d, axis=-1)
        for k, (d, _, _) in enumerate(self.drives):
            rel = pose[..., self._drv_ib[k], 2] - pose[..., self._drv_ia[k], 2]
            out[..., self._drv_rows[k]] = rel - d.angle(t)
        return out

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Phi_q, shape (..., n_constraints, nq)."""
        pose = self._ext(q)
        batch = pose.shape[:-2]
        jac = np.zeros(batch + (self.n_constraints * (self.nq + 3),))
        jac[..., self._jac_const_idx] = self._jac_const_val
        vals = []
        (_, _, pa_p, pb_p, n), (da, db, pa_d, pb_d, n_d) = self._rotated(pose)
        if len(self._rev[0]):
            vals += [da[..., 0], da[..., 1], -db[..., 0], -db[..., 1]]
        rows, ia, ib = self._pri[:3]
        if len(rows):
            d = pose[..., ib, :2] + pb_p - pose[..., ia, :2] - pa_p
            vals += [
                -n[..., 0],
                -n[..., 1],
                np.sum(n_d * d - n * pa_d, axis=-1),
                n[..., 0],
                n[..., 1],
                np.sum(n * pb_d, axis=-1),
            ]
        if vals:
            jac[..., self._jac_var_idx] = np.concatenate(vals, axis=-1)
        return jac.reshape(batch + (self.n_constraints, self.nq + 3))[..., : self.nq]

    def phi_t(self, t: float | np.ndarray) -> np.ndarray:
        """Partial time derivative of Phi, shape (..., n_constraints) [m/s or rad/s]."""
        t = np.asarray(t, dtype=float)
        out = np.zeros(t.shape + (self.n_constraints,))
        for k, (d, _, _) in enumerate(self.drives):
            out[..., self._drv_rows[k]] = -d.rate(t)
        return out

    def gamma(self, q: np.ndarray, qd: np.ndarray, t: float | np.ndarray) -> np.ndarray:
        """Acceleration right-hand side: Phi_q qdd = gamma, shape (..., n_constraints)."""
        pose, vel = self._ext(q), self._ext(qd)
        out = np.zeros(pose.shape[:-2] + (self.n_constraints,))
        (rev_a, rev_b, ra_p, rb_p, n), (_, _, ra_d, rb_d, n_d) = self._rotated(pose)
        rows, ia, ib = self._rev[:3]
        if len(rows):
            wa, wb = vel[..., ia, 2:3], vel[..., ib, 2:3]
            res = wa**2 * rev_a - wb**2 * rev_b
            out[..., rows], out[..., rows + 1] = res[..., 0], res[..., 1]
        rows, ia, ib = self._pri[:3]
        if len(rows):
            wa, wb = vel[..., ia, 2:3], vel[..., ib, 2:3]
            nd = wa * n_d
            d = pose[..., ib, :2] + rb_p - pose[..., ia, :2] - ra_p
            dd = vel[..., ib, :2] + wb * rb_d - vel[..., ia, :2] - wa * ra_d
            rest = (
                -(wa[..., 0] ** 2) * np.sum(n * d, axis=-1)
                + 2 * np.sum(nd * dd, axis=-1)
                + np.sum(n * (-(wb**2) * rb_p + wa**2 * ra_p), axis=-1)
            )
            out[..., rows + 1] = -rest
        for k, (d, _, _) in enumerate(self.drives):
            out[..., self._drv_rows[k]] = d.acceleration(t)
        return out

    def singularity_measure(self, q: np.ndarray) -> np.ndarray:
        """1 / condition number of the dimensionless Jacobian, shape (...,) in (0, 1].

        Lengths are scaled by `length_scale`; 0 means singular (a dead point).
        """
        jac = self.jacobian(q)
        scale_rows = np.ones(self.n_constraints)
        scale_rows[: 2 * len(self.pairs)] = 1.0 / self.length_scale
        scale_rows[self._pri[0]] = 1.0  # relative-angle rows of prismatic pairs
        scale_cols = np.tile([self.length_scale, self.length_scale, 1.0], self.n_links)
        sv = np.linalg.svd(jac * scale_rows[:, None] * scale_cols, compute_uv=False)
        return sv[..., -1] / sv[..., 0]


def _length_scale(mechanism: Mechanism) -> float:
    """Largest distance of a named point from its link frame origin [m] (at least 1 mm)."""
    r = [math.hypot(*p) for lk in mechanism.links for p in lk.points.values()]
    return max([1e-3, *r])
