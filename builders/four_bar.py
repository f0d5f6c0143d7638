"""Crank-rocker four-bar linkage.

Dimensions are the project's own (the criticality study of Alok, Chaudhary and Guha 2020,
docs/references.md, gives link lengths only in figures we do not have). They were chosen for a Grashof crank-rocker
(s + l = 0.17 m < p + q = 0.23 m, crank shortest) of bench size (crank 40 mm, as for the
classic slider-crank's 50 mm) whose transmission angle stays within 44-95 deg over the
whole revolution, comfortably inside the usual 40-140 deg design range, so that no loop
comes near a dead point at any speed.

Topology: ground 1, crank 2 (driven, pivot O2), coupler 3, rocker 4 (output, pivot O4).
"""

from __future__ import annotations

from typing import Unpack

from clearance.builders._contact import ClearanceFactory, ContactKeywords, contact_keywords
from clearance.builders._linkage import (
    DEFAULT_LINEAR_DENSITY,
    LinkageInfo,
    bar_link,
    crank_mechanism,
    positive,
)
from clearance.builders._loops import crank_rocker, crank_rocker_joints
from clearance.builders.slider_crank import rpm
from clearance.kinematics import TransmissionAngle
from clearance.model import Link, Mechanism, Output, OutputKind

__all__ = ["four_bar", "FOUR_BAR_INFO"]

FOUR_BAR_INFO = LinkageInfo(
    topology=(
        "Grashof crank-rocker: ground 1 (pivots O2, O4), crank 2 (O2-A, driven at constant "
        "speed), coupler 3 (A-B), rocker 4 (O4-B, output: its angle)."
    ),
    driven=("O2",),
    output_pivot="O4",
    clearable=("A", "B", "O4"),
    criticality=("A", "B"),
    transmission=(TransmissionAngle("B", ("coupler3", "A"), follower=("rocker4", "O4")),),
    provenance="project's own dimensions (Grashof crank-rocker, transmission angle 44-95 deg)",
)


@contact_keywords(clearance_at=("B",))
def four_bar(
    *,
    crank_length: float = 0.04,
    coupler_length: float = 0.13,
    rocker_length: float = 0.10,
    ground_length: float = 0.13,
    linear_density: float = DEFAULT_LINEAR_DENSITY,
    crank_speed: float = rpm(1000.0),
    start_angle: float = 0.0,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the crank-rocker four-bar with clearance at the chosen revolute joints.

    The crank pivot O2 is at the origin and the rocker pivot O4 on the +x axis; the coupler
    assembles above the ground line. Output ``rocker_angle`` is the angle of rocker 4
    (O4 -> B) from +x [rad].

    Args:
        crank_length, coupler_length, rocker_length, ground_length: O2-A, A-B, O4-B, O2-O4 [m].
        linear_density: mass per length of the steel bars [kg/m].
        crank_speed: constant crank speed [rad/s] (default 1000 rpm).
        start_angle: crank angle at t = 0 [rad] from +x.
        clearance_at, radial_clearance, bearing_radius, restitution, friction, law,
            material, gravity, name: the contact keywords (`ContactKeywords`);
            ``clearance_at`` any of ``A``, ``B``, ``O4``.

    Returns:
        The mechanism.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or lengths that do
            not close the loop at the start angle.
        AssemblyError: the start position is singular.
    """
    a = positive("crank_length", crank_length)
    b = positive("coupler_length", coupler_length)
    c = positive("rocker_length", rocker_length)
    d = positive("ground_length", ground_length)
    lam = positive("linear_density", linear_density, "kg/m")
    clr = ClearanceFactory(FOUR_BAR_INFO.clearable, contact)
    p = crank_rocker(a, b, c, d, start_angle)
    links = (
        Link("ground", 0.0, 0.0, points={"O2": p["O2"], "O4": p["O4"]}),
        bar_link("crank2", {"O2": p["O2"], "A": p["A"]}, density=lam),
        bar_link("coupler3", {"A": p["A"], "B": p["B"]}, density=lam),
        bar_link("rocker4", {"O4": p["O4"], "B": p["B"]}, density=lam),
    )
    joints = crank_rocker_joints(clr)
    dims = {"crank_length": a, "coupler_length": b, "rocker_length": c, "ground_length": d}
    output = Output("rocker_angle", "rocker4", OutputKind.ANGLE)
    return crank_mechanism(
        clr, links, joints, output, dims, linear_density=lam, crank_speed=crank_speed, start_angle=start_angle
    )
