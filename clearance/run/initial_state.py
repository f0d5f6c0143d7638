"""Initial states other than the default (every journal centred, ideal velocities).

`offset_journals` moves journals off-centre in their bearings at t = 0 (e.g. resting in
contact) with the smallest change of the joint coordinates that keeps the ideal loop
closures and the drive angles: a minimum-norm Gauss-Newton iteration on the compiled
model's own kinematics.
"""

from __future__ import annotations

from collections.abc import Mapping

import mujoco
import numpy as np

__all__ = ["offset_journals"]


def _site_jac(model: mujoco.MjModel, data: mujoco.MjData, site: str) -> tuple[np.ndarray, np.ndarray]:
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
    jac = np.zeros((3, model.nv))
    mujoco.mj_jacSite(model, data, jac, None, sid)
    return data.site_xpos[sid].copy(), jac


def offset_journals(
    model: mujoco.MjModel,
    qpos: np.ndarray,
    targets: Mapping[str, tuple[float, float]],
    *,
    bearings: Mapping[str, float],
    fixed_joints: list[str],
    tol: float = 1e-12,
    max_iter: int = 30,
) -> np.ndarray:
    """Joint coordinates that put each named journal at a target eccentricity.

    Args:
        model: compiled clearance model (hinge and slide joints only, so nq == nv).
        qpos: starting coordinates (nq,), normally the keyframe's.
        targets: clearance joint name -> (e_x, e_y) in the bearing frame [m].
        bearings: clearance joint name -> radial clearance c [m] (for the error message).
        fixed_joints: joints whose coordinate must not change (the driven joints).
        tol: residual tolerance [m].
        max_iter: iteration limit.

    Returns:
        The new qpos (nq,).

    Raises:
        ValueError: the target cannot be reached with the loop closures and drives held.
    """
    data = mujoco.MjData(model)
    q = np.array(qpos, dtype=float)
    fixed = [model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in fixed_joints]
    eqs = [i for i in range(model.neq) if model.eq_type[i] == mujoco.mjtEq.mjEQ_CONNECT]
    res = np.inf
    for _ in range(max_iter):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        rows, rhs = [], []
        for name, target in targets.items():
            pj, jj = _site_jac(model, data, f"{name}__journal")
            pb, jb = _site_jac(model, data, f"{name}__bearing")
            sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{name}__bearing")
            rot = data.site_xmat[sid].reshape(3, 3)[:2, :2]
            e = rot.T @ (pj - pb)[:2]
            rows.append(rot.T @ (jj - jb)[:2])
            rhs.append(np.asarray(target, dtype=float) - e)
        for i in eqs:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_EQUALITY, i)
            pa, ja = _site_jac(model, data, f"{name}__a")
            pb, jb = _site_jac(model, data, f"{name}__b")
            rows.append((ja - jb)[:2])
            rhs.append((pb - pa)[:2])
        for d in fixed:
            r = np.zeros((1, model.nv))
            r[0, d] = 1.0
            rows.append(r)
            rhs.append(np.array([qpos[d] - q[d]]))
        a, b = np.vstack(rows), np.concatenate(rhs)
        res = float(np.max(np.abs(b)))
        if res < tol:
            return q
        step, *_ = np.linalg.lstsq(a, b, rcond=None)
        q = q + step
    raise ValueError(
        f"initial_eccentricity {dict(targets)} cannot be reached with the loop closures and drive "
        f"angles held (residual {res:.3g} m; clearances {dict(bearings)} m): choose an "
        "eccentricity the mechanism's free motions allow"
    )
