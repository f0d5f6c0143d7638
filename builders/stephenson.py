"""Stephenson six-bar linkages: type I (plain and with slider) and type II (1) and (2).

In Stephenson's chain the two ternary links are not joined directly. Textbooks number its
inversions differently; here they are defined by the fixed link (the numbering we recall
from the kinematic-synthesis literature, not checked against a textbook): type I fixes a
binary link that joins both ternaries, type II fixes a ternary link, type III a binary
link next to one ternary only. Inputs, outputs, sliders and the
variants (1) and (2) are the project's own choices (Alok, Chaudhary and Guha 2020,
docs/references.md, show them only in figures we do not have):

* Stephenson I: ternary crank 2 and ternary rocker 4 both pivot on the ground; coupler 3
  closes the four-bar, the dyad 5-6 joins crank and rocker. With slider: rocker 4 becomes
  a ternary slider on a horizontal guide.
* Stephenson II (1): a crank-rocker four-bar whose coupler point drives the dyad 5-6 to the
  output rocker 6 (all loops solvable dyad by dyad).
* Stephenson II (2): the crank drives, through rod 3, the ternary coupler 4 of a
  double-rocker 5-4-6; the output is rocker 5 (a three-link Assur group, not solvable
  dyad by dyad).

Dimensions are the project's own, bench size like the classic slider-crank (crank 30-40
mm, links 100-220 mm); the four-bar loop is the catalogue's crank-rocker, and the dyads
were chosen by a grid search over arm angles and lengths for the transmission angle
farthest from 0 and 180 deg over the whole revolution (see docs/catalogue/catalogue.md).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Unpack

from clearance.builders._contact import ClearanceFactory, ContactKeywords, contact_keywords
from clearance.builders._linkage import (
    DEFAULT_LINEAR_DENSITY as _LAM,
)
from clearance.builders._linkage import (
    LinkageInfo,
    advance,
    angle_of,
    bar_link,
    circle_circle,
    crank_mechanism,
    lengths,
    polar,
    positive,
    slider_link,
)
from clearance.builders._loops import (
    coupler_bars,
    coupler_point,
    crank_rocker,
    crank_rocker_joints,
    slider_crank_joints,
    slider_crank_loop,
)
from clearance.builders.slider_crank import rpm
from clearance.kinematics import TransmissionAngle as _T
from clearance.model import Link, Mechanism, Output, OutputKind

__all__ = [
    "stephenson_i",
    "stephenson_i_slider",
    "stephenson_ii_1",
    "stephenson_ii_2",
    "STEPHENSON_I_INFO",
    "STEPHENSON_I_SLIDER_INFO",
    "STEPHENSON_II_1_INFO",
    "STEPHENSON_II_2_INFO",
]

_OWN = "project's own dimensions (grid search for the best transmission angle of the dyads)"

STEPHENSON_I_INFO = LinkageInfo(
    topology="Stephenson I: ground 1 (binary: O2, O4), ternary crank 2 (O2, A, E; driven), coupler 3 "
    "(A-B), ternary rocker 4 (O4, B, F; output: its angle), link 5 (E-G), link 6 (G-F).",
    driven=("O2",),
    output_pivot="O4",
    clearable=("A", "B", "O4", "E", "G", "F"),
    criticality=("A", "B", "E", "G", "F"),
    transmission=(
        _T("B", ("coupler3", "A"), follower=("rocker4", "O4")),
        _T("G", ("link5", "E"), follower=("link6", "F")),
    ),
    provenance=_OWN,
)
STEPHENSON_I_SLIDER_INFO = LinkageInfo(
    topology="Stephenson I with slider: ground 1 (binary: O2, guide P4), ternary crank 2 (O2, A, E; "
    "driven), rod 3 (A-B), ternary slider 4 (pins B, F; horizontal guide; output: its x), "
    "link 5 (E-G), link 6 (G-F).",
    driven=("O2",),
    output_pivot="P4",
    sliders=("P4",),
    clearable=("A", "B", "E", "G", "F"),
    criticality=("A", "B", "E", "G", "F"),
    transmission=(_T("B", ("rod3", "A"), guide="P4"), _T("G", ("link5", "E"), follower=("link6", "F"))),
    provenance=_OWN,
)
STEPHENSON_II_1_INFO = LinkageInfo(
    topology="Stephenson II (1): ground 1 (ternary: O2, O4, O6), crank 2 (O2-A, driven), ternary "
    "coupler 3 (A, B, C), rocker 4 (O4-B), link 5 (C-D), rocker 6 (O6-D, output: its angle).",
    driven=("O2",),
    output_pivot="O6",
    clearable=("A", "B", "O4", "C", "D", "O6"),
    criticality=("A", "B", "O4", "C", "D"),
    transmission=(
        _T("B", ("coupler3", "A"), follower=("rocker4", "O4")),
        _T("D", ("link5", "C"), follower=("rocker6", "O6")),
    ),
    provenance=_OWN,
)
STEPHENSON_II_2_INFO = LinkageInfo(
    topology="Stephenson II (2): ground 1 (ternary: O2, O5, O6), crank 2 (O2-A, driven), rod 3 (A-B), "
    "ternary coupler 4 (B, C, D), rocker 5 (O5-C, output: its angle), rocker 6 (O6-D).",
    driven=("O2",),
    output_pivot="O5",
    clearable=("A", "B", "C", "O5", "D", "O6"),
    criticality=("A", "B", "C", "D", "O6"),
    transmission=(
        _T("C", ("coupler4", "D"), follower=("rocker5", "O5")),
        _T("D", ("coupler4", "C"), follower=("rocker6", "O6")),
    ),
    provenance=_OWN + "; near-parallelogram double rocker with the rod along the coupler",
)


@contact_keywords(clearance_at=("B",))
def stephenson_i(
    *,
    crank_length: float = 0.04,
    crank_arm: float = 0.03,
    crank_arm_angle: float = math.radians(-45.0),
    coupler3_length: float = 0.13,
    rocker4_length: float = 0.10,
    ground_length: float = 0.13,
    rocker4_arm: float = 0.07,
    rocker4_arm_angle: float = math.radians(-60.0),
    link5_length: float = 0.14,
    link6_length: float = 0.12,
    linear_density: float = _LAM,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the Stephenson I six-bar (four-bar plus a dyad from crank to rocker).

    Output ``rocker_angle``: angle of rocker 4 (O4 -> B) from +x [rad].

    Args:
        crank_length, coupler3_length, rocker4_length, ground_length: four-bar O2-A, A-B,
            O4-B, O2-O4 [m].
        crank_arm, crank_arm_angle: O2-E [m] and angle from O2->A to O2->E [rad].
        rocker4_arm, rocker4_arm_angle: O4-F [m] and angle from O4->B to O4->F [rad].
        link5_length, link6_length: E-G, G-F [m].
        linear_density: mass per length of the steel bars [kg/m].
        crank_speed: constant crank speed [rad/s] (default 1000 rpm).
        start_angle: crank angle at t = 0 [rad] from +x.
        clearance_at, radial_clearance, bearing_radius, restitution, friction, law,
            material, gravity, name: the contact keywords (`ContactKeywords`);
            ``clearance_at`` any of `STEPHENSON_I_INFO.clearable`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    dims: dict[str, Any] = lengths(
        crank_length=crank_length,
        crank_arm=crank_arm,
        coupler3_length=coupler3_length,
        rocker4_length=rocker4_length,
        ground_length=ground_length,
        rocker4_arm=rocker4_arm,
        link5_length=link5_length,
        link6_length=link6_length,
    )
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(STEPHENSON_I_INFO.clearable, contact)
    p = crank_rocker(crank_length, coupler3_length, rocker4_length, ground_length, start_angle)
    o2, o4, pa, pb = p["O2"], p["O4"], p["A"], p["B"]
    pe = polar(o2, crank_arm, start_angle + crank_arm_angle)
    pf = polar(o4, rocker4_arm, angle_of(o4, pb) + rocker4_arm_angle)
    pg = circle_circle(pe, link5_length, pf, link6_length, left=False, what="link 5 / link 6")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": o2, "O4": o4}),
        bar_link("crank2", {"O2": o2, "A": pa, "E": pe}, density=lam, bars=[("O2", "A"), ("O2", "E")]),
        bar_link("coupler3", {"A": pa, "B": pb}, density=lam),
        bar_link("rocker4", {"O4": o4, "B": pb, "F": pf}, density=lam, bars=[("O4", "B"), ("O4", "F")]),
        bar_link("link5", {"E": pe, "G": pg}, density=lam),
        bar_link("link6", {"G": pg, "F": pf}, density=lam),
    )
    joints = (
        *crank_rocker_joints(clr),
        clr.pin("E", "crank2", "link5"),
        clr.pin("G", "link5", "link6"),
        clr.pin("F", "link6", "rocker4"),
    )
    dims.update(crank_arm_angle=float(crank_arm_angle), rocker4_arm_angle=float(rocker4_arm_angle))
    return crank_mechanism(
        clr,
        links,
        joints,
        Output("rocker_angle", "rocker4", OutputKind.ANGLE),
        dims,
        linear_density=lam,
        crank_speed=crank_speed,
        start_angle=start_angle,
    )


@contact_keywords(clearance_at=("B",))
def stephenson_i_slider(
    *,
    crank_length: float = 0.04,
    crank_arm: float = 0.03,
    crank_arm_angle: float = math.radians(-45.0),
    rod3_length: float = 0.13,
    slider_pin_offset: tuple[float, float] = (0.0, -0.05),
    link5_length: float = 0.10,
    link6_length: float = 0.10,
    slider_mass: float = 0.2,
    slider_inertia: float = 3.3e-5,
    linear_density: float = _LAM,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the Stephenson I six-bar with an output slider (in-line, on the x axis).

    Output ``slider_x``: x position of the slider pin B [m].

    Args:
        crank_length, rod3_length: O2-A, A-B [m].
        crank_arm, crank_arm_angle: O2-E [m] and angle from O2->A to O2->E [rad].
        slider_pin_offset: F relative to B on the slider (x, y) [m].
        link5_length, link6_length: E-G, G-F [m].
        slider_mass: [kg]; slider_inertia: [kg m^2] (a 40 mm x 20 mm steel block).
        linear_density, crank_speed, start_angle, clearance_at, radial_clearance,
            bearing_radius, restitution, friction, law, material, gravity, name: as in
            `stephenson_i`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    dims: dict[str, Any] = lengths(
        crank_length=crank_length,
        crank_arm=crank_arm,
        rod3_length=rod3_length,
        link5_length=link5_length,
        link6_length=link6_length,
    )
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(STEPHENSON_I_SLIDER_INFO.clearable, contact, sliders=STEPHENSON_I_SLIDER_INFO.sliders)
    off = (float(slider_pin_offset[0]), float(slider_pin_offset[1]))
    p = slider_crank_loop(crank_length, rod3_length, start_angle, pin="F", offset=off)
    o2, pa, pb, pf = p["O2"], p["A"], p["B"], p["F"]
    pe = polar(o2, crank_arm, start_angle + crank_arm_angle)
    pg = circle_circle(pe, link5_length, pf, link6_length, left=False, what="link 5 / link 6")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": o2, "G4": (rod3_length, 0.0)}),
        bar_link("crank2", {"O2": o2, "A": pa, "E": pe}, density=lam, bars=[("O2", "A"), ("O2", "E")]),
        bar_link("rod3", {"A": pa, "B": pb}, density=lam),
        slider_link("slider4", {"B": pb, "F": pf}, mass=ms, inertia=js),
        bar_link("link5", {"E": pe, "G": pg}, density=lam),
        bar_link("link6", {"G": pg, "F": pf}, density=lam),
    )
    joints = (
        *slider_crank_joints(clr),
        clr.pin("E", "crank2", "link5"),
        clr.pin("G", "link5", "link6"),
        clr.pin("F", "link6", "slider4"),
    )
    dims.update(crank_arm_angle=float(crank_arm_angle), slider_pin_offset=list(off), slider_mass=ms, slider_inertia=js)
    return crank_mechanism(
        clr,
        links,
        joints,
        Output("slider_x", "slider4", OutputKind.POSITION_X, point="B"),
        dims,
        linear_density=lam,
        crank_speed=crank_speed,
        start_angle=start_angle,
    )


@contact_keywords(clearance_at=("D",))
def stephenson_ii_1(
    *,
    crank_length: float = 0.04,
    coupler3_length: float = 0.13,
    rocker4_length: float = 0.10,
    ground_length: float = 0.13,
    coupler3_point: tuple[float, float] = (0.16, 0.0),
    link5_length: float = 0.16,
    rocker6_length: float = 0.10,
    rocker6_pivot: tuple[float, float] = (0.21, -0.05),
    linear_density: float = _LAM,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build Stephenson II (1): a crank-rocker whose coupler point drives a dyad to rocker 6.

    Output ``rocker_angle``: angle of rocker 6 (O6 -> D) from +x [rad].

    Args:
        crank_length, coupler3_length, rocker4_length, ground_length: four-bar [m].
        coupler3_point: C in the coupler frame (origin A, x towards B) [m].
        link5_length, rocker6_length: C-D, O6-D [m].
        rocker6_pivot: O6 (x, y) [m].
        linear_density, crank_speed, start_angle, clearance_at, radial_clearance,
            bearing_radius, restitution, friction, law, material, gravity, name: as in
            `stephenson_i`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    dims: dict[str, Any] = lengths(
        crank_length=crank_length,
        coupler3_length=coupler3_length,
        rocker4_length=rocker4_length,
        ground_length=ground_length,
        link5_length=link5_length,
        rocker6_length=rocker6_length,
    )
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(STEPHENSON_II_1_INFO.clearable, contact)
    o6 = (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    p = crank_rocker(crank_length, coupler3_length, rocker4_length, ground_length, start_angle)
    o2, o4, pa, pb = p["O2"], p["O4"], p["A"], p["B"]
    u, v = float(coupler3_point[0]), float(coupler3_point[1])
    pc = coupler_point(p, (u, v))
    pd = circle_circle(pc, link5_length, o6, rocker6_length, left=True, what="link 5 / rocker 6")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": o2, "O4": o4, "O6": o6}),
        bar_link("crank2", {"O2": o2, "A": pa}, density=lam),
        bar_link("coupler3", {"A": pa, "B": pb, "C": pc}, density=lam, bars=coupler_bars((u, v))),
        bar_link("rocker4", {"O4": o4, "B": pb}, density=lam),
        bar_link("link5", {"C": pc, "D": pd}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd}, density=lam),
    )
    joints = (
        *crank_rocker_joints(clr),
        clr.pin("C", "coupler3", "link5"),
        clr.pin("D", "link5", "rocker6"),
        clr.pin("O6", "ground", "rocker6"),
    )
    dims.update(coupler3_point=[u, v], rocker6_pivot=list(o6))
    return crank_mechanism(
        clr,
        links,
        joints,
        Output("rocker_angle", "rocker6", OutputKind.ANGLE),
        dims,
        linear_density=lam,
        crank_speed=crank_speed,
        start_angle=start_angle,
    )


@contact_keywords(clearance_at=("B",))
def stephenson_ii_2(
    *,
    crank_length: float = 0.03,
    rod3_length: float = 0.22,
    coupler4_length: float = 0.10,
    coupler4_point: tuple[float, float] = (0.05, -0.03),
    rocker5_length: float = 0.10,
    rocker6_length: float = 0.12,
    rocker5_pivot: tuple[float, float] = (0.20, 0.10),
    rocker6_pivot: tuple[float, float] = (0.30, 0.12),
    linear_density: float = _LAM,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build Stephenson II (2): crank and rod drive the coupler of a double rocker.

    At crank angle 0 the coupler 4 (C-D) hangs horizontally below the pivots O5 and O6;
    the assembly at ``start_angle`` follows that branch. Output ``rocker_angle``: angle of
    rocker 5 (O5 -> C) from +x [rad].

    Args:
        crank_length, rod3_length: O2-A, A-B [m].
        coupler4_length: C-D [m].
        coupler4_point: B in the coupler frame (origin C, x towards D) [m].
        rocker5_length, rocker6_length: O5-C, O6-D [m].
        rocker5_pivot, rocker6_pivot: O5 and O6 (x, y) [m].
        linear_density, crank_speed, start_angle, clearance_at, radial_clearance,
            bearing_radius, restitution, friction, law, material, gravity, name: as in
            `stephenson_i`.

    Raises:
        ValueError: a value out of range or an unknown clearance joint.
        AssemblyError: the loops cannot be closed, or the start position is singular.
    """
    dims: dict[str, Any] = lengths(
        crank_length=crank_length,
        rod3_length=rod3_length,
        coupler4_length=coupler4_length,
        rocker5_length=rocker5_length,
        rocker6_length=rocker6_length,
    )
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(STEPHENSON_II_2_INFO.clearable, contact)
    o2 = (0.0, 0.0)
    o5, o6 = (float(rocker5_pivot[0]), float(rocker5_pivot[1])), (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    # rough pose at crank angle 0 (rockers hanging down, coupler horizontal); Newton closes it
    pc = (o5[0], o5[1] - rocker5_length)
    pd = (pc[0] + coupler4_length, pc[1])
    u, v = float(coupler4_point[0]), float(coupler4_point[1])
    pb = (pc[0] + u, pc[1] + v)
    pa = (crank_length, 0.0)
    links = (
        Link("ground", 0.0, 0.0, points={"O2": o2, "O5": o5, "O6": o6}),
        bar_link("crank2", {"O2": o2, "A": pa}, density=lam),
        bar_link("rod3", {"A": pa, "B": pb}, density=lam),
        bar_link("coupler4", {"C": pc, "D": pd, "B": pb}, density=lam),
        bar_link("rocker5", {"O5": o5, "C": pc}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd}, density=lam),
    )
    # the rough pose fixes the lengths of rod 3 and rocker 6 only approximately: set them exactly
    links = (
        *links[:2],
        _resized(links[2], "A", "B", rod3_length, lam),
        *links[3:5],
        _resized(links[5], "O6", "D", rocker6_length, lam),
    )
    joints = (
        clr.pin("O2", "ground", "crank2"),
        clr.pin("A", "crank2", "rod3"),
        clr.pin("B", "rod3", "coupler4"),
        clr.pin("C", "coupler4", "rocker5"),
        clr.pin("O5", "ground", "rocker5"),
        clr.pin("D", "coupler4", "rocker6"),
        clr.pin("O6", "ground", "rocker6"),
    )
    dims.update(coupler4_point=[u, v], rocker5_pivot=list(o5), rocker6_pivot=list(o6))
    mech = crank_mechanism(
        clr,
        links,
        joints,
        Output("rocker_angle", "rocker5", OutputKind.ANGLE),
        dims,
        linear_density=lam,
        crank_speed=crank_speed,
        start_angle=0.0,
    )
    mech = advance(mech, float(start_angle))
    return _with_params(mech, start_angle=float(start_angle))


def _resized(link: Link, p0: str, p1: str, length: float, lam: float) -> Link:
    """A two-point bar link with its second point moved to ``length`` along its x axis."""
    x, y, th = link.pose_guess
    return bar_link(link.name, {p0: (x, y), p1: (x + length * math.cos(th), y + length * math.sin(th))}, density=lam)


def _with_params(mech: Mechanism, **changes: Any) -> Mechanism:
    return dataclasses.replace(mech, parameters={**mech.parameters, **changes})
