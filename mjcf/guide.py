"""A slider with play in its guide, in an MjSpec: sites, the slider's freedom, corners and plates.

A prismatic joint with a `clearance.translational.TranslationalClearance` holds nothing: the
slider (the joint's link_b) moves in the plane relative to the guide (link_a), along the guide,
across it and tilting, and only its four corners' contacts with the guide's two lines hold it.
Where the joint is a tree edge its child body gets three dofs relative to its parent (a slide
along the guide named like the joint, a slide across it ``<joint>__across`` and a hinge
``<joint>__tilt``); where it is a cut of the tree the loop gives the slider that freedom.

Every slider with play gets two sites, as the compiled contact
(`clearance.contact_plugin.slider_guide`) reads them: ``<joint>__slider`` at the block's centre
(point_b) on the slider, its x axis along the block's length (the guide's axis at zero tilt),
and ``<joint>__guide`` at the guide's centre-line point (point_a) on the guide, its x axis the
guide's axis u, its y axis the normal n. The block and the guide's two lines are drawn.

The portable form (stock MuJoCo, the ring modes) makes each corner a small sphere on the slider
centred on the corner, and each guide line a plate (a box) on the guide whose inner face lies the
sphere's radius r beyond the line: a sphere's penetration into its plate is then
r - (H/2 + c + r - s) = |s| - (H/2 + c), the corner's exact penetration for any position and
tilt, along the guide's normal. Each corner has one explicit `<pair>` with the plate on its side
(corners 0, 1: the +n plate; 2, 3: the -n plate; `clearance.translational.CORNERS`), with the
contact parameters of `clearance.mjcf.contact.apply_corner_contact`. The contact acts at the middle of the overlap, r
from the corner along n: the normal force's moment is the corner's, friction's moment is off by
r F_t (r = `CORNER_RADIUS_FRACTION` of c).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from clearance.mjcf.bearing_geoms import HALF_THICKNESS, z_rotation
from clearance.model import Joint, Link, Mechanism
from clearance.translational import CORNERS, TranslationalClearance

__all__ = [
    "CORNER_RADIUS_FRACTION",
    "GuideGeometry",
    "add_play_dofs",
    "add_slider_in_guide",
    "add_corner_pair",
    "add_slider_sensors",
    "corner_pair_name",
    "slider_site",
    "guide_site",
]

CORNER_RADIUS_FRACTION = 0.5
"""Radius of a portable corner sphere, as a fraction of the clearance c: far above a corner's
deepest penetration (a few % of c in the published benchmark), small beside the block."""

_SIDE = ("pos", "neg")
_BLOCK_RGBA = [0.85, 0.35, 0.2, 0.6]
_GUIDE_RGBA = [0.3, 0.45, 0.75, 0.35]


@dataclass(frozen=True)
class GuideGeometry:
    """One slider with play in a built spec.

    Attributes:
        joint: the prismatic joint's name.
        play: its `TranslationalClearance`.
        slider_body, guide_body: the bodies holding the slider (link_b) and the guide (link_a;
            ``world`` for ground).
        corner_radius: radius r of the portable corner spheres [m] (0 for the compiled contact).
        plate_half_length: half-length of the guide plates along the guide [m]: the slider's
            centre stays within `reach` of the guide's point, its corners' spheres within the
            block's half-diagonal and r of the centre, so no sphere leaves its plate.
    """

    joint: str
    play: TranslationalClearance
    slider_body: str
    guide_body: str
    corner_radius: float
    plate_half_length: float


def slider_site(joint: str) -> str:
    """Name of the site at the block's centre on the slider."""
    return f"{joint}__slider"


def guide_site(joint: str) -> str:
    """Name of the site at the guide's centre-line point on the guide."""
    return f"{joint}__guide"


def corner_pair_name(joint: str, corner: int) -> str:
    """Name of corner ``corner``'s contact pair (portable form)."""
    return f"{joint}__corner{corner}"


def add_play_dofs(body: mujoco.MjsBody, joint: Joint, axis: list[float], anchor: tuple[float, float]) -> None:
    """The two dofs a tree-edge slider with play adds to its slide along the guide.

    Args:
        body: the child body (it already has the slide along the guide, named like the joint).
        joint: the prismatic joint with play.
        axis: the guide's axis in the child body's frame at assembly (3 values).
        anchor: the child's joint point in its frame [m].
    """
    across = [-axis[1], axis[0], 0.0]
    pos = [anchor[0], anchor[1], 0.0]
    body.add_joint(name=f"{joint.name}__across", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=across, pos=pos)
    body.add_joint(name=f"{joint.name}__tilt", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], pos=pos)


def reach(mechanism: Mechanism, joint: Joint) -> float:
    """A bound on how far the slider's centre can be from the guide's point [m].

    A chain from a ground point to the slider's centre passes through moving links, each adding
    at most its diameter (the largest distance between two of its points), and the guide's point
    lies within the ground's points' spread of them.
    """

    def diameter(link: Link) -> float:
        pts = list(link.points.values()) or [(0.0, 0.0)]
        return max(math.hypot(a[0] - b[0], a[1] - b[1]) for a in pts for b in pts)

    ground = mechanism.link(mechanism.ground)
    chain = sum(diameter(lk) for lk in mechanism.moving_links)
    if joint.link_a == mechanism.ground:
        g = ground.point(joint.point_a)
        return chain + max((math.hypot(p[0] - g[0], p[1] - g[1]) for p in ground.points.values()), default=0.0)
    # a moving guide's point is itself within a chain's reach of the ground
    return 2.0 * chain + diameter(ground)


def add_slider_in_guide(
    spec: mujoco.MjSpec,
    bodies: dict[str, mujoco.MjsBody],
    mechanism: Mechanism,
    joint: Joint,
    *,
    offset: float,
    portable: bool,
    impedance: float,
) -> GuideGeometry:
    """Sites, drawing and (portable form) corner spheres, plates and pairs of one slider with play.

    Args:
        spec: the spec (pairs are added to it).
        bodies: link name -> body (ground -> the world body).
        mechanism: the mechanism.
        joint: the prismatic joint with play.
        offset: theta_b - theta_a at assembly [rad] (the slider's zero tilt).
        portable: add the corner spheres, plates and pairs (else the plates are drawn only).
        impedance: the pairs' constant impedance (`clearance.options.ModelOptions.impedance`).

    Returns:
        The slider's `GuideGeometry`.
    """
    play = joint.require_translational()
    links = {lk.name: lk for lk in mechanism.links}
    u = math.atan2(joint.axis[1], joint.axis[0])  # the guide's axis in link_a's frame
    sbody, gbody = bodies[joint.link_b], bodies[joint.link_a]
    sp, gp = links[joint.link_b].point(joint.point_b), links[joint.link_a].point(joint.point_a)
    s_angle = u - offset
    sbody.add_site(name=slider_site(joint.name), pos=[sp[0], sp[1], 0.0], quat=z_rotation(s_angle), group=3)
    gbody.add_site(name=guide_site(joint.name), pos=[gp[0], gp[1], 0.0], quat=z_rotation(u), group=3)
    length, height, c = play.slider_length, play.slider_height, play.clearance
    r = CORNER_RADIUS_FRACTION * c if portable else 0.0
    half = math.hypot(0.5 * length, 0.5 * height) + r + reach(mechanism, joint)  # a corner at any tilt, its sphere
    nocol = dict(contype=0, conaffinity=0, mass=0)
    sbody.add_geom(
        name=f"{joint.name}__block",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.5 * length, 0.5 * height, HALF_THICKNESS],
        pos=[sp[0], sp[1], 0.0],
        quat=z_rotation(s_angle),
        rgba=_BLOCK_RGBA,
        group=1,
        **nocol,
    )
    thick = 0.25 * height  # half-thickness of a plate across the guide
    cu, su = math.cos(u), math.sin(u)
    for side, sign in zip(_SIDE, (1.0, -1.0)):
        d = sign * (0.5 * height + c + r + thick)
        gbody.add_geom(
            name=f"{joint.name}__plate_{side}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[half, thick, HALF_THICKNESS],
            pos=[gp[0] - su * d, gp[1] + cu * d, 0.0],
            quat=z_rotation(u),
            rgba=_GUIDE_RGBA,
            group=2,
            **nocol,
        )
    if portable:
        cs, ss = math.cos(s_angle), math.sin(s_angle)
        for k, (fu, fn) in enumerate(CORNERS):
            x, y = fu * length, fn * height
            sbody.add_geom(
                name=f"{joint.name}__corner{k}_sphere",
                type=mujoco.mjtGeom.mjGEOM_SPHERE,
                size=[r, 0, 0],
                pos=[sp[0] + cs * x - ss * y, sp[1] + ss * x + cs * y, 0.0],
                rgba=_BLOCK_RGBA,
                group=1,
                **nocol,
            )
            add_corner_pair(spec, joint.name, k, play.friction, impedance)
    return GuideGeometry(
        joint.name,
        play,
        joint.link_b if joint.link_b != mechanism.ground else "world",
        joint.link_a if joint.link_a != mechanism.ground else "world",
        r,
        half,
    )


def add_corner_pair(spec: mujoco.MjSpec, joint: str, corner: int, friction: float, impedance: float) -> None:
    """The explicit pair of corner ``corner``'s sphere with the plate on its side.

    Like a ring's pairs (`clearance.mjcf.bearing_geoms.add_journal_and_bearing`) it carries the
    small constant impedance ``impedance`` (`clearance.options.ModelOptions.impedance`) and
    placeholder solref values until `clearance.mjcf.contact.apply_corner_contact` writes the
    corner's contact parameters.
    """
    side = _SIDE[0] if CORNERS[corner][1] > 0 else _SIDE[1]
    pair = spec.add_pair(
        name=corner_pair_name(joint, corner),
        geomname1=f"{joint}__plate_{side}",
        geomname2=f"{joint}__corner{corner}_sphere",
    )
    pair.condim = 3 if friction > 0 else 1
    pair.friction = [friction, friction, 0.005, 0.0001, 0.0001]
    pair.solimp = [impedance, impedance, 0.001, 0.5, 2.0]
    pair.solref = [-1.0, -0.0]


def add_slider_sensors(spec: mujoco.MjSpec, geometry: GuideGeometry) -> None:
    """The sensors a run reads a slider with play from (`clearance.run.slider_readout`).

    ``<joint>__spos`` and ``__sxaxis``: the slider site's position and x axis in the guide
    site's frame; ``__svel``, ``__gvel``, ``__sangvel``, ``__gangvel``: the two sites' world
    linear and angular velocities; ``__gxaxis``: the guide site's x axis (world); in the portable
    form ``<joint>__corner<k>_force``: the net contact force on corner k's sphere (world).
    """
    obj, sens = mujoco.mjtObj, mujoco.mjtSensor
    j, s, g = geometry.joint, slider_site(geometry.joint), guide_site(geometry.joint)
    for name, kind, site, ref in (
        ("spos", sens.mjSENS_FRAMEPOS, s, g),
        ("sxaxis", sens.mjSENS_FRAMEXAXIS, s, g),
        ("svel", sens.mjSENS_FRAMELINVEL, s, None),
        ("gvel", sens.mjSENS_FRAMELINVEL, g, None),
        ("sangvel", sens.mjSENS_FRAMEANGVEL, s, None),
        ("gangvel", sens.mjSENS_FRAMEANGVEL, g, None),
        ("gxaxis", sens.mjSENS_FRAMEXAXIS, g, None),
    ):
        sensor = spec.add_sensor(name=f"{j}__{name}", type=kind, objtype=obj.mjOBJ_SITE, objname=site)
        if ref is not None:
            sensor.reftype, sensor.refname = obj.mjOBJ_SITE, ref
    if geometry.corner_radius == 0:
        return
    for k, (_, fn) in enumerate(CORNERS):
        side = _SIDE[0] if fn > 0 else _SIDE[1]
        sensor = spec.add_sensor(
            name=f"{j}__corner{k}_force",
            type=sens.mjSENS_CONTACT,
            objtype=obj.mjOBJ_GEOM,
            objname=f"{j}__plate_{side}",
            reftype=obj.mjOBJ_GEOM,
            refname=f"{j}__corner{k}_sphere",
        )
        sensor.intprm[:3] = [2, 3, 1]  # data = force, reduce = netforce, num = 1: the force on the sphere
