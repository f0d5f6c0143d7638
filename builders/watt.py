"""Watt six-bar linkages: plain, with an output slider (1), with an intermediate slider (2).

All three are Watt II inversions of Watt's chain (the two ternary links share a joint; here
the ternary ground and a ternary rocker or slider): two four-bar loops in series, the first
driven by the crank, the second by the first loop's ternary output link. Which inversion
and where the sliders sit are the project's own choices (REFERENCES.md section 5 and
CLARIFICATIONS.md: the source defines the variants only in figures we do not have).

Dimensions are the project's own, of bench size like the classic slider-crank: the first
loop is the catalogue's crank-rocker four-bar (crank 40 mm, coupler 130 mm, rocker 100 mm,
ground 130 mm; transmission angle 44-95 deg) or an in-line slider-crank of the same crank
and rod; the second loop is laid out so that at mid-swing its coupler is perpendicular to
both of its rockers (or along the guide), which keeps every transmission angle within
about 90 +- 35 deg.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from clearance.builders._linkage import (
    DEFAULT_LINEAR_DENSITY,
    DEFAULT_RADIAL_CLEARANCE,
    ClearanceFactory,
    LinkageInfo,
    bar_link,
    circle_circle,
    finish,
    line_circle,
    polar,
    positive,
    slider_link,
)
from clearance.builders.slider_crank import rpm
from clearance.kinematics import TransmissionAngle
from clearance.model import (
    STEEL,
    ContactLaw,
    Drive,
    Joint,
    JointType,
    Link,
    Material,
    Mechanism,
    Output,
    OutputKind,
)

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
    clearable=("A", "B", "C", "D", "O6"),
    criticality=("A", "B", "C", "D"),
    transmission=(
        TransmissionAngle("B", ("rod3", "A"), guide="P4"),
        TransmissionAngle("D", ("coupler5", "C"), follower=("rocker6", "O6")),
    ),
    provenance=_OWN + "a slider-rocker with the rocker across the coupler at mid-stroke)",
)


def _crank_rocker(a: float, b: float, c: float, d: float, th: float, lam: float) -> tuple[list[Link], dict]:
    """Loop 1 shared by the plain Watt and slider (1): crank 2, coupler 3, rocker 4 (O4-B)."""
    o2, o4 = (0.0, 0.0), (d, 0.0)
    pa = polar(o2, a, th)
    pb = circle_circle(pa, b, o4, c, left=True, what="coupler 3 / rocker 4")
    return [
        bar_link("crank2", {"O2": o2, "A": pa}, density=lam),
        bar_link("coupler3", {"A": pa, "B": pb}, density=lam),
    ], {"O2": o2, "O4": o4, "A": pa, "B": pb}


def _common(clr: ClearanceFactory, crank_speed: float, start_angle: float, lam: float, gravity: float) -> dict:
    return {
        "linear_density": lam,
        "crank_speed": float(crank_speed),
        "start_angle": float(start_angle),
        **clr.parameters(),
        "gravity": float(gravity),
    }


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
    clearance_at: Sequence[str] = ("D",),
    radial_clearance: float = DEFAULT_RADIAL_CLEARANCE,
    bearing_radius: float = 0.010,
    restitution: float = 0.9,
    friction: float = 0.0,
    law: ContactLaw = ContactLaw.LANKARANI_NIKRAVESH,
    material: Material = STEEL,
    gravity: float = 0.0,
    name: str = "watt_six_bar",
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
        clearance_at: joints with clearance, any of A, B, O4, C, D, O6.
        radial_clearance: c [m]; bearing_radius: R_B [m].
        restitution, friction, law, material: contact properties of every clearance joint.
        gravity: gravitational acceleration [m/s^2] along -y (0 for none).
        name: mechanism name.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    a, b, c, d = (
        positive(n, v)
        for n, v in (
            ("crank_length", crank_length),
            ("coupler3_length", coupler3_length),
            ("rocker4_length", rocker4_length),
            ("ground_length", ground_length),
        )
    )
    e, f, g = (
        positive(n, v)
        for n, v in (
            ("rocker4_arm", rocker4_arm),
            ("coupler5_length", coupler5_length),
            ("rocker6_length", rocker6_length),
        )
    )
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(
        clearance_at,
        WATT_INFO.clearable,
        radial_clearance=radial_clearance,
        bearing_radius=bearing_radius,
        restitution=restitution,
        friction=friction,
        law=law,
        material=material,
    )
    links, p = _crank_rocker(a, b, c, d, start_angle, lam)
    o6 = (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    th4 = math.atan2(p["B"][1] - p["O4"][1], p["B"][0] - p["O4"][0])
    pc = polar(p["O4"], e, th4 + rocker4_arm_angle)
    pd = circle_circle(pc, f, o6, g, left=False, what="coupler 5 / rocker 6")
    links = [
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"], "O6": o6}),
        *links,
        bar_link("rocker4", {"O4": p["O4"], "B": p["B"], "C": pc}, density=lam),
        bar_link("coupler5", {"C": pc, "D": pd}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd}, density=lam),
    ]
    joints = (
        clr.revolute("O2", "ground", "O2", "crank2", "O2"),
        clr.revolute("A", "crank2", "A", "coupler3", "A"),
        clr.revolute("B", "coupler3", "B", "rocker4", "B"),
        clr.revolute("O4", "ground", "O4", "rocker4", "O4"),
        clr.revolute("C", "rocker4", "C", "coupler5", "C"),
        clr.revolute("D", "coupler5", "D", "rocker6", "D"),
        clr.revolute("O6", "ground", "O6", "rocker6", "O6"),
    )
    params = {
        "crank_length": a,
        "coupler3_length": b,
        "rocker4_length": c,
        "ground_length": d,
        "rocker4_arm": e,
        "rocker4_arm_angle": float(rocker4_arm_angle),
        "coupler5_length": f,
        "rocker6_length": g,
        "rocker6_pivot": list(o6),
        **_common(clr, crank_speed, start_angle, lam, gravity),
    }
    return finish(
        Mechanism(
            name=name,
            links=tuple(links),
            joints=joints,
            drives=(Drive("crank", "O2", speed=crank_speed, start_angle=start_angle),),
            outputs=(Output("rocker_angle", "rocker6", OutputKind.ANGLE),),
            gravity=(0.0, -gravity),
            parameters=params,
        )
    )


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
    clearance_at: Sequence[str] = ("D",),
    radial_clearance: float = DEFAULT_RADIAL_CLEARANCE,
    bearing_radius: float = 0.010,
    restitution: float = 0.9,
    friction: float = 0.0,
    law: ContactLaw = ContactLaw.LANKARANI_NIKRAVESH,
    material: Material = STEEL,
    gravity: float = 0.0,
    name: str = "watt_six_bar_slider_1",
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
    a, b, c, d = (
        positive(n, v)
        for n, v in (
            ("crank_length", crank_length),
            ("coupler3_length", coupler3_length),
            ("rocker4_length", rocker4_length),
            ("ground_length", ground_length),
        )
    )
    e, f = positive("rocker4_arm", rocker4_arm), positive("rod5_length", rod5_length)
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(
        clearance_at,
        WATT_SLIDER_1_INFO.clearable,
        radial_clearance=radial_clearance,
        bearing_radius=bearing_radius,
        restitution=restitution,
        friction=friction,
        law=law,
        material=material,
    )
    links, p = _crank_rocker(a, b, c, d, start_angle, lam)
    th4 = math.atan2(p["B"][1] - p["O4"][1], p["B"][0] - p["O4"][0])
    pc = polar(p["O4"], e, th4 + rocker4_arm_angle)
    g6 = (d + f, float(guide_height))
    pd = line_circle(g6, (1.0, 0.0), pc, f, forward=True, what="rod 5 / slider 6")
    links = [
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"], "G6": g6}),
        *links,
        bar_link("rocker4", {"O4": p["O4"], "B": p["B"], "C": pc}, density=lam),
        bar_link("rod5", {"C": pc, "D": pd}, density=lam),
        slider_link("slider6", {"D": pd}, mass=ms, inertia=js),
    ]
    joints = (
        clr.revolute("O2", "ground", "O2", "crank2", "O2"),
        clr.revolute("A", "crank2", "A", "coupler3", "A"),
        clr.revolute("B", "coupler3", "B", "rocker4", "B"),
        clr.revolute("O4", "ground", "O4", "rocker4", "O4"),
        clr.revolute("C", "rocker4", "C", "rod5", "C"),
        clr.revolute("D", "rod5", "D", "slider6", "D"),
        Joint("P6", JointType.PRISMATIC, "ground", "G6", "slider6", "D", axis=(1.0, 0.0)),
    )
    params = {
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
        **_common(clr, crank_speed, start_angle, lam, gravity),
    }
    return finish(
        Mechanism(
            name=name,
            links=tuple(links),
            joints=joints,
            drives=(Drive("crank", "O2", speed=crank_speed, start_angle=start_angle),),
            outputs=(Output("slider_x", "slider6", OutputKind.POSITION_X, point="D"),),
            gravity=(0.0, -gravity),
            parameters=params,
        )
    )


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
    clearance_at: Sequence[str] = ("D",),
    radial_clearance: float = DEFAULT_RADIAL_CLEARANCE,
    bearing_radius: float = 0.010,
    restitution: float = 0.9,
    friction: float = 0.0,
    law: ContactLaw = ContactLaw.LANKARANI_NIKRAVESH,
    material: Material = STEEL,
    gravity: float = 0.0,
    name: str = "watt_six_bar_slider_2",
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
    clr = ClearanceFactory(
        clearance_at,
        WATT_SLIDER_2_INFO.clearable,
        radial_clearance=radial_clearance,
        bearing_radius=bearing_radius,
        restitution=restitution,
        friction=friction,
        law=law,
        material=material,
    )
    o2, o6 = (0.0, 0.0), (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    pa = polar(o2, a, start_angle)
    pb = line_circle(o2, (1.0, 0.0), pa, b, forward=True, what="rod 3 / slider 4")
    off = (float(slider_pin_offset[0]), float(slider_pin_offset[1]))
    pc = (pb[0] + off[0], pb[1] + off[1])
    pd = circle_circle(pc, f, o6, g, left=False, what="coupler 5 / rocker 6")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": o2, "G4": (b, 0.0), "O6": o6}),
        bar_link("crank2", {"O2": o2, "A": pa}, density=lam),
        bar_link("rod3", {"A": pa, "B": pb}, density=lam),
        slider_link("slider4", {"B": pb, "C": pc}, mass=ms, inertia=js),
        bar_link("coupler5", {"C": pc, "D": pd}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd}, density=lam),
    )
    joints = (
        clr.revolute("O2", "ground", "O2", "crank2", "O2"),
        clr.revolute("A", "crank2", "A", "rod3", "A"),
        clr.revolute("B", "rod3", "B", "slider4", "B"),
        Joint("P4", JointType.PRISMATIC, "ground", "G4", "slider4", "B", axis=(1.0, 0.0)),
        clr.revolute("C", "slider4", "C", "coupler5", "C"),
        clr.revolute("D", "coupler5", "D", "rocker6", "D"),
        clr.revolute("O6", "ground", "O6", "rocker6", "O6"),
    )
    params = {
        "crank_length": a,
        "rod3_length": b,
        "slider_pin_offset": list(off),
        "coupler5_length": f,
        "rocker6_length": g,
        "rocker6_pivot": list(o6),
        "slider_mass": ms,
        "slider_inertia": js,
        **_common(clr, crank_speed, start_angle, lam, gravity),
    }
    return finish(
        Mechanism(
            name=name,
            links=links,
            joints=joints,
            drives=(Drive("crank", "O2", speed=crank_speed, start_angle=start_angle),),
            outputs=(Output("rocker_angle", "rocker6", OutputKind.ANGLE),),
            gravity=(0.0, -gravity),
            parameters=params,
        )
    )
