"""Every constraint of a retrofitted model keeps the softness it had in the unmodified model.

MuJoCo regularises each constraint row by R = (1 - d)/d Â, Â the row's inverse weight at
qpos0: ``dof_invweight0`` for a joint's limit and friction loss, ``tendon_invweight0`` for a
tendon's, the bodies' translational ``body_invweight0`` for a connect, a weld or a contact. A
retrofit's two slides before a hinge let the hinge's whole subtree translate in the mass matrix
the compiler inverts at qpos0, so Â of every row near it grows (on robosuite's Panda a play at
one hinge raised the next hinge's by 50 %) although the bearing holds those slides within
micrometres: the model's own joint limits and friction losses softened, and a Panda that starts
against a limit moved its hand by a millimetre in 0.1 s with 1 µm of play.

The edit therefore writes, for every row whose Â moved, the solimp and solref that give it
the twin's R, K and B (`kept_softness`): the impedance is raised (or lowered) until
(1 - d)/d Â is the twin's, and the time constant (or the direct-mode stiffness and damping)
rescaled so that K and B stay. Where the impedance would have to pass MuJoCo's bounds it stops
there and ``softer`` says by how much the row's R differs.

Here: joint limits and friction losses, tendon limits and friction losses, equality constraints
(a weld keeps its translational rows' softness; its rotational rows follow the same rescale).
Contacts mix two geoms' values: `clearance.retrofit.contact_softness` gives them explicit pairs.
"""

from __future__ import annotations

from collections.abc import Container, Mapping, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

__all__ = [
    "MAX_IMPEDANCE",
    "MIN_IMPEDANCE",
    "KeptSoftness",
    "Softness",
    "keep_constraint_softness",
    "kept_softness",
    "moved",
    "refsafe",
    "row_softness",
    "softness_note",
    "stiffness_damping",
]

MAX_IMPEDANCE = 0.9999
"""MuJoCo's largest impedance d (mjMAXIMP)."""

MIN_IMPEDANCE = 1e-4
"""MuJoCo's smallest impedance d (mjMINIMP)."""

MOVED = 1e-9
"""A row's Â has moved when it differs from the twin's by more than this fraction [-] (rounding of
the compiler's inversion stays below 1e-12 on the corpus)."""


@dataclass(frozen=True)
class Softness:
    """Solver parameters that keep a constraint's softness at a new inverse weight.

    Attributes:
        solimp: (5,) to write. solref: (2,) to write.
        inverse_weight: Â of the row in the twin and in the edited model (compiled before the
            rescale) [1/kg or 1/(kg m^2)].
        softer: R of the edited row over the twin's [-] (1: kept; otherwise the impedance stopped
            at one of MuJoCo's bounds).
    """

    solimp: tuple[float, ...]
    solref: tuple[float, float]
    inverse_weight: tuple[float, float]
    softer: float


def _impedance_for(d: float, scale: float) -> float:
    """The impedance whose (1 - d)/d is ``scale`` times ``d``'s, within MuJoCo's range."""
    rho = (1.0 - d) / d * scale
    return min(max(1.0 / (1.0 + rho), MIN_IMPEDANCE), MAX_IMPEDANCE)


def kept_softness(
    a_old: float,
    a_new: float,
    solimp: Sequence[float],
    solref: Sequence[float],
    *,
    step: float,
    refsafe: bool,
) -> Softness:
    """The solimp and solref that give a row of inverse weight ``a_new`` the force it had at ``a_old``.

    MuJoCo's row force is f = (aref - a0)/(A + R), aref = -B v - K d(r) r: with the row's true
    inverse inertia A unchanged (the bearing holds the added slides), the force stays when R, B
    and K d stay. The impedance is moved until R = (1 - d)/d Â is the twin's at d0 and at d_width;
    B = 2/(dmax tc) is kept by the time constant, and K d at d0 (the impedance at small violation,
    where a limit, a contact's onset or an equality sits) by the damping ratio (K = 1/(dmax^2 tc^2
    zeta^2); direct mode: K = -S/dmax^2, B = -D/dmax). Deep in the transition zone K d moves by
    (n0/d0)/(nw/dw) (within 4 % for MuJoCo's default 0.9/0.95 and a doubled Â). A time constant that
    ``refsafe`` would raise to 2 ``step`` is taken raised, and one that would fall below it is
    written in direct mode, which MuJoCo leaves alone.

    Args:
        a_old, a_new: the row's Â in the twin and in the edited model [its unit].
        solimp: (5,) the twin's. solref: (2,) the twin's.
        step: the time step both models run at [s].
        refsafe: whether MuJoCo raises time constants below 2 ``step`` (its refsafe flag).
    """
    scale = a_old / a_new
    old = [float(v) for v in solimp]
    d0, dw = (min(max(d, MIN_IMPEDANCE), MAX_IMPEDANCE) for d in old[:2])
    n0, nw = _impedance_for(d0, scale), _impedance_for(dw, scale)
    softer = max(((1 - n0) / n0) / ((1 - d0) / d0 * scale), ((1 - nw) / nw) / ((1 - dw) / dw * scale))
    k, b = stiffness_damping(dw, solref, step, refsafe)
    new_ref: tuple[float, float]
    tc = float(solref[0])
    if tc > 0 and (tc := max(tc, 2 * step) if refsafe else tc) * dw / nw >= (2 * step if refsafe else 0):
        new_ref = (tc * dw / nw, float(solref[1]) * (n0 / d0) ** 0.5)
    else:  # direct: S = -K' nw^2 with K' n0 = K d0, D = -B nw
        new_ref = (-k * d0 / n0 * nw**2, -b * nw)
    return Softness((n0, nw, *old[2:]), new_ref, (a_old, a_new), softer)


def stiffness_damping(dw: float, solref: Sequence[float], step: float, safe: bool) -> tuple[float, float]:
    """MuJoCo's mass-normalised K and B of a row whose solimp's dmax is ``dw`` (module docstring).

    Args:
        dw: the impedance at the end of solimp's width, dmax [-].
        solref: (2,): (time constant [s], damping ratio [-]), or direct (-S, -D).
        step: the time step [s]. safe: whether time constants below 2 ``step`` are raised (refsafe).

    Returns:
        (K [1/s^2], B [1/s]) of the row's reference acceleration aref = -B v - K d r.
    """
    tc, zeta = float(solref[0]), float(solref[1])
    if tc > 0:
        tc = max(tc, 2 * step) if safe else tc
        return 1 / (dw * tc * zeta) ** 2, 2 / (dw * tc)
    return -tc / dw**2, -zeta / dw


def row_softness(a: float, solimp: Sequence[float], solref: Sequence[float], *, step: float, safe: bool) -> np.ndarray:
    """(R at d0, R at d_width, K d0, B) of a row of inverse weight ``a``: what `kept_softness` keeps.

    Args:
        a: the row's Â. solimp: (5,). solref: (2,).
        step: the time step [s]. safe: whether time constants below 2 ``step`` are raised (refsafe).
    """
    d0, dw = (min(max(float(d), MIN_IMPEDANCE), MAX_IMPEDANCE) for d in solimp[:2])
    k, b = stiffness_damping(dw, solref, step, safe)
    return np.array([(1 - d0) / d0 * a, (1 - dw) / dw * a, k * d0, b])


def refsafe(model: mujoco.MjModel) -> bool:
    """Whether MuJoCo raises ``model``'s time constants below two steps (refsafe not disabled)."""
    return not int(model.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_REFSAFE)


@dataclass(frozen=True)
class KeptSoftness:
    """A row the edit rescaled to keep the twin's softness.

    Attributes:
        element: 'joint' or 'tendon' and its name (``#id`` if unnamed), e.g. "joint 'elbow'".
        constraint: 'limit' or 'friction loss'.
        softness: what was written.
    """

    element: str
    constraint: str
    softness: Softness

    @property
    def label(self) -> str:
        """How a report names the row, e.g. "joint 'elbow' limit"."""
        return f"{self.element} {self.constraint}"


def _label(model: mujoco.MjModel, obj: mujoco.mjtObj, i: int, kind: str) -> str:
    return f"{kind} '{mujoco.mj_id2name(model, obj, i) or f'#{i}'}'"


def moved(a_old: float, a_new: float) -> bool:
    """Whether a row's Â moved beyond rounding (`MOVED`)."""
    return a_old > 0 and abs(a_new / a_old - 1.0) > MOVED


def keep_constraint_softness(
    spec: mujoco.MjSpec,
    twin: mujoco.MjModel,
    model: mujoco.MjModel,
    joints: Sequence[tuple[int, int]],
    step: float,
    *,
    skip: Container[str] = (),
) -> list[KeptSoftness]:
    """Rescale the limits, friction losses and equality constraints of the twin's joints, tendons and
    equalities whose Â moved (module docstring).

    Args:
        spec: the edited spec, compiled into ``model`` (its elements carry ``model``'s ids).
        twin: the unmodified model.
        model: ``spec`` compiled after the edit's joints were added, before this rescale.
        joints: (twin joint id, model joint id) of every joint of the twin.
        step: the time step both models run at [s].
        skip: equalities the edit sets itself (a loop closure's moved connect).

    Returns:
        Every row rescaled, in joint, tendon, then equality order.
    """
    safe = refsafe(twin)
    by_id = {int(j.id): j for j in spec.joints}
    kept: list[KeptSoftness] = []
    for tj, mj in joints:
        dofs = range(int(twin.jnt_dofadr[tj]), int(twin.jnt_dofadr[tj]) + _dof_count(twin, tj))
        mdofs = range(int(model.jnt_dofadr[mj]), int(model.jnt_dofadr[mj]) + len(dofs))
        a_old = float(np.mean(twin.dof_invweight0[list(dofs)]))
        a_new = float(np.mean(model.dof_invweight0[list(mdofs)]))
        if not moved(a_old, a_new):
            continue
        joint, label = by_id[mj], _label(twin, mujoco.mjtObj.mjOBJ_JOINT, tj, "joint")
        if twin.jnt_limited[tj]:
            s = kept_softness(a_old, a_new, twin.jnt_solimp[tj], twin.jnt_solref[tj], step=step, refsafe=safe)
            joint.solimp_limit, joint.solref_limit = list(s.solimp), list(s.solref)
            kept.append(KeptSoftness(label, "limit", s))
        if float(np.max(twin.dof_frictionloss[list(dofs)])) > 0:
            first = dofs[0]
            s = kept_softness(a_old, a_new, twin.dof_solimp[first], twin.dof_solref[first], step=step, refsafe=safe)
            joint.solimp_friction, joint.solref_friction = list(s.solimp), list(s.solref)
            kept.append(KeptSoftness(label, "friction loss", s))
    tendons = list(spec.tendons)
    for t in range(twin.ntendon):
        a_old, a_new = float(twin.tendon_invweight0[t]), float(model.tendon_invweight0[t])
        if not moved(a_old, a_new):
            continue
        tendon, label = tendons[t], _label(twin, mujoco.mjtObj.mjOBJ_TENDON, t, "tendon")
        if twin.tendon_limited[t]:
            s = kept_softness(
                a_old, a_new, twin.tendon_solimp_lim[t], twin.tendon_solref_lim[t], step=step, refsafe=safe
            )
            tendon.solimp_limit, tendon.solref_limit = list(s.solimp), list(s.solref)
            kept.append(KeptSoftness(label, "limit", s))
        if twin.tendon_frictionloss[t] > 0:
            s = kept_softness(
                a_old, a_new, twin.tendon_solimp_fri[t], twin.tendon_solref_fri[t], step=step, refsafe=safe
            )
            tendon.solimp_friction, tendon.solref_friction = list(s.solimp), list(s.solref)
            kept.append(KeptSoftness(label, "friction loss", s))
    kept += _keep_equalities(spec, twin, model, joints, step, skip)
    return kept


def _equality_weight(model: mujoco.MjModel, eq: int, joint: Mapping[int, int] | None) -> float:
    """Â of an equality's rows (the translational one for a weld): MuJoCo's diagApprox of it."""
    kind, a, b = int(model.eq_type[eq]), int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq])
    if kind in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD):
        if model.eq_objtype[eq] == mujoco.mjtObj.mjOBJ_SITE:
            a, b = int(model.site_bodyid[a]), int(model.site_bodyid[b])
        return float(model.body_invweight0[a, 0] + model.body_invweight0[b, 0])
    if kind == mujoco.mjtEq.mjEQ_JOINT:
        ids = [j if joint is None else joint[j] for j in (a, b) if j >= 0]
        return float(sum(model.dof_invweight0[model.jnt_dofadr[j]] for j in ids))
    if kind == mujoco.mjtEq.mjEQ_TENDON:
        return float(sum(model.tendon_invweight0[t] for t in (a, b) if t >= 0))
    return 0.0  # flex and other kinds: not rescaled


def _keep_equalities(
    spec: mujoco.MjSpec,
    twin: mujoco.MjModel,
    model: mujoco.MjModel,
    joints: Sequence[tuple[int, int]],
    step: float,
    skip: Container[str],
) -> list[KeptSoftness]:
    """Rescale the twin's equality constraints whose Â moved (those named in ``skip`` are the edit's own)."""
    jmap = dict(joints)
    equalities, kept = list(spec.equalities), []
    for e in range(twin.neq):
        label = mujoco.mj_id2name(twin, mujoco.mjtObj.mjOBJ_EQUALITY, e) or f"#{e}"
        a_old, a_new = _equality_weight(twin, e, None), _equality_weight(model, e, jmap)
        if label in skip or not moved(a_old, a_new):
            continue
        soft = kept_softness(a_old, a_new, twin.eq_solimp[e], twin.eq_solref[e], step=step, refsafe=refsafe(twin))
        equalities[e].solimp, equalities[e].solref = list(soft.solimp), list(soft.solref)
        kept.append(KeptSoftness(f"equality '{label}'", "constraint", soft))
    return kept


def softness_note(rows: Sequence[tuple[str, Softness]]) -> str:
    """One line for a report: the rows rescaled (label, what was written) and how far their Â moved."""
    ratios = [soft.inverse_weight[1] / soft.inverse_weight[0] for _, soft in rows]
    off = [(label, soft) for label, soft in rows if abs(soft.softer - 1) > 1e-9]
    shown = ", ".join(label for label, _ in rows[:12]) + (f" and {len(rows) - 12} more" if len(rows) > 12 else "")
    return (
        f"solimp and solref of {len(rows)} constraint(s) rescaled to keep the twin's softness (R, K d0, B) at their "
        f"new inverse weights (x{min(ratios):.3g} to x{max(ratios):.3g}: the added coordinates' share of M^-1 at "
        f"qpos0): {shown}"
        + (
            "; at MuJoCo's impedance bound: " + ", ".join(f"{lab} R x{soft.softer:.3g}" for lab, soft in off)
            if off
            else ""
        )
    )


def _dof_count(model: mujoco.MjModel, j: int) -> int:
    return {0: 6, 1: 3, 2: 1, 3: 1}[int(model.jnt_type[j])]
