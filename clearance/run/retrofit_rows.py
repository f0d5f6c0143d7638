"""Reading a retrofitted model's run: sensor and position rows -> a `SimulationResult` (`RowReader`),
and the full-rate series a thinned run keeps for its statistics.

Rows are the sensor rows of `mujoco.rollout` (row i at t = i h, before step i). Each row carries
every body's world pose and, per retrofitted hinge, the journal centre in its bearing frame, the
penetration |e| - c and the net contact force on the journal rotated into the bearing frame
(`clearance.run.retrofitted` says more).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np

from clearance.contact_plugin.attributes import sensor_offsets
from clearance.results import JointResult, SimulationResult
from clearance.retrofit.loop import connect_residual
from clearance.retrofit.manifest import BacklashRecord, HingeRecord
from clearance.run.backlash_readout import BacklashReader
from clearance.run.readout import _exact_contact_force

__all__ = ["RowReader", "default_output_interval", "point_of", "row_bytes", "site_output_names"]

_STOP_FORCE = mujoco.mjtSensor.mjSENS_TENDONLIMITFRC
"""A hinge whose force sensor is of this type holds its journal by a robot-step radial stop."""


def point_of(model: mujoco.MjModel, name: str) -> tuple[str, int]:
    """('site', id) of the site ``name``, else ('body', id) of the body (its origin); KeyError if neither."""
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)
    if sid >= 0:
        return "site", int(sid)
    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
    if bid >= 0:
        return "body", int(bid)
    raise KeyError(name)


def site_output_names(site: str) -> list[str]:
    """Output names of a site's world position: ``site/<name>/x``, ``/y``, ``/z``."""
    return [f"site/{site}/{a}" for a in "xyz"]


class RowReader:
    """Sensor and position rows -> a `SimulationResult` chunk."""

    def __init__(
        self,
        model: mujoco.MjModel,
        hinges: Sequence[HingeRecord],
        sites: Sequence[str],
        backlash: Sequence[BacklashRecord] = (),
    ) -> None:
        self.model, self.hinges, self.sites = model, hinges, list(sites)
        self.backlash = BacklashReader(model, backlash)
        self.data = mujoco.MjData(model)

        def sensor(name: str) -> slice:
            s = model.sensor(name)
            return slice(int(s.adr[0]), int(s.adr[0] + s.dim[0]))

        def jid(kind: mujoco.mjtObj, name: str) -> int:
            return int(mujoco.mj_name2id(model, kind, name))

        self.ecc = {hr.name: sensor(hr.eccentricity_sensor) for hr in hinges}
        stop = {hr.name for hr in hinges if model.sensor(hr.force_sensor).type == _STOP_FORCE}  # robot step
        self.exact = {
            hr.name: sensor_offsets(model, hr.force_sensor) for hr in hinges if hr.segments == 0 and hr.name not in stop
        }
        self.force = {hr.name: sensor(hr.force_sensor) for hr in hinges if hr.segments > 0}
        self.stop = {hr.name: sensor(hr.force_sensor) for hr in hinges if hr.name in stop}
        self.bearing_site = {hr.name: jid(mujoco.mjtObj.mjOBJ_SITE, hr.bearing_site) for hr in hinges}
        self.slide_dof = {
            hr.name: [int(model.jnt_dofadr[jid(mujoco.mjtObj.mjOBJ_JOINT, s)]) for s in hr.slides] for hr in hinges
        }
        self.points = [point_of(model, s) for s in self.sites]
        self.connects = [
            e for e in range(model.neq) if model.eq_type[e] == mujoco.mjtEq.mjEQ_CONNECT and model.eq_active0[e]
        ]

    def eccentricity(self, sens: np.ndarray, hinge: HingeRecord) -> tuple[np.ndarray, np.ndarray]:
        """(eccentricity (n, 2) [m], penetration |e| - c (n,) [m]) of a hinge from sensor rows."""
        e = sens[:, self.ecc[hinge.name]][:, :2].copy()
        return e, np.hypot(e[:, 0], e[:, 1]) - hinge.radial_clearance

    def full_rate(self, sens: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Hinge -> (penetration (n,) [m], contact-force magnitude (n,) [N]) from sensor rows alone (a ring's
        force is the net contact force's magnitude, its axial part included: none for a planar ring)."""
        out = {}
        for hr in self.hinges:
            e, pen = self.eccentricity(sens, hr)
            if hr.name in self.exact:
                f = np.hypot(*_exact_contact_force(sens, self.exact[hr.name], e, False)[0].T)  # a dry journal
            elif hr.name in self.stop:
                f = np.abs(sens[:, self.stop[hr.name]][:, 0])
            else:
                f = np.linalg.norm(sens[:, self.force[hr.name]], axis=1)
            out[hr.name] = (pen, f)
        return out

    def penetrations(self, sens: np.ndarray) -> dict[str, np.ndarray]:
        """Hinge -> its penetration (n,) [m] over sensor rows."""
        return {hr.name: self.eccentricity(sens, hr)[1] for hr in self.hinges}

    def read(self, times: np.ndarray, sens: np.ndarray, q: np.ndarray, v: np.ndarray) -> SimulationResult:
        model, data = self.model, self.data
        n = len(times)
        poses = np.zeros((n, model.nbody, 7))
        site_pos = np.zeros((n, len(self.points), 3))
        bearing_rot = {name: np.zeros((n, 3, 3)) for name in self.bearing_site}
        closure = np.zeros(n)
        for i in range(n):
            data.qpos[:] = q[i]
            if not np.isfinite(q[i]).all():
                poses[i:] = np.nan
                site_pos[i:] = np.nan
                closure[i:] = np.nan
                break
            mujoco.mj_kinematics(model, data)
            closure[i] = max((connect_residual(model, data, e) for e in self.connects), default=0.0)
            poses[i, :, :3] = data.xpos
            poses[i, :, 3:] = data.xquat
            for k, (kind, pid) in enumerate(self.points):
                site_pos[i, k] = data.site_xpos[pid] if kind == "site" else data.xpos[pid]
            for name, sid in self.bearing_site.items():
                bearing_rot[name][i] = data.site_xmat[sid].reshape(3, 3)
        joints = {}
        for hr in self.hinges:
            e, pen = self.eccentricity(sens, hr)
            rate = v[:, self.slide_dof[hr.name]]
            if hr.name in self.exact:  # the plugin's normal and tangential force, in the bearing frame
                f = _exact_contact_force(sens, self.exact[hr.name], e, False)[0]  # a retrofit's journals are dry
            elif hr.name in self.stop:  # the tendon limit pushes the journal back along the line of centres
                f = _stop_force(sens[:, self.stop[hr.name]][:, 0], e)
            else:
                # the sensor names only the journal geom, so it reads the force the journal exerts on
                # the ring: the force on the journal is its opposite
                f_world = -sens[:, self.force[hr.name]]
                f = np.einsum("nji,nj->ni", bearing_rot[hr.name], f_world)[:, :2]
            joints[hr.name] = JointResult(e, rate, pen, f)
        outputs = {}
        for k, s in enumerate(self.sites):
            for a, name in enumerate(site_output_names(s)):
                outputs[name] = site_pos[:, k, a].copy()
        outputs.update(self.backlash.read(sens, q))
        return SimulationResult(
            times=np.asarray(times, dtype=float),
            outputs=outputs,
            joints=joints,
            drive_angle=np.zeros((n, 0)),
            drive_speed=np.zeros((n, 0)),
            drive_torque=np.zeros((n, 0)),
            link_poses=np.zeros((n, 0, 3)),
            closure_violation=closure,
            body_poses=poses,
        )


def _stop_force(force: np.ndarray, e: np.ndarray) -> np.ndarray:
    """(n, 2) force on the journal in the bearing frame [N] from a radial stop's limit force (n,) [N] (>= 0,
    `clearance.retrofit.radial_stop`) and the eccentricity (n, 2) [m]: -F e/|e| (0 where |e| = 0)."""
    size = np.hypot(e[:, 0], e[:, 1])
    unit = np.divide(e, size[:, None], out=np.zeros_like(e), where=size[:, None] > 0)
    return -np.abs(force)[:, None] * unit


def row_bytes(model: mujoco.MjModel, hinges: int, sites: int, backlash: int) -> int:
    """Bytes one row of a run of ``model`` takes in its arrays: time, every body's pose (7), per hinge its
    eccentricity, rate, penetration and force (7), per site its position (3), per band angle and torque (2),
    and the loop residual."""
    return 8 * (2 + 7 * model.nbody + 7 * hinges + 3 * sites + 2 * backlash)


def default_output_interval(model: mujoco.MjModel, duration: float, per_row: int, budget: float) -> float | None:
    """The row interval [s] that keeps a run of ``duration`` [s] within ``budget`` bytes (rows of ``per_row``
    bytes, `row_bytes`): a whole number of steps; None where every step fits."""
    h = float(model.opt.timestep)
    every = math.ceil(round(duration / h) * per_row / budget)
    return None if every <= 1 else every * h
