"""The bearing frame of a hinge, in the child body (journal) and in the parent body (bearing).

A hinge's position p and unit axis a are given in its body's frame. The play is the motion
of the journal centre in the plane through p normal to a. The bearing frame has its origin
at p, its z along a, and its x along the body's x axis projected onto that plane (the body's
y axis when x is along a), y = z × x; so a hinge about z, as in planar models, gets the
body's own x and y. At the unmodified model's qpos0 (the hinge at its reference angle) the
frame is expressed in the parent body as well, which is where the ring is fixed.

MuJoCo writes 6 significant digits: a ring placed by its body-frame coordinates would be bumpy
wherever the bearing sits far from its body's origin (1 m away, segment centres move by up to
0.5 µm, 0.5 % of a 0.1 mm clearance). The ring is therefore written in a bearing-centred
`<frame>` (`BearingFrame.chain`): the child body's own pose, then the hinge's position and the
bearing axes, the same numbers the child body and the journal are written with, so the ring's
centre falls on the journal's at qpos0 and its segments sit at centimetre offsets that 6 digits
hold to 5e-8 m (4.4e-4 of a 0.1 mm clearance, measured).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.mjcf.bearing_geoms import Placement

__all__ = ["BearingFrame", "bearing_frame", "in_plane_axes", "placement"]


def in_plane_axes(axis: np.ndarray) -> np.ndarray:
    """(3, 3) rotation whose columns are the bearing frame's x, y, z for a hinge axis (body frame)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    for guess in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        x = guess - (guess @ a) * a
        if np.linalg.norm(x) > 1e-6:
            break
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(a, x), a])


def _quat(rotation: np.ndarray) -> tuple[float, float, float, float]:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(rotation, dtype=float).reshape(9))
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def placement(origin: np.ndarray, rotation: np.ndarray) -> Placement:
    """A placement at ``origin`` (3,) whose axes are the columns of ``rotation`` (3, 3)."""
    return Placement((float(origin[0]), float(origin[1]), float(origin[2])), _quat(rotation))


@dataclass(frozen=True)
class BearingFrame:
    """The bearing frame of one hinge.

    Attributes:
        journal: origin and rotation of the frame in the child body (the journal's placement).
        bearing: origin and rotation of the frame in the parent body at qpos0 (the ring's).
        axes: (3, 3) columns x, y, z of the frame in the child body frame.
        axes_in_parent: (3, 3) the same columns in the parent body frame at qpos0.
        chain: the placements that lead from the parent body's frame to the bearing frame, each
            in the previous one (nested `<frame>` elements); their composition is ``bearing``.
    """

    journal: Placement
    bearing: Placement
    axes: np.ndarray
    axes_in_parent: np.ndarray
    chain: tuple[Placement, ...] = ()


def bearing_frame(model: mujoco.MjModel, data: mujoco.MjData, joint_id: int) -> BearingFrame:
    """The bearing frame of hinge ``joint_id``.

    Args:
        model: the unmodified compiled model.
        data: its data with ``mujoco.mj_kinematics`` done at qpos0.
        joint_id: the hinge.
    """
    child = int(model.jnt_bodyid[joint_id])
    parent = int(model.body_parentid[child])
    p = np.array(model.jnt_pos[joint_id], dtype=float)
    axes = in_plane_axes(model.jnt_axis[joint_id])
    rc, rp = data.xmat[child].reshape(3, 3), data.xmat[parent].reshape(3, 3)
    world_origin = data.xpos[child] + rc @ p
    origin_in_parent = rp.T @ (world_origin - data.xpos[parent])
    axes_in_parent = rp.T @ rc @ axes
    journal = placement(p, axes)
    child_pose = Placement(
        tuple(float(v) for v in model.body_pos[child]),  # type: ignore[arg-type]
        tuple(float(v) for v in model.body_quat[child]),  # type: ignore[arg-type]
    )
    return BearingFrame(
        journal, placement(origin_in_parent, axes_in_parent), axes, axes_in_parent, (child_pose, journal)
    )
