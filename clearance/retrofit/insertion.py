"""The elements a retrofit adds to a hinge: slides, sites, journal, ring, pairs and sensors.

For hinge ``J`` (prefix ``clr_J``): slides ``clr_J__x`` and ``clr_J__y`` before the hinge in
the child body; sites ``clr_J__journal`` (child) and ``clr_J__bearing`` (parent) at the
hinge position with the bearing frame's axes; the journal geom ``clr_J__journal``, the ring
``clr_J__segNNN`` on the parent and the pairs ``clr_J__pairNNN`` (`clearance.mjcf.bearing_geoms`,
the same as a mechanism's); sensors ``clr_J__ecc`` (journal centre in the bearing frame) and
``clr_J__force`` (net contact force on the journal). All in the class `DEFAULT_CLASS`,
massless and colliding through their pairs only. Sensors are appended after the model's own,
so its sensor data keeps its layout.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco

from clearance.mjcf.bearing import RingGeometry
from clearance.mjcf.bearing_geoms import Placement, RingElements, add_journal_and_bearing
from clearance.model import Clearance
from clearance.options import ModelOptions
from clearance.retrofit.elements import rebuild_hinge_after_slides
from clearance.retrofit.frames import BearingFrame
from clearance.retrofit.play import PREFIX

__all__ = [
    "PlayElements",
    "prefix_of",
    "add_slides_and_sites",
    "add_bearing",
    "add_bearing_frame",
    "add_eccentricity_sensor",
    "add_exact_contact",
    "bearing_frame_name",
    "exact_contact_name",
]

_SITE_SIZE = [0.001, 0.0, 0.0]
_SENS = mujoco.mjtSensor
_OBJ = mujoco.mjtObj


def prefix_of(hinge: str) -> str:
    """The name prefix of everything added for ``hinge``."""
    return f"{PREFIX}{hinge}"


@dataclass
class PlayElements:
    """Names of the elements added for one hinge.

    Attributes:
        hinge: the hinge.
        slides: its x and y slides.
        journal_site, bearing_site: the sites at the journal and bearing centres.
        journal_body, bearing_body: the bodies holding them (name, or ``#id`` if unnamed).
        journal_geom: the journal geom ('' until the ring is added).
        segments: the ring's segment geoms.
        pairs: the journal-segment pairs.
        sensors: the sensors added.
    """

    hinge: str
    slides: tuple[str, str]
    journal_site: str
    bearing_site: str
    journal_body: str
    bearing_body: str
    journal_geom: str = ""
    segments: list[str] = field(default_factory=list)
    pairs: list[str] = field(default_factory=list)
    sensors: list[str] = field(default_factory=list)


def bearing_frame_name(hinge: str) -> str:
    """The `<frame>` at a hinge's bearing centre that holds its ring and bearing site."""
    return f"{prefix_of(hinge)}__bearing_frame"


def add_bearing_frame(
    body: mujoco.MjsBody, prefix: str, frame: BearingFrame, default: mujoco.MjsDefault
) -> mujoco.MjsFrame:
    """Nested `<frame>` elements in ``body`` along ``frame.chain`` (the innermost at the bearing centre
    with the bearing axes, named ``<prefix>__bearing_frame``) and the bearing site at its origin."""
    holder: mujoco.MjsBody | mujoco.MjsFrame = body
    for k, place in enumerate(frame.chain):
        last = k == len(frame.chain) - 1
        holder = holder.add_frame(
            name=f"{prefix}__bearing_frame" if last else "",
            pos=list(place.origin),
            quat=list(place.quat or (1.0, 0.0, 0.0, 0.0)),
        )
    _site(holder, f"{prefix}__bearing", Placement((0.0, 0.0, 0.0)), default)
    assert isinstance(holder, mujoco.MjsFrame)  # a bearing frame's chain is never empty
    return holder


def _site(body: mujoco.MjsBody | mujoco.MjsFrame, name: str, place: Placement, default: mujoco.MjsDefault) -> None:
    body.add_site(
        default=default,
        name=name,
        pos=place.point(0.0, 0.0),
        size=_SITE_SIZE,
        group=3,
        **place.orientation(),
    )


def _label(body: mujoco.MjsBody) -> str:
    return body.name or f"#{body.id}"


def add_slides_and_sites(
    spec: mujoco.MjSpec,
    hinge: mujoco.MjsJoint,
    bearing_body: mujoco.MjsBody,
    frame: BearingFrame,
    default: mujoco.MjsDefault,
) -> PlayElements:
    """Put the slides before the hinge and the two centre sites; returns the names added.

    Args:
        spec: the spec being edited.
        hinge: the hinge (the only joint of its body).
        bearing_body: the parent body in the spec (the body the compiled model's parent is).
        frame: the hinge's bearing frame.
        default: the retrofit's default class.
    """
    prefix = prefix_of(hinge.name)
    journal_body = hinge.parent
    name = hinge.name
    slides, _ = rebuild_hinge_after_slides(
        spec, hinge, prefix, frame.journal.point(0.0, 0.0), frame.axes[:, :2].T, default
    )
    _site(journal_body, f"{prefix}__journal", frame.journal, default)
    add_bearing_frame(bearing_body, prefix, frame, default)
    return PlayElements(
        name,
        (slides[0].name, slides[1].name),
        f"{prefix}__journal",
        f"{prefix}__bearing",
        _label(journal_body),
        _label(bearing_body),
    )


def add_bearing(
    spec: mujoco.MjSpec,
    elements: PlayElements,
    journal_body: mujoco.MjsBody,
    frame: BearingFrame,
    ring: RingGeometry,
    options: ModelOptions,
    friction: float,
    default: mujoco.MjsDefault,
) -> RingElements:
    """Add the journal, ring, pairs and sensors of one hinge; fills ``elements``' names.

    The ring goes into the hinge's bearing-centred frame (`add_bearing_frame`, added with the sites).
    """
    prefix = prefix_of(elements.hinge)
    added = add_journal_and_bearing(
        spec,
        journal_body,
        spec.frame(bearing_frame_name(elements.hinge)),  # the bearing-centred frame: 6 digits hold the ring
        prefix,
        frame.journal,
        Placement((0.0, 0.0, 0.0)),
        ring,
        options,
        friction,
        default=default,
    )
    elements.journal_geom = added.journal.name
    elements.segments = [g.name for g in added.segments]
    elements.pairs = [p.name for p in added.pairs]
    ecc = add_eccentricity_sensor(spec, elements)
    force = spec.add_sensor(
        name=f"{prefix}__force", type=_SENS.mjSENS_CONTACT, objtype=_OBJ.mjOBJ_GEOM, objname=added.journal.name
    )
    force.intprm[:3] = [2, 3, 1]  # data = force, reduce = netforce, num = 1
    elements.sensors = [ecc.name, force.name]
    return added


def add_eccentricity_sensor(spec: mujoco.MjSpec, elements: PlayElements) -> mujoco.MjsSensor:
    """Add the sensor ``clr_<hinge>__ecc``: the journal's centre in the bearing frame [m] (framepos)."""
    ecc = spec.add_sensor(
        name=f"{prefix_of(elements.hinge)}__ecc",
        type=_SENS.mjSENS_FRAMEPOS,
        objtype=_OBJ.mjOBJ_SITE,
        objname=elements.journal_site,
    )
    ecc.reftype = _OBJ.mjOBJ_SITE
    ecc.refname = elements.bearing_site
    return ecc


def exact_contact_name(hinge: str) -> str:
    """Name of a hinge's compiled exact contact (plugin instance and its sensor)."""
    return f"{prefix_of(hinge)}__contact"


def add_exact_contact(spec: mujoco.MjSpec, elements: PlayElements, clearance: Clearance) -> None:
    """Add the compiled exact contact of one hinge (no ring, no journal geom) and the eccentricity
    sensor; fills ``elements``' sensors (eccentricity, then the plugin's sensor).

    Raises:
        clearance.contact_plugin.PluginUnavailableError: the plugin is not installed.
    """
    from clearance.contact_plugin.attributes import add_for_clearance

    ecc = add_eccentricity_sensor(spec, elements)
    name = exact_contact_name(elements.hinge)
    add_for_clearance(
        spec, clearance, name=name, journal_site=elements.journal_site, bearing_site=elements.bearing_site
    )
    elements.sensors = [ecc.name, name]
