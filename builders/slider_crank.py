"""The classic slider-crank of the clearance-joint literature (Flores and Ambrosio family).

Default dimensions and properties follow Flores and Ambrósio 2004, docs/references.md. Crank 0.05 m and rod
0.12 m are checked against a public re-implementation; the masses (0.30 / 0.21 / 0.14 kg),
moments of inertia (1e-5 / 2.5e-4 / 1e-4 kg m^2), bearing radius 10 mm, clearance 0.5 mm,
steel (E = 207 GPa, nu = 0.3), restitution 0.9 and 5000 rpm are *recalled* values commonly
quoted for this benchmark, not verified against the original papers.
"""

from __future__ import annotations

import math
from typing import Unpack

from clearance.builders._contact import ClearanceFactory, ContactKeywords, contact_keywords
from clearance.checks import finite, positive
from clearance.model import (
    Drive,
    DriveKind,
    Joint,
    JointType,
    Link,
    Mechanism,
    Output,
    OutputKind,
)
from clearance.units import UNITS

__all__ = ["slider_crank", "SLIDER_CRANK_JOINTS", "rpm"]

SLIDER_CRANK_JOINTS = ("crank_pivot", "crank_rod", "rod_slider", "slider_guide")
"""Joint names; clearance may be put at ``crank_rod``, ``rod_slider`` (radial) and ``slider_guide`` (translational)."""

_CLEARABLE = ("crank_rod", "rod_slider")
_SLIDERS = ("slider_guide",)


def rpm(value: float) -> float:
    """Convert revolutions per minute to rad/s.

    Raises:
        clearance.checks.NotANumberError: ``value`` is not a finite number (a `TypeError`).
    """
    return finite("rpm", value) * UNITS["angular_speed"]["rpm"]


@contact_keywords(clearance_at=("rod_slider",), radial_clearance=0.5e-3)
def slider_crank(
    *,
    crank_length: float = 0.05,
    rod_length: float = 0.12,
    crank_mass: float = 0.30,
    rod_mass: float = 0.21,
    slider_mass: float = 0.14,
    crank_inertia: float = 1.0e-5,
    rod_inertia: float = 2.5e-4,
    slider_inertia: float = 1.0e-4,
    crank_speed: float = rpm(5000.0),
    start_angle: float = 0.0,
    free_crank: bool = False,
    **contact: Unpack[ContactKeywords],
) -> Mechanism:
    """Build the in-line slider-crank with clearance at the chosen revolute joints.

    The crank turns about the ground pivot at the origin; the slider moves along the x
    axis. Output ``slider_x`` is the slider pin's x position [m] (with ``slider_x_vel``,
    ``slider_x_acc`` in results). Centres of mass are at mid-length.

    Args:
        crank_length, rod_length: link lengths [m].
        crank_mass, rod_mass, slider_mass: masses [kg].
        crank_inertia, rod_inertia, slider_inertia: moments of inertia about the centre of
            mass [kg m^2].
        crank_speed: constant crank speed [rad/s] (default 5000 rpm; see `rpm`); with
            ``free_crank`` the crank's speed at t = 0.
        start_angle: crank angle at t = 0 [rad] (0: crank along +x, slider at top dead
            centre).
        free_crank: no drive: the crank turns freely from ``crank_speed`` at t = 0 (a torque
            drive of 0 N m; Flores, Leine and Glocker 2010).
        clearance_at, radial_clearance, bearing_radius, restitution, friction, law,
            material, slider_length, slider_height, guide_stiffness, gravity, name: the
            contact keywords (`ContactKeywords`); ``clearance_at`` any of ``crank_rod``,
            ``rod_slider`` and ``slider_guide`` (the slider's play in its guide, a block of
            ``slider_length`` by ``slider_height`` centred on its pin); ``radial_clearance``
            0.5 mm by default.

    Returns:
        The mechanism.

    Raises:
        ValueError: a value out of range, an unknown clearance joint, or a rod too short to
            close the loop.
    """
    clr = ClearanceFactory(_CLEARABLE, contact, sliders=_SLIDERS)
    if not isinstance(free_crank, bool):
        raise ValueError(f"free_crank must be true or false (got {free_crank!r})")
    positive("crank_length", crank_length, "m")
    positive("rod_length", rod_length, "m")
    if rod_length <= crank_length:
        raise ValueError(
            f"rod_length must be > crank_length = {crank_length} m for the slider-crank to "
            f"assemble over a whole revolution (got {rod_length} m)"
        )
    r, rod = crank_length, rod_length
    th = start_angle
    bx, by = r * math.cos(th), r * math.sin(th)
    beta = math.asin(-by / rod)
    sx = bx + rod * math.cos(beta)
    links = (
        Link("ground", 0.0, 0.0, points={"crank_pivot": (0.0, 0.0), "guide": (0.0, 0.0)}),
        Link(
            "crank",
            crank_mass,
            crank_inertia,
            com=(r / 2, 0.0),
            points={"pivot": (0.0, 0.0), "pin": (r, 0.0)},
            pose_guess=(0.0, 0.0, th),
        ),
        Link(
            "rod",
            rod_mass,
            rod_inertia,
            com=(rod / 2, 0.0),
            points={"big_end": (0.0, 0.0), "small_end": (rod, 0.0)},
            pose_guess=(bx, by, beta),
        ),
        Link(
            "slider",
            slider_mass,
            slider_inertia,
            points={"pin": (0.0, 0.0)},
            pose_guess=(sx, 0.0, 0.0),
        ),
    )

    joints = (
        Joint("crank_pivot", JointType.REVOLUTE, "ground", "crank_pivot", "crank", "pivot"),
        clr.revolute("crank_rod", "crank", "pin", "rod", "big_end"),
        clr.revolute("rod_slider", "rod", "small_end", "slider", "pin"),
        clr.prismatic("slider_guide", "ground", "guide", "slider", "pin", axis=(1.0, 0.0)),
    )
    if free_crank:
        drive = Drive("crank", "crank_pivot", DriveKind.TORQUE, initial_speed=crank_speed, start_angle=th)
    else:
        drive = Drive("crank", "crank_pivot", DriveKind.CONSTANT_SPEED, speed=crank_speed, start_angle=th)
    drives = (drive,)
    outputs = (Output("slider_x", "slider", OutputKind.POSITION_X, point="pin"),)
    params = {
        "crank_length": r,
        "rod_length": rod,
        "crank_mass": crank_mass,
        "rod_mass": rod_mass,
        "slider_mass": slider_mass,
        "crank_inertia": crank_inertia,
        "rod_inertia": rod_inertia,
        "slider_inertia": slider_inertia,
        "crank_speed": crank_speed,
        "start_angle": th,
        **({"free_crank": True} if free_crank else {}),
        **clr.parameters(),
    }
    return Mechanism(
        name=clr.name,
        links=links,
        joints=joints,
        drives=drives,
        outputs=outputs,
        gravity=(0.0, -clr.gravity),
        parameters=params,
    )
