"""Coordinates of the unmodified model inside the retrofitted one, and keyframes extended.

The retrofitted model has the unmodified model's joints in the same order, with two slides
inserted before each retrofitted hinge. `CoordinateMap` holds where each of the unmodified
model's qpos and qvel entries went, and where each hinge's slides are, so a state of one
model becomes a state of the other.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

__all__ = [
    "CoordinateMap",
    "coordinate_map",
    "check_map",
    "extend_keyframes",
    "extend_paired_keyframes",
    "joint_index_map",
]

_NQ = {
    mujoco.mjtJoint.mjJNT_FREE: 7,
    mujoco.mjtJoint.mjJNT_BALL: 4,
    mujoco.mjtJoint.mjJNT_SLIDE: 1,
    mujoco.mjtJoint.mjJNT_HINGE: 1,
}
_NV = {
    mujoco.mjtJoint.mjJNT_FREE: 6,
    mujoco.mjtJoint.mjJNT_BALL: 3,
    mujoco.mjtJoint.mjJNT_SLIDE: 1,
    mujoco.mjtJoint.mjJNT_HINGE: 1,
}


@dataclass(frozen=True)
class CoordinateMap:
    """Where the unmodified model's coordinates sit in the retrofitted model.

    Attributes:
        qpos: (nq_twin,) index in the retrofitted qpos of each unmodified qpos entry.
        qvel: (nv_twin,) likewise for qvel (and every per-dof array).
        slide_qpos: hinge name -> (2,) qpos indices of its x and y slides.
        slide_dof: hinge name -> (2,) dof indices of its x and y slides.
        nq, nv: sizes of the retrofitted model.
    """

    qpos: np.ndarray
    qvel: np.ndarray
    slide_qpos: dict[str, np.ndarray]
    slide_dof: dict[str, np.ndarray]
    nq: int
    nv: int

    def model_qpos(self, twin_qpos: np.ndarray, offsets: Mapping[str, tuple[float, float]] | None = None) -> np.ndarray:
        """A retrofitted qpos from an unmodified one, each journal at ``offsets`` (default centred)."""
        q = np.zeros(self.nq)
        q[self.qpos] = twin_qpos
        for name, e in (offsets or {}).items():
            q[self.slide_qpos[name]] = e
        return q

    def model_qvel(self, twin_qvel: np.ndarray) -> np.ndarray:
        """A retrofitted qvel from an unmodified one (journals at rest in their bearings)."""
        v = np.zeros(self.nv)
        v[self.qvel] = twin_qvel
        return v


def coordinate_map(
    twin: mujoco.MjModel, hinges: Mapping[str, int], pins: Mapping[str, int] | None = None
) -> CoordinateMap:
    """Where the unmodified coordinates go once each hinge in ``hinges`` gets two slides before it
    and each loop closure in ``pins`` a pin with two slides.

    Compiled joints follow the body tree and each body's joint order, so every joint moves
    by two places per pair of slides inserted at or before it (a hinge's own slides come
    first; a pin's slides come before the joint given, after every joint of its body's subtree).

    Args:
        twin: the unmodified model.
        hinges: hinge name -> its joint id in ``twin``.
        pins: loop closure name -> the joint id in ``twin`` its pin's slides come before
            (``njnt``: at the end; `clearance.retrofit.loop.pin_insertion_joint`), in the order
            the pins were added to the spec (pins on one body follow one another in that order).
    """
    # at one joint a pin's slides come before a hinge's; pins at one joint (the same body2) in the
    # order they were added (the mappings' order), not by name
    inserts = [
        (j, kind, name)
        for j, kind, _, name in sorted(
            [(j, 1, k, n) for k, (n, j) in enumerate(hinges.items())]
            + [(j, 0, k, n) for k, (n, j) in enumerate((pins or {}).items())]
        )
    ]
    qpos = np.zeros(twin.nq, dtype=int)
    qvel = np.zeros(twin.nv, dtype=int)
    for j in range(twin.njnt):
        kind = mujoco.mjtJoint(int(twin.jnt_type[j]))
        shift = 2 * sum(1 for at, _, _ in inserts if at <= j)
        a = int(twin.jnt_qposadr[j])
        qpos[a : a + _NQ[kind]] = np.arange(a, a + _NQ[kind]) + shift
        a = int(twin.jnt_dofadr[j])
        qvel[a : a + _NV[kind]] = np.arange(a, a + _NV[kind]) + shift
    slide_qpos, slide_dof = {}, {}
    for k, (at, _, name) in enumerate(inserts):
        base_q = int(twin.jnt_qposadr[at]) if at < twin.njnt else int(twin.nq)
        base_v = int(twin.jnt_dofadr[at]) if at < twin.njnt else int(twin.nv)
        slide_qpos[name] = base_q + 2 * k + np.array([0, 1])
        slide_dof[name] = base_v + 2 * k + np.array([0, 1])
    return CoordinateMap(
        qpos, qvel, slide_qpos, slide_dof, int(twin.nq) + 2 * len(inserts), int(twin.nv) + 2 * len(inserts)
    )


def joint_index_map(
    twin: mujoco.MjModel, model: mujoco.MjModel, joints: Sequence[int]
) -> tuple[np.ndarray, np.ndarray]:
    """Where the unmodified coordinates sit in an edited model, read from its compiled joints.

    Args:
        twin: the unmodified model.
        model: the edited model.
        joints: for each joint of ``twin`` in order, its id in ``model``.

    Returns:
        (qpos, qvel): index in ``model``'s qpos / qvel of each of ``twin``'s entries.
    """
    qpos = np.zeros(twin.nq, dtype=int)
    qvel = np.zeros(twin.nv, dtype=int)
    for jt, jm in enumerate(joints):
        kind = mujoco.mjtJoint(int(twin.jnt_type[jt]))
        a, b = int(twin.jnt_qposadr[jt]), int(model.jnt_qposadr[jm])
        qpos[a : a + _NQ[kind]] = np.arange(b, b + _NQ[kind])
        a, b = int(twin.jnt_dofadr[jt]), int(model.jnt_dofadr[jm])
        qvel[a : a + _NV[kind]] = np.arange(b, b + _NV[kind])
    return qpos, qvel


def check_map(cmap: CoordinateMap, model: mujoco.MjModel, slides: Mapping[str, tuple[str, str]]) -> None:
    """Check the map against the compiled retrofitted model: sizes and each hinge's slides.

    Raises:
        RuntimeError: the compiled model's coordinates are not where the map puts them.
    """
    if (model.nq, model.nv) != (cmap.nq, cmap.nv):
        raise RuntimeError(f"retrofitted model has nq, nv = {model.nq}, {model.nv}; expected {cmap.nq}, {cmap.nv}")
    for hinge, names in slides.items():
        for k, name in enumerate(names):
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
            if jid < 0 or model.jnt_qposadr[jid] != cmap.slide_qpos[hinge][k]:
                raise RuntimeError(f"slide '{name}' of hinge '{hinge}' is not where the coordinate map puts it")


def extend_keyframes(
    spec: mujoco.MjSpec,
    twin: mujoco.MjModel,
    cmap: CoordinateMap,
    offsets: Mapping[str, tuple[float, float]],
) -> int:
    """Rewrite every keyframe of ``spec`` for the retrofitted coordinates; returns their count.

    Each keyframe's qpos and qvel become full vectors of the retrofitted model: the
    unmodified keyframe's values (as the unmodified model compiled them, so an omitted qpos
    is its qpos0) in their new places, each journal at its offset in the bearing frame and
    at rest relative to it. Time, act, ctrl and mocap poses are untouched.
    """
    keys = list(spec.keys)
    for k, key in enumerate(keys):
        key.qpos = list(cmap.model_qpos(twin.key_qpos[k], offsets))
        key.qvel = list(cmap.model_qvel(twin.key_qvel[k]))
    return len(keys)


def extend_paired_keyframes(
    spec: mujoco.MjSpec,
    twin: mujoco.MjModel,
    model: mujoco.MjModel,
    qmap: np.ndarray,
    vmap: np.ndarray,
    pairs: Sequence[tuple[int, int]],
) -> int:
    """Rewrite each keyframe of ``spec`` for ``model``, where each pair's second hinge follows its first.

    Each keyframe's qpos and qvel become full vectors of ``model``: the twin's values where its
    joints now sit (``qmap``, ``vmap``: `joint_index_map`), every other coordinate at qpos0 and
    at rest, then each second hinge of ``pairs`` (joint ids in ``model``: a backlash motor after
    its load) at its first's angle and speed (the band centred). Returns the count.
    """
    for k, key in enumerate(spec.keys):
        qpos = model.qpos0.copy()
        qvel = np.zeros(model.nv)
        qpos[qmap] = twin.key_qpos[k]
        qvel[vmap] = twin.key_qvel[k]
        for first, second in pairs:
            qpos[model.jnt_qposadr[second]] = qpos[model.jnt_qposadr[first]]
            qvel[model.jnt_dofadr[second]] = qvel[model.jnt_dofadr[first]]
        key.qpos = qpos
        key.qvel = qvel
    return len(spec.keys)
