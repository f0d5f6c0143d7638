"""The hybrid-driven seven-bar press of the press paper (Shock and Vibration 2020; docs/references.md).

Topology as in the press paper: frame 1; crank 2 (constant-speed motor) and crank 7 (servo
motor), both pivoted on the frame; connecting rod 3 joins crank 2 to triangle plate 4;
plate 4 also joins crank 7 and connecting rod 5; rod 5 drives slider 6 on a vertical
guide. 2 DOF, gravity on. The press paper's clearances are A (crank 2 / rod 3) and C (plate 4 /
rod 5); the joints carry those names.

The press paper's tables of dimensions, masses and speeds are not available to us: the
dimensions are the project's own. They were picked by a grid search over crank radii,
rod lengths, plate shape and crank phase for a press of bench size (crank 80 mm, servo
crank 40 mm, frame pivots 350 mm apart, slider stroke about 130 mm) whose transmission
angles stay above 68 deg over the whole cycle with both cranks turning at the same speed;
the links are 20 mm x 20 mm steel bars (3.14 kg/m) and the slider a 1 kg block. Speeds
follow the press paper's range (crank 2 at pi rad/s by default; bifurcations over 1-3 pi rad/s);
the servo's default period equals crank 2's (a choice of the project: the paper's servo law is
not available to us).
"""

from __future__ import annotations

import math
from typing import Any, Unpack

from clearance.builders._contact import ClearanceFactory, ContactKeywords, contact_keywords
from clearance.builders._linkage import (
    LinkageInfo,
    angle_of,
    bar_link,
    circle_circle,
    frame_point,
    lengths,
    line_circle,
    make_mechanism,
    polar,
    positive,
    slider_link,
)
from clearance.kinematics import TransmissionAngle
from clearance.model import (
    Drive,
    DriveKind,
    Link,
    Mechanism,
    MotionLaw,
    Output,
    OutputKind,
)

__all__ = ["seven_bar_press", "PRESS_INFO", "PRESS_LINEAR_DENSITY"]

PRESS_LINEAR_DENSITY = 3.14
"""Linear density of the press's bars [kg/m]: steel (7850 kg/m^3), 20 mm x 20 mm."""

PRESS_INFO = LinkageInfo(
    topology="Hybrid seven-bar press (2 DOF): frame 1 (O2, O7, vertical guide P6), crank 2 (O2-A, "
    "constant-speed motor), rod 3 (A-B), triangle plate 4 (B, E, C), crank 7 (O7-E, servo), "
    "rod 5 (C-D), slider 6 (D; output: its y). Seed clearances: A and C.",
    driven=("O2", "O7"),
    output_pivot="P6",
    sliders=("P6",),
    clearable=("A", "B", "E", "C", "D"),
    criticality=("A", "B", "E", "C", "D"),
    transmission=(
        TransmissionAngle("B", ("rod3", "A"), follower=("plate4", "E")),
        TransmissionAngle("D", ("rod5", "C"), guide="P6"),
    ),
    provenance="topology from the press paper (Shock and Vibration 2020); project's own dimensions "
    "(its tables are not available)",
)


def _drive(name: str, joint: str, speed: float, motion: MotionLaw | None, start: float) -> Drive:
    if motion is None:
        return Drive(name, joint, DriveKind.CONSTANT_SPEED, speed=speed, start_angle=start)
    if not isinstance(motion, MotionLaw):
        raise ValueError(f"{name}_motion must be a MotionLaw or None (got {motion!r})")
    return Drive(name, joint, DriveKind.MOTION_LAW, motion=motion, start_angle=start)


def _law_params(motion: MotionLaw) -> dict[str, Any]:
    out: dict[str, Any] = {"speed": motion.speed, "harmonics": [list(h) for h in motion.harmonics]}
    if motion.period is not None:
        out["period"] = motion.period
    return out


@contact_keywords(clearance_at=("A", "C"), gravity=9.81)
def seven_bar_press(
    *,
    crank2_length: float = 0.08,
    rod3_length: float = 0.30,
    plate4_length: float = 0.18,
    plate4_point: tuple[float, float] = (0.08, -0.15),
    crank7_length: float = 0.04,
    crank7_pivot: tuple[float, float] = (0.35, 0.0),
    rod5_length: float = 0.25,
    guide_x: float = 0.21,
    slider_mass: float = 1.0,
    slider_inertia: float = 6.7e-4,
    linear_density: float = PRESS_LINEAR_DENSITY,
    crank2_speed: float = math.pi,
    crank2_motion: MotionLaw | None = None,
    crank2_start_angle: float = 0.0,
    crank7_speed: float | None = None,
    crank7_motion: MotionLaw | None = None,
    crank7_start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the hybrid-driven seven-bar press with clearance at the chosen joints.

    Crank 2 pivots at the origin, crank 7 at ``crank7_pivot``; plate 4 assembles above the
    frame and the slider hangs below it on the vertical guide x = ``guide_x``. Output
    ``slider_y`` is the y position of the slider pin D [m].

    Args:
        crank2_length, rod3_length: O2-A, A-B [m].
        plate4_length: B-E [m].
        plate4_point: C in the plate frame (origin B, x towards E) [m].
        crank7_length: O7-E [m]; crank7_pivot: O7 (x, y) [m].
        rod5_length: C-D [m]; guide_x: x of the vertical slider guide [m].
        slider_mass: [kg]; slider_inertia: [kg m^2].
        linear_density: mass per length of the steel bars [kg/m].
        crank2_speed: constant speed of crank 2 [rad/s] (default pi rad/s).
        crank2_motion: a motion law for crank 2 instead of constant speed, or None.
        crank2_start_angle: crank 2 angle at t = 0 [rad] from +x.
        crank7_speed: constant speed of servo crank 7 [rad/s]; None: crank 2's (mean) speed,
            so that both have the same period.
        crank7_motion: a servo motion law theta(t) for crank 7, or None for constant speed.
        crank7_start_angle: crank 7 angle at t = 0 [rad] from +x.
        clearance_at, radial_clearance, bearing_radius, restitution, friction, law,
            material, gravity, name: the contact keywords (`ContactKeywords`);
            ``clearance_at`` any of A, B, E, C, D (default the press paper's A, C); ``gravity``
            9.81 m/s^2 by default.

    Returns:
        The mechanism (2 drives: ``crank2`` on O2, ``crank7`` on O7).

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close a loop at the start angles.
        AssemblyError: the start position is singular.
    """
    dims: dict[str, Any] = lengths(
        crank2_length=crank2_length,
        rod3_length=rod3_length,
        plate4_length=plate4_length,
        crank7_length=crank7_length,
        rod5_length=rod5_length,
    )
    ms, js = positive("slider_mass", slider_mass, "kg"), positive("slider_inertia", slider_inertia, "kg m^2")
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(PRESS_INFO.clearable, contact, sliders=PRESS_INFO.sliders)
    drive2 = _drive("crank2", "O2", crank2_speed, crank2_motion, crank2_start_angle)
    if crank7_speed is None:
        crank7_speed = crank2_motion.speed if crank2_motion is not None else crank2_speed
    drive7 = _drive("crank7", "O7", crank7_speed, crank7_motion, crank7_start_angle)
    o2, o7 = (0.0, 0.0), (float(crank7_pivot[0]), float(crank7_pivot[1]))
    pa = polar(o2, crank2_length, crank2_start_angle)
    pe = polar(o7, crank7_length, crank7_start_angle)
    pb = circle_circle(pa, rod3_length, pe, plate4_length, left=True, what="rod 3 / plate 4")
    u, v = float(plate4_point[0]), float(plate4_point[1])
    pc = frame_point(pb, angle_of(pb, pe), (u, v))
    g6 = (float(guide_x), 0.0)
    pd = line_circle(g6, (0.0, 1.0), pc, rod5_length, forward=False, what="rod 5 / slider 6")
    links = (
        Link("ground", 0.0, 0.0, points={"O2": o2, "O7": o7, "G6": g6}),
        bar_link("crank2", {"O2": o2, "A": pa}, density=lam),
        bar_link("rod3", {"A": pa, "B": pb}, density=lam),
        bar_link("plate4", {"B": pb, "E": pe, "C": pc}, density=lam),
        bar_link("crank7", {"O7": o7, "E": pe}, density=lam),
        bar_link("rod5", {"C": pc, "D": pd}, density=lam),
        slider_link("slider6", {"D": pd}, mass=ms, inertia=js),
    )
    joints = (
        clr.pin("O2", "ground", "crank2"),
        clr.pin("A", "crank2", "rod3"),
        clr.pin("B", "rod3", "plate4"),
        clr.pin("E", "plate4", "crank7"),
        clr.pin("O7", "ground", "crank7"),
        clr.pin("C", "plate4", "rod5"),
        clr.pin("D", "rod5", "slider6"),
        clr.prismatic("P6", "ground", "G6", "slider6", "D", axis=(0.0, 1.0)),
    )
    dims.update(
        plate4_point=[u, v],
        crank7_pivot=list(o7),
        guide_x=float(guide_x),
        slider_mass=ms,
        slider_inertia=js,
        linear_density=lam,
        crank2_speed=float(crank2_speed),
        crank2_start_angle=float(crank2_start_angle),
        crank7_speed=float(crank7_speed),
        crank7_start_angle=float(crank7_start_angle),
        **clr.parameters(),
    )
    if crank2_motion is not None:
        dims["crank2_motion"] = _law_params(crank2_motion)
    if crank7_motion is not None:
        dims["crank7_motion"] = _law_params(crank7_motion)
    output = Output("slider_y", "slider6", OutputKind.POSITION_Y, point="D")
    return make_mechanism(clr, links, joints, (drive2, drive7), (output,), dims)
