"""Journal and bearing geoms of one clearance joint, placed in a frame of each body.

A ring of N segments around the bearing centre on one body, a journal on the other, and an
explicit `<pair>` between the journal and each segment (the geoms themselves collide with
nothing: contype = conaffinity = 0); or, for the compiled exact contact, two cylinders
drawn for the viewer only. The ring lies in the x-y plane of a `Placement`: a mechanism
places it in the body's own plane (no rotation), a retrofit in the plane normal to a hinge
axis of any orientation (`clearance.retrofit`). New geoms carry no mass.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np

from clearance.mjcf.bearing import RingGeometry, segment_centres
from clearance.options import GeomType, ModelOptions

__all__ = [
    "HALF_THICKNESS",
    "Placement",
    "RingElements",
    "add_journal_and_bearing",
    "add_journal_and_bearing_visual",
    "z_rotation",
]

HALF_THICKNESS = 0.004
"""Half-thickness along the ring's axis of capsule, cylinder and box segments and journals [m]."""

_JOURNAL_RGBA = [0.85, 0.35, 0.2, 1.0]
_BEARING_RGBA = [0.3, 0.45, 0.75, 0.35]


def z_rotation(theta: float) -> list[float]:
    """Quaternion (w, x, y, z) of a rotation by ``theta`` [rad] about z."""
    return [math.cos(theta / 2), 0.0, 0.0, math.sin(theta / 2)]


@dataclass(frozen=True)
class Placement:
    """A journal or bearing centre and its ring plane, in the frame of the body holding it.

    Attributes:
        origin: (x, y, z) of the centre in the body frame [m].
        quat: (w, x, y, z) rotation from the body frame to the placement's axes, whose z is
            the ring's axis and whose x-y plane holds the ring; None: the body's own axes.
    """

    origin: tuple[float, float, float]
    quat: tuple[float, float, float, float] | None = None
    _rotation: np.ndarray | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.quat is not None:
            mat = np.zeros(9)
            mujoco.mju_quat2Mat(mat, np.asarray(self.quat, dtype=float))
            object.__setattr__(self, "_rotation", mat.reshape(3, 3))

    def point(self, x: float, y: float) -> list[float]:
        """The body-frame position of the in-plane point (x, y) of the placement [m]."""
        o = self.origin
        if self._rotation is None:
            return [o[0] + x, o[1] + y, o[2]]
        p = np.asarray(o, dtype=float) + self._rotation @ np.array([x, y, 0.0])
        return [float(v) for v in p]

    def orientation(self, local: Sequence[float] | None = None) -> dict[str, list[float]]:
        """``{"quat": ...}`` for a geom whose own rotation in the placement is ``local``.

        Empty when neither the placement nor the geom is rotated (the geom keeps MuJoCo's
        default orientation: its axis along the body's z).
        """
        if self.quat is None:
            return {} if local is None else {"quat": list(local)}
        if local is None:
            return {"quat": [float(v) for v in self.quat]}
        q = np.zeros(4)
        mujoco.mju_mulQuat(q, np.asarray(self.quat, dtype=float), np.asarray(local, dtype=float))
        return {"quat": [float(v) for v in q]}


@dataclass
class RingElements:
    """The elements one clearance joint's bearing added to a spec.

    Attributes:
        journal: the journal geom.
        segments: the ring's segment geoms (empty for the viewer-only bearing).
        pairs: the journal-segment contact pairs, in segment order.
        bearing: the viewer-only bearing cylinder (None for a ring).
    """

    journal: mujoco.MjsGeom
    segments: list[mujoco.MjsGeom] = field(default_factory=list)
    pairs: list[mujoco.MjsPair] = field(default_factory=list)
    bearing: mujoco.MjsGeom | None = None


def _geom_type(g: GeomType) -> int:
    return {
        GeomType.SPHERE: mujoco.mjtGeom.mjGEOM_SPHERE,
        GeomType.CAPSULE: mujoco.mjtGeom.mjGEOM_CAPSULE,
        GeomType.BOX: mujoco.mjtGeom.mjGEOM_BOX,
        GeomType.CYLINDER: mujoco.mjtGeom.mjGEOM_CYLINDER,
    }[g]


def _default(default: mujoco.MjsDefault | None) -> dict[str, mujoco.MjsDefault]:
    return {} if default is None else {"default": default}


def add_journal_and_bearing_visual(
    jbody: mujoco.MjsBody,
    bbody: mujoco.MjsBody,
    name: str,
    journal: Placement,
    bearing: Placement,
    ring: RingGeometry,
    *,
    default: mujoco.MjsDefault | None = None,
) -> RingElements:
    """Journal and bearing drawn for the viewer only (the compiled contact needs no geometry).

    Args:
        jbody, bbody: the bodies holding the journal and the bearing.
        name: prefix of the geom names (``<name>__journal``, ``<name>__bearing``).
        journal, bearing: where each centre sits in its body.
        ring: the bearing's geometry.
        default: the default class the geoms are created in (None: the spec's own).

    Returns:
        The two geoms.
    """
    jgeom = jbody.add_geom(
        **_default(default),
        name=f"{name}__journal",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[ring.journal_radius, HALF_THICKNESS, 0],
        pos=journal.point(0, 0),
        **journal.orientation(),
        rgba=_JOURNAL_RGBA,
        contype=0,
        conaffinity=0,
        mass=0,
    )
    bgeom = bbody.add_geom(
        **_default(default),
        name=f"{name}__bearing",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[ring.bearing_radius, 0.5 * HALF_THICKNESS, 0],
        pos=bearing.point(0, 0),
        **bearing.orientation(),
        rgba=_BEARING_RGBA,
        group=2,
        contype=0,
        conaffinity=0,
        mass=0,
    )
    return RingElements(jgeom, bearing=bgeom)


def add_journal_and_bearing(
    spec: mujoco.MjSpec,
    jbody: mujoco.MjsBody,
    bbody: mujoco.MjsBody | mujoco.MjsFrame,
    name: str,
    journal: Placement,
    bearing: Placement,
    ring: RingGeometry,
    options: ModelOptions,
    friction: float,
    *,
    default: mujoco.MjsDefault | None = None,
) -> RingElements:
    """The journal, the ring of segments and one contact pair per segment.

    Segment i sits at angle 2πi/N from the placement's x axis (`segment_centres`). The pairs
    carry the constant impedance ``options.impedance`` and placeholder solref values until
    the contact parameters are written (`clearance.mjcf.contact.apply_contact`).

    Args:
        spec: the spec (the pairs are added to it).
        jbody, bbody: the bodies holding the journal and the bearing ring (or a `<frame>` in the
            bearing's body, where ``bearing`` is then placed).
        name: prefix of the names (``<name>__journal``, ``<name>__segNNN``, ``<name>__pairNNN``).
        journal, bearing: where each centre and ring plane sit in its body.
        ring: the bearing's geometry.
        options: journal and segment geom types, impedance.
        friction: Coulomb friction coefficient of the pairs (condim 3 when > 0, else 1).
        default: the default class the geoms and pairs are created in (None: the spec's own).

    Returns:
        The journal, segment geoms and pairs.
    """
    nocol = dict(contype=0, conaffinity=0)
    jg = options.journal_geom
    size = [ring.journal_radius, HALF_THICKNESS, 0] if jg is not GeomType.SPHERE else [ring.journal_radius, 0, 0]
    out = RingElements(
        jbody.add_geom(
            **_default(default),
            name=f"{name}__journal",
            type=_geom_type(jg),
            size=size,
            pos=journal.point(0, 0),
            **journal.orientation(),
            rgba=_JOURNAL_RGBA,
            group=0,
            mass=0,
            **nocol,
        )
    )
    sg = options.segment_geom
    centres = segment_centres(ring)
    rs = ring.segment_radius
    for i, (x, y) in enumerate(centres):
        phi = math.atan2(y, x)
        gname = f"{name}__seg{i:03d}"
        if sg is GeomType.BOX:
            half_t = ring.bearing_radius * math.tan(math.pi / ring.segments) * 1.05
            hx = 0.25 * ring.bearing_radius
            r = ring.bearing_radius + hx
            g = bbody.add_geom(
                **_default(default),
                name=gname,
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[hx, half_t, HALF_THICKNESS],
                pos=bearing.point(r * math.cos(phi), r * math.sin(phi)),
                **bearing.orientation(z_rotation(phi)),
                **nocol,
            )
        else:
            size = [rs, 0, 0] if sg is GeomType.SPHERE else [rs, HALF_THICKNESS, 0]
            g = bbody.add_geom(
                **_default(default),
                name=gname,
                type=_geom_type(sg),
                size=size,
                pos=bearing.point(x, y),
                **bearing.orientation(),
                **nocol,
            )
        g.rgba = _BEARING_RGBA
        g.group = 2
        g.mass = 0
        pair = spec.add_pair(
            **_default(default), name=f"{name}__pair{i:03d}", geomname1=f"{name}__journal", geomname2=gname
        )
        pair.condim = 3 if friction > 0 else 1
        pair.friction = [friction, friction, 0.005, 0.0001, 0.0001]
        d = options.impedance
        pair.solimp = [d, d, 0.001, 0.5, 2.0]
        pair.solref = [-1.0, -0.0]
        out.segments.append(g)
        out.pairs.append(pair)
    return out
