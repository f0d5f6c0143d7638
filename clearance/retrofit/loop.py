"""Radial play at a loop closure: a `connect` equality, as closed linkages write a revolute
joint that the body tree cannot hold.

A connect ties an anchor of body1 to the point of body2 that coincides with it at qpos0.
Given play, body2 gets a pin: a new child body ``clr_<name>__pin`` at that point with two
slides in the plane normal to the play's axis, and the connect is moved to tie body1's
anchor to the pin. The pin holds the journal, body2 the bearing (ring segments or the
compiled exact contact), so the slides' coordinates are the journal's eccentricity in the
bearing frame. The axis is that of a hinge of body2, or else of body1 (the first one in the
body's joint order), at qpos0.

The pin is the one body a retrofit adds, and it is a real share of a link's mass: a point mass
cut from its donor at the connect's anchor (`clearance.retrofit.masses.split_point_mass`), the
donor being body1 (the pin follows body1's anchor, so donor + pin move as the original body) or
body2 where body1 is the world. A near-massless pin gave the connect's row an inverse weight
of 1e12: MuJoCo's regularisation R = (1 - d)/d Â grew with it and the loop opened by a
quarter of a metre while the contact pushed the pin about.

The moved connect keeps the twin's softness (`connect_softness`): MuJoCo gives a soft
constraint the static compliance R/K per newton of load (K, B from solref and solimp's d_width),
so the impedance is raised until R(r) = (1 - d(r))/d(r) Â is the twin's at the connect's new
Â, and the time constant (or the direct-mode stiffness and damping) is rescaled so that K and
B stay. Where the impedance would have to exceed MuJoCo's largest, 0.9999, it stops there and
the report says how much softer the connect is.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.retrofit.frames import BearingFrame, in_plane_axes, placement
from clearance.retrofit.insertion import PlayElements, add_bearing_frame, prefix_of
from clearance.retrofit.masses import PIN_INERTIA, Inertial, PointMassSplit, split_point_mass
from clearance.retrofit.play import RetrofitError
from clearance.retrofit.softness import Softness, kept_softness, refsafe

__all__ = [
    "Pin",
    "add_pin",
    "check_connect",
    "connect_frame",
    "connect_load",
    "connect_residual",
    "connect_softness",
    "pin_donor",
    "pin_insertion_joint",
    "pin_share",
    "soften_like_twin",
]

_OBJ = mujoco.mjtObj


def _hinge_axis(model: mujoco.MjModel, body: int) -> int:
    """Id of the first hinge of ``body``, or -1."""
    first = int(model.body_jntadr[body])
    for j in range(first, first + int(model.body_jntnum[body])):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            return j
    return -1


def check_connect(model: mujoco.MjModel, eq: int, name: str, label: str) -> tuple[int, int, int]:
    """Check that connect ``eq`` can be given play; returns (body1, body2, the hinge giving the axis).

    Raises:
        RetrofitError: the connect names sites instead of bodies, or neither body has a hinge.
    """
    if model.eq_objtype[eq] != _OBJ.mjOBJ_BODY:
        raise RetrofitError(
            f"connect '{name}' of {label} ties sites: only a connect between bodies (body1, body2, anchor) can be "
            "given play"
        )
    b1, b2 = int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq])
    for body in (b2, b1):
        j = _hinge_axis(model, body)
        if j >= 0:
            return b1, b2, j
    names = [mujoco.mj_id2name(model, _OBJ.mjOBJ_BODY, b) or f"#{b}" for b in (b1, b2)]
    raise RetrofitError(
        f"connect '{name}' of {label}: neither body ({', '.join(names)}) has a hinge to take the play's axis from; "
        "planar play needs the axis of the revolute joint the connect closes"
    )


def connect_frame(model: mujoco.MjModel, data: mujoco.MjData, eq: int, axis_joint: int) -> BearingFrame:
    """The bearing frame of a connect: origin at body1's anchor at qpos0, z along the hinge's axis.

    Args:
        model: the unmodified compiled model.
        data: its data with ``mujoco.mj_kinematics`` done at qpos0.
        eq: the connect.
        axis_joint: the hinge giving the axis (`check_connect`).

    The frame is expressed in body2 (the bearing) and in the pin (the journal), which has
    body2's orientation and its origin at the anchor.
    """
    b1, b2 = int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq])
    r1, r2 = data.xmat[b1].reshape(3, 3), data.xmat[b2].reshape(3, 3)
    anchor = data.xpos[b1] + r1 @ np.asarray(model.eq_data[eq, :3], dtype=float)
    origin = r2.T @ (anchor - data.xpos[b2])
    hb = int(model.jnt_bodyid[axis_joint])
    axis_world = data.xmat[hb].reshape(3, 3) @ np.asarray(model.jnt_axis[axis_joint], dtype=float)
    axes = in_plane_axes(r2.T @ axis_world)
    bearing = placement(origin, axes)
    return BearingFrame(placement(np.zeros(3), axes), bearing, axes, axes, (bearing,))


def connect_load(data: mujoco.MjData, eq: int, body2: int, frame: BearingFrame) -> np.ndarray:
    """(2,) the connect's constraint force in its bearing frame's x-y plane [N] (after mj_forward)."""
    n = data.nefc
    rows = np.nonzero((data.efc_type[:n] == mujoco.mjtConstraint.mjCNSTR_EQUALITY) & (data.efc_id[:n] == eq))[0]
    if len(rows) != 3:
        return np.zeros(2)
    world = data.xmat[body2].reshape(3, 3) @ frame.axes_in_parent
    return np.asarray(world.T @ data.efc_force[rows])[:2]


def pin_insertion_joint(model: mujoco.MjModel, body2: int) -> int:
    """The unmodified joint the pin's slides come before (``njnt``: at the end).

    The pin is body2's last child, so it follows body2's whole subtree in the compiled body
    order, and its slides follow every joint of that subtree.
    """
    last = body2
    for b in range(body2 + 1, model.nbody):
        p = b
        while p not in (0, body2):
            p = int(model.body_parentid[p])
        if p == body2 or body2 == 0:
            last = b
        else:
            break
    for j in range(model.njnt):
        if model.jnt_bodyid[j] > last:
            return j
    return int(model.njnt)


def pin_donor(model: mujoco.MjModel, eq: int) -> tuple[int, np.ndarray]:
    """(the body a connect's pin takes its mass from, the anchor in that body's frame [m]): body1, or
    body2 where body1 is the world."""
    b1 = int(model.eq_obj1id[eq])
    if b1 > 0:
        return b1, np.asarray(model.eq_data[eq, :3], dtype=float)
    return int(model.eq_obj2id[eq]), np.asarray(model.eq_data[eq, 3:6], dtype=float)


def add_pin(
    spec: mujoco.MjSpec,
    name: str,
    body2: mujoco.MjsBody,
    frame: BearingFrame,
    split: PointMassSplit,
    default: mujoco.MjsDefault,
) -> PlayElements:
    """Add the pin to ``body2`` and move connect ``name`` to it; returns the names added.

    Args:
        spec: the spec being edited.
        name: the connect.
        body2: its body2 in the spec (the bearing's body).
        frame: its bearing frame (`connect_frame`).
        split: the pin's share of its donor's mass (`pin_share`); the caller writes the donor's remainder.
        default: the retrofit's default class.
    """
    prefix = prefix_of(name)
    connect = spec.equality(name)
    origin = [float(v) for v in frame.bearing.origin]
    pin = body2.add_body(name=f"{prefix}__pin", pos=origin)
    pin.mass = split.pin_mass
    pin.inertia = [PIN_INERTIA] * 3
    pin.explicitinertial = True
    pin.ipos, pin.iquat = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]  # set, so the MJCF writer writes the inertial
    slides = [
        pin.add_joint(
            default=default,
            name=f"{prefix}__{k}",
            type=mujoco.mjtJoint.mjJNT_SLIDE,
            axis=[float(v) for v in frame.axes[:, i]],
        )
        for i, k in enumerate(("x", "y"))
    ]
    size = [0.001, 0.0, 0.0]
    pin.add_site(default=default, name=f"{prefix}__journal", size=size, group=3, **frame.journal.orientation())
    add_bearing_frame(body2, prefix, frame, default)
    connect.name2 = pin.name
    return PlayElements(
        name,
        (slides[0].name, slides[1].name),
        f"{prefix}__journal",
        f"{prefix}__bearing",
        pin.name,
        body2.name or f"#{body2.id}",
    )


def pin_share(twin: mujoco.MjModel, eq: int, donors: dict[int, Inertial]) -> PointMassSplit:
    """The pin's point mass cut from the connect's donor (`pin_donor`) at the anchor.

    Args:
        twin: the unmodified model.
        eq: the connect.
        donors: body id -> its mass properties after the cuts so far (updated: two pins may
            share a donor).
    """
    donor, point = pin_donor(twin, eq)
    now = donors.get(donor) or Inertial.of_body(twin, donor)
    split = split_point_mass(donor, now, point, label=mujoco.mj_id2name(twin, _OBJ.mjOBJ_BODY, donor) or f"#{donor}")
    donors[donor] = split.remainder
    return split


def connect_softness(twin: mujoco.MjModel, model: mujoco.MjModel, eq: int, step: float) -> Softness:
    """The solimp and solref that give the moved connect ``eq`` the twin's R(r), K and B (module docstring;
    `clearance.retrofit.softness.kept_softness` at the connect's Â, the translational ``body_invweight0``
    sums of its two bodies).

    Args:
        twin: the unmodified model.
        model: the edited model with the pin (its solimp and solref not yet set).
        eq: the connect's id (the same in both).
        step: the time step [s].
    """
    a_old = float(twin.body_invweight0[twin.eq_obj1id[eq], 0] + twin.body_invweight0[twin.eq_obj2id[eq], 0])
    a_new = float(model.body_invweight0[model.eq_obj1id[eq], 0] + model.body_invweight0[model.eq_obj2id[eq], 0])
    return kept_softness(a_old, a_new, twin.eq_solimp[eq], twin.eq_solref[eq], step=step, refsafe=refsafe(twin))


@dataclass(frozen=True)
class Pin:
    """What a loop closure's pin took and how its connect was set.

    Attributes:
        share: its point mass cut from the donor. softness: the moved connect's solver parameters.
    """

    share: PointMassSplit
    softness: Softness


def soften_like_twin(
    spec: mujoco.MjSpec, twin: mujoco.MjModel, model: mujoco.MjModel, name: str, share: PointMassSplit, step: float
) -> Pin:
    """Write the moved connect ``name``'s solimp and solref that keep the twin's softness (`connect_softness`).

    Args:
        spec: the spec being edited. twin: the unmodified model. model: ``spec`` compiled with the pin.
        name: the connect. share: its pin's share of the donor's mass. step: the time step [s].
    """
    eq = mujoco.mj_name2id(twin, _OBJ.mjOBJ_EQUALITY, name)
    soft = connect_softness(twin, model, eq, step)
    connect = spec.equality(name)
    connect.solimp = list(soft.solimp)
    connect.solref = list(soft.solref)
    return Pin(share, soft)


def connect_residual(model: mujoco.MjModel, data: mujoco.MjData, eq: int) -> float:
    """|anchor on body1 - anchor on body2| of connect ``eq`` [m]: the size of the three constraint rows'
    residual MuJoCo solves (``efc_pos``), from positions (after ``mj_kinematics``)."""
    a, b = int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq])
    if model.eq_objtype[eq] == mujoco.mjtObj.mjOBJ_SITE:
        return float(np.linalg.norm(data.site_xpos[a] - data.site_xpos[b]))
    p1 = data.xpos[a] + data.xmat[a].reshape(3, 3) @ model.eq_data[eq, :3]
    p2 = data.xpos[b] + data.xmat[b].reshape(3, 3) @ model.eq_data[eq, 3:6]
    return float(np.linalg.norm(p1 - p2))
