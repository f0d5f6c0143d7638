"""An eight-bar and a ten-bar linkage (1 DOF, revolute and prismatic pairs).

Both topologies and all dimensions are the project's own (REFERENCES.md section 5 and
CLARIFICATIONS.md: the source shows its eight- and ten-bar only in figures we do not
have). Both start from the catalogue's crank-rocker four-bar (crank 40 mm, coupler 130
mm, rocker 100 mm, ground 130 mm) and grow by dyads, so that every loop is closed dyad by
dyad, and both end in a slider:

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
from collections.abc import Sequence

from clearance.builders._linkage import (
    DEFAULT_LINEAR_DENSITY as _LAM,
)
from clearance.builders._linkage import (
    DEFAULT_RADIAL_CLEARANCE as _C,
)
from clearance.builders._linkage import (
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
from clearance.kinematics import TransmissionAngle as _T
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

__all__ = ["eight_bar", "ten_bar", "EIGHT_BAR_INFO", "TEN_BAR_INFO"]

_LN = ContactLaw.LANKARANI_NIKRAVESH
_OWN = "project's own topology and dimensions (grid search for the best transmission angles)"

EIGHT_BAR_INFO = LinkageInfo(
    topology="Eight-bar: ground 1 (O2, O4, O6, guide P8), crank 2 (O2-A, driven), ternary coupler 3 "
    "(A, B, C), rocker 4 (O4-B), link 5 (C-D), ternary rocker 6 (O6, D, E), rod 7 (E-F), "
    "slider 8 (F, horizontal guide; output: its x).",
    driven=("O2",),
    output_pivot="P8",
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


def _four_bar(
    crank: float, coupler: float, rocker: float, ground: float, point: tuple[float, float], th: float
) -> dict[str, tuple[float, float]]:
    o2, o4 = (0.0, 0.0), (ground, 0.0)
    pa = polar(o2, crank, th)
    pb = circle_circle(pa, coupler, o4, rocker, left=True, what="coupler 3 / rocker 4")
    t3 = math.atan2(pb[1] - pa[1], pb[0] - pa[0])
    u, v = point
    pc = (pa[0] + u * math.cos(t3) - v * math.sin(t3), pa[1] + u * math.sin(t3) + v * math.cos(t3))
    return {"O2": o2, "O4": o4, "A": pa, "B": pb, "C": pc}


def _angle(p: tuple[float, float], q: tuple[float, float]) -> float:
    return math.atan2(q[1] - p[1], q[0] - p[0])


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
    clearance_at: Sequence[str] = ("D",),
    radial_clearance: float = _C,
    bearing_radius: float = 0.010,
    restitution: float = 0.9,
    friction: float = 0.0,
    law: ContactLaw = _LN,
    material: Material = STEEL,
    gravity: float = 0.0,
    name: str = "eight_bar",
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
        clearance_at: joints with clearance (see `EIGHT_BAR_INFO.clearable`).
        radial_clearance, bearing_radius: c and R_B [m].
        restitution, friction, law, material: contact properties of every clearance joint.
        gravity: gravitational acceleration [m/s^2] along -y (0 for none).
        name: mechanism name.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    dims = {
        k: positive(k, v)
        for k, v in (
            ("crank_length", crank_length),
            ("coupler3_length", coupler3_length),
            ("rocker4_length", rocker4_length),
            ("ground_length", ground_length),
            ("link5_length", link5_length),
            ("rocker6_length", rocker6_length),
            ("rocker6_arm", rocker6_arm),
            ("rod7_length", rod7_length),
        )
    }
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(
        clearance_at,
        EIGHT_BAR_INFO.clearable,
        radial_clearance=radial_clearance,
        bearing_radius=bearing_radius,
        restitution=restitution,
        friction=friction,
        law=law,
        material=material,
    )
    cp = (float(coupler3_point[0]), float(coupler3_point[1]))
    p = _four_bar(crank_length, coupler3_length, rocker4_length, ground_length, cp, start_angle)
    o6 = (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    pd = circle_circle(p["C"], link5_length, o6, rocker6_length, left=True, what="link 5 / rocker 6")
    pe = polar(o6, rocker6_arm, _angle(o6, pd) + rocker6_arm_angle)
    g8 = (o6[0], float(guide_height))
    pf = line_circle(g8, (1.0, 0.0), pe, rod7_length, forward=True, what="rod 7 / slider 8")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"], "O6": o6, "G8": g8}),
        bar_link("crank2", {"O2": p["O2"], "A": p["A"]}, density=lam),
        bar_link(
            "coupler3",
            {"A": p["A"], "B": p["B"], "C": p["C"]},
            density=lam,
            bars=[("A", "C")] if cp[1] == 0 and cp[0] >= 0 else None,
        ),
        bar_link("rocker4", {"O4": p["O4"], "B": p["B"]}, density=lam),
        bar_link("link5", {"C": p["C"], "D": pd}, density=lam),
        bar_link("rocker6", {"O6": o6, "D": pd, "E": pe}, density=lam, bars=[("O6", "D"), ("O6", "E")]),
        bar_link("rod7", {"E": pe, "F": pf}, density=lam),
        slider_link("slider8", {"F": pf}, mass=ms, inertia=js),
    )
    joints = (
        clr.revolute("O2", "ground", "O2", "crank2", "O2"),
        clr.revolute("A", "crank2", "A", "coupler3", "A"),
        clr.revolute("B", "coupler3", "B", "rocker4", "B"),
        clr.revolute("O4", "ground", "O4", "rocker4", "O4"),
        clr.revolute("C", "coupler3", "C", "link5", "C"),
        clr.revolute("D", "link5", "D", "rocker6", "D"),
        clr.revolute("O6", "ground", "O6", "rocker6", "O6"),
        clr.revolute("E", "rocker6", "E", "rod7", "E"),
        clr.revolute("F", "rod7", "F", "slider8", "F"),
        Joint("P8", JointType.PRISMATIC, "ground", "G8", "slider8", "F", axis=(1.0, 0.0)),
    )
    dims.update(
        coupler3_point=list(cp),
        rocker6_pivot=list(o6),
        rocker6_arm_angle=float(rocker6_arm_angle),
        guide_height=float(guide_height),
        slider_mass=ms,
        slider_inertia=js,
        linear_density=lam,
        crank_speed=float(crank_speed),
        start_angle=float(start_angle),
        **clr.parameters(),
        gravity=float(gravity),
    )
    return finish(
        Mechanism(
            name=name,
            links=links,
            joints=joints,
            drives=(Drive("crank", "O2", speed=crank_speed, start_angle=start_angle),),
            outputs=(Output("slider_x", "slider8", OutputKind.POSITION_X, point="F"),),
            gravity=(0.0, -gravity),
            parameters=dims,
        )
    )


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
    clearance_at: Sequence[str] = ("G",),
    radial_clearance: float = _C,
    bearing_radius: float = 0.010,
    restitution: float = 0.9,
    friction: float = 0.0,
    law: ContactLaw = _LN,
    material: Material = STEEL,
    gravity: float = 0.0,
    name: str = "ten_bar",
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
        linear_density, crank_speed, start_angle, clearance_at (see
            `TEN_BAR_INFO.clearable`), radial_clearance, bearing_radius, restitution,
            friction, law, material, gravity, name: as in `eight_bar`.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angle.
        AssemblyError: the start position is singular.
    """
    dims = {
        k: positive(k, v)
        for k, v in (
            ("crank_length", crank_length),
            ("coupler3_length", coupler3_length),
            ("rocker4_length", rocker4_length),
            ("ground_length", ground_length),
            ("rocker4_arm", rocker4_arm),
            ("link5_length", link5_length),
            ("rocker6_length", rocker6_length),
            ("rocker6_arm", rocker6_arm),
            ("link7_length", link7_length),
            ("link8_length", link8_length),
            ("rod9_length", rod9_length),
        )
    }
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(
        clearance_at,
        TEN_BAR_INFO.clearable,
        radial_clearance=radial_clearance,
        bearing_radius=bearing_radius,
        restitution=restitution,
        friction=friction,
        law=law,
        material=material,
    )
    cp = (float(coupler3_point[0]), float(coupler3_point[1]))
    p = _four_bar(crank_length, coupler3_length, rocker4_length, ground_length, cp, start_angle)
    o6 = (float(rocker6_pivot[0]), float(rocker6_pivot[1]))
    pd = polar(p["O4"], rocker4_arm, _angle(p["O4"], p["B"]) + rocker4_arm_angle)
    pe = circle_circle(p["C"], link5_length, o6, rocker6_length, left=False, what="link 5 / rocker 6")
    pf = polar(o6, rocker6_arm, _angle(o6, pe) + rocker6_arm_angle)
    pg = circle_circle(pd, link7_length, pf, link8_length, left=False, what="link 7 / link 8")
    t8 = _angle(pf, pg)
    hu, hv = float(link8_point[0]), float(link8_point[1])
    ph = (pf[0] + hu * math.cos(t8) - hv * math.sin(t8), pf[1] + hu * math.sin(t8) + hv * math.cos(t8))
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
        slider_link("slider10", {"I": pi_}, mass=ms, inertia=js),
    )
    joints = (
        clr.revolute("O2", "ground", "O2", "crank2", "O2"),
        clr.revolute("A", "crank2", "A", "coupler3", "A"),
        clr.revolute("B", "coupler3", "B", "rocker4", "B"),
        clr.revolute("O4", "ground", "O4", "rocker4", "O4"),
        clr.revolute("C", "coupler3", "C", "link5", "C"),
        clr.revolute("E", "link5", "E", "rocker6", "E"),
        clr.revolute("O6", "ground", "O6", "rocker6", "O6"),
        clr.revolute("D", "rocker4", "D", "link7", "D"),
        clr.revolute("G", "link7", "G", "link8", "G"),
        clr.revolute("F", "rocker6", "F", "link8", "F"),
        clr.revolute("H", "link8", "H", "rod9", "H"),
        clr.revolute("I", "rod9", "I", "slider10", "I"),
        Joint("P10", JointType.PRISMATIC, "ground", "G10", "slider10", "I", axis=(1.0, 0.0)),
    )
    dims.update(
        coupler3_point=list(cp),
        rocker4_arm_angle=float(rocker4_arm_angle),
        rocker6_pivot=list(o6),
        rocker6_arm_angle=float(rocker6_arm_angle),
        link8_point=[hu, hv],
        guide_height=float(guide_height),
        slider_mass=ms,
        slider_inertia=js,
        linear_density=lam,
        crank_speed=float(crank_speed),
        start_angle=float(start_angle),
        **clr.parameters(),
        gravity=float(gravity),
    )
    return finish(
        Mechanism(
            name=name,
            links=links,
            joints=joints,
            drives=(Drive("crank", "O2", speed=crank_speed, start_angle=start_angle),),
            outputs=(Output("slider_x", "slider10", OutputKind.POSITION_X, point="I"),),
            gravity=(0.0, -gravity),
            parameters=dims,
        )
    )
