"""An eight-bar and a ten-bar linkage (1 DOF, revolute and prismatic pairs).

Both topologies and all dimensions are the project's own: Alok, Chaudhary and Guha 2020
(docs/references.md) show their eight- and ten-bar only in figures we do not have. Both
start from the catalogue's crank-rocker four-bar (crank 40 mm, coupler 130 mm, rocker 100 mm,
ground 130 mm) and grow by dyads, so that every loop is closed dyad by dyad, and both end in
a slider:

* eight-bar (8 links, 10 joints): the Stephenson II (1) six-bar (coupler point C drives
  link 5 and ternary rocker 6), whose rocker arm E drives rod 7 and slider 8;
* ten-bar (10 links, 13 joints): the four-bar's coupler point C drives link 5 and ternary
  rocker 6; the dyad 7-8 joins the ternary rocker 4 (arm D) to rocker 6 (arm F); the
  ternary link 8 drives rod 9 and slider 10.

Arm angles, lengths and pivots were picked by grid searches for transmission angles far
from 0 and 180 deg over the whole revolution (docs/catalogue/catalogue.md lists them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Unpack

from clearance.builders._contact import ClearanceFactory, ContactKeywords, contact_keywords
from clearance.builders._linkage import (
    DEFAULT_LINEAR_DENSITY as _LAM,
)
from clearance.builders._linkage import (
    LinkageInfo,
    Point,
    angle_of,
    bar_link,
    circle_circle,
    crank_mechanism,
    frame_point,
    lengths,
    line_circle,
    polar,
    positive,
    slider_link,
)
from clearance.builders._loops import coupler_bars, coupler_point, crank_rocker, crank_rocker_joints
from clearance.builders.slider_crank import rpm
from clearance.kinematics import TransmissionAngle as _T
from clearance.model import Joint, Link, Mechanism, Output, OutputKind

__all__ = ["eight_bar", "ten_bar", "EIGHT_BAR_INFO", "TEN_BAR_INFO"]

_OWN = "project's own topology and dimensions (grid search for the best transmission angles)"

EIGHT_BAR_INFO = LinkageInfo(
    topology="Eight-bar: ground 1 (O2, O4, O6, guide P8), crank 2 (O2-A, driven), ternary coupler 3 "
    "(A, B, C), rocker 4 (O4-B), link 5 (C-D), ternary rocker 6 (O6, D, E), rod 7 (E-F), "
    "slider 8 (F, horizontal guide; output: its x).",
    driven=("O2",),
    output_pivot="P8",
    sliders=("P8",),
    clearable=("A", "B", "O4", "C", "D", "O6", "E", "F"),
    criticality=("A", "B", "O4", "C", "D", "O6", "E", "F"),
    transmission=(
        _T("B", ("coupler3", "A"), follower=("rocker4", "O4")),
        _T("D", ("link5", "C"), follower=("rocker6", "O6")),
        _T("F", ("rod7", "E"), guide="P8"),
    ),
    provenance=_OWN,
)
TEN_BAR_INFO = LinkageInfo(
    topology="Ten-bar: ground 1 (O2, O4, O6, guide P10), crank 2 (O2-A, driven), ternary coupler 3 "
    "(A, B, C), ternary rocker 4 (O4, B, D), link 5 (C-E), ternary rocker 6 (O6, E, F), link 7 "
    "(D-G), ternary link 8 (F, G, H), rod 9 (H-I), slider 10 (I, horizontal guide; output: its x).",
    driven=("O2",),
    output_pivot="P10",
    sliders=("P10",),
    clearable=("A", "B", "O4", "C", "E", "O6", "D", "G", "F", "H", "I"),
    criticality=("A", "B", "O4", "C", "E", "O6", "D", "G", "F", "H", "I"),
    transmission=(
        _T("B", ("coupler3", "A"), follower=("rocker4", "O4")),
        _T("E", ("link5", "C"), follower=("rocker6", "O6")),
        _T("G", ("link7", "D"), follower=("link8", "F")),
        _T("I", ("rod9", "H"), guide="P10"),
    ),
    provenance=_OWN,
)


@dataclass(frozen=True)
class _Opening:
    """What the eight- and ten-bar builders open with.

    Attributes:
        dims: the checked lengths by keyword [m] (the first builder parameters).
        clr: the call's contact keywords.
        points: O2, O4, A, B, C of the four-bar and the pivot O6, at t = 0 [m].
        coupler3_point: C in the coupler frame [m].
        slider_mass, slider_inertia, linear_density: checked [kg, kg m^2, kg/m].
    """

    dims: dict[str, Any]
    clr: ClearanceFactory
    points: dict[str, Point]
    coupler3_point: Point
    slider_mass: float
    slider_inertia: float
    linear_density: float


def _open(
    info: LinkageInfo,
    contact: ContactKeywords,
    dims: dict[str, Any],
    *,
    coupler3_point: tuple[float, float],
    rocker6_pivot: tuple[float, float],
    slider_mass: float,
    slider_inertia: float,
    linear_density: float,
    start_angle: float,
) -> _Opening:
    """Check the other common arguments and assemble the four-bar with coupler point C at t = 0.

    Args:
        info: the builder's linkage.
        contact: the call's contact keywords.
        dims: the builder's checked lengths (`lengths`) [m].
        coupler3_point, rocker6_pivot, slider_mass, slider_inertia, linear_density,
            start_angle: the builder's arguments.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or a four-bar that
            does not close at the start angle.
    """
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(info.clearable, contact, sliders=info.sliders)
    cp = (float(coupler3_point[0]), float(coupler3_point[1]))
    p = crank_rocker(
        dims["crank_length"], dims["coupler3_length"], dims["rocker4_length"], dims["ground_length"], start_angle
    )
    p["C"] = coupler_point(p, cp)
    p["O6"] = (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    return _Opening(dims, clr, p, cp, ms, js, lam)


def _four_bar_joints(clr: ClearanceFactory) -> tuple[Joint, ...]:
    """The joints of the four-bar (O2, A, B, O4) and of coupler point C to link 5."""
    return (*crank_rocker_joints(clr), clr.pin("C", "coupler3", "link5"))


def _close(
    o: _Opening,
    links: Sequence[Link],
    joints: Sequence[Joint],
    own: Mapping[str, Any],
    guide_height: float,
    slider: str,
    pin: str,
    crank_speed: float,
    start_angle: float,
) -> Mechanism:
    """The mechanism, whose output is the x position of ``pin`` of link ``slider`` [m].

    Args:
        o: the opening.
        links, joints: the mechanism's.
        own: the builder's parameters between ``coupler3_point`` and ``guide_height``.
        guide_height: y of the horizontal guide [m].
        slider, pin: the output slider and its pin.
        crank_speed, start_angle: of the crank [rad/s, rad].
    """
    dims = {
        **o.dims,
        "coupler3_point": list(o.coupler3_point),
        **own,
        "guide_height": float(guide_height),
        "slider_mass": o.slider_mass,
        "slider_inertia": o.slider_inertia,
    }
    output = Output("slider_x", slider, OutputKind.POSITION_X, point=pin)
    return crank_mechanism(
        o.clr,
        links,
        joints,
        output,
        dims,
        linear_density=o.linear_density,
        crank_speed=crank_speed,
        start_angle=start_angle,
    )


@contact_keywords(clearance_at=("D",))
def eight_bar(
    *,
    crank_length: float = 0.04,
    coupler3_length: float = 0.13,
    rocker4_length: float = 0.10,
    ground_length: float = 0.13,
    coupler3_point: tuple[float, float] = (0.16, 0.0),
    link5_length: float = 0.16,
    rocker6_length: float = 0.10,
    rocker6_pivot: tuple[float, float] = (0.21, -0.05),
    rocker6_arm: float = 0.08,
    rocker6_arm_angle: float = math.radians(-142.0),
    rod7_length: float = 0.12,
    guide_height: float = -0.13,
    slider_mass: float = 0.2,
    slider_inertia: float = 3.3e-5,
    linear_density: float = _LAM,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the eight-bar: Stephenson II (1) plus rod 7 and an output slider.

    Output ``slider_x``: x position of the slider pin F [m] on the guide y = ``guide_height``.

    Args:
        crank_length, coupler3_length, rocker4_length, ground_length: four-bar [m].
        coupler3_point: C in the coupler frame (origin A, x towards B) [m].
        link5_length, rocker6_length: C-D, O6-D [m]; rocker6_pivot: O6 (x, y) [m].
        rocker6_arm, rocker6_arm_angle: O6-E [m] and angle from O6->D to O6->E [rad].
        rod7_length: E-F [m]; guide_height: y of the horizontal guide [m].
        slider_mass: [kg]; slider_inertia: [kg m^2].
        linear_density: mass per length of the steel bars [kg/m].
        crank_speed: constant crank speed [rad/s] (default 1000 rpm).
        start_angle: crank angle at t = 0 [rad] from +x.
        clearance_at, radial_clearance, bearing_radius, restitution, friction, law,
            material, gravity, name: the contact keywords (`ContactKeywords`);
            ``clearance_at`` any of `EIGHT_BAR_INFO.clearable`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    o = _open(
        EIGHT_BAR_INFO,
        contact,
        lengths(
            crank_length=crank_length,
            coupler3_length=coupler3_length,
            rocker4_length=rocker4_length,
            ground_length=ground_length,
            link5_length=link5_length,
            rocker6_length=rocker6_length,
            rocker6_arm=rocker6_arm,
            rod7_length=rod7_length,
        ),
        coupler3_point=coupler3_point,
        rocker6_pivot=rocker6_pivot,
        slider_mass=slider_mass,
        slider_inertia=slider_inertia,
        linear_density=linear_density,
        start_angle=start_angle,
    )
    p, cp, lam, clr = o.points, o.coupler3_point, o.linear_density, o.clr
    o6 = p["O6"]
    pd = circle_circle(p["C"], link5_length, o6, rocker6_length, left=True, what="link 5 / rocker 6")
    pe = polar(o6, rocker6_arm, angle_of(o6, pd) + rocker6_arm_angle)
    g8 = (o6[0], float(guide_height))
    pf = line_circle(g8, (1.0, 0.0), pe, rod7_length, forward=True, what="rod 7 / slider 8")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"], "O6": o6, "G8": g8}),
        bar_link("crank2", {"O2": p["O2"], "A": p["A"]}, density=lam),
        bar_link(
            "coupler3",
            {"A": p["A"], "B": p["B"], "C": p["C"]},
            density=lam,
            bars=coupler_bars(cp),
        ),
        bar_link("rocker4", {"O4": p["O4"], "B": p["B"]}, density=lam),
        bar_link("link5", {"C": p["C"], "D": pd}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd, "E": pe}, density=lam, bars=[("O6", "D"), ("O6", "E")]),
        bar_link("rod7", {"E": pe, "F": pf}, density=lam),
        slider_link("slider8", {"F": pf}, mass=o.slider_mass, inertia=o.slider_inertia),
    )
    joints = (
        *_four_bar_joints(clr),
        clr.pin("D", "link5", "rocker6"),
        clr.pin("O6", "ground", "rocker6"),
        clr.pin("E", "rocker6", "rod7"),
        clr.pin("F", "rod7", "slider8"),
        clr.prismatic("P8", "ground", "G8", "slider8", "F", axis=(1.0, 0.0)),
    )
    own = {"rocker6_pivot": list(o6), "rocker6_arm_angle": float(rocker6_arm_angle)}
    return _close(o, links, joints, own, guide_height, "slider8", "F", crank_speed, start_angle)


@contact_keywords(clearance_at=("G",))
def ten_bar(
    *,
    crank_length: float = 0.04,
    coupler3_length: float = 0.13,
    rocker4_length: float = 0.10,
    ground_length: float = 0.13,
    coupler3_point: tuple[float, float] = (0.09, -0.04),
    rocker4_arm: float = 0.05,
    rocker4_arm_angle: float = math.radians(-150.0),
    link5_length: float = 0.12,
    rocker6_length: float = 0.08,
    rocker6_pivot: tuple[float, float] = (0.14, -0.10),
    rocker6_arm: float = 0.07,
    rocker6_arm_angle: float = math.radians(120.0),
    link7_length: float = 0.10,
    link8_length: float = 0.10,
    link8_point: tuple[float, float] = (0.0, 0.08),
    rod9_length: float = 0.10,
    guide_height: float = -0.224,
    slider_mass: float = 0.2,
    slider_inertia: float = 3.3e-5,
    linear_density: float = _LAM,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the ten-bar: four-bar, dyad 5-6 to ground, dyad 7-8 between the rockers, slider.

    Output ``slider_x``: x position of the slider pin I [m] on the guide y = ``guide_height``.

    Args:
        crank_length, coupler3_length, rocker4_length, ground_length: four-bar [m].
        coupler3_point: C in the coupler frame (origin A, x towards B) [m].
        rocker4_arm, rocker4_arm_angle: O4-D [m] and angle from O4->B to O4->D [rad].
        link5_length, rocker6_length: C-E, O6-E [m]; rocker6_pivot: O6 (x, y) [m].
        rocker6_arm, rocker6_arm_angle: O6-F [m] and angle from O6->E to O6->F [rad].
        link7_length, link8_length: D-G, F-G [m].
        link8_point: H in the frame of link 8 (origin F, x towards G) [m].
        rod9_length: H-I [m]; guide_height: y of the horizontal guide [m].
        slider_mass: [kg]; slider_inertia: [kg m^2].
        linear_density, crank_speed, start_angle, clearance_at (any of
            `TEN_BAR_INFO.clearable`), radial_clearance, bearing_radius, restitution,
            friction, law, material, gravity, name: as in `eight_bar`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    o = _open(
        TEN_BAR_INFO,
        contact,
        lengths(
            crank_length=crank_length,
            coupler3_length=coupler3_length,
            rocker4_length=rocker4_length,
            ground_length=ground_length,
            rocker4_arm=rocker4_arm,
            link5_length=link5_length,
            rocker6_length=rocker6_length,
            rocker6_arm=rocker6_arm,
            link7_length=link7_length,
            link8_length=link8_length,
            rod9_length=rod9_length,
        ),
        coupler3_point=coupler3_point,
        rocker6_pivot=rocker6_pivot,
        slider_mass=slider_mass,
        slider_inertia=slider_inertia,
        linear_density=linear_density,
        start_angle=start_angle,
    )
    p, lam, clr = o.points, o.linear_density, o.clr
    o6 = p["O6"]
    pd = polar(p["O4"], rocker4_arm, angle_of(p["O4"], p["B"]) + rocker4_arm_angle)
    pe = circle_circle(p["C"], link5_length, o6, rocker6_length, left=False, what="link 5 / rocker 6")
    pf = polar(o6, rocker6_arm, angle_of(o6, pe) + rocker6_arm_angle)
    pg = circle_circle(pd, link7_length, pf, link8_length, left=False, what="link 7 / link 8")
    hu, hv = float(link8_point[0]), float(link8_point[1])
    ph = frame_point(pf, angle_of(pf, pg), (hu, hv))
    g10 = (o6[0], float(guide_height))
    pi_ = line_circle(g10, (1.0, 0.0), ph, rod9_length, forward=True, what="rod 9 / slider 10")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"], "O6": o6, "G10": g10}),
        bar_link("crank2", {"O2": p["O2"], "A": p["A"]}, density=lam),
        bar_link("coupler3", {"A": p["A"], "B": p["B"], "C": p["C"]}, density=lam),
        bar_link("rocker4", {"O4": p["O4"], "B": p["B"], "D": pd}, density=lam, bars=[("O4", "B"), ("O4", "D")]),
        bar_link("link5", {"C": p["C"], "E": pe}, density=lam),
        bar_link("rocker6", {"O6": o6, "E": pe, "F": pf}, density=lam, bars=[("O6", "E"), ("O6", "F")]),
        bar_link("link7", {"D": pd, "G": pg}, density=lam),
        bar_link("link8", {"F": pf, "G": pg, "H": ph}, density=lam),
        bar_link("rod9", {"H": ph, "I": pi_}, density=lam),
        slider_link("slider10", {"I": pi_}, mass=o.slider_mass, inertia=o.slider_inertia),
    )
    joints = (
        *_four_bar_joints(clr),
        clr.pin("E", "link5", "rocker6"),
        clr.pin("O6", "ground", "rocker6"),
        clr.pin("D", "rocker4", "link7"),
        clr.pin("G", "link7", "link8"),
        clr.pin("F", "rocker6", "link8"),
        clr.pin("H", "link8", "rod9"),
        clr.pin("I", "rod9", "slider10"),
        clr.prismatic("P10", "ground", "G10", "slider10", "I", axis=(1.0, 0.0)),
    )
    own = {
        "rocker4_arm_angle": float(rocker4_arm_angle),
        "rocker6_pivot": list(o6),
        "rocker6_arm_angle": float(rocker6_arm_angle),
        "link8_point": [hu, hv],
    }
    return _close(o, links, joints, own, guide_height, "slider10", "I", crank_speed, start_angle)
