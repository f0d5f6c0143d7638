"""`ReferenceSystem`: the equations of motion of a planar mechanism with clearance joints.

Coordinates: internally z = (x_c, y_c, theta) of each moving link's centre of mass, so the
mass matrix is the constant diagonal diag(m, m, J) per link. The public entry points take
and return the link-frame coordinates q = (x, y, theta) of `clearance.kinematics` (frame
origin, not centre of mass); `to_com` and `from_com` convert.

Equations (the augmented Lagrange-multiplier form of the Flores–Ambrósio papers): the ideal joints
and prescribed drives are holonomic constraints Phi(z, t) = 0 (`ConstraintRows`),

    M zdd + G^T lambda = Q(t, z, zd),      G zdd = gamma - 2 alpha Phi_dot - beta^2 Phi,

with G = Phi_z. The Baumgarte terms are zero when the integrator projects instead.
Clearance joints are not constraints: each adds its contact force
(`clearance.reference.contact`) to Q. As M is diagonal, lambda solves the small symmetric
system (G M^-1 G^T) lambda = G M^-1 Q - gamma_s: one dense solve per call.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple, TypedDict, Unpack

import numpy as np
from scipy.linalg.lapack import dposv

from clearance.contact_calibration.cylindrical_laws import elastic_energy
from clearance.contact_calibration.laws import MIN_APPROACH_SPEED
from clearance.kinematics import assemble, velocities
from clearance.model import Drive, DriveKind, Joint, Link, Mechanism
from clearance.reference.constraints import ConstraintRows
from clearance.reference.contact import ContactJoint, contact_joints
from clearance.reference.corner_contact import CornerContact, corner_contacts

__all__ = ["ReferenceSystem", "ReferenceOptions", "SingularConstraintsError", "Evaluation"]


class ReferenceOptions(TypedDict, total=False):
    """The keyword options of `ReferenceSystem` (see there)."""

    baumgarte: tuple[float, float]
    min_approach_speed: float
    friction_v0: float
    friction_v1: float
    impact_c_max: float | None
    impact_d_max: float | None


_DEFAULTS: ReferenceOptions = {
    "baumgarte": (5.0, 5.0),
    "min_approach_speed": MIN_APPROACH_SPEED,
    "friction_v0": 1e-4,
    "friction_v1": 1e-3,
    "impact_c_max": None,
    "impact_d_max": None,
}


class SingularConstraintsError(ArithmeticError):
    """The constraint Jacobian lost rank (a singular position of the ideal joints)."""


def _spd_solve(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    """Solve the symmetric positive definite system a x = b (LAPACK dposv)."""
    _, x, info = dposv(a, b)
    if info != 0:
        raise SingularConstraintsError(
            f"the constraint Jacobian is singular at t = {t:.9g} s (a singular position of the "
            "ideal joints, or redundant constraints)"
        )
    return x


class Evaluation(NamedTuple):
    """Everything the equations of motion give at one state (centre-of-mass coordinates).

    Attributes:
        zdd: (nq,) accelerations [m/s^2, rad/s^2].
        lam: (n_constraints,) multipliers [N or N m].
        phi: constraint residuals (list) [m or rad].
        contacts: per contact point (`ReferenceSystem.contacts`) the tuple of
            `contact.evaluate_contact` or `corner_contact.evaluate_corner`.
        drive_torque: (n_drives,) torque each drive applies to its link_b [N m].
    """

    zdd: np.ndarray
    lam: np.ndarray
    phi: list[float]
    contacts: list[tuple[float, ...]]
    drive_torque: list[float]


class ReferenceSystem:
    """Equations of motion of a mechanism whose clearance joints are held by contact.

    Build it from a `Mechanism`, or with `from_parts` for systems the mechanism rules do
    not admit (a free body whose journal sits in a ground-fixed bearing).

    Args:
        mechanism: the mechanism.
        baumgarte: (alpha, beta) [1/s] of Baumgarte stabilisation; (0, 0) for none (the
            integrator's coordinate projection).
        min_approach_speed: floor [m/s] on the approach speed recorded at contact onset (a
            grazing onset would otherwise divide the damping term by almost 0); default
            `MIN_APPROACH_SPEED` (1e-3 m/s), the floor of the exact-LN MuJoCo mode.
        friction_v0, friction_v1: Ambrosio's friction thresholds [m/s].
        impact_c_max, impact_d_max: C_max [N s/m] and d_max [m] for joints using the IMPACT
            law (required only for those).

    Raises:
        TypeError: mechanism is not a `Mechanism`.
        ValueError: an argument out of range, or an IMPACT joint without its parameters.
    """

    def __init__(self, mechanism: Mechanism, **options: Unpack[ReferenceOptions]) -> None:
        if not isinstance(mechanism, Mechanism):
            raise TypeError(f"mechanism must be a Mechanism (got {type(mechanism).__name__})")
        self._build(mechanism.links, mechanism.joints, mechanism.drives, mechanism.ground, mechanism.gravity, options)
        self.mechanism: Mechanism | None = mechanism
        self.name = mechanism.name

    @classmethod
    def from_parts(
        cls,
        links: Sequence[Link],
        joints: Sequence[Joint],
        *,
        ground: str = "ground",
        drives: Sequence[Drive] = (),
        gravity: tuple[float, float] = (0.0, 0.0),
        name: str = "system",
        **options: Unpack[ReferenceOptions],
    ) -> ReferenceSystem:
        """A system from links and joints, without the mechanism's one-drive-per-DOF rule.

        Args:
            links: all links, ground included.
            joints: the joints; every clearance must name its ``journal_link``.
            ground: the fixed link.
            drives: drives on ideal revolute joints.
            gravity: (g_x, g_y) [m/s^2].
            name: system name (metadata).
            **options: the constructor's keyword options.

        Raises:
            ValueError: unknown link or point names, a clearance without journal link.
        """
        self = cls.__new__(cls)
        links_by = {lk.name: lk for lk in links}
        if ground not in links_by:
            raise ValueError(f"ground link '{ground}' is not among the links {sorted(links_by)}")
        for j in joints:
            for ln, pn in ((j.link_a, j.point_a), (j.link_b, j.point_b)):
                if ln not in links_by:
                    raise ValueError(f"joint '{j.name}' link '{ln}' is not among the links")
                links_by[ln].point(pn)
            if j.clearance is not None and j.clearance.journal_link is None:
                raise ValueError(f"joint '{j.name}': from_parts needs clearance.journal_link")
        self._build(tuple(links), tuple(joints), tuple(drives), ground, tuple(gravity), options)
        self.mechanism = None
        self.name = name
        return self

    def _build(
        self,
        links: Sequence[Link],
        joints: Sequence[Joint],
        drives: Sequence[Drive],
        ground: str,
        gravity: Sequence[float],
        options: ReferenceOptions,
    ) -> None:
        unknown = set(options) - set(_DEFAULTS)
        if unknown:
            raise TypeError(f"unexpected keyword argument(s) {sorted(unknown)}")
        o: ReferenceOptions = {**_DEFAULTS, **options}
        try:
            alpha, beta = (float(v) for v in o["baumgarte"])
        except (TypeError, ValueError):
            raise ValueError(f"baumgarte must be a pair (alpha, beta) (got {o['baumgarte']!r})") from None
        if not (math.isfinite(alpha) and math.isfinite(beta) and alpha >= 0 and beta >= 0):
            raise ValueError(f"baumgarte must be two finite numbers >= 0 (got {o['baumgarte']!r} 1/s)")
        vmin = float(o["min_approach_speed"])
        if not (math.isfinite(vmin) and vmin > 0):
            raise ValueError(f"min_approach_speed must be > 0 (got {vmin!r} m/s)")
        self.alpha, self.beta, self.min_approach_speed = alpha, beta, vmin
        self.options = o
        self.ground = ground
        self.joint_links = {j.name: (j.link_a, j.link_b) for j in joints}
        """joint name -> (link_a, link_b), in the joints' order."""
        self.links = tuple(lk for lk in links if lk.name != ground)
        self.link_names = [lk.name for lk in self.links]
        index = {n: i for i, n in enumerate(self.link_names)}
        index[ground] = -1
        self.index = index
        self.nq = 3 * len(self.links)
        self.mass = np.array([[lk.mass, lk.mass, lk.inertia] for lk in self.links]).reshape(-1)
        self.minv = 1.0 / self.mass
        self.gravity = tuple(float(v) for v in gravity)
        gx, gy = self.gravity
        self._qgrav = [v for lk in self.links for v in (lk.mass * gx, lk.mass * gy, 0.0)]
        com = {lk.name: lk.com for lk in links}
        com[ground] = (0.0, 0.0)
        self.com = [lk.com for lk in self.links]
        by = {lk.name: lk for lk in links}

        def rel(link: str, point: str) -> tuple[float, float]:
            p = by[link].point(point)
            return (p[0] - com[link][0], p[1] - com[link][1])

        guess = {lk.name: lk.pose_guess for lk in links}
        guess[ground] = (0.0, 0.0, 0.0)
        offsets = {j.name: guess[j.link_b][2] - guess[j.link_a][2] for j in joints}
        self.offsets = offsets
        """joint name -> theta_b - theta_a at assembly [rad] (a prismatic joint's zero tilt)."""
        self.rows = ConstraintRows(joints, drives, index, rel, offsets, self.nq)
        self.n_constraints = self.rows.n
        self.drives = self.rows.drives
        self.drive_names = [d.name for d in self.drives]
        v0, v1, c_max, d_max = float(o["friction_v0"]), float(o["friction_v1"]), o["impact_c_max"], o["impact_d_max"]
        self.contacts: list[ContactJoint | CornerContact] = [
            *contact_joints(joints, index, rel, v0=v0, v1=v1, c_max=c_max, d_max=d_max),
            *corner_contacts(joints, index, rel, offsets, v0=v0, v1=v1, c_max=c_max, d_max=d_max),
        ]
        """The contact points: each clearance joint's journal, then each slider's four corners."""
        self.contact_names = [c.name for c in self.contacts]
        """The joint of each contact point (a slider's name four times)."""
        self._torque = [(d.ia, d.ib, d.torque) for d in self.drives if d.kind is DriveKind.TORQUE]
        # row of each prescribed drive among the constraints, -1 for torque drives
        base, k, self._drive_row = 2 * len(self.rows.pairs), 0, []
        for d in self.drives:
            if d.kind is DriveKind.TORQUE:
                self._drive_row.append(-1)
            else:
                self._drive_row.append(base + k)
                k += 1

    # -- coordinates ------------------------------------------------------------------------
    def to_com(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Link-frame (q, qd), shape (..., nq), to centre-of-mass coordinates (z, zd)."""
        z, zd = np.array(q, dtype=float), np.array(qd, dtype=float)
        for i, (cx, cy) in enumerate(self.com):
            th, w = z[..., 3 * i + 2], zd[..., 3 * i + 2]
            c, s = np.cos(th), np.sin(th)
            ax, ay = c * cx - s * cy, s * cx + c * cy
            z[..., 3 * i] += ax
            z[..., 3 * i + 1] += ay
            zd[..., 3 * i] -= w * ay
            zd[..., 3 * i + 1] += w * ax
        return z, zd

    def from_com(self, z: np.ndarray, zd: np.ndarray, zdd: np.ndarray) -> tuple[np.ndarray, ...]:
        """Centre-of-mass (z, zd, zdd), shape (..., nq), to link-frame (q, qd, qdd)."""
        q, qd, qdd = (np.array(a, dtype=float) for a in (z, zd, zdd))
        for i, (cx, cy) in enumerate(self.com):
            th, w, al = q[..., 3 * i + 2], qd[..., 3 * i + 2], qdd[..., 3 * i + 2]
            c, s = np.cos(th), np.sin(th)
            ax, ay = c * cx - s * cy, s * cx + c * cy
            q[..., 3 * i] -= ax
            q[..., 3 * i + 1] -= ay
            qd[..., 3 * i] += w * ay
            qd[..., 3 * i + 1] -= w * ax
            qdd[..., 3 * i] += al * ay + w * w * ax
            qdd[..., 3 * i + 1] += -al * ax + w * w * ay
        return q, qd, qdd

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The ideal mechanism assembled at t = 0 with ideal velocities, journals and sliders centred.

        A torque-driven joint starts at its drive's start angle, turning at the drive's
        initial speed relative to its other link.

        Returns:
            (q, qd): link-frame coordinates (nq,) [m, rad] and velocities [m/s, rad/s].

        Raises:
            ValueError: for a system built with `from_parts` (give the state explicitly).
            AssemblyError: the mechanism cannot be assembled.
        """
        if self.mechanism is None:
            raise ValueError("a system built from parts has no assembly: give q0 and qd0")
        # kinematics sees a torque drive at its start angle, turning at its initial speed
        q = assemble(self.mechanism, 0.0)
        return q, velocities(self.mechanism, q, 0.0)

    # -- dynamics ----------------------------------------------------------------------------
    def evaluate(self, t: float, zl: Sequence[float], zdl: Sequence[float], vin: Sequence[float]) -> Evaluation:
        """Solve the equations of motion at one state.

        Args:
            t: time [s].
            zl, zdl: centre-of-mass coordinates and velocities (nq,) as floats.
            vin: per contact point the approach speed of the current impact [m/s], or 0
                for a joint not in contact mode.

        Returns:
            The `Evaluation`.

        Raises:
            SingularConstraintsError: the constraint Jacobian is singular.
        """
        q = list(self._qgrav)
        for ia, ib, tau in self._torque:
            if ib >= 0:
                q[3 * ib + 2] += tau
            if ia >= 0:
                q[3 * ia + 2] -= tau
        cres = []
        for cj, v in zip(self.contacts, vin):
            r = cj.evaluate(zl, zdl, v)
            cres.append(r)
            if r[11] != 0.0 or r[7] != 0.0 or r[8] != 0.0 or r[9] != 0.0:  # dry contact, or an oil film
                if not math.isfinite(r[11]):  # a rejected trial stage far outside the physics
                    nan = np.full(self.nq, math.nan)
                    return Evaluation(
                        nan, np.full(self.n_constraints, math.nan), [], cres, [math.nan] * len(self.drives)
                    )
                i, k = cj.ij, cj.ib
                if i >= 0:
                    q[3 * i] += r[7]
                    q[3 * i + 1] += r[8]
                    q[3 * i + 2] += r[9]
                if k >= 0:
                    q[3 * k] -= r[7]
                    q[3 * k + 1] -= r[8]
                    q[3 * k + 2] += r[10]
        qa = np.array(q)
        if self.n_constraints == 0:
            return Evaluation(self.minv * qa, np.zeros(0), [], cres, self._torques(np.zeros(0)))
        phi, gam, phit = self.rows.evaluate(t, zl, zdl)
        g = self.rows.G
        gs = np.array(gam)
        if self.alpha or self.beta:
            phidot = g @ np.array(zdl) + np.array(phit)
            gs -= 2.0 * self.alpha * phidot + self.beta * self.beta * np.array(phi)
        gm = g * self.minv
        lam = _spd_solve(gm @ g.T, gm @ qa - gs, t)
        zdd = self.minv * (qa - g.T @ lam)
        return Evaluation(zdd, lam, phi, cres, self._torques(lam))

    def _torques(self, lam: np.ndarray) -> list[float]:
        out = []
        for d, row in zip(self.drives, self._drive_row):
            out.append(d.torque if row < 0 else -float(lam[row]))
        return out

    def rate(self, zdl: Sequence[float], d_index: int) -> float:
        """Relative angular speed theta_b' - theta_a' of drive ``d_index`` [rad/s]."""
        d = self.drives[d_index]
        wb = zdl[3 * d.ib + 2] if d.ib >= 0 else 0.0
        wa = zdl[3 * d.ia + 2] if d.ia >= 0 else 0.0
        return wb - wa

    def rhs(self, t: float, y: np.ndarray, vin: Sequence[float]) -> np.ndarray:
        """State derivative for ``solve_ivp``-type solvers.

        Args:
            t: time [s].
            y: state (z, zd) of length 2 nq, optionally followed by the work done by each
                drive [J] (then its power is returned there).
            vin: per contact point the current approach speed [m/s] or 0 (free).

        Returns:
            dy/dt, same length as y.
        """
        nq = self.nq
        yl = y.tolist()
        zdl = yl[nq : 2 * nq]
        ev = self.evaluate(t, yl[:nq], zdl, vin)
        out = np.empty(len(yl))
        out[:nq] = zdl
        out[nq : 2 * nq] = ev.zdd
        if len(yl) > 2 * nq:
            out[2 * nq :] = [tau * self.rate(zdl, k) for k, tau in enumerate(ev.drive_torque)]
        return out

    def project(
        self, t: float, z: np.ndarray, zd: np.ndarray, *, tol: float = 1e-14, max_iter: int = 5
    ) -> tuple[np.ndarray, np.ndarray]:
        """Mass-weighted projection of (z, zd) onto Phi = 0 and Phi_dot = 0.

        Args:
            t: time [s].
            z, zd: centre-of-mass coordinates and velocities (nq,).
            tol: target max |Phi| [m or rad].
            max_iter: Newton iterations on the positions.

        Returns:
            The projected (z, zd).
        """
        if self.n_constraints == 0:
            return z, zd
        z = np.array(z, dtype=float)
        for _ in range(max_iter):
            phi = np.array(self.rows.evaluate(t, z.tolist())[0])
            g = self.rows.G
            gm = g * self.minv
            if np.max(np.abs(phi)) <= tol:
                break
            z -= gm.T @ _spd_solve(gm @ g.T, phi, t)
        _, _, phit = self.rows.evaluate(t, z.tolist())
        g = self.rows.G
        gm = g * self.minv
        zd = np.array(zd, dtype=float)
        zd -= gm.T @ _spd_solve(gm @ g.T, g @ zd + np.array(phit), t)
        return z, zd

    def energy(self, z: np.ndarray, zd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Kinetic, elastic contact and gravity potential energy [J], shape (...,) each.

        The contact potential is that of the elastic part K delta^(n+1) / (n+1) of each
        joint in penetration (exact for Hertz and LN with c_e = 1), or a cylindrical law's
        `cylindrical_laws.elastic_energy`.
        """
        z, zd = np.asarray(z, dtype=float), np.asarray(zd, dtype=float)
        kin = 0.5 * np.sum(self.mass * zd * zd, axis=-1)
        gx, gy = self.gravity
        grav = np.zeros(z.shape[:-1])
        for i, lk in enumerate(self.links):
            grav -= lk.mass * (gx * z[..., 3 * i] + gy * z[..., 3 * i + 1])
        pot = np.zeros(z.shape[:-1])
        for cj in self.contacts:
            delta = np.array([cj.evaluate(zi, zi, 0.0)[4] for zi in z.reshape(-1, self.nq).tolist()]).reshape(
                z.shape[:-1]
            )
            if isinstance(cj, ContactJoint) and cj.cylinder is not None:
                cyl = cj.cylinder
                pot += np.vectorize(lambda d, cyl=cyl: elastic_energy(cyl, d), otypes=[float])(delta)
                continue
            n = cj.exponent
            pot += cj.stiffness * np.maximum(delta, 0.0) ** (n + 1) / (n + 1)
        return kin, pot, grav
