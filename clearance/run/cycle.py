"""The ideal cycle a run is sized from: joint loads and effective masses over one drive period.

Two parts, so that a sweep pays for the pose-dependent work once per mechanism:

* `CycleShape`, the parts that depend on the poses only: the ideal twin's joint reactions over
  one period of its drive (181 times) split into the inertial share at unit drive speed and the
  share of gravity, and the journal-to-bearing mobility A = J W Jᵀ (2 x 2) of every clearance
  joint at 36 poses. `cycle_shape` computes it; `clearance.run.cycle_cache` keeps it.
* `IdealCycle`, the cycle at the run's own speed, from a shape (`scale_cycle`): with one
  constant-speed drive turning at ω, every velocity of the ideal twin scales with ω and every
  acceleration with ω², so its joint reactions are ω² λ_unit + λ_gravity at the same drive angles;
  the effective mass at each pose is 1 / (nᵀ A n) with n along that load (the direction median
  where the joint is lightly loaded, as `clearance.contact_calibration.cycle_effective_mass`
  takes it). Other drives (torque, motion law, several drives) are solved at their own speeds
  (scale 1).

The mobility is computed in the ideal twin's Cartesian coordinates (x, y, θ per moving link):
with Φ_q the square Jacobian of every pair and drive row, M the links' mass matrix and F the rows
left free in the clearance model (the clearance joints' and sliders' with play, torque drives),
A_F = (Yᵀ M Y)⁻¹ with Y = Φ_q⁻¹ E_F (the Schur complement of the held rows in Φ_q M⁻¹ Φ_qᵀ, whose
inverse is Φ_q⁻ᵀ M Φ_q⁻¹), and a joint's A is its 2 x 2 block. It is the mobility the compiled
clearance model gives through MuJoCo's mass matrix and Jacobians (loop closures and speed drives
held), without mapping each pose onto the model's coordinates; tests/test_cycle.py compares the
two.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from clearance.contact_calibration.effective_mass import LIGHT_LOAD, EffectiveMass
from clearance.kinematics import ConstraintSystem, solve_kinematics
from clearance.loads import generalized_inertial_forces
from clearance.model import DriveKind, Mechanism
from clearance.run.sizing import median

__all__ = [
    "CYCLE_TIMES",
    "MASS_POSES",
    "CycleShape",
    "IdealCycle",
    "canonical_mechanism",
    "cycle_shape",
    "scale_cycle",
]

CYCLE_TIMES = 181
"""Times over one drive period (both ends included) at which the loads are taken."""

MASS_POSES = 36
"""Poses over one period (every fifth time of the load grid) at which the effective mass is taken."""

_DIRECTIONS = 36
"""Normal directions of the direction median (a lightly loaded joint's effective mass)."""

KINEMATICS_STEP = math.radians(30.0)
"""Largest drive-angle step [rad] of the continuation that follows the cycle's assembly branch
(`clearance.kinematics.solve_kinematics`; the poses agree with its default 5 degrees to its Newton
tolerance, 1e-12, on every catalogue mechanism: tests/test_cycle.py)."""


@dataclass(frozen=True)
class CycleShape:
    """The pose-dependent parts of a mechanism's ideal cycle (module docstring).

    Attributes:
        times: (181,) times of one period of the canonical mechanism [s] (at unit drive speed
            when ``unit_speed``).
        unit_speed: the reactions' inertial share is at drive speed ±1 rad/s and scales with ω².
        inertial: pair (joint) name -> (181, 2) the ideal twin's reaction multipliers without
            gravity [N at 1 rad/s, or N] (`clearance.loads.joint_reaction_vectors`' convention).
        gravity: pair name -> (181, 2) the multipliers of gravity alone [N].
        mobility: clearance joint name -> (36, 2, 2) journal-to-bearing mobility in world x/y at
            every fifth time [1/kg].
    """

    times: np.ndarray
    unit_speed: bool
    inertial: dict[str, np.ndarray]
    gravity: dict[str, np.ndarray]
    mobility: dict[str, np.ndarray]


@dataclass(frozen=True)
class IdealCycle:
    """The ideal cycle at a run's speed.

    Attributes:
        times: (181,) times of one drive period [s].
        loads: pair name -> (181, 2) reaction multipliers of the ideal twin [N] (world x/y for a
            revolute pair), as `clearance.loads.joint_reaction_vectors` gives them.
        masses: clearance joint name -> its `EffectiveMass` over the cycle.
    """

    times: np.ndarray
    loads: dict[str, np.ndarray]
    masses: dict[str, EffectiveMass]


def _scales(mechanism: Mechanism) -> bool:
    """One constant-speed drive: the cycle's loads scale with its speed squared."""
    return len(mechanism.drives) == 1 and mechanism.drives[0].kind is DriveKind.CONSTANT_SPEED


def canonical_mechanism(mechanism: Mechanism) -> Mechanism:
    """The mechanism whose cycle `cycle_shape` solves: its drive at ±1 rad/s when the loads scale
    with the speed (`IdealCycle`), else the mechanism itself."""
    if not _scales(mechanism):
        return mechanism
    d = mechanism.drives[0]
    return dataclasses.replace(mechanism, drives=(dataclasses.replace(d, speed=math.copysign(1.0, d.speed)),))


def _mass_matrix(mechanism: Mechanism, q: np.ndarray) -> np.ndarray:
    """(n, nq, nq) the moving links' mass matrix in Cartesian coordinates at poses q (n, nq)."""
    n = len(q)
    links = mechanism.moving_links
    out = np.zeros((n, 3 * len(links), 3 * len(links)))
    for i, lk in enumerate(links):
        th = q[:, 3 * i + 2]
        c, s = np.cos(th), np.sin(th)
        rx, ry = c * lk.com[0] - s * lk.com[1], s * lk.com[0] + c * lk.com[1]
        k = 3 * i
        out[:, k, k] = out[:, k + 1, k + 1] = lk.mass
        out[:, k, k + 2] = out[:, k + 2, k] = -lk.mass * ry
        out[:, k + 1, k + 2] = out[:, k + 2, k + 1] = lk.mass * rx
        out[:, k + 2, k + 2] = lk.inertia + lk.mass * (lk.com[0] ** 2 + lk.com[1] ** 2)
    return out


def _mobility(mechanism: Mechanism, cs: ConstraintSystem, q: np.ndarray) -> dict[str, np.ndarray]:
    """Clearance joint -> (n, 2, 2) mobility at poses q (n, nq) (module docstring)."""
    jac = cs.jacobian(q)
    play = {j.name for j in mechanism.joints if j.has_play}
    free: list[int] = []
    for k, name in enumerate(cs.pair_names):
        if name in play:
            free += [2 * k, 2 * k + 1]
    # a torque drive leaves its joint free (the speed drives' velocity actuators hold theirs)
    free += [2 * len(cs.pairs) + k for k, d in enumerate(mechanism.drives) if d.kind is DriveKind.TORQUE]
    select = np.zeros((cs.n_constraints, len(free)))
    select[free, np.arange(len(free))] = 1.0
    y = np.linalg.solve(jac, np.broadcast_to(select, jac.shape[:-1] + (len(free),)))
    mass = np.swapaxes(y, -1, -2) @ _mass_matrix(mechanism, q) @ y
    mobility = np.linalg.inv(mass)
    out = {}
    for j in mechanism.clearance_joints:
        at = free.index(2 * cs.pair_names.index(j.name))
        out[j.name] = np.ascontiguousarray(mobility[:, at : at + 2, at : at + 2])
    return out


def cycle_shape(mechanism: Mechanism) -> CycleShape:
    """The pose-dependent parts of the mechanism's ideal cycle (module docstring).

    Raises:
        AssemblyError: the mechanism cannot be assembled, or reaches a singular position, over
            the cycle.
    """
    canon = canonical_mechanism(mechanism)
    ideal = canon.ideal_twin()
    times = np.linspace(0.0, canon.drive_period or 1.0, CYCLE_TIMES)
    kin = solve_kinematics(ideal, times, max_step=KINEMATICS_STEP)
    cs = ConstraintSystem(ideal)
    weightless = dataclasses.replace(ideal, gravity=(0.0, 0.0))
    still = np.zeros_like(kin.q)
    forces = np.stack(
        [
            generalized_inertial_forces(weightless, kin.q, kin.qd, kin.qdd),
            generalized_inertial_forces(ideal, kin.q, still, still),
        ],
        axis=-1,
    )
    lam = np.linalg.solve(np.swapaxes(cs.jacobian(kin.q), -1, -2), forces)
    inertial = {name: np.ascontiguousarray(lam[:, 2 * k : 2 * k + 2, 0]) for k, name in enumerate(cs.pair_names)}
    gravity = {name: np.ascontiguousarray(lam[:, 2 * k : 2 * k + 2, 1]) for k, name in enumerate(cs.pair_names)}
    every = (CYCLE_TIMES - 1) // MASS_POSES
    mobility = _mobility(mechanism, cs, kin.q[: every * MASS_POSES : every]) if mechanism.clearance_joints else {}
    return CycleShape(times, _scales(mechanism), inertial, gravity, mobility)


def _direction_median(mobility: np.ndarray) -> np.ndarray:
    """(n,) median over `_DIRECTIONS` normals of 1 / (nᵀ A n) for mobilities (n, 2, 2) [kg]."""
    ang = np.linspace(0, np.pi, _DIRECTIONS, endpoint=False)
    normals = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    inv = np.einsum("di,nij,dj->nd", normals, mobility, normals)
    return median(1.0 / np.maximum(inv, 1e-300), axis=1)


def scale_cycle(shape: CycleShape, mechanism: Mechanism) -> IdealCycle:
    """The cycle of ``mechanism`` (at its own drive speed) from its shape.

    Args:
        shape: `cycle_shape` of the mechanism (or of one that differs only in its drive's speed,
            its clearances' sizes and their contact properties: `clearance.run.cycle_cache`).
        mechanism: the mechanism.
    """
    speed = abs(mechanism.drives[0].speed) if shape.unit_speed else 1.0
    times = shape.times / speed
    loads = {k: speed**2 * v + shape.gravity[k] for k, v in shape.inertial.items()}
    every = (CYCLE_TIMES - 1) // MASS_POSES
    pose_times = times[: every * MASS_POSES : every]
    masses = {}
    for name, a in shape.mobility.items():
        load = loads[name][: every * MASS_POSES : every]
        size = np.hypot(load[:, 0], load[:, 1])
        heavy = size > LIGHT_LOAD * float(np.max(size))
        n = load / np.where(heavy, size, 1.0)[:, None]
        along = 1.0 / np.maximum(np.einsum("ni,nij,nj->n", n, a, n), 1e-300)
        values = np.where(heavy, along, _direction_median(a))
        masses[name] = EffectiveMass(
            float(median(values)), float(values.min()), float(values.max()), pose_times, values
        )
    return IdealCycle(times, loads, masses)
