"""Turn a chunk of MuJoCo sensor rows into a `SimulationResult` (vectorised, no per-step Python).

Sensor names are those written by `clearance.mjcf.spec`. With `mujoco.rollout`, sensor
row i describes the state at t_i = i h (before step i is integrated). A model with the energy
meter also gets its energy series (`clearance.run.energy`).
"""

from __future__ import annotations

import mujoco
import numpy as np

from clearance.contact_plugin.attributes import sensor_offsets
from clearance.model import OutputKind
from clearance.results import JointResult, SimulationResult
from clearance.run.energy import read_energy
from clearance.run.preparation import PreparedModel, exact_contact_name

__all__ = ["read_sensors", "sensor_slices"]


def sensor_slices(model: mujoco.MjModel) -> dict[str, slice]:
    """Sensor name -> slice into a sensordata row."""
    out = {}
    for i in range(model.nsensor):
        s = model.sensor(i)
        out[s.name] = slice(int(s.adr[0]), int(s.adr[0] + s.dim[0]))
    return out


def _exact_contact_force(sens: np.ndarray, at: dict[str, int], e: np.ndarray) -> np.ndarray:
    """Contact force on the journal [N], (n, 2) in the bearing frame, as the ring's contact sensor gives it.

    The plugin gives the normal force F_n >= 0 and the tangential force F_t on the journal
    along t = z x n, n = e/|e|: the force on the journal is -F_n n + F_t t.
    """
    r = np.hypot(e[:, 0], e[:, 1])
    safe = np.where(r > 0, r, 1.0)
    n = np.where(r[:, None] > 0, e / safe[:, None], np.array([1.0, 0.0]))
    t = np.stack([-n[:, 1], n[:, 0]], axis=1)
    fn, ft = sens[:, at["normal_force"]], sens[:, at["tangential_force"]]
    return -fn[:, None] * n + ft[:, None] * t


def _angle(xaxis: np.ndarray) -> np.ndarray:
    return np.unwrap(np.arctan2(xaxis[:, 1], xaxis[:, 0]))


def read_sensors(prepared: PreparedModel, times: np.ndarray, sens: np.ndarray) -> SimulationResult:
    """Build a result from sensor rows of shape (n, nsensordata) at ``times`` (n,) [s].

    ``times`` are multiples of the time step counted from the run's start (row i of the run at
    step i): the energy meter's step count is checked against them.
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
        poses[:, i, 2] = _angle(get(f"{lk.name}__xaxis"))

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
    for jname, ring in prepared.built.rings.items():
        e = get(f"{jname}__ecc")[:, :2].copy()
        bx = get(f"{jname}__bxaxis")
        c, s = bx[:, 0], bx[:, 1]
        dv = get(f"{jname}__jvel")[:, :2] - get(f"{jname}__bvel")[:, :2]
        w = get(f"{jname}__bangvel")[:, 2]
        # e = R^T (p_j - p_b)  =>  e' = R^T (v_j - v_b) + w (e_y, -e_x)
        erate = np.stack(
            [c * dv[:, 0] + s * dv[:, 1] + w * e[:, 1], -s * dv[:, 0] + c * dv[:, 1] - w * e[:, 0]], axis=1
        )
        if prepared.built.exact_contact:
            force = _exact_contact_force(sens, sensor_offsets(model, exact_contact_name(jname)), e)
        else:
            fw = get(f"{jname}__force")[:, :2]
            force = np.stack([c * fw[:, 0] + s * fw[:, 1], -s * fw[:, 0] + c * fw[:, 1]], axis=1)
        pen = np.hypot(e[:, 0], e[:, 1]) - ring.radial_clearance
        joints[jname] = JointResult(e, erate, pen, force)

    nd = len(mech.drives)
    angle, speed, torque = np.empty((n, nd)), np.empty((n, nd)), np.empty((n, nd))
    for k, d in enumerate(mech.drives):
        g = prepared.built.drive_gear[d.name]
        angle[:, k] = d.start_angle + g * get(f"{d.name}__angle")[:, 0]
        speed[:, k] = g * get(f"{d.name}__speed")[:, 0]
        torque[:, k] = get(f"{d.name}__torque")[:, 0]
        arm = float(model.dof_armature[model.jnt_dofadr[model.joint(d.joint).id]])
        if arm and n > 1:
            # torque passed to the mechanism = actuator torque - armature inertial torque
            torque[:, k] -= arm * np.gradient(speed[:, k], times)

    cuts = prepared.built.tree.ideal_cuts
    if cuts:
        closure = np.max(np.stack([np.linalg.norm(get(f"{j.name}__closure"), axis=1) for j in cuts]), axis=0)
    else:
        closure = np.zeros(n)
    energy = read_energy(prepared, times, sens)
    return SimulationResult(times, outputs, joints, angle, speed, torque, poses, closure, {}, energy)
