"""Radial play at a loop closure: a `connect` equality, as closed linkages write a revolute
joint that the body tree cannot hold.

A connect ties an anchor of body1 to the point of body2 that coincides with it at qpos0.
Given play, body2 gets a pin: a new child body ``clr_<name>__pin`` at that point with two
slides in the plane normal to the play's axis, and the connect is moved to tie body1's
anchor to the pin. The pin holds the journal, body2 the bearing (ring segments or the
compiled exact contact), so the slides' coordinates are the journal's eccentricity in the
bearing frame. The axis is that of a hinge of body2, or else of body1 (the first one in the
body's joint order), at qpos0.

The pin is the one body a retrofit adds. MuJoCo refuses a moving body without mass, so it
gets `PIN_MASS` and `PIN_INERTIA` (MuJoCo's floor is 1e-15), and its translational inertia
is the slides' armature: `PIN_ARMATURE_FRACTION` of body1's subtree mass, added to the mass
the journal carries. With so light a pin the connect's default soft impedance (0.9-0.95)
would let the pin run from the anchor (the constraint's force per metre scales with the
row's mass); the moved connect gets `CONNECT_IMPEDANCE`, MuJoCo's largest, so the loop
closes as stiffly as before. Measured on the slider-crank's rod_slider (c = 0.5 mm, steel,
exact contact, 2 us, a 2.1e-4 kg pin): the journal orbit within 0.40 % of c of the native
clearance model over 0.8 ms, the first impact on the same step (tests/test_retrofit_loop.py);
20 ms ran without a warning with the armature anywhere from 1e-5 to 1e-2 kg. With the
connect's default impedance the orbit was 48 % of c off at 0.5 ms (3 us, 1e-3 kg pin), and
an armature below 1e-3 kg diverged.
"""

from __future__ import annotations

import mujoco
import numpy as np

from clearance.retrofit.frames import BearingFrame, in_plane_axes, placement
from clearance.retrofit.insertion import PlayElements, prefix_of
from clearance.retrofit.play import RetrofitError

__all__ = [
    "CONNECT_IMPEDANCE",
    "PIN_ARMATURE_FRACTION",
    "PIN_INERTIA",
    "PIN_MASS",
    "add_pin",
    "check_connect",
    "connect_frame",
    "connect_load",
    "pin_insertion_joint",
]

PIN_MASS = 1e-12
"""Mass of the pin body [kg]: the smallest MuJoCo compiles comfortably above its 1e-15 floor."""

PIN_INERTIA = 1e-12
"""Rotational inertia of the pin body [kg m^2] (the pin does not turn; MuJoCo requires one)."""

PIN_ARMATURE_FRACTION = 1e-3
"""Armature of the pin's slides as a fraction of body1's subtree mass [-]: the journal's added mass."""

CONNECT_IMPEDANCE = 0.9999
"""solimp d0 = d_width of the moved connect: MuJoCo's largest impedance."""

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
    return BearingFrame(placement(np.zeros(3), axes), placement(origin, axes), axes, axes)


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


def add_pin(
    spec: mujoco.MjSpec,
    name: str,
    body2: mujoco.MjsBody,
    frame: BearingFrame,
    armature: float,
    default: mujoco.MjsDefault,
) -> PlayElements:
    """Add the pin to ``body2`` and move connect ``name`` to it; returns the names added.

    Args:
        spec: the spec being edited.
        name: the connect.
        body2: its body2 in the spec (the bearing's body).
        frame: its bearing frame (`connect_frame`).
        armature: the slides' armature [kg] (the pin's translational inertia).
        default: the retrofit's default class.
    """
    prefix = prefix_of(name)
    connect = spec.equality(name)
    origin = [float(v) for v in frame.bearing.origin]
    pin = body2.add_body(name=f"{prefix}__pin", pos=origin)
    pin.mass = PIN_MASS
    pin.inertia = [PIN_INERTIA] * 3
    pin.explicitinertial = True
    pin.ipos, pin.iquat = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]  # set, so the MJCF writer writes the inertial
    slides = [
        pin.add_joint(
            default=default,
            name=f"{prefix}__{k}",
            type=mujoco.mjtJoint.mjJNT_SLIDE,
            axis=[float(v) for v in frame.axes[:, i]],
            armature=armature,
        )
        for i, k in enumerate(("x", "y"))
    ]
    size = [0.001, 0.0, 0.0]
    pin.add_site(default=default, name=f"{prefix}__journal", size=size, group=3, **frame.journal.orientation())
    body2.add_site(
        default=default,
        name=f"{prefix}__bearing",
        pos=frame.bearing.point(0.0, 0.0),
        size=size,
        group=3,
        **frame.bearing.orientation(),
    )
    connect.name2 = pin.name
    solimp = list(connect.solimp)
    connect.solimp = [CONNECT_IMPEDANCE, CONNECT_IMPEDANCE, *solimp[2:]]
    return PlayElements(
        name,
        (slides[0].name, slides[1].name),
        f"{prefix}__journal",
        f"{prefix}__bearing",
        pin.name,
        body2.name or f"#{body2.id}",
    )
