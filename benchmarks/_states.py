"""The initial state of a prepared model as `mujoco.rollout` takes it (benchmark scripts)."""

from __future__ import annotations

import mujoco
import numpy as np


def keyframe_state(model: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray]:
    """(full-physics state, controls) of the model at its initial keyframe (keyframe 0)."""
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, kind))
    mujoco.mj_getState(model, data, state, kind)
    return state, data.ctrl.copy()
