"""Holonomic constraints of the ideal joints and prescribed drives, in plain floats (joints with play have none).

The same constraints as `clearance.kinematics.ConstraintSystem` (and tested against it),
written for the reference solver's right-hand side: centre-of-mass coordinates
z = (x_c, y_c, theta) per moving link, scalar math, and a constraint Jacobian G whose
sparsity is fixed once (constant entries preset, variable entries written by flat index).

Rows, in order: two per ideal joint (revolute: point_a - point_b in the world; prismatic:
theta_b - theta_a - offset, then the distance of point_b from the guide line), then one per
constant-speed or motion-law drive (theta_b - theta_a - angle(t)).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from clearance.model import Drive, DriveKind, Joint, JointType

__all__ = ["DriveRow", "ConstraintRows"]

_Pair = tuple[bool, int, int, float, float, float, float, float, float, float]
"""One ideal joint: (revolute?, ia, ib, sax, say, sbx, sby, ux, uy, offset)."""


class DriveRow:
    """Scalar evaluation of one drive (prescribed angle, rate, acceleration; or torque).

    Attributes:
        name: drive name.
        kind: `DriveKind`.
        ia, ib: moving-link indices of the driven joint's link_a and link_b (-1: ground).
        torque: constant torque [N m] of a torque drive.
    """

    __slots__ = ("name", "kind", "ia", "ib", "theta0", "speed", "harmonics", "w", "torque")

    def __init__(self, drive: Drive, ia: int, ib: int) -> None:
        self.name, self.kind, self.ia, self.ib = drive.name, drive.kind, ia, ib
        self.theta0, self.torque = drive.start_angle, drive.torque
        self.speed, self.w = drive.speed, 0.0
        self.harmonics: tuple[tuple[float, float], ...] = ()
        if drive.kind is DriveKind.MOTION_LAW:
            law = drive.require_motion()
            self.speed, self.harmonics, self.w = law.speed, tuple(law.harmonics), law.fundamental

    def evaluate(self, t: float) -> tuple[float, float, float]:
        """(angle [rad], rate [rad/s], acceleration [rad/s^2]) at time t [s]."""
        ang, rate, acc = self.theta0 + self.speed * t, self.speed, 0.0
        w = self.w
        for k, (a, ph) in enumerate(self.harmonics, start=1):
            kw = k * w
            s, c = math.sin(kw * t + ph), math.cos(kw * t + ph)
            ang += a * (s - math.sin(ph))
            rate += a * kw * c
            acc -= a * kw * kw * s
        return ang, rate, acc


class ConstraintRows:
    """Constraint rows of the ideal (non-clearance) joints and the prescribed drives.

    Args:
        joints: all joints (clearance joints are skipped).
        drives: all drives (torque drives add no row).
        index: link name -> moving-link index (-1 for ground).
        rel: (link, point) -> point relative to the link's centre of mass [m].
        offsets: joint name -> theta_b - theta_a of the pose guesses (prismatic rows) [rad].
        nq: number of coordinates.
    """

    def __init__(
        self,
        joints: Sequence[Joint],
        drives: Sequence[Drive],
        index: Mapping[str, int],
        rel: Callable[[str, str], tuple[float, float]],
        offsets: Mapping[str, float],
        nq: int,
    ) -> None:
        self.pairs: list[_Pair] = []
        self.pair_names: list[str] = []
        for j in joints:
            if j.has_play:
                continue
            sa, sb = rel(j.link_a, j.point_a), rel(j.link_b, j.point_b)
            rev = j.kind is JointType.REVOLUTE
            u = (-j.axis[1], j.axis[0])
            self.pairs.append((rev, index[j.link_a], index[j.link_b], *sa, *sb, *u, offsets[j.name]))
            self.pair_names.append(j.name)
        jmap = {j.name: j for j in joints}
        self.drives = [DriveRow(d, index[jmap[d.joint].link_a], index[jmap[d.joint].link_b]) for d in drives]
        self.rheonomic = [d for d in self.drives if d.kind is not DriveKind.TORQUE]
        self.n = 2 * len(self.pairs) + len(self.rheonomic)
        self.nq = nq
        self._structure()

    def _structure(self) -> None:
        m, nq = self.n, self.nq
        g = np.zeros((m, nq))
        var: list[int] = []
        k = 0
        for rev, ia, ib, *_ in self.pairs:
            if rev:
                for i, sgn in ((ia, 1.0), (ib, -1.0)):
                    if i >= 0:
                        g[k, 3 * i] = g[k + 1, 3 * i + 1] = sgn
                        var += [k * nq + 3 * i + 2, (k + 1) * nq + 3 * i + 2]
            else:
                for i, sgn in ((ia, -1.0), (ib, 1.0)):
                    if i >= 0:
                        g[k, 3 * i + 2] = sgn
                        var += [(k + 1) * nq + 3 * i + c for c in range(3)]
            k += 2
        for d in self.rheonomic:
            if d.ib >= 0:
                g[k, 3 * d.ib + 2] = 1.0
            if d.ia >= 0:
                g[k, 3 * d.ia + 2] = -1.0
            k += 1
        self.G = g
        self._gflat = g.reshape(-1)
        self._var = np.array(var, dtype=np.intp)

    def evaluate(
        self, t: float, zl: Sequence[float], zdl: Sequence[float] | None = None
    ) -> tuple[list[float], list[float], list[float]]:
        """Evaluate the rows at time t [s] and coordinates zl; update ``self.G`` in place.

        Args:
            t: time [s].
            zl: centre-of-mass coordinates (nq,) as floats.
            zdl: their velocities (nq,); None skips gamma.

        Returns:
            (phi, gamma, phi_t): residuals [m or rad], the acceleration right-hand side
            (G zdd = gamma; empty if zdl is None) and the explicit time derivative of phi.
        """
        phi: list[float] = []
        gv: list[float] = []
        gam: list[float] = []
        cos, sin = math.cos, math.sin
        vel = zdl is not None
        zero3 = (0.0, 0.0, 0.0)
        for rev, ia, ib, sax, say, sbx, sby, ux, uy, off in self.pairs:
            if ia >= 0:
                xa, ya, tha = zl[3 * ia], zl[3 * ia + 1], zl[3 * ia + 2]
                ca, sa = cos(tha), sin(tha)
                ax, ay = ca * sax - sa * say, sa * sax + ca * say
            else:
                xa = ya = tha = 0.0
                ca, sa, ax, ay = 1.0, 0.0, sax, say
            if ib >= 0:
                xb, yb, thb = zl[3 * ib], zl[3 * ib + 1], zl[3 * ib + 2]
                cb, sb = cos(thb), sin(thb)
                bx, by = cb * sbx - sb * sby, sb * sbx + cb * sby
            else:
                xb = yb = thb = 0.0
                bx, by = sbx, sby
            if zdl is not None:
                va = zdl[3 * ia : 3 * ia + 3] if ia >= 0 else zero3
                vb = zdl[3 * ib : 3 * ib + 3] if ib >= 0 else zero3
                wa, wb = va[2], vb[2]
            if rev:
                phi += (xa + ax - xb - bx, ya + ay - yb - by)
                if ia >= 0:
                    gv += (-ay, ax)
                if ib >= 0:
                    gv += (by, -bx)
                if vel:
                    gam += (wa * wa * ax - wb * wb * bx, wa * wa * ay - wb * wb * by)
            else:
                nx, ny = ca * ux - sa * uy, sa * ux + ca * uy
                dx, dy = xb + bx - xa - ax, yb + by - ya - ay
                phi += (thb - tha - off, nx * dx + ny * dy)
                if ia >= 0:
                    gv += (-nx, -ny, (-ny * dx + nx * dy) - (-nx * ay + ny * ax))
                if ib >= 0:
                    gv += (nx, ny, -nx * by + ny * bx)
                if vel:
                    ddx = vb[0] - wb * by - va[0] + wa * ay
                    ddy = vb[1] + wb * bx - va[1] - wa * ax
                    rest = (
                        -wa * wa * (nx * dx + ny * dy)
                        + 2.0 * wa * (-ny * ddx + nx * ddy)
                        + nx * (wa * wa * ax - wb * wb * bx)
                        + ny * (wa * wa * ay - wb * wb * by)
                    )
                    gam += (0.0, -rest)
        phit = [0.0] * len(phi)
        for d in self.rheonomic:
            ang, rate, acc = d.evaluate(t)
            tb = zl[3 * d.ib + 2] if d.ib >= 0 else 0.0
            ta = zl[3 * d.ia + 2] if d.ia >= 0 else 0.0
            phi.append(tb - ta - ang)
            phit.append(-rate)
            if vel:
                gam.append(acc)
        if gv:
            self._gflat[self._var] = gv
        return phi, gam, phit

    def closure(self, phi: Sequence[float]) -> float:
        """Largest loop-closure error [m] among the metric rows (revolute: vector norm)."""
        worst = 0.0
        for k, p in enumerate(self.pairs):
            v = math.hypot(phi[2 * k], phi[2 * k + 1]) if p[0] else abs(phi[2 * k + 1])
            worst = max(worst, v)
        return worst
