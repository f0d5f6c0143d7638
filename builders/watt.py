"""Watt six-bar linkages: plain, with an output slider (1), with an intermediate slider (2).

All three are Watt II inversions of Watt's chain (the two ternary links share a joint; here
the ternary ground and a ternary rocker or slider): two four-bar loops in series, the first
driven by the crank, the second by the first loop's ternary output link. Which inversion
and where the sliders sit are the project's own choices (Alok, Chaudhary and Guha 2020,
docs/references.md, define the variants only in figures we do not have).

Dimensions are the project's own, of bench size like the classic slider-crank: the first
loop is the catalogue's crank-rocker four-bar (crank 40 mm, coupler 130 mm, rocker 100 mm,
ground 130 mm; transmission angle 44-95 deg) or an in-line slider-crank of the same crank
and rod; the second loop is laid out so that at mid-swing its coupler is perpendicular to
both of its rockers (or along the guide), which keeps every transmission angle within
about 90 +- 35 deg.
"""

from __future__ import annotations

import math
from typing import Any, Unpack

from clearance.builders._contact import ClearanceFactory, ContactKeywords, contact_keywords
from clearance.builders._linkage import (
    DEFAULT_LINEAR_DENSITY,
    LinkageInfo,
    Point,
    angle_of,
    bar_link,
    circle_circle,
    crank_mechanism,
    line_circle,
    polar,
    positive,
    slider_link,
)
from clearance.builders._loops import crank_rocker, crank_rocker_joints, slider_crank_joints, slider_crank_loop
from clearance.builders.slider_crank import rpm
from clearance.kinematics import TransmissionAngle
from clearance.model import Joint, Link, Mechanism, Output, OutputKind

__all__ = [
    "watt_six_bar",
    "watt_six_bar_slider_1",
    "watt_six_bar_slider_2",
    "WATT_INFO",
    "WATT_SLIDER_1_INFO",
    "WATT_SLIDER_2_INFO",
]

_OWN = "project's own dimensions (first loop = catalogue four-bar or slider-crank; second loop "
_T_B = TransmissionAngle("B", ("coupler3", "A"), follower=("rocker4", "O4"))

WATT_INFO = LinkageInfo(
    topology=(
        "Watt II: ground 1 (ternary: O2, O4, O6), crank 2 (O2-A, driven), coupler 3 (A-B), "
        "ternary rocker 4 (O4, B, C), coupler 5 (C-D), rocker 6 (O6-D, output: its angle)."
    ),
    driven=("O2",),
    output_pivot="O6",
    clearable=("A", "B", "O4", "C", "D", "O6"),
    criticality=("A", "B", "O4", "C", "D"),
    transmission=(_T_B, TransmissionAngle("D", ("coupler5", "C"), follower=("rocker6", "O6"))),
    provenance=_OWN + "with both rockers perpendicular to its coupler at mid-swing)",
)

WATT_SLIDER_1_INFO = LinkageInfo(
    topology=(
        "Watt II with output slider: ground 1 (O2, O4, guide P6), crank 2 (O2-A, driven), "
        "coupler 3 (A-B), ternary rocker 4 (O4, B, C), rod 5 (C-D), slider 6 (D, on a "
        "horizontal guide; output: its x position)."
    ),
    driven=("O2",),
    output_pivot="P6",
    sliders=("P6",),
    clearable=("A", "B", "O4", "C", "D"),
    criticality=("A", "B", "O4", "C", "D"),
    transmission=(_T_B, TransmissionAngle("D", ("rod5", "C"), guide="P6")),
    provenance=_OWN + "a rocker-slider with the rod along the guide at mid-stroke)",
)

WATT_SLIDER_2_INFO = LinkageInfo(
    topology=(
        "Watt II with intermediate slider: ground 1 (O2, guide P4, O6), crank 2 (O2-A, "
        "driven), rod 3 (A-B), ternary slider 4 (pins B and C, horizontal guide), coupler 5 "
        "(C-D), rocker 6 (O6-D, output: its angle)."
    ),
    driven=("O2",),
    output_pivot="O6",
    sliders=("P4",),
    clearable=("A", "B", "C", "D", "O6"),
    criticality=("A", "B", "C", "D"),
    transmission=(
        TransmissionAngle("B", ("rod3", "A"), guide="P4"),
        TransmissionAngle("D", ("coupler5", "C"), follower=("rocker6", "O6")),
    ),
    provenance=_OWN + "a slider-rocker with the rocker across the coupler at mid-stroke)",
)


def _loop1_lengths(crank: float, coupler3: float, rocker4: float, ground: float) -> tuple[float, float, float, float]:
    """The checked lengths [m] of loop 1 of the plain Watt and slider (1)."""
    return (
        positive("crank_length", crank),
        positive("coupler3_length", coupler3),
        positive("rocker4_length", rocker4),
        positive("ground_length", ground),
    )


def _loop1(
    a: float, b: float, c: float, d: float, e: float, arm_angle: float, th: float, lam: float
) -> tuple[list[Link], dict[str, Point]]:
    """Loop 1 of the plain Watt and slider (1): crank 2, coupler 3, ternary rocker 4 (O4, B, C)."""
    p = crank_rocker(a, b, c, d, th)
    p["C"] = polar(p["O4"], e, angle_of(p["O4"], p["B"]) + arm_angle)
    return [
        bar_link("crank2", {"O2": p["O2"], "A": p["A"]}, density=lam),
        bar_link("coupler3", {"A": p["A"], "B": p["B"]}, density=lam),
        bar_link("rocker4", {"O4": p["O4"], "B": p["B"], "C": p["C"]}, density=lam),
    ], p


def _loop1_joints(clr: ClearanceFactory, link5: str) -> tuple[Joint, ...]:
    """The joints of loop 1 (O2, A, B, O4) and of rocker 4's arm C to ``link5``."""
    return (*crank_rocker_joints(clr), clr.pin("C", "rocker4", link5))


@contact_keywords(clearance_at=("D",))
def watt_six_bar(
    *,
    crank_length: float = 0.04,
    coupler3_length: float = 0.13,
    rocker4_length: float = 0.10,
    ground_length: float = 0.13,
    rocker4_arm: float = 0.07,
    rocker4_arm_angle: float = math.radians(160.0),
    coupler5_length: float = 0.14,
    rocker6_length: float = 0.05,
    rocker6_pivot: tuple[float, float] = (0.27, -0.02),
    linear_density: float = DEFAULT_LINEAR_DENSITY,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the plain Watt II six-bar (two crank-rocker loops in series).

    O2 is at the origin, O4 on +x; output ``rocker_angle`` is the angle of rocker 6
    (O6 -> D) from +x [rad].

    Args:
        crank_length, coupler3_length, rocker4_length, ground_length: loop 1, O2-A, A-B,
            O4-B, O2-O4 [m].
        rocker4_arm: O4-C [m].
        rocker4_arm_angle: angle from O4->B to O4->C, counter-clockwise [rad].
        coupler5_length, rocker6_length: C-D, O6-D [m].
        rocker6_pivot: O6 (x, y) [m].
        linear_density: mass per length of the steel bars [kg/m].
        crank_speed: constant crank speed [rad/s] (default 1000 rpm).
        start_angle: crank angle at t = 0 [rad] from +x.
        clearance_at, radial_clearance, bearing_radius, restitution, friction, law,
            material, gravity, name: the contact keywords (`ContactKeywords`);
            ``clearance_at`` any of A, B, O4, C, D, O6.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    a, b, c, d = _loop1_lengths(crank_length, coupler3_length, rocker4_length, ground_length)
    e, f, g = (
        positive(n, v)
        for n, v in (
            ("rocker4_arm", rocker4_arm),
            ("coupler5_length", coupler5_length),
            ("rocker6_length", rocker6_length),
        )
    )
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(WATT_INFO.clearable, contact)
    loop1, p = _loop1(a, b, c, d, e, rocker4_arm_angle, start_angle, lam)
    o6 = (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    pd = circle_circle(p["C"], f, o6, g, left=False, what="coupler 5 / rocker 6")
    links = [
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"], "O6": o6}),
        *loop1,
        bar_link("coupler5", {"C": p["C"], "D": pd}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd}, density=lam),
    ]
    joints = (
        *_loop1_joints(clr, "coupler5"),
        clr.pin("D", "coupler5", "rocker6"),
        clr.pin("O6", "ground", "rocker6"),
    )
    dims: dict[str, Any] = {
        "crank_length": a,
        "coupler3_length": b,
        "rocker4_length": c,
        "ground_length": d,
        "rocker4_arm": e,
        "rocker4_arm_angle": float(rocker4_arm_angle),
        "coupler5_length": f,
        "rocker6_length": g,
        "rocker6_pivot": list(o6),
    }
    output = Output("rocker_angle", "rocker6", OutputKind.ANGLE)
    return crank_mechanism(
        clr, links, joints, output, dims, linear_density=lam, crank_speed=crank_speed, start_angle=start_angle
    )


@contact_keywords(clearance_at=("D",))
def watt_six_bar_slider_1(
    *,
    crank_length: float = 0.04,
    coupler3_length: float = 0.13,
    rocker4_length: float = 0.10,
    ground_length: float = 0.13,
    rocker4_arm: float = 0.07,
    rocker4_arm_angle: float = math.radians(160.0),
    rod5_length: float = 0.14,
    guide_height: float = -0.07,
    slider_mass: float = 0.2,
    slider_inertia: float = 3.3e-5,
    linear_density: float = DEFAULT_LINEAR_DENSITY,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the Watt II six-bar whose output is a slider driven by the ternary rocker.

    Output ``slider_x`` is the x position of the slider pin D [m]; the guide is the line
    y = ``guide_height``.

    Args:
        crank_length, coupler3_length, rocker4_length, ground_length: loop 1 [m].
        rocker4_arm: O4-C [m]; rocker4_arm_angle: angle from O4->B to O4->C [rad].
        rod5_length: C-D [m].
        guide_height: y of the horizontal slider guide [m].
        slider_mass: [kg]; slider_inertia: [kg m^2] (a 40 mm x 20 mm steel block).
        linear_density, crank_speed, start_angle, clearance_at (any of A, B, O4, C, D),
            radial_clearance, bearing_radius, restitution, friction, law, material,
            gravity, name: as in `watt_six_bar`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    a, b, c, d = _loop1_lengths(crank_length, coupler3_length, rocker4_length, ground_length)
    e, f = positive("rocker4_arm", rocker4_arm), positive("rod5_length", rod5_length)
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(WATT_SLIDER_1_INFO.clearable, contact, sliders=WATT_SLIDER_1_INFO.sliders)
    loop1, p = _loop1(a, b, c, d, e, rocker4_arm_angle, start_angle, lam)
    g6 = (d + f, float(guide_height))
    pd = line_circle(g6, (1.0, 0.0), p["C"], f, forward=True, what="rod 5 / slider 6")
    links = [
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"], "G6": g6}),
        *loop1,
        bar_link("rod5", {"C": p["C"], "D": pd}, density=lam),
        slider_link("slider6", {"D": pd}, mass=ms, inertia=js),
    ]
    joints = (
        *_loop1_joints(clr, "rod5"),
        clr.pin("D", "rod5", "slider6"),
        clr.prismatic("P6", "ground", "G6", "slider6", "D", axis=(1.0, 0.0)),
    )
    dims: dict[str, Any] = {
        "crank_length": a,
        "coupler3_length": b,
        "rocker4_length": c,
        "ground_length": d,
        "rocker4_arm": e,
        "rocker4_arm_angle": float(rocker4_arm_angle),
        "rod5_length": f,
        "guide_height": float(guide_height),
        "slider_mass": ms,
        "slider_inertia": js,
    }
    output = Output("slider_x", "slider6", OutputKind.POSITION_X, point="D")
    return crank_mechanism(
        clr, links, joints, output, dims, linear_density=lam, crank_speed=crank_speed, start_angle=start_angle
    )


@contact_keywords(clearance_at=("D",))
def watt_six_bar_slider_2(
    *,
    crank_length: float = 0.04,
    rod3_length: float = 0.13,
    slider_pin_offset: tuple[float, float] = (0.0, -0.05),
    coupler5_length: float = 0.14,
    rocker6_length: float = 0.08,
    rocker6_pivot: tuple[float, float] = (0.27, 0.03),
    slider_mass: float = 0.2,
    slider_inertia: float = 3.3e-5,
    linear_density: float = DEFAULT_LINEAR_DENSITY,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the Watt II six-bar whose first loop is an in-line slider-crank.

    The ternary slider 4 runs on the x axis; its second pin C drives coupler 5 and the
    output rocker 6. Output ``rocker_angle`` is the angle of rocker 6 (O6 -> D) [rad].

    Args:
        crank_length, rod3_length: O2-A, A-B [m].
        slider_pin_offset: C relative to B on the slider (x, y) [m].
        coupler5_length, rocker6_length: C-D, O6-D [m].
        rocker6_pivot: O6 (x, y) [m].
        slider_mass: [kg]; slider_inertia: [kg m^2].
        linear_density, crank_speed, start_angle, clearance_at (any of A, B, C, D, O6),
            radial_clearance, bearing_radius, restitution, friction, law, material,
            gravity, name: as in `watt_six_bar`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    a, b = positive("crank_length", crank_length), positive("rod3_length", rod3_length)
    f, g = positive("coupler5_length", coupler5_length), positive("rocker6_length", rocker6_length)
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    if b <= a:
        raise ValueError(f"rod3_length must be > crank_length = {a} m (got {b} m)")
    clr = ClearanceFactory(WATT_SLIDER_2_INFO.clearable, contact, sliders=WATT_SLIDER_2_INFO.sliders)
    o6 = (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    off = (float(slider_pin_offset[0]), float(slider_pin_offset[1]))
    p = slider_crank_loop(a, b, start_angle, pin="C", offset=off)
    pd = circle_circle(p["C"], f, o6, g, left=False, what="coupler 5 / rocker 6")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "G4": (b, 0.0), "O6": o6}),
        bar_link("crank2", {"O2": p["O2"], "A": p["A"]}, density=lam),
        bar_link("rod3", {"A": p["A"], "B": p["B"]}, density=lam),
        slider_link("slider4", {"B": p["B"], "C": p["C"]}, mass=ms, inertia=js),
        bar_link("coupler5", {"C": p["C"], "D": pd}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd}, density=lam),
    )
    joints = (
        *slider_crank_joints(clr),
        clr.pin("C", "slider4", "coupler5"),
        clr.pin("D", "coupler5", "rocker6"),
        clr.pin("O6", "ground", "rocker6"),
    )
    dims: dict[str, Any] = {
        "crank_length": a,
        "rod3_length": b,
        "slider_pin_offset": list(off),
        "coupler5_length": f,
        "rocker6_length": g,
        "rocker6_pivot": list(o6),
        "slider_mass": ms,
        "slider_inertia": js,
    }
    output = Output("rocker_angle", "rocker6", OutputKind.ANGLE)
    return crank_mechanism(
        clr, links, joints, output, dims, linear_density=lam, crank_speed=crank_speed, start_angle=start_angle
    )
