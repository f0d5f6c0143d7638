"""Poses a retrofit samples a model at: every hinge and slide uniform in its range.

An unlimited hinge is drawn over a turn; free, ball and unlimited slide joints stay at qpos0.
The same rule serves the backlash stop's inertia range (`clearance.retrofit.backlash_stop`) and
the randomised play's stability check (`clearance.retrofit.play_weights`).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

__all__ = ["random_pose"]

_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)
_SLIDE = int(mujoco.mjtJoint.mjJNT_SLIDE)


def random_pose(model: mujoco.MjModel, rng: np.random.Generator, qpos: np.ndarray) -> None:
    """Write a pose drawn from ``rng`` into ``qpos`` (nq,), starting from qpos0 (module docstring)."""
    qpos[:] = model.qpos0
    for j in range(model.njnt):
        kind = int(model.jnt_type[j])
        if kind not in (_HINGE, _SLIDE):
            continue
        if model.jnt_limited[j]:
            qpos[model.jnt_qposadr[j]] = rng.uniform(*model.jnt_range[j])
        elif kind == _HINGE:
            qpos[model.jnt_qposadr[j]] = rng.uniform(-math.pi, math.pi)
