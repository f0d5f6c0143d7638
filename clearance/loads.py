"""Inverse dynamics of the ideal mechanism: joint reaction forces over a drive cycle.

Used to size things before a run: the typical and peak load of each clearance joint give
its typical contact penetration (for the segment-count rule) and the divergence bound.
"""

from __future__ import annotations

import numpy as np

from clearance.kinematics import ConstraintSystem, solve_kinematics
from clearance.model import Mechanism

__all__ = ["generalized_inertial_forces", "joint_reaction_vectors", "joint_reactions"]


def generalized_inertial_forces(mechanism: Mechanism, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """M(q) qdd - Q(q, qd) in Cartesian link-frame coordinates, shape (n, nq).

    Link frames need not sit at the centre of mass: the centre-of-mass acceleration is
    a + alpha R' c - omega^2 R c, and the moment is taken about the frame origin. Q holds
    gravity only.
    """
    g = np.array(mechanism.gravity)
    out = np.zeros_like(q)
    for i, lk in enumerate(mechanism.moving_links):
        th, w, al = q[:, 3 * i + 2], qd[:, 3 * i + 2], qdd[:, 3 * i + 2]
        c, s = np.cos(th), np.sin(th)
        cx, cy = lk.com
        rc = np.stack([c * cx - s * cy, s * cx + c * cy], axis=-1)
        drc = np.stack([-s * cx - c * cy, c * cx - s * cy], axis=-1)
        acom = qdd[:, 3 * i : 3 * i + 2] + al[:, None] * drc - (w**2)[:, None] * rc
        f = lk.mass * (acom - g)
        out[:, 3 * i : 3 * i + 2] = f
        out[:, 3 * i + 2] = lk.inertia * al + rc[:, 0] * f[:, 1] - rc[:, 1] * f[:, 0]
    return out


def joint_reaction_vectors(
    mechanism: Mechanism, times: np.ndarray
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Reaction forces of the ideal twin at every joint and drive.

    Solves Phi_q^T lambda = M qdd - Q at each time.

    Args:
        mechanism: the mechanism (its ideal twin is solved).
        times: (n,) times [s].

    Returns:
        (pairs, drives): joint name -> (n, 2) multipliers of the joint's two constraint
        rows [N], in the world x/y frame for revolute joints (their direction is the line
        along which the joint is loaded); drive name -> (n,) drive torque or force.

    Raises:
        AssemblyError: the mechanism cannot be assembled at some time.
    """
    ideal = mechanism.ideal_twin()
    kin = solve_kinematics(ideal, times)
    cs = ConstraintSystem(ideal)
    inert = generalized_inertial_forces(ideal, kin.q, kin.qd, kin.qdd)
    lam = np.array([np.linalg.solve(cs.jacobian(qi).T, fi) for qi, fi in zip(kin.q, inert)])
    pairs = {name: lam[:, 2 * k : 2 * k + 2] for k, name in enumerate(cs.pair_names)}
    base = 2 * len(cs.pair_names)
    drives = {d.name: lam[:, base + k] for k, (d, _, _) in enumerate(cs.drives)}
    return pairs, drives


def joint_reactions(mechanism: Mechanism, times: np.ndarray) -> dict[str, np.ndarray]:
    """Reaction force magnitude [N] at every joint of the ideal twin, shape (n,) each.

    The drives' rows give the drive torques, returned under the drive names (see
    `joint_reaction_vectors`).

    Raises:
        AssemblyError: the mechanism cannot be assembled at some time.
    """
    pairs, drives = joint_reaction_vectors(mechanism, times)
    return {**{name: np.hypot(v[:, 0], v[:, 1]) for name, v in pairs.items()}, **drives}
