"""The motion a retrofit is sized from: the unmodified model under a control, with its hinge loads.

The unmodified model runs at its own time step from its first keyframe (qpos0 when it has
none) under `SineControl`. At every step the force each chosen hinge carries in the plane of
its bearing is read from MuJoCo's ``cfrc_int`` (the force the parent exerts on the child's
subtree; its translational part is the same about any point), a connect's from its
constraint force: that in-plane load is what drives the journal across its clearance once
the hinge has play. The load's axial part is carried by the hinge itself (planar play only,
no tilt).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np

from clearance.retrofit.frames import BearingFrame
from clearance.retrofit.loop import connect_load
from clearance.retrofit.play import ControlTable, RetrofitError, SineControl
from clearance.retrofit.selection import Hinge

__all__ = ["Motion", "control_signal", "initial_data", "fired_warnings", "scalar_coordinates", "twin_motion"]


def control_signal(model: mujoco.MjModel, control: SineControl | ControlTable, times: np.ndarray) -> np.ndarray:
    """(n, nu) controls of ``control`` at ``times`` [s] for ``model``'s actuators.

    A `ControlTable` is interpolated linearly and held beyond its rows; its column count
    must be the model's actuator count (`RetrofitError` otherwise).
    """
    nu = model.nu
    t = np.asarray(times, dtype=float)
    if isinstance(control, ControlTable):
        if control.values.shape[1] != nu:
            raise RetrofitError(
                f"control table {control.source}: {control.values.shape[1]} actuator columns, the model has {nu}"
            )
        return np.column_stack([np.interp(t, control.times, control.values[:, k]) for k in range(nu)]).reshape(
            len(t), nu
        )
    t = t[:, None]
    k = np.arange(nu)[None, :]
    limited = np.asarray(model.actuator_ctrllimited, dtype=bool)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    mid = np.where(limited, 0.5 * (lo + hi), 0.0)
    amp = np.where(limited, 0.5 * (hi - lo), 1.0) * control.amplitude
    phase = 2 * np.pi * k / max(nu, 1)
    return mid[None, :] + amp[None, :] * np.sin(2 * np.pi * control.frequency * t + phase)


def initial_data(model: mujoco.MjModel) -> mujoco.MjData:
    """Data at the model's first keyframe, or at qpos0 when it has none."""
    data = mujoco.MjData(model)
    if model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    return data


def fired_warnings(data: mujoco.MjData) -> dict[str, int]:
    """MuJoCo warnings raised so far in ``data``: name -> count (empty when none)."""
    return {
        mujoco.mjtWarning(i).name: int(data.warning[i].number)
        for i in range(mujoco.mjtWarning.mjNWARNING.value)
        if data.warning[i].number
    }


@dataclass
class Motion:
    """The unmodified model's motion and the in-plane loads of the chosen hinges.

    Attributes:
        times: (n,) [s].
        qpos: (n, nq) positions of the unmodified model.
        loads: hinge name -> (n, 2) force through the hinge in its bearing frame's x-y plane [N].
        warnings: MuJoCo warnings the motion raised (name -> count).
    """

    times: np.ndarray
    qpos: np.ndarray
    loads: dict[str, np.ndarray]
    warnings: dict[str, int] = field(default_factory=dict)

    def load_size(self, hinge: str) -> np.ndarray:
        """(n,) size of a hinge's in-plane load [N]."""
        f = self.loads[hinge]
        return np.hypot(f[:, 0], f[:, 1])


def twin_motion(
    model: mujoco.MjModel,
    hinges: Sequence[Hinge],
    frames: Mapping[str, BearingFrame],
    control: SineControl | ControlTable,
    duration: float,
) -> Motion:
    """Run the unmodified model for ``duration`` [s] and record the hinges' in-plane loads.

    Stops early, keeping what was recorded, at a non-finite state (its warnings are
    returned for the caller to report).
    """
    n = max(2, int(round(duration / model.opt.timestep)))
    times = np.arange(n) * model.opt.timestep
    ctrl = control_signal(model, control, times)
    data = initial_data(model)
    qpos = np.zeros((n, model.nq))
    loads = {h.name: np.zeros((n, 2)) for h in hinges}
    done = n
    for i in range(n):
        data.ctrl[:] = ctrl[i]
        mujoco.mj_forward(model, data)
        mujoco.mj_rnePostConstraint(model, data)
        if not (np.isfinite(data.qpos).all() and np.isfinite(data.qacc).all()):
            done = i
            break
        qpos[i] = data.qpos
        for h in hinges:
            if h.is_connect:
                loads[h.name][i] = connect_load(data, h.equality_id, h.parent_id, frames[h.name])
                continue
            world = data.xmat[h.parent_id].reshape(3, 3) @ frames[h.name].axes_in_parent
            f = world.T @ data.cfrc_int[h.child_id, 3:6]
            loads[h.name][i] = f[:2]
        mujoco.mj_step(model, data)
    return Motion(times[:done], qpos[:done], {k: v[:done] for k, v in loads.items()}, fired_warnings(data))


def scalar_coordinates(model: mujoco.MjModel) -> np.ndarray:
    """qpos indices of every hinge and slide, and of every free joint's position (no quaternion entries)."""
    out: list[int] = []
    for j in range(model.njnt):
        kind, adr = int(model.jnt_type[j]), int(model.jnt_qposadr[j])
        if kind in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            out.append(adr)
        elif kind == int(mujoco.mjtJoint.mjJNT_FREE):
            out += [adr, adr + 1, adr + 2]
    return np.array(out, dtype=int)
