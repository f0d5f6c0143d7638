"""Mechanism -> `mujoco.MjSpec`: planar bodies, ring-segment bearings, pairs, drives, sensors.

The body tree is built at the assembled t = 0 pose, so qpos0 is that pose; a keyframe
``initial`` stores the ideal-mechanism velocities and the drive controls. Every body moves
in the x-y plane through hinge-z and slide joints only. Inertials are explicit (geoms add no
mass). Collisions happen only through explicit `<pair>` elements between each journal and
its own bearing segments (and each slider corner and its guide plate,
`clearance.mjcf.guide`); every geom has contype = conaffinity = 0.

Sensor names (read by `clearance.simulate`):
  ``<link>__pos``, ``<link>__xaxis``: link (body) frame origin and x axis (world);
  ``<joint>__ecc``: journal centre in the bearing frame;
  ``<joint>__jvel``, ``<joint>__bvel``, ``<joint>__bangvel``, ``<joint>__bxaxis``: world
  velocities of journal and bearing centres, bearing angular velocity and x axis;
  ``<joint>__force``: net contact force between bearing and journal bodies (world);
  a slider with play: the sensors of `clearance.mjcf.guide.add_slider_sensors`;
  ``<output>__pos``, ``__vel``, ``__acc`` (point outputs) or ``__angvel``, ``__angacc``;
  ``<drive>__angle``, ``__speed``, ``__torque``; ``<cut>__closure`` for ideal cuts;
  ``<joint>__reaction``: for every tree joint, the force its parent body exerts on the child
  body's subtree (MuJoCo's ``cfrc_int``), in the frame of a site at the child's anchor whose axes
  are the child body's; ``<link>__comacc``: centre-of-mass acceleration minus gravity (world) of
  each link that an ideal cut touches (`clearance.run.reactions` reads both).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from clearance.kinematics import assemble, velocities
from clearance.mjcf.bearing import RingGeometry
from clearance.mjcf.bearing_geoms import (
    HALF_THICKNESS,
    Placement,
    add_journal_and_bearing,
    add_journal_and_bearing_visual,
)
from clearance.mjcf.bearing_geoms import z_rotation as _quat
from clearance.mjcf.guide import GuideGeometry, add_play_dofs, add_slider_in_guide, add_slider_sensors
from clearance.mjcf.tree import BodyTree, body_tree
from clearance.model import DriveKind, Joint, JointType, Link, Mechanism, OutputKind
from clearance.options import ContactMode, GeomType, ModelOptions

__all__ = [
    "BuiltModel",
    "build_spec",
    "drive_armature",
    "drive_gear",
    "ring_geometry",
]

_OBJ = mujoco.mjtObj
_SENS = mujoco.mjtSensor
_THICK = HALF_THICKNESS  # half-thickness of visual link geoms along z [m]


@dataclass
class BuiltModel:
    """A spec and what is needed to read its runs.

    Attributes:
        spec: the MjSpec.
        tree: body tree (parents and cuts).
        rings: clearance joint name -> ring geometry.
        journal_body, bearing_body: clearance joint name -> body name.
        drive_gear: drive name -> +1 or -1 (sign between hinge qpos and drive angle).
        q0, qd0: assembled Cartesian coordinates and ideal velocities at t = 0.
        link_order: moving links in the order of the Cartesian coordinates.
        exact_contact: the compiled-contact family: clearance joints have sites and visual
            geoms only (no ring, no pairs, no contact sensor); their contact is added by the
            run as engine-plugin instances (`clearance.contact_plugin`).
        guides: slider with play (prismatic joint name) -> its `GuideGeometry` (sites, and in
            the ring modes corner spheres, plates and pairs; `clearance.mjcf.guide`).
    """

    spec: mujoco.MjSpec
    tree: BodyTree
    rings: dict[str, RingGeometry]
    journal_body: dict[str, str]
    bearing_body: dict[str, str]
    drive_gear: dict[str, float]
    q0: np.ndarray
    qd0: np.ndarray
    link_order: tuple[str, ...] = ()
    exact_contact: bool = False
    guides: dict[str, GuideGeometry] = field(default_factory=dict)


def ring_geometry(joint: Joint, segments: int, options: ModelOptions) -> RingGeometry:
    """Ring geometry of a clearance joint for the chosen geoms and segment count."""
    c = joint.require_clearance()
    n_pc = 2 if (options.journal_geom is GeomType.CAPSULE and options.segment_geom is GeomType.CAPSULE) else 1
    return RingGeometry.make(
        c.bearing_radius,
        c.radial_clearance,
        segments,
        flat=options.segment_geom is GeomType.BOX,
        contacts_per_pair=n_pc,
    )


def drive_gear(tree: BodyTree, mechanism: Mechanism) -> dict[str, float]:
    """+1 when the driven joint's link_b is the child body, else -1."""
    out = {}
    for d in mechanism.drives:
        j = mechanism.joint(d.joint)
        child = j.link_b if j.link_b in tree.parent and tree.parent[j.link_b][1] is j else j.link_a
        out[d.name] = 1.0 if child == j.link_b else -1.0
    return out


def _to_frame(pose: np.ndarray, world: np.ndarray) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    d = world - pose[:2]
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])


def _sensor(
    spec: mujoco.MjSpec,
    name: str,
    stype: mujoco.mjtSensor,
    objtype: mujoco.mjtObj,
    objname: str,
    reftype: mujoco.mjtObj | None = None,
    refname: str = "",
) -> mujoco.MjsSensor:
    s = spec.add_sensor(name=name, type=stype, objtype=objtype, objname=objname)
    if reftype is not None:
        s.reftype = reftype
        s.refname = refname
    return s


def build_spec(
    mechanism: Mechanism,
    options: ModelOptions,
    segments: dict[str, int],
) -> BuiltModel:
    """Build the MuJoCo spec of a mechanism.

    Args:
        mechanism: the mechanism (its clearance joints get ring bearings, its sliders with play
            their guides: `clearance.mjcf.guide`).
        options: numerical options (geoms, time step, integrator, impedance).
        segments: clearance joint name -> segment count N.

    Returns:
        The spec and its reading aids. Contact pairs carry placeholder solref values until
        `clearance.mjcf.contact.apply_contact` sets them.

    Raises:
        AssemblyError: the mechanism cannot be assembled at t = 0.
        ValueError: a loop cannot be cut (see `body_tree`).
    """
    tree = body_tree(mechanism)
    q0 = assemble(mechanism, 0.0)
    qd0 = velocities(mechanism, q0, 0.0)
    names = [lk.name for lk in mechanism.moving_links]
    pose = {mechanism.ground: np.zeros(3)}
    for i, n in enumerate(names):
        pose[n] = q0[3 * i : 3 * i + 3]
    links = {lk.name: lk for lk in mechanism.links}

    spec = mujoco.MjSpec()
    spec.modelname = mechanism.name
    spec.compiler.degree = False
    spec.option.timestep = options.timestep
    spec.option.integrator = {
        "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
        "euler": mujoco.mjtIntegrator.mjINT_EULER,
        "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
        "rk4": mujoco.mjtIntegrator.mjINT_RK4,
    }[options.integrator]
    spec.option.gravity = [mechanism.gravity[0], mechanism.gravity[1], 0.0]
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
    spec.visual.global_.offwidth = 1280
    spec.stat.extent = max(0.05, float(np.max(np.abs(q0.reshape(-1, 3)[:, :2])) * 2.5 + 0.05))

    bodies = {mechanism.ground: spec.worldbody}
    for child in tree.order:
        par, joint = tree.parent[child]
        lk = links[child]
        rel = _to_frame(pose[par], pose[child][:2])
        body = bodies[par].add_body(name=child, pos=[rel[0], rel[1], 0.0], quat=_quat(pose[child][2] - pose[par][2]))
        body.mass = lk.mass
        body.inertia = [lk.inertia, lk.inertia, lk.inertia]
        body.ipos = [lk.com[0], lk.com[1], 0.0]
        body.explicitinertial = True
        bodies[child] = body
        cpoint = joint.point_b if joint.link_b == child else joint.point_a
        anchor = lk.point(cpoint)
        if joint.kind is JointType.PRISMATIC:
            th_a = pose[joint.link_a][2]
            world_axis = np.array(
                [
                    math.cos(th_a) * joint.axis[0] - math.sin(th_a) * joint.axis[1],
                    math.sin(th_a) * joint.axis[0] + math.cos(th_a) * joint.axis[1],
                ]
            )
            c, s = math.cos(pose[child][2]), math.sin(pose[child][2])
            ax = [c * world_axis[0] + s * world_axis[1], -s * world_axis[0] + c * world_axis[1], 0.0]
            body.add_joint(name=joint.name, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=ax, pos=[anchor[0], anchor[1], 0])
            if joint.translational_clearance is not None:
                add_play_dofs(body, joint, ax, anchor)
        elif joint.clearance is None:
            body.add_joint(
                name=joint.name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], pos=[anchor[0], anchor[1], 0]
            )
        else:
            for k, ax in (("x", [1, 0, 0]), ("y", [0, 1, 0])):
                body.add_joint(
                    name=f"{joint.name}__{k}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=ax, pos=[anchor[0], anchor[1], 0]
                )
            body.add_joint(
                name=joint.name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], pos=[anchor[0], anchor[1], 0]
            )
        _visual_link(body, lk)

    # ideal cuts -> connect equalities
    tc = options.closure_timeconst if options.closure_timeconst is not None else 2 * options.timestep
    for j in tree.ideal_cuts:
        pa = links[j.link_a].point(j.point_a)
        pb = links[j.link_b].point(j.point_b)
        eq = spec.add_equality(
            name=j.name,
            type=mujoco.mjtEq.mjEQ_CONNECT,
            objtype=_OBJ.mjOBJ_BODY,
            name1=j.link_a if j.link_a != mechanism.ground else "world",
            name2=j.link_b if j.link_b != mechanism.ground else "world",
        )
        eq.data[:3] = [pa[0], pa[1], 0.0]
        eq.solref = [tc, 1.0]
        _site(bodies[j.link_a], f"{j.name}__a", pa)
        _site(bodies[j.link_b], f"{j.name}__b", pb)
        _sensor(
            spec,
            f"{j.name}__closure",
            _SENS.mjSENS_FRAMEPOS,
            _OBJ.mjOBJ_SITE,
            f"{j.name}__b",
            _OBJ.mjOBJ_SITE,
            f"{j.name}__a",
        )

    exact = options.contact_mode is ContactMode.EXACT
    rings, jbody, bbody = {}, {}, {}
    for j in mechanism.clearance_joints:
        cl = j.require_clearance()
        jl = cl.journal_link
        assert jl is not None  # Mechanism resolves the journal side of every clearance
        bl = j.link_b if jl == j.link_a else j.link_a
        jp = links[jl].point(j.point_a if jl == j.link_a else j.point_b)
        bp = links[bl].point(j.point_a if bl == j.link_a else j.point_b)
        ring = ring_geometry(j, segments[j.name], options)
        rings[j.name], jbody[j.name], bbody[j.name] = ring, jl, bl
        jplace, bplace = Placement((jp[0], jp[1], 0.0)), Placement((bp[0], bp[1], 0.0))
        if exact:
            add_journal_and_bearing_visual(bodies[jl], bodies[bl], j.name, jplace, bplace, ring)
        else:
            add_journal_and_bearing(spec, bodies[jl], bodies[bl], j.name, jplace, bplace, ring, options, cl.friction)
        _site(bodies[jl], f"{j.name}__journal", jp)
        _site(bodies[bl], f"{j.name}__bearing", bp)
        _sensor(
            spec,
            f"{j.name}__ecc",
            _SENS.mjSENS_FRAMEPOS,
            _OBJ.mjOBJ_SITE,
            f"{j.name}__journal",
            _OBJ.mjOBJ_SITE,
            f"{j.name}__bearing",
        )
        _sensor(spec, f"{j.name}__jvel", _SENS.mjSENS_FRAMELINVEL, _OBJ.mjOBJ_SITE, f"{j.name}__journal")
        _sensor(spec, f"{j.name}__bvel", _SENS.mjSENS_FRAMELINVEL, _OBJ.mjOBJ_SITE, f"{j.name}__bearing")
        _sensor(spec, f"{j.name}__bangvel", _SENS.mjSENS_FRAMEANGVEL, _OBJ.mjOBJ_SITE, f"{j.name}__bearing")
        _sensor(spec, f"{j.name}__bxaxis", _SENS.mjSENS_FRAMEXAXIS, _OBJ.mjOBJ_SITE, f"{j.name}__bearing")
        if exact:
            continue  # the contact's force is the plugin's sensor
        s = _sensor(
            spec,
            f"{j.name}__force",
            _SENS.mjSENS_CONTACT,
            _OBJ.mjOBJ_BODY,
            bl if bl != mechanism.ground else "world",
            _OBJ.mjOBJ_BODY,
            jl if jl != mechanism.ground else "world",
        )
        s.intprm[:3] = [2, 3, 1]  # data = force, reduce = netforce, num = 1

    guides = {}
    for j in mechanism.translational_joints:
        offset = float(pose[j.link_b][2] - pose[j.link_a][2])
        guides[j.name] = add_slider_in_guide(
            spec, bodies, mechanism, j, offset=offset, portable=not exact, impedance=options.impedance
        )
        add_slider_sensors(spec, guides[j.name])

    _reaction_sensors(spec, bodies, tree, links, mechanism.ground)

    for n in names:
        # xbody: the body (link) frame; "body" would be the inertial frame at the centre of mass
        _sensor(spec, f"{n}__pos", _SENS.mjSENS_FRAMEPOS, _OBJ.mjOBJ_XBODY, n)
        _sensor(spec, f"{n}__xaxis", _SENS.mjSENS_FRAMEXAXIS, _OBJ.mjOBJ_XBODY, n)

    for o in mechanism.outputs:
        if o.kind is OutputKind.ANGLE:
            _sensor(spec, f"{o.name}__angvel", _SENS.mjSENS_FRAMEANGVEL, _OBJ.mjOBJ_BODY, o.link)
            _sensor(spec, f"{o.name}__angacc", _SENS.mjSENS_FRAMEANGACC, _OBJ.mjOBJ_BODY, o.link)
        else:
            _site(bodies[o.link], f"{o.name}__site", links[o.link].point(o.require_point()))
            for suffix, st in (
                ("pos", _SENS.mjSENS_FRAMEPOS),
                ("vel", _SENS.mjSENS_FRAMELINVEL),
                ("acc", _SENS.mjSENS_FRAMELINACC),
            ):
                _sensor(spec, f"{o.name}__{suffix}", st, _OBJ.mjOBJ_SITE, f"{o.name}__site")

    gears = drive_gear(tree, mechanism)
    for d in mechanism.drives:
        act = spec.add_actuator(name=d.name, target=d.joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.gear[0] = gears[d.name]
        if d.kind is DriveKind.TORQUE:
            act.set_to_motor()
        else:
            act.set_to_velocity(kv=_drive_gain(mechanism, options))
            spec.joint(d.joint).armature = drive_armature(mechanism)
        _sensor(spec, f"{d.name}__angle", _SENS.mjSENS_JOINTPOS, _OBJ.mjOBJ_JOINT, d.joint)
        _sensor(spec, f"{d.name}__speed", _SENS.mjSENS_JOINTVEL, _OBJ.mjOBJ_JOINT, d.joint)
        _sensor(spec, f"{d.name}__torque", _SENS.mjSENS_ACTUATORFRC, _OBJ.mjOBJ_ACTUATOR, d.name)

    return BuiltModel(spec, tree, rings, jbody, bbody, gears, q0, qd0, tuple(names), exact, guides)


def _reaction_sensors(
    spec: mujoco.MjSpec,
    bodies: dict[str, mujoco.MjsBody],
    tree: BodyTree,
    links: dict[str, Link],
    ground: str,
) -> None:
    """Sensors from which a run reads every joint's reaction (see the module docstring).

    A FORCE sensor per tree joint reads the force through it; a body that an ideal cut touches
    also gets its centre-of-mass acceleration, so that the cut's force follows from the body's
    Newton equation. Both need MuJoCo's post-constraint pass, which the output acceleration
    sensors already request, so they add little to a step.
    """
    for child in tree.order:
        _, joint = tree.parent[child]
        anchor = links[child].point(joint.point_b if joint.link_b == child else joint.point_a)
        _site(bodies[child], f"{joint.name}__anchor", anchor)
        _sensor(spec, f"{joint.name}__reaction", _SENS.mjSENS_FORCE, _OBJ.mjOBJ_SITE, f"{joint.name}__anchor")
    touched = sorted({lk for j in tree.ideal_cuts for lk in (j.link_a, j.link_b) if lk != ground})
    for n in touched:
        # objtype BODY: the inertial frame, at the centre of mass
        _sensor(spec, f"{n}__comacc", _SENS.mjSENS_FRAMELINACC, _OBJ.mjOBJ_BODY, n)


def _drive_gain(mechanism: Mechanism, options: ModelOptions) -> float:
    """Velocity-actuator gain kv [N m s/rad].

    implicitfast integrates the actuator's damping implicitly, so a large kv is stable.
    kv = 1e3 * (sum of link inertias about their pivots) / h makes the speed error of a
    torque tau equal tau / kv: under 1e-5 relative at 5000 rpm with 500 N m for the
    default slider-crank (1e3 * ~1e-4 kg m^2 / 1e-6 s = 1e5).
    """
    inertia = sum(lk.inertia + lk.mass * (lk.com[0] ** 2 + lk.com[1] ** 2) for lk in mechanism.moving_links)
    return 1e3 * max(inertia, 1e-6) / options.timestep


def drive_armature(mechanism: Mechanism) -> float:
    """Armature [kg m^2] of a speed-driven joint: 100 x the links' inertias about their frames.

    The velocity actuator's gain acts only in the implicit integration, which the
    constraint solver does not see: with two speed-driven cranks in one loop (the press)
    the loop closure then fights the drives and the run blows up. A heavy armature makes
    the solver see a crank that the drive holds (tests/test_catalogue_mujoco.py); its
    inertial torque is removed from the reported drive torque.
    """
    inertia = sum(lk.inertia + lk.mass * (lk.com[0] ** 2 + lk.com[1] ** 2) for lk in mechanism.moving_links)
    return 100.0 * inertia


def _site(body: mujoco.MjsBody, name: str, p: tuple[float, float]) -> None:
    body.add_site(name=name, pos=[p[0], p[1], 0.0], size=[0.001, 0, 0], group=3)


def _visual_link(body: mujoco.MjsBody, link: Link) -> None:
    pts = list(link.points.values())
    rgba = [0.55, 0.6, 0.7, 1.0]
    kw = dict(contype=0, conaffinity=0, group=1, rgba=rgba, mass=0)
    if len(pts) == 1:
        body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.012, 0.008, _THICK], pos=[pts[0][0], pts[0][1], 0], **kw)
        return
    for i in range(len(pts)):
        for k in range(i + 1, len(pts)):
            a, b = pts[i], pts[k]
            if math.hypot(b[0] - a[0], b[1] - a[1]) < 1e-9:
                continue
            body.add_geom(
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                size=[_THICK / 2, 0, 0],
                fromto=[a[0], a[1], -_THICK, b[0], b[1], -_THICK],
                **kw,
            )
