"""Effective mass at each bearing over one cycle of the ideal mechanism.

The mass a journal impact sees along the contact normal n is 1 / (nᵀ A n), with
A = J W Jᵀ: J the relative translation Jacobian of journal and bearing centres (xy) and W
the inverse mass matrix of the compiled model restricted by its other constraints:
W = M⁻¹ − M⁻¹ Gᵀ (G M⁻¹ Gᵀ)⁺ G M⁻¹, where G holds the loop-closure equality rows and,
for velocity-driven cranks, the driven joint (a velocity actuator with kv·h ≫ inertia holds
the crank speed through an impact: its time constant I/kv is ~1e-9 s against ~50 µs
contacts). At each pose n is the direction of the ideal joint's reaction force
(`clearance.loads.joint_reaction_vectors`): the load drives the journal across its
clearance, so impacts arrive along it. Where the joint carries (almost) no load the
direction-median of 1/(nᵀ A n) is taken instead, as in `clearance.mjcf.effective_masses`
(which uses qpos0 only and omits G); ``along_load=False`` takes it at every pose.

Along the load the mass differs from the direction median: on the default slider-crank's
rod-slider joint 0.145 kg (0.075–0.160 over the cycle) against 0.093 kg, because along the
guide the journal carries the slider's 0.14 kg while across it the slider cannot move.
Calibrated at the load-direction mass, the calibrated mode's long-run statistics on that
scenario came much closer to the reference solver's (impacts per revolution +37 % against
+80 %, 95th-percentile force +2.7 % against +16.9 %; benchmarks/speed_error.md).

A slider with play (`clearance.mjcf.guide`) gets the mass its corners' contact rows see along
the guide's normal n, from the corners' mobility A = R W Rᵀ (4 x 4), R_k = nᵀ J_k with J_k the
translation Jacobian of corner k relative to the guide's material point under it. Where the
ideal prismatic pair's load (normal force N, moment M) keeps both corners of the side it
presses on in contact (|M|/L <= |N|/2: the slider lands and slides level on that side) each of
the two rows sees 1 / ((A_aa + A_bb)/2 + A_ab), half the mass of the slider's level landing;
otherwise one corner takes the impact, 1 / A_kk (the median of that side's two); with no load
the median of the four corners alone. The minimum of a slider's range is the lightest corner
alone over the cycle, whatever the load: a tilted landing meets it, and a row's stability is
checked there. The two differ widely: on the published slider-crank of
Flores, Leine and Glocker (2010), whose slider turns easily (J = 2.7e-6 kg m²), one corner alone
sees 1.1 g where a level landing puts tens of grams on each corner.

Poses come from the exact ideal kinematics (`clearance.kinematics.solve_kinematics`) over
one drive period, mapped onto the model's qpos by Gauss–Newton on the body frames.
The fit is made at the median over the cycle; the min–max range is kept as the valid range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.kinematics import solve_kinematics
from clearance.loads import joint_reaction_vectors
from clearance.mjcf.guide import GuideGeometry, guide_site, slider_site
from clearance.mjcf.spec import BuiltModel
from clearance.model import DriveKind, Mechanism
from clearance.translational import CORNERS

__all__ = ["EffectiveMass", "LIGHT_LOAD", "cycle_effective_mass", "normal_effective_mass"]

LIGHT_LOAD = 1e-3
"""Fraction of a joint's peak ideal load below which its load direction is not used."""


@dataclass(frozen=True)
class EffectiveMass:
    """Effective mass of one bearing over the cycle.

    Attributes:
        median: median over the cycle [kg] (the value to calibrate at).
        minimum: smallest over the cycle [kg].
        maximum: largest over the cycle [kg].
        times: (n,) sample times [s].
        values: (n,) effective mass at each time [kg] (along the load, or the
            direction median; see `cycle_effective_mass`).
    """

    median: float
    minimum: float
    maximum: float
    times: np.ndarray
    values: np.ndarray

    @property
    def valid_range(self) -> tuple[float, float]:
        """(minimum, maximum) [kg]."""
        return (self.minimum, self.maximum)


def _body_pose(data: mujoco.MjData, bid: int) -> np.ndarray:
    q = data.xquat[bid]
    return np.array([data.xpos[bid, 0], data.xpos[bid, 1], 2 * math.atan2(q[3], q[0])])


def _set_pose(model: mujoco.MjModel, data: mujoco.MjData, bids: list[int], target: np.ndarray) -> float:
    """Gauss-Newton on qpos so the bodies' (x, y, θ) match ``target`` (n_b, 3); returns residual."""
    jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    res = math.inf
    for _ in range(30):
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        rows, err = [], []
        for bid, t in zip(bids, target):
            p = _body_pose(data, bid)
            d = t - p
            d[2] = (d[2] + math.pi) % (2 * math.pi) - math.pi
            mujoco.mj_jacBody(model, data, jp, jr, bid)
            rows += [jp[0].copy(), jp[1].copy(), jr[2].copy()]
            err += list(d)
        err_a = np.array(err)
        res = float(np.max(np.abs(err_a)))
        if res < 1e-12:
            break
        dq, *_ = np.linalg.lstsq(np.array(rows), err_a, rcond=None)
        mujoco.mj_integratePos(model, data.qpos, dq, 1.0)
    return res


def _constraint_rows(model: mujoco.MjModel, data: mujoco.MjData, mechanism: Mechanism, lock_drives: bool) -> np.ndarray:
    rows = []
    eq = data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    if np.any(eq):
        jac = np.zeros((data.nefc, model.nv))
        if mujoco.mj_isSparse(model):
            mujoco.mju_sparse2dense(jac, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind)
        else:
            jac = data.efc_J[: data.nefc * model.nv].reshape(data.nefc, model.nv)
        rows += list(jac[eq])
    for d in mechanism.drives:
        if d.kind is DriveKind.TORQUE or not lock_drives:
            continue
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, d.joint)
        if jid >= 0:
            r = np.zeros(model.nv)
            r[model.jnt_dofadr[jid]] = 1.0
            rows.append(r)
    return np.array(rows).reshape(-1, model.nv)


def _held_inverse_mass(model: mujoco.MjModel, data: mujoco.MjData, g: np.ndarray) -> np.ndarray:
    """W = M⁻¹ − M⁻¹ Gᵀ (G M⁻¹ Gᵀ)⁺ G M⁻¹ (nv, nv): the inverse mass with the rows g held."""
    nv = model.nv
    minv = np.zeros((nv, nv))
    mujoco.mj_solveM(model, data, minv, np.eye(nv))
    w = minv
    if len(g):
        gm = g @ minv
        w = minv - gm.T @ np.linalg.pinv(gm @ g.T, rcond=1e-10) @ gm
    return w


def _mobility(model: mujoco.MjModel, data: mujoco.MjData, joint: str, g: np.ndarray) -> np.ndarray:
    """A = J W Jᵀ (2, 2) [1/kg]: journal-to-bearing mobility in world xy with rows g held."""
    nv = model.nv
    w = _held_inverse_mass(model, data, g)
    jac = np.zeros((2, 3, nv))
    for k, site in enumerate((f"{joint}__journal", f"{joint}__bearing")):
        sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
        mujoco.mj_jacSite(model, data, jac[k], None, sid)
    jrel = (jac[0] - jac[1])[:2]
    return jrel @ w @ jrel.T


def _corner_mass(
    model: mujoco.MjModel, data: mujoco.MjData, geometry: GuideGeometry, g: np.ndarray, load: np.ndarray | None
) -> tuple[float, float]:
    """(the mass a corner's contact row sees along the guide's normal, the lightest corner alone) [kg].

    Args:
        model, data: the model at the pose.
        geometry: the slider.
        g: the rows held (`_constraint_rows`).
        load: (moment [N m], normal force [N]) of the ideal prismatic pair on the slider, or None
            (light or no load: the median of the four corners alone).

    See the module docstring.
    """
    w = _held_inverse_mass(model, data, g)
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, slider_site(geometry.joint))
    gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, guide_site(geometry.joint))
    normal = data.site_xmat[gid].reshape(3, 3)[:, 1]
    rot = data.site_xmat[sid].reshape(3, 3)
    bodies = [int(model.site_bodyid[sid]), int(model.site_bodyid[gid])]
    play = geometry.play
    rows = np.zeros((len(CORNERS), model.nv))
    for k, (fu, fn) in enumerate(CORNERS):
        point = data.site_xpos[sid] + rot @ np.array([fu * play.slider_length, fn * play.slider_height, 0.0])
        jac = np.zeros((2, 3, model.nv))
        for b, body in enumerate(bodies):
            mujoco.mj_jac(model, data, jac[b], None, point, body)
        rows[k] = normal @ (jac[0] - jac[1])
    a = rows @ w @ rows.T  # (4, 4) the corners' normal mobilities [1/kg]
    alone = 1.0 / np.maximum(np.diag(a), 1e-300)
    lightest = float(alone.min())
    if load is None:
        return float(np.median(alone)), lightest
    moment, force = float(load[0]), float(load[1])
    pair = [2, 3] if force > 0 else [0, 1]  # the guide pushes the slider towards +n from its -n line
    if abs(moment) / play.slider_length <= 0.5 * abs(force):
        # both corners of that side carry the load: each row sees half the level landing's mass
        level = 0.5 * (a[pair[0], pair[0]] + a[pair[1], pair[1]]) + a[pair[0], pair[1]]
        return 1.0 / max(float(level), 1e-300), lightest
    return float(np.median(alone[pair])), lightest


def _bearing_mass(model: mujoco.MjModel, data: mujoco.MjData, joint: str, g: np.ndarray, n_dir: int) -> float:
    a = _mobility(model, data, joint, g)
    ang = np.linspace(0, np.pi, n_dir, endpoint=False)
    n = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    inv = np.einsum("ni,ij,nj->n", n, a, n)
    return float(np.median(1.0 / np.maximum(inv, 1e-300)))


def normal_effective_mass(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    mechanism: Mechanism,
    joint: str,
    normal: np.ndarray,
    *,
    lock_velocity_drives: bool = True,
) -> float:
    """Effective mass a journal impact sees along one normal, at the data's current pose.

    The same 1 / (nᵀ A n) as `cycle_effective_mass` (loop closures and, by default,
    velocity drives held), for one direction instead of the median over directions: the
    mass of a particular impact.

    Args:
        model: the compiled clearance model.
        data: its data at the pose of interest (positions are read; `mujoco.mj_forward`
            is called on it).
        mechanism: the mechanism.
        joint: clearance joint name.
        normal: (2,) contact normal in world xy (normalised here).
        lock_velocity_drives: treat constant-speed and servo drives as locked.

    Returns:
        The effective mass [kg].

    Raises:
        ValueError: a zero or non-finite normal.
    """
    n = np.asarray(normal, dtype=float).reshape(2)
    size = float(np.hypot(*n))
    if not (np.isfinite(size) and size > 0):
        raise ValueError(f"normal must be a non-zero finite (x, y) vector (got {tuple(n)})")
    n = n / size
    mujoco.mj_forward(model, data)
    g = _constraint_rows(model, data, mechanism, lock_velocity_drives)
    return float(1.0 / max(n @ _mobility(model, data, joint, g) @ n, 1e-300))


def cycle_effective_mass(
    model: mujoco.MjModel,
    built: BuiltModel,
    mechanism: Mechanism,
    *,
    n_poses: int = 36,
    n_dir: int = 36,
    lock_velocity_drives: bool = True,
    along_load: bool = True,
) -> dict[str, EffectiveMass]:
    """Effective mass at every clearance joint and slider with play over one drive period of the
    ideal cycle.

    Args:
        model: the compiled clearance model (``prepare(...).model``).
        built: its `BuiltModel` (body tree, rings, link order).
        mechanism: the mechanism.
        n_poses: poses over one period (uniform in time).
        n_dir: normal directions for the direction median.
        lock_velocity_drives: treat constant-speed and servo drives as locked during an
            impact (see the module docstring); torque drives are never locked.
        along_load: the mass along the ideal joint's reaction force at each pose (the
            direction median where the load is below `LIGHT_LOAD` of the cycle's peak);
            False: the direction median at every pose.

    Returns:
        joint name -> `EffectiveMass` (a slider's: its corners' rows along the guide's normal, its
        minimum the lightest corner alone over the cycle).

    Raises:
        RuntimeError: a cycle pose cannot be reproduced in the model's coordinates.
    """
    period = mechanism.drive_period or 1.0
    times = np.linspace(0.0, period, n_poses, endpoint=False)
    kin = solve_kinematics(mechanism, times)
    names = [lk.name for lk in mechanism.moving_links]
    bids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in names]
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    out = {j: np.zeros(n_poses) for j in (*built.rings, *built.guides)}
    lightest = {j: np.zeros(n_poses) for j in built.guides}
    loads = joint_reaction_vectors(mechanism, times, kinematics=kin)[0] if along_load else {}
    sizes = {j: np.hypot(v[:, 0], v[:, 1]) for j, v in loads.items()}
    light = {j: LIGHT_LOAD * float(np.max(v)) for j, v in sizes.items()}
    for i, q in enumerate(kin.q):
        res = _set_pose(model, data, bids, q.reshape(-1, 3))
        if res > 1e-8:
            raise RuntimeError(f"cycle pose at t = {times[i]:g} s not reproduced (residual {res:.3g})")
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        g = _constraint_rows(model, data, mechanism, lock_velocity_drives)
        for j in built.rings:
            if j in loads and sizes[j][i] > light[j]:
                n = loads[j][i] / sizes[j][i]
                out[j][i] = 1.0 / max(float(n @ _mobility(model, data, j, g) @ n), 1e-300)
            else:
                out[j][i] = _bearing_mass(model, data, j, g, n_dir)
        for j, geometry in built.guides.items():
            load = loads[j][i] if j in loads and sizes[j][i] > light[j] else None
            out[j][i], lightest[j][i] = _corner_mass(model, data, geometry, g, load)
    # a slider's rows range down to its lightest corner alone, whatever the load (the stability check's mass)
    low = {j: float(min(v.min(), lightest[j].min() if j in lightest else np.inf)) for j, v in out.items()}
    return {j: EffectiveMass(float(np.median(v)), low[j], float(v.max()), times, v) for j, v in out.items()}
