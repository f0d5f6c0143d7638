"""Turn a chunk of MuJoCo sensor rows into a `SimulationResult` (vectorised, no per-step Python).

Sensor names are those written by `clearance.mjcf.spec`. With `mujoco.rollout`, sensor
row i describes the state at t_i = i h (before step i is integrated) and state row i the state
after it, at t_i + h. A model with the energy meter also gets its energy series
(`clearance.run.energy`); every run gets its joint reactions (`clearance.run.reactions`) and its
sliders with play (`clearance.run.slider_readout`).

Drive torque. A speed drive is a velocity actuator that implicitfast integrates implicitly:
over step i it applies F(v_i) + dF/dv (v_{i+1} - v_i), the force at the step's end velocity,
not the force F(v_i) its sensor reads at the step's start (with the drive's large gain they
differ by up to a hundred N m at an impact). Row i's drive torque is that applied force less the
armature's share, armature * (v_{i+1} - v_i) / h: the torque the drive passed to the mechanism
over step i, which state row i's velocity gives exactly.
"""

from __future__ import annotations

import mujoco
import numpy as np

from clearance.contact_plugin.attributes import sensor_offsets
from clearance.model import OutputKind
from clearance.results import JointResult, SimulationResult
from clearance.run.energy import read_energy
from clearance.run.preparation import PreparedModel, exact_contact_name
from clearance.run.reactions import frame_rate, reaction_layout, read_reactions, rotate
from clearance.run.slider_readout import read_sliders

__all__ = ["read_sensors", "sensor_slices"]


def sensor_slices(model: mujoco.MjModel) -> dict[str, slice]:
    """Sensor name -> slice into a sensordata row."""
    out = {}
    for i in range(model.nsensor):
        s = model.sensor(i)
        out[s.name] = slice(int(s.adr[0]), int(s.adr[0] + s.dim[0]))
    return out


def _exact_contact_force(
    sens: np.ndarray, at: dict[str, int], e: np.ndarray, lubricated: bool
) -> tuple[np.ndarray, np.ndarray | None]:
    """Contact force on the journal [N], (n, 2) in the bearing frame, as the ring's contact sensor
    gives it, and a lubricated joint's film force (its part of it; None for a dry joint).

    The plugin gives the normal force F_n >= 0 and the tangential force F_t on the journal
    along t = z x n, n = e/|e|: the force on the journal is -F_n n + F_t t, plus a lubricated
    joint's film force G_n n + G_t t (its components along n and t; 0 for a dry joint).
    """
    r = np.hypot(e[:, 0], e[:, 1])
    safe = np.where(r > 0, r, 1.0)
    n = np.where(r[:, None] > 0, e / safe[:, None], np.array([1.0, 0.0]))
    t = np.stack([-n[:, 1], n[:, 0]], axis=1)
    gn, gt = sens[:, at["film_normal_force"]], sens[:, at["film_tangential_force"]]
    fn = sens[:, at["normal_force"]] - gn
    ft = sens[:, at["tangential_force"]] + gt
    film = gn[:, None] * n + gt[:, None] * t if lubricated else None
    return -fn[:, None] * n + ft[:, None] * t, film


def _angle(xaxis: np.ndarray, before: float | None) -> np.ndarray:
    """Unwrapped angle of a body's x axis [rad], continuing from ``before`` (the row before, unwrapped)."""
    angle = np.arctan2(xaxis[:, 1], xaxis[:, 0])
    if before is None:
        return np.unwrap(angle)
    return np.unwrap(np.concatenate([[before], angle]))[1:]


def read_sensors(
    prepared: PreparedModel,
    times: np.ndarray,
    sens: np.ndarray,
    states: np.ndarray | None = None,
    *,
    angles_before: np.ndarray | None = None,
) -> SimulationResult:
    """Build a result from sensor rows of shape (n, nsensordata) at ``times`` (n,) [s].

    ``times`` are multiples of the time step counted from the run's start (row i of the run at
    step i): the energy meter's step count is checked against them.

    Args:
        prepared: the model.
        times: (n,) [s].
        sens: (n, nsensordata) sensor rows, row i at the state before step i.
        states: (n, nstate) full-physics state rows of the same rollout, row i after step i:
            they give the drives' end-of-step velocities (module docstring). Without them the
            next sensor row stands in, and the last row keeps the step-start force with no
            armature correction.
        angles_before: (n_links,) the links' unwrapped angles [rad] in the row before ``times[0]``
            (the previous chunk's last row), so that a chunked run's angles continue across
            chunk boundaries as one run's do; None: the first chunk.
    """
    mech, model = prepared.mechanism, prepared.model
    if prepared.slices is None:
        prepared.slices = sensor_slices(model)
    sl = prepared.slices

    def get(name: str) -> np.ndarray:
        return sens[:, sl[name]]

    n = len(times)
    links = mech.moving_links
    poses = np.empty((n, len(links), 3))
    for i, lk in enumerate(links):
        poses[:, i, :2] = get(f"{lk.name}__pos")[:, :2]
        poses[:, i, 2] = _angle(get(f"{lk.name}__xaxis"), None if angles_before is None else angles_before[i])

    outputs: dict[str, np.ndarray] = {}
    for o in mech.outputs:
        if o.kind is OutputKind.ANGLE:
            i = [lk.name for lk in links].index(o.link)
            outputs[o.name] = poses[:, i, 2].copy()
            outputs[o.name + "_vel"] = get(f"{o.name}__angvel")[:, 2].copy()
            outputs[o.name + "_acc"] = get(f"{o.name}__angacc")[:, 2].copy()
        else:
            comp = 0 if o.kind is OutputKind.POSITION_X else 1
            for suffix, key in (("pos", o.name), ("vel", o.name + "_vel"), ("acc", o.name + "_acc")):
                outputs[key] = get(f"{o.name}__{suffix}")[:, comp].copy()
            # MuJoCo's frame linear acceleration includes -gravity (as an accelerometer
            # reads it); the output is the kinematic acceleration
            outputs[o.name + "_acc"] += model.opt.gravity[comp]

    joints: dict[str, JointResult] = {}
    journal_world: dict[str, np.ndarray] = {}
    for jname, ring in prepared.built.rings.items():
        e = get(f"{jname}__ecc")[:, :2].copy()
        bx = get(f"{jname}__bxaxis")
        c, s = bx[:, 0], bx[:, 1]
        dv = get(f"{jname}__jvel")[:, :2] - get(f"{jname}__bvel")[:, :2]
        erate = frame_rate(bx, dv, get(f"{jname}__bangvel")[:, 2], e)  # e = R^T (p_j - p_b)
        film = None
        if prepared.built.exact_contact:
            oiled = mech.joint(jname).require_clearance().lubrication is not None
            force, film = _exact_contact_force(sens, sensor_offsets(model, exact_contact_name(jname)), e, oiled)
            journal_world[jname] = rotate(bx, force)
        else:
            fw = get(f"{jname}__force")[:, :2]
            force = np.stack([c * fw[:, 0] + s * fw[:, 1], -s * fw[:, 0] + c * fw[:, 1]], axis=1)
            journal_world[jname] = fw.copy()
        pen = np.hypot(e[:, 0], e[:, 1]) - ring.radial_clearance
        joints[jname] = JointResult(e, erate, pen, force, film)

    sliders, slider_world = read_sliders(prepared, get, sens)
    journal_world |= slider_world  # a slider's contact force acts on it as a journal's does
    if prepared.reactions is None:
        tree = prepared.built.tree
        prepared.reactions = reaction_layout(
            mech,
            {child: (par, j.name) for child, (par, j) in tree.parent.items()},
            tuple(j.name for j in tree.ideal_cuts),
            exact_contact=prepared.built.exact_contact,
        )
    reactions = read_reactions(prepared.reactions, get, journal_world, n)

    nd = len(mech.drives)
    angle, speed, torque = np.empty((n, nd)), np.empty((n, nd)), np.empty((n, nd))
    for k, d in enumerate(mech.drives):
        g = prepared.built.drive_gear[d.name]
        angle[:, k] = d.start_angle + g * get(f"{d.name}__angle")[:, 0]
        speed[:, k] = g * get(f"{d.name}__speed")[:, 0]
        torque[:, k] = _drive_torque(prepared, d.joint, d.name, get(f"{d.name}__torque")[:, 0], speed[:, k], g, states)

    cuts = prepared.built.tree.ideal_cuts
    if cuts:
        closure = np.max(np.stack([np.linalg.norm(get(f"{j.name}__closure"), axis=1) for j in cuts]), axis=0)
    else:
        closure = np.zeros(n)
    energy = read_energy(prepared, times, sens)
    return SimulationResult(
        times, outputs, joints, angle, speed, torque, poses, closure, {}, energy, reactions, sliders=sliders
    )


def _drive_torque(
    prepared: PreparedModel,
    joint: str,
    actuator: str,
    force: np.ndarray,
    speed: np.ndarray,
    gear: float,
    states: np.ndarray | None,
) -> np.ndarray:
    """(n,) torque a drive passed to the mechanism over each step [N m] (module docstring).

    Args:
        prepared: the model.
        joint, actuator: the driven joint and the drive's actuator.
        force: (n,) actuator force at each step's start (its sensor) [N m].
        speed: (n,) drive speed at each step's start, gear * qvel [rad/s].
        gear: +1 or -1 (drive angle = start + gear * qpos).
        states: (n, nstate) state rows after each step, or None.
    """
    model = prepared.model
    dof = int(model.jnt_dofadr[model.joint(joint).id])
    n = len(force)
    if states is not None:
        at = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_TIME | mujoco.mjtState.mjSTATE_QPOS) + dof
        end = gear * states[:n, at]
        full = n
    else:
        end = np.append(speed[1:], speed[-1:])
        full = n - 1
    dv = np.zeros(n)
    dv[:full] = (end - speed)[:full]  # change of gear * qvel over each step
    act = model.actuator(actuator).id
    implicit = model.opt.integrator in (mujoco.mjtIntegrator.mjINT_IMPLICIT, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
    dfdv = 0.0
    if implicit and model.actuator_biastype[act] == mujoco.mjtBias.mjBIAS_AFFINE:
        # the actuator force's velocity derivative that implicit integration applies (the drives'
        # gains are fixed, so the bias alone carries it); actuator velocity = gear * qvel
        dfdv = float(model.actuator_biasprm[act, 2])
    arm = float(model.dof_armature[dof])
    h = model.opt.timestep
    # torque passed to the mechanism = force applied over the step - armature inertial torque
    return force + dfdv * dv - arm * dv / h
