"""Build a `SimulationResult` from a reference `Trajectory` (same conventions as MuJoCo runs).

At each output sample the equations of motion are solved once more (in the contact mode of
that sample) for accelerations, contact forces and drive torques. Frames and signs:

  * eccentricity: journal centre minus bearing centre in the bearing link's frame;
    eccentricity_rate: the time derivative of that frame-expressed vector;
  * contact_force: force on the journal (normal + friction, and a lubricated joint's film) in
    the bearing frame; film_force: the film's part of it (`contact.film_at` at the sample's state);
  * drive_angle, drive_speed: theta_b - theta_a of the driven joint and its rate;
    drive_torque: torque the drive applies to link_b (positive work at positive speed);
  * closure_violation: largest ideal-joint closure error [m] (revolute: norm of the
    position mismatch; prismatic: distance from the guide line);
  * link_poses: link-frame poses (x, y, theta) of the moving links;
  * joint_reactions: per joint, the force its link_a exerts on its link_b, world frame: for an
    ideal joint from the Lagrange multipliers of its two rows (M zdd + G' lambda = Q, so a
    revolute row pair p_a - p_b = 0 gives link_b the force +lambda; a prismatic pair's distance
    row n . (p_b - p_a) = 0 gives link_b -lambda_2 n, n the guide's normal), for a clearance joint
    its contact force (on the journal, signed by which side the journal is), for a slider with
    play the sum of its corners' contact forces on the slider;
  * sliders: per prismatic joint with play a `SliderResult` in the guide frame (`_slider`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clearance.kinematics import output_kinematics
from clearance.reference.contact import ContactJoint, film_at
from clearance.reference.corner_contact import CornerContact
from clearance.reference.integrator import Trajectory
from clearance.reference.system import ReferenceSystem
from clearance.results import JointResult, SimulationResult, energy_balance
from clearance.translational import SliderResult, classify_contact

__all__ = ["assemble_result"]


def assemble_result(system: ReferenceSystem, traj: Trajectory, metadata: dict[str, Any]) -> SimulationResult:
    """Evaluate every sample of ``traj`` and pack the `SimulationResult`.

    Args:
        system: the system that produced the trajectory.
        traj: the raw solution.
        metadata: the result's metadata (completed here with energy data if tracked: also
            `SimulationResult.energy` with kinetic, gravity_potential, contact_potential and
            drive_work (summed over drives), and the ``energy_balance`` summary, whose residual is
            None: the reference records no constraint or dissipated work).
    """
    n, nq, nc, nd = len(traj.times), system.nq, len(system.contacts), len(system.drives)
    zdd = np.empty((n, nq))
    cres = np.zeros((n, nc, 13))
    torque = np.empty((n, nd))
    closure = np.empty(n)
    lam = np.zeros((n, system.n_constraints))
    for i in range(n):
        ev = system.evaluate(float(traj.times[i]), traj.z[i].tolist(), traj.zd[i].tolist(), traj.vin[i].tolist())
        zdd[i] = ev.zdd
        lam[i] = ev.lam
        if nc:
            cres[i] = ev.contacts
        torque[i] = ev.drive_torque
        closure[i] = system.rows.closure(ev.phi) if ev.phi else 0.0
    q, qd, qdd = system.from_com(traj.z, traj.zd, zdd)
    mech = system.mechanism
    outputs = output_kinematics(mech, q, qd, qdd) if mech is not None else {}

    joints: dict[str, JointResult] = {}
    for k, cj in enumerate(system.contacts):
        if not isinstance(cj, ContactJoint):
            continue
        ex, ey, edx, edy = (cres[:, k, i] for i in range(4))
        fx, fy = cres[:, k, 7], cres[:, k, 8]
        if cj.ib >= 0:
            th, w = q[:, 3 * cj.ib + 2], qd[:, 3 * cj.ib + 2]
        else:
            th, w = np.zeros(n), np.zeros(n)
        c, s = np.cos(th), np.sin(th)
        e = np.stack([c * ex + s * ey, -s * ex + c * ey], axis=1)
        # d/dt (R^T e_w) = R^T e_w' + w (e_y, -e_x) in the bearing frame
        erate = np.stack([c * edx + s * edy + w * e[:, 1], -s * edx + c * edy - w * e[:, 0]], axis=1)
        force = np.stack([c * fx + s * fy, -s * fx + c * fy], axis=1)
        pen = np.hypot(e[:, 0], e[:, 1]) - cj.c
        film = _film_series(cj, traj, cres[:, k, :4])
        if film is not None:
            film = np.stack([c * film[:, 0] + s * film[:, 1], -s * film[:, 0] + c * film[:, 1]], axis=1)
        joints[cj.name] = JointResult(e, erate, pen, force, film)

    reactions = _reactions(system, q, lam, cres)
    corners: dict[str, list[int]] = {}
    for k, cj in enumerate(system.contacts):
        if isinstance(cj, CornerContact):
            corners.setdefault(cj.name, []).append(k)
    sliders = {name: _slider(system, traj, cres, ks) for name, ks in corners.items()}
    angle, speed = np.empty((n, nd)), np.empty((n, nd))
    for k, d in enumerate(system.drives):
        tb = q[:, 3 * d.ib + 2] if d.ib >= 0 else 0.0
        ta = q[:, 3 * d.ia + 2] if d.ia >= 0 else 0.0
        wb = qd[:, 3 * d.ib + 2] if d.ib >= 0 else 0.0
        wa = qd[:, 3 * d.ia + 2] if d.ia >= 0 else 0.0
        angle[:, k] = tb - ta
        speed[:, k] = wb - wa
    meta = dict(metadata)
    energy: dict[str, np.ndarray] = {}
    if traj.work is not None:
        kin, pot, grav = system.energy(traj.z, traj.zd)
        meta["drive_work"] = traj.work.tolist()
        meta["energy"] = {
            "kinetic": kin.tolist(),
            "contact_potential": pot.tolist(),
            "gravity_potential": grav.tolist(),
        }
        # the terms the reference integrates; it records no constraint or dissipated work (its
        # joints are exact), so its balance summary lists those as missing and has no residual
        energy = {
            "kinetic": np.asarray(kin, dtype=float),
            "gravity_potential": np.asarray(grav, dtype=float),
            "contact_potential": np.asarray(pot, dtype=float),
            "drive_work": np.asarray(traj.work, dtype=float).sum(axis=1),
        }
        meta["energy_balance"] = energy_balance(energy)
    meta["max_closure_violation"] = float(closure.max()) if n else 0.0
    return SimulationResult(
        times=np.array(traj.times, dtype=float),
        outputs=outputs,
        joints=joints,
        drive_angle=angle,
        drive_speed=speed,
        drive_torque=torque,
        link_poses=q.reshape(n, len(system.links), 3),
        closure_violation=closure,
        metadata=meta,
        energy=energy,
        joint_reactions=reactions,
        sliders=sliders,
    )


def _film_series(cj: ContactJoint, traj: Trajectory, geometry: np.ndarray) -> np.ndarray | None:
    """A lubricated joint's film force on the journal at every sample, world frame [N], (n, 2).

    `clearance.reference.contact.film_at` at each sample's state (the eccentricity and its rate
    as the sample's evaluation computed them, the links' angular velocities), so the series is
    the film part of the contact force the solver applied there; None for a dry joint.

    Args:
        cj: the joint.
        traj: the run (its velocities give the links' spin).
        geometry: (n, 4) the samples' e (world) [m] and ė [m/s], columns 0-3 of the evaluations.
    """
    if cj.clearance.lubrication is None:
        return None
    n = len(geometry)
    wj = traj.zd[:, 3 * cj.ij + 2] if cj.ij >= 0 else np.zeros(n)
    wb = traj.zd[:, 3 * cj.ib + 2] if cj.ib >= 0 else np.zeros(n)
    out = np.empty((n, 2))
    for i, ((ex, ey, edx, edy), a, b) in enumerate(zip(geometry.tolist(), wj.tolist(), wb.tolist())):
        film = film_at(cj, ex, ey, edx, edy, a, b)
        if film is None:
            return None
        out[i] = film[:2]
    return out


def _slider(system: ReferenceSystem, traj: Trajectory, cres: np.ndarray, ks: list[int]) -> SliderResult:
    """The `SliderResult` of one slider with play from its four corner contacts ``ks``.

    The slider's centre (point_b) is the mean of its corners; the guide frame turns with the
    guide link: a guide-frame coordinate x = u_w . d has rate u_w . d_dot + w_a n_w . d.
    """
    cc = [system.contacts[k] for k in ks]
    first = cc[0]
    assert isinstance(first, CornerContact)
    i, g = first.ij, first.ib
    z, zd = traj.z, traj.zd
    n = len(z)
    sk = np.mean([c.sk for c in cc if isinstance(c, CornerContact)], axis=0)
    th, w = z[:, 3 * i + 2], zd[:, 3 * i + 2]
    c, s = np.cos(th), np.sin(th)
    ax, ay = c * sk[0] - s * sk[1], s * sk[0] + c * sk[1]
    p = np.stack([z[:, 3 * i] + ax, z[:, 3 * i + 1] + ay], axis=1)
    pv = np.stack([zd[:, 3 * i] - w * ay, zd[:, 3 * i + 1] + w * ax], axis=1)
    if g >= 0:
        tg, wg = z[:, 3 * g + 2], zd[:, 3 * g + 2]
        cg, sg = np.cos(tg), np.sin(tg)
        bx, by = cg * first.sg[0] - sg * first.sg[1], sg * first.sg[0] + cg * first.sg[1]
        gp = np.stack([z[:, 3 * g] + bx, z[:, 3 * g + 1] + by], axis=1)
        gv = np.stack([zd[:, 3 * g] - wg * by, zd[:, 3 * g + 1] + wg * bx], axis=1)
        u = np.stack([cg * first.u[0] - sg * first.u[1], sg * first.u[0] + cg * first.u[1]], axis=1)
    else:
        tg, wg = np.zeros(n), np.zeros(n)
        gp, gv = np.broadcast_to(first.sg, (n, 2)), np.zeros((n, 2))
        u = np.broadcast_to(first.u, (n, 2))
    nrm = np.stack([-u[:, 1], u[:, 0]], axis=1)
    d, dv = p - gp, pv - gv
    along, across = np.sum(u * d, axis=1), np.sum(nrm * d, axis=1)
    position = np.stack([along, across], axis=1)
    velocity = np.stack([np.sum(u * dv, axis=1) + wg * across, np.sum(nrm * dv, axis=1) - wg * along], axis=1)
    pen = cres[:, ks, 4]
    force = cres[:, ks, 7:9].sum(axis=1)
    return SliderResult(
        position=position,
        velocity=velocity,
        tilt=th - tg - system.offsets[first.name],
        tilt_rate=w - wg,
        corner_penetration=pen,
        corner_force=cres[:, ks, 11],
        contact_force=np.stack([np.sum(u * force, axis=1), np.sum(nrm * force, axis=1)], axis=1),
        contact_case=classify_contact(pen),
    )


def _reactions(system: ReferenceSystem, q: np.ndarray, lam: np.ndarray, cres: np.ndarray) -> dict[str, np.ndarray]:
    """Joint name -> (n, 2) force its link_a exerts on its link_b, world [N] (module docstring).

    Args:
        system: the system.
        q: (n, nq) link-frame coordinates.
        lam: (n, n_constraints) multipliers.
        cres: (n, n_contacts, 13) contact evaluations (force on the journal at 7, 8).
    """
    out: dict[str, np.ndarray] = {}
    for k, (name, pair) in enumerate(zip(system.rows.pair_names, system.rows.pairs)):
        rev, ia = pair[0], pair[1]
        if rev:
            out[name] = lam[:, 2 * k : 2 * k + 2].copy()
            continue
        ux, uy = pair[7], pair[8]
        th = q[:, 3 * ia + 2] if ia >= 0 else np.zeros(len(q))
        c, s = np.cos(th), np.sin(th)
        normal = np.stack([c * ux - s * uy, s * ux + c * uy], axis=1)
        out[name] = -lam[:, 2 * k + 1 : 2 * k + 2] * normal
    for k, cj in enumerate(system.contacts):
        if isinstance(cj, CornerContact):  # force on the slider, link_b: its corners' sum
            out[cj.name] = out[cj.name] + cres[:, k, 7:9] if cj.name in out else cres[:, k, 7:9].copy()
            continue
        on_journal = cres[:, k, 7:9]
        out[cj.name] = -on_journal if system.joint_links[cj.name][0] == cj.journal_link else on_journal.copy()
    return {name: out[name] for name in system.joint_links if name in out}
