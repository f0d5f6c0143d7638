"""Inverse dynamics of the ideal mechanism: joint reaction forces over a drive cycle.

Used to size things before a run: the typical and peak load of each clearance joint give
its typical contact penetration (for the segment-count rule) and the divergence bound. It is
also the exact baseline of the joint reactions a run reports (`joint_reaction_forces` uses the
runs' convention: the force the joint's link_a exerts on its link_b, world frame). The
accelerations come from the exact kinematics (no finite differences), so the loads are exact to
the kinematics solver's tolerance.
"""

from __future__ import annotations

import numpy as np

from clearance.kinematics import ConstraintSystem, KinematicsResult, solve_kinematics
from clearance.model import JointType, Mechanism

__all__ = ["generalized_inertial_forces", "joint_reaction_forces", "joint_reaction_vectors", "joint_reactions"]


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
    mechanism: Mechanism, times: np.ndarray, *, kinematics: KinematicsResult | None = None
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Reaction forces of the ideal twin at every joint and drive.

    Solves Phi_q^T lambda = M qdd - Q at each time.

    Args:
        mechanism: the mechanism (its ideal twin is solved).
        times: (n,) times [s].
        kinematics: `solve_kinematics` of the mechanism (or of its ideal twin: the same) at
            ``times``, when the caller has it already; solved here otherwise.

    Returns:
        (pairs, drives): joint name -> (n, 2) multipliers of the joint's two constraint
        rows [N], in the world x/y frame for revolute joints (their direction is the line
        along which the joint is loaded); drive name -> (n,) drive torque or force.

    Raises:
        AssemblyError: the mechanism cannot be assembled at some time.
    """
    _, pairs, drives = _multipliers(mechanism, times, kinematics)
    return pairs, drives


def _multipliers(
    mechanism: Mechanism, times: np.ndarray, kinematics: KinematicsResult | None = None
) -> tuple[KinematicsResult, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """(ideal kinematics, pair multipliers, drive multipliers): see `joint_reaction_vectors`."""
    ideal = mechanism.ideal_twin()
    kin = kinematics if kinematics is not None else solve_kinematics(ideal, times)
    cs = ConstraintSystem(ideal)
    inert = generalized_inertial_forces(ideal, kin.q, kin.qd, kin.qdd)
    lam = np.linalg.solve(np.swapaxes(cs.jacobian(kin.q), -1, -2), inert[..., None])[..., 0]
    pairs = {name: lam[:, 2 * k : 2 * k + 2] for k, name in enumerate(cs.pair_names)}
    base = 2 * len(cs.pair_names)
    drives = {d.name: lam[:, base + k] for k, (d, _, _) in enumerate(cs.drives)}
    return kin, pairs, drives


def joint_reaction_forces(
    mechanism: Mechanism, times: np.ndarray
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Reaction forces of the ideal twin in the runs' convention, and the drive torques.

    The convention of `clearance.results.SimulationResult.joint_reactions`: the force the
    joint's link_a exerts on its link_b (link_a receives the opposite), world frame. A
    prismatic pair's force is normal to its guide; the moment the pair carries is not included.

    Args:
        mechanism: the mechanism (its ideal twin is solved; clearance joints count as ideal).
        times: (n,) times [s].

    Returns:
        (forces, drives): joint name -> (n, 2) force [N]; drive name -> (n,) torque the drive
        applies to its joint's link_b [N m] (force [N] for a prismatic drive).

    Raises:
        AssemblyError: the mechanism cannot be assembled at some time.
    """
    ideal = mechanism.ideal_twin()
    kin, pairs, drives = _multipliers(mechanism, times)
    index = {lk.name: i for i, lk in enumerate(ideal.moving_links)}
    forces: dict[str, np.ndarray] = {}
    for name, lam in pairs.items():
        j = ideal.joint(name)
        if j.kind is JointType.REVOLUTE:
            # Phi = p_a - p_b and M qdd = Q + Phi_q' lambda: link_a receives +lambda
            forces[name] = -lam
            continue
        # rows (theta_b - theta_a, n . (p_b - p_a)), n = R_a u: link_b receives lambda_2 n
        th = kin.q[:, 3 * index[j.link_a] + 2] if j.link_a in index else np.zeros(len(lam))
        ux, uy = -j.axis[1], j.axis[0]
        c, s = np.cos(th), np.sin(th)
        forces[name] = lam[:, 1:2] * np.stack([c * ux - s * uy, s * ux + c * uy], axis=1)
    return forces, drives


def joint_reactions(mechanism: Mechanism, times: np.ndarray) -> dict[str, np.ndarray]:
    """Reaction force magnitude [N] at every joint of the ideal twin, shape (n,) each.

    The drives' rows give the drive torques, returned under the drive names (see
    `joint_reaction_vectors`).

    Raises:
        AssemblyError: the mechanism cannot be assembled at some time.
    """
    pairs, drives = joint_reaction_vectors(mechanism, times)
    return {**{name: np.hypot(v[:, 0], v[:, 1]) for name, v in pairs.items()}, **drives}
