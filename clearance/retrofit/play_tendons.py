"""The play tendons of a compiled model: which they are, and how light each gets.

A retrofit's robot-step play is held in limited tendons named ``clr_<hinge>__backlash`` (a
fixed tendon q_load - q_motor: a backlash band) and ``clr_<hinge>__radial`` (a spatial tendon
from the bearing's centre to the journal's: a radial stop); `play_tendons` finds them.

How light: a tendon's largest inverse weight A = J M⁻¹ Jᵀ over sampled poses. A tendon-limit
stop's spring and damper act on the tendon's effective inertia 1/A, which moves with the pose;
the stop is least stable where A is largest (`clearance.retrofit.randomised_play` checks a range
of stops there). Poses: qpos0 and `POSE_SAMPLES` draws of `clearance.retrofit.poses.random_pose`,
with each backlash band's motor at its load's angle (the band closed) and each radial stop's
journal at half its clearance in a random direction (at |e| = 0 a spatial tendon has no
direction: MuJoCo takes the world's x axis).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.retrofit.play import PREFIX
from clearance.retrofit.poses import random_pose

__all__ = ["POSE_SAMPLES", "PlayKind", "PlayTendon", "lightest_invweights", "play_tendon_name", "play_tendons"]

POSE_SAMPLES = 64
"""Poses drawn besides qpos0 (seeded: the same model gives the same answer)."""

_JOINT_WRAP = int(mujoco.mjtWrap.mjWRAP_JOINT)


class PlayKind(enum.Enum):
    """The play a tendon holds."""

    BACKLASH = "backlash"
    """A band q_load - q_motor within [-b, b]; size b [rad], K [N m/rad], B [N m s/rad]."""
    RADIAL = "radial"
    """A journal within a circle of radius c about its bearing's centre; size c [m], K [N/m], B [N s/m]."""

    @property
    def units(self) -> tuple[str, str, str]:
        """Units of (size, stiffness, damping)."""
        if self is PlayKind.BACKLASH:
            return ("rad", "N m/rad", "N m s/rad")
        return ("m", "N/m", "N s/m")


@dataclass(frozen=True)
class PlayTendon:
    """One play tendon of a compiled model.

    Attributes:
        hinge: the hinge whose play it holds. kind: backlash band or radial stop.
        tendon: its id. invweight: Â, its ``tendon_invweight0`` [1/(kg m^2) or 1/kg].
    """

    hinge: str
    kind: PlayKind
    tendon: int
    invweight: float


def play_tendon_name(hinge: str, kind: PlayKind) -> str:
    """The name of ``hinge``'s play tendon of ``kind``."""
    return f"{PREFIX}{hinge}__{kind.value}"


def play_tendons(model: mujoco.MjModel) -> tuple[PlayTendon, ...]:
    """The limited play tendons of ``model``, in tendon order."""
    out = []
    for t in range(model.ntendon):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_TENDON, t) or ""
        for kind in PlayKind:
            tail = f"__{kind.value}"
            if name.startswith(PREFIX) and name.endswith(tail) and model.tendon_limited[t]:
                out.append(PlayTendon(name[len(PREFIX) : -len(tail)], kind, t, float(model.tendon_invweight0[t])))
    return tuple(out)


def _wrapped_joints(model: mujoco.MjModel, tendon: int) -> list[tuple[int, float]]:
    """(joint id, coefficient) of a fixed tendon's wraps."""
    adr, num = int(model.tendon_adr[tendon]), int(model.tendon_num[tendon])
    return [
        (int(model.wrap_objid[adr + i]), float(model.wrap_prm[adr + i]))
        for i in range(num)
        if int(model.wrap_type[adr + i]) == _JOINT_WRAP
    ]


def _play_slides(model: mujoco.MjModel, hinge: str) -> tuple[int, int] | None:
    """qpos addresses of the radial play's x and y slides of ``hinge`` (None where absent)."""
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{PREFIX}{hinge}__{a}") for a in "xy"]
    if min(ids) < 0:
        return None
    return int(model.jnt_qposadr[ids[0]]), int(model.jnt_qposadr[ids[1]])


def lightest_invweights(model: mujoco.MjModel, tendons: Sequence[PlayTendon]) -> np.ndarray:
    """(n,) the largest inverse weight of each play tendon over the poses (module docstring) [1/(kg m^2) or 1/kg]."""
    rng = np.random.default_rng(0)
    data = mujoco.MjData(model)
    ids = np.array([t.tendon for t in tendons], dtype=int)
    closes = [
        _wrapped_joints(model, t.tendon) if t.kind is PlayKind.BACKLASH else [] for t in tendons
    ]  # load (+1) then motor (-1)
    slides = [_play_slides(model, t.hinge) if t.kind is PlayKind.RADIAL else None for t in tendons]
    worst = np.zeros(len(tendons))
    x = np.zeros((len(tendons), model.nv))
    dense = np.zeros((model.ntendon, model.nv))
    for i in range(POSE_SAMPLES + 1):
        if i:
            random_pose(model, rng, data.qpos)
        else:
            data.qpos[:] = model.qpos0
        for k, t in enumerate(tendons):
            wraps = sorted(closes[k], key=lambda w: -w[1])
            if len(wraps) == 2:
                load, motor = (int(model.jnt_qposadr[j]) for j, _ in wraps)
                data.qpos[motor] = data.qpos[load]
            pair = slides[k]
            if pair is not None:
                theta = rng.uniform(-math.pi, math.pi)
                half = 0.5 * float(model.tendon_range[t.tendon, 1])
                data.qpos[list(pair)] = half * math.cos(theta), half * math.sin(theta)
        mujoco.mj_forward(model, data)
        mujoco.mju_sparse2dense(dense, data.ten_J, model.ten_J_rownnz, model.ten_J_rowadr, model.ten_J_colind)
        jac = dense[ids]
        mujoco.mj_solveM(model, data, x, jac)
        worst = np.maximum(worst, np.einsum("ij,ij->i", jac, x))
    return worst
