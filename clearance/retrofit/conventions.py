"""The edited model means what the unmodified one meant: joints, keyframes, sensors, actuators.

Checked on every retrofit (radial play and backlash), on the compiled models, so a unit or a
reference angle that went astray in the spec edit (degrees written as radians, a reference
angle left at 0) stops the edit instead of locking a joint: every joint of the unmodified
model keeps its type, range, limit, reference and spring reference angles (qpos0,
qpos_spring) and margin where the map puts it, and its limit's and friction loss's softness
(R, K and B at the run's step: `clearance.retrofit.softness`, which rescales solimp and solref
where the edit moved a row's inverse weight); a backlash motor hinge has its
load's range, limit and reference angle; every keyframe holds the same values; each of the
model's sensors and actuators reads or drives the same object (a moved one: its motor hinge)
with the same parameters, and the model's own sensor data keeps its layout.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import mujoco
import numpy as np

from clearance.retrofit.softness import refsafe, row_softness

__all__ = ["JOINT_FIELDS", "SOFTNESS_RTOL", "check_conventions", "joint_ids"]

JOINT_FIELDS = ("jnt_type", "jnt_limited", "jnt_range", "jnt_margin", "jnt_stiffness")
"""Per-joint values an edit keeps, compared exactly (the edit copies them)."""

SOFTNESS_RTOL = 1e-9
"""Relative tolerance on a limit's or friction loss's R, K and B (`clearance.retrofit.softness.row_softness`):
where the edit rescaled solimp and solref to keep them, a few roundings of the rescale (1e-15 each)."""

_SENSOR_FIELDS = ("sensor_type", "sensor_datatype", "sensor_dim", "sensor_adr", "sensor_cutoff", "sensor_noise")
_ACTUATOR_FIELDS = (
    "actuator_trntype",
    "actuator_dyntype",
    "actuator_gaintype",
    "actuator_biastype",
    "actuator_gear",
    "actuator_ctrlrange",
    "actuator_forcerange",
    "actuator_gainprm",
    "actuator_biasprm",
    "actuator_dynprm",
)
_KEY_FIELDS = ("key_time", "key_ctrl", "key_act")
_OBJ = mujoco.mjtObj


def joint_ids(twin: mujoco.MjModel, model: mujoco.MjModel, qpos_map: np.ndarray) -> list[int]:
    """For each joint of ``twin``, its id in ``model`` (read from where its first qpos went)."""
    at = {int(model.jnt_qposadr[j]): j for j in range(model.njnt)}
    return [at[int(qpos_map[twin.jnt_qposadr[j]])] for j in range(twin.njnt)]


def _name(model: mujoco.MjModel, objtype: int, objid: int) -> str | None:
    if objid < 0:
        return None
    return mujoco.mj_id2name(model, objtype, objid)


def _same_object(
    twin: mujoco.MjModel, model: mujoco.MjModel, objtype: int, a: int, b: int, jmap: Sequence[int]
) -> bool:
    """Whether object ``a`` of ``twin`` and ``b`` of ``model`` (of ``objtype``) are the same one."""
    if objtype == _OBJ.mjOBJ_JOINT:
        return a < 0 and b < 0 or (a >= 0 and jmap[a] == b)
    name = _name(twin, objtype, a)
    return name == _name(model, objtype, b) if name else True  # an unnamed object: nothing to compare it by


def _check_softness(twin: mujoco.MjModel, model: mujoco.MjModel, j: int, jm: int, label: str) -> None:
    """Joint ``j``'s limit and friction loss (first dof) are as soft in ``model`` (joint ``jm``) as in ``twin``."""
    step, safe = float(model.opt.timestep), refsafe(twin)
    d, dm = int(twin.jnt_dofadr[j]), int(model.jnt_dofadr[jm])
    a, am = float(twin.dof_invweight0[d]), float(model.dof_invweight0[dm])
    rows = [("limit", "jnt", j, jm)] if twin.jnt_limited[j] else []
    rows += [("friction loss", "dof", d, dm)] if twin.dof_frictionloss[d] > 0 else []
    for what, kind, i, im in rows:
        old = row_softness(
            a, getattr(twin, f"{kind}_solimp")[i], getattr(twin, f"{kind}_solref")[i], step=step, safe=safe
        )
        new = row_softness(
            am, getattr(model, f"{kind}_solimp")[im], getattr(model, f"{kind}_solref")[im], step=step, safe=safe
        )
        if not np.allclose(new, old, rtol=SOFTNESS_RTOL, atol=0):
            _fail(f"joint '{label}': its {what}'s R, K, B {new} instead of {old}")


def _fail(what: str) -> None:
    raise RuntimeError(f"the edit changed what the model means: {what}")


def check_conventions(
    twin: mujoco.MjModel,
    model: mujoco.MjModel,
    qpos_map: np.ndarray,
    qvel_map: np.ndarray,
    *,
    motors: Mapping[int, int] | None = None,
    moved_sensors: Sequence[int] = (),
) -> None:
    """Check joints, keyframes, sensors and actuators across an edit (module docstring).

    Args:
        twin: the unmodified model.
        model: the edited model.
        qpos_map, qvel_map: where each of ``twin``'s qpos and qvel entries sits in ``model``.
        motors: backlash: a hinge's id in ``twin`` -> its motor hinge's id in ``model`` (its
            actuators drive the motor hinge; its armature and damping moved there).
        moved_sensors: ids of ``twin``'s sensors that read the motor hinge now.

    Raises:
        RuntimeError: something moved, named (a defect of the edit, not of the model).
    """
    motors = motors or {}
    jmap = joint_ids(twin, model, qpos_map)
    for j, jm in enumerate(jmap):
        label = _name(twin, _OBJ.mjOBJ_JOINT, j) or f"#{j}"
        for f in JOINT_FIELDS:
            if not np.array_equal(getattr(model, f)[jm], getattr(twin, f)[j]):
                _fail(f"joint '{label}': {f[4:]} {getattr(model, f)[jm]} instead of {getattr(twin, f)[j]}")
        if j not in motors:  # a backlashed hinge's limit moved to its motor side with the rotor's inertia
            _check_softness(twin, model, j, jm, label)
        q = int(twin.jnt_qposadr[j])
        for f in ("qpos0", "qpos_spring"):
            if getattr(model, f)[qpos_map[q]] != getattr(twin, f)[q]:
                _fail(f"joint '{label}': {f} {getattr(model, f)[qpos_map[q]]} instead of {getattr(twin, f)[q]}")
        if j in motors:
            m = motors[j]
            for f in ("jnt_limited", "jnt_range"):
                if not np.array_equal(getattr(model, f)[m], getattr(twin, f)[j]):
                    _fail(f"the motor hinge of '{label}': {f[4:]} {getattr(model, f)[m]} instead of the hinge's")
            start = model.qpos0[model.jnt_qposadr[m]]
            if start != twin.qpos0[q]:
                _fail(f"the motor hinge of '{label}' starts at {start}, the hinge at {twin.qpos0[q]}")
    if model.nkey != twin.nkey:
        _fail(f"{model.nkey} keyframes instead of {twin.nkey}")
    for k in range(twin.nkey):
        same = np.array_equal(model.key_qpos[k][qpos_map], twin.key_qpos[k]) and np.array_equal(
            model.key_qvel[k][qvel_map], twin.key_qvel[k]
        )
        if not same or any(not np.array_equal(getattr(model, f)[k], getattr(twin, f)[k]) for f in _KEY_FIELDS):
            _fail(f"keyframe {_name(twin, _OBJ.mjOBJ_KEY, k) or k}")
    for k in range(twin.nsensor):
        label = _name(twin, _OBJ.mjOBJ_SENSOR, k) or f"#{k}"
        if any(not np.array_equal(getattr(model, f)[k], getattr(twin, f)[k]) for f in _SENSOR_FIELDS):
            _fail(f"sensor '{label}' changed kind, size or place in the sensor data")
        a, b = int(twin.sensor_objid[k]), int(model.sensor_objid[k])
        kind = int(twin.sensor_objtype[k])
        if k in moved_sensors:
            ok = kind == _OBJ.mjOBJ_JOINT and motors.get(a) == b
        else:
            ok = int(model.sensor_objtype[k]) == kind and _same_object(twin, model, kind, a, b, jmap)
            ref = int(twin.sensor_reftype[k])
            ok = ok and _same_object(twin, model, ref, int(twin.sensor_refid[k]), int(model.sensor_refid[k]), jmap)
        if not ok:
            _fail(f"sensor '{label}' reads another object")
    for k in range(twin.nu):
        label = _name(twin, _OBJ.mjOBJ_ACTUATOR, k) or f"#{k}"
        if any(not np.array_equal(getattr(model, f)[k], getattr(twin, f)[k]) for f in _ACTUATOR_FIELDS):
            _fail(f"actuator '{label}' changed its parameters")
        a, b = int(twin.actuator_trnid[k, 0]), int(model.actuator_trnid[k, 0])
        kind = int(twin.actuator_trntype[k])
        if kind in (mujoco.mjtTrn.mjTRN_JOINT, mujoco.mjtTrn.mjTRN_JOINTINPARENT):
            ok = (motors.get(a) if a in motors else jmap[a]) == b
        else:
            objtype = {mujoco.mjtTrn.mjTRN_TENDON: _OBJ.mjOBJ_TENDON, mujoco.mjtTrn.mjTRN_BODY: _OBJ.mjOBJ_BODY}.get(
                mujoco.mjtTrn(kind), _OBJ.mjOBJ_SITE
            )
            ok = _same_object(twin, model, objtype, a, b, jmap)
        if not ok:
            _fail(f"actuator '{label}' drives another object")
