"""Small canonical systems for the reference solver (checks against closed-form answers).

`journal_in_bearing`: a free body whose journal starts centred in a ground-fixed bearing
and moves toward the wall: the single radial impact of `clearance.contact_calibration`'s
impact reference, but through the full multibody machinery (geometry, events, forces).
`slider_in_guide`: a free block with play in a ground-fixed guide along x, started at any
position, tilt and velocity: each of the four contact cases of a slider, one at a time.
The mechanism rules cannot express them (the body has no drive), so they are built with
`ReferenceSystem.from_parts`.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Unpack

import numpy as np

from clearance.model import Clearance, Joint, JointType, Link
from clearance.reference.system import ReferenceOptions, ReferenceSystem
from clearance.translational import TranslationalClearance

__all__ = ["journal_in_bearing", "slider_in_guide"]


def journal_in_bearing(
    clearance: Clearance,
    *,
    mass: float,
    inertia: float = 1e-5,
    speed: float,
    direction: float = 0.0,
    tangential_speed: float = 0.0,
    **options: Unpack[ReferenceOptions],
) -> tuple[ReferenceSystem, np.ndarray, np.ndarray]:
    """A free body (journal at its centre of mass) inside a ground-fixed bearing.

    Args:
        clearance: the joint's clearance (the journal link is set to the body).
        mass: body mass [kg] > 0.
        inertia: body moment of inertia [kg m^2] > 0.
        speed: initial speed toward the wall [m/s] > 0.
        direction: direction of travel in the plane [rad] (0: along +x).
        tangential_speed: initial speed perpendicular to it [m/s] (oblique impact).
        **options: `ReferenceSystem` options.

    Returns:
        (system, q0, qd0): the system and its initial state (body centred, moving).

    Raises:
        ValueError: mass, inertia or speed not positive and finite.
    """
    for name, v in (("mass", mass), ("inertia", inertia), ("speed", speed)):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be > 0 and finite (got {v!r})")
    links = (
        Link("ground", 0.0, 0.0, points={"bearing": (0.0, 0.0)}),
        Link("body", mass, inertia, points={"journal": (0.0, 0.0)}),
    )
    cl = dataclasses.replace(clearance, journal_link="body")
    joints = (Joint("pin", JointType.REVOLUTE, "ground", "bearing", "body", "journal", clearance=cl),)
    system = ReferenceSystem.from_parts(links, joints, name="journal_in_bearing", **options)
    c, s = math.cos(direction), math.sin(direction)
    qd0 = np.array([speed * c - tangential_speed * s, speed * s + tangential_speed * c, 0.0])
    return system, np.zeros(3), qd0


def slider_in_guide(
    clearance: TranslationalClearance,
    *,
    mass: float,
    inertia: float,
    across: float = 0.0,
    tilt: float = 0.0,
    velocity: tuple[float, float] = (0.0, 0.0),
    spin: float = 0.0,
    **options: Unpack[ReferenceOptions],
) -> tuple[ReferenceSystem, np.ndarray, np.ndarray]:
    """A free block (centre of mass at its centre) with play in a ground-fixed guide along +x.

    The guide's centre line is the x axis; the block starts at x = 0.

    Args:
        clearance: the slider's play (block size, clearance, law, friction).
        mass: block mass [kg] > 0.
        inertia: block moment of inertia about its centre [kg m^2] > 0.
        across: initial position of the centre across the guide (y) [m].
        tilt: initial tilt [rad].
        velocity: initial velocity of the centre (along, across) [m/s].
        spin: initial angular velocity [rad/s].
        **options: `ReferenceSystem` options.

    Returns:
        (system, q0, qd0): the system (joint ``guide``) and its initial state.

    Raises:
        ValueError: mass or inertia not positive and finite, or the block starting inside
            a guide line.
    """
    for name, v in (("mass", mass), ("inertia", inertia)):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be > 0 and finite (got {v!r})")
    links = (
        Link("ground", 0.0, 0.0, points={"guide": (0.0, 0.0)}),
        Link("block", mass, inertia, points={"centre": (0.0, 0.0)}),
    )
    joints = (
        Joint("guide", JointType.PRISMATIC, "ground", "guide", "block", "centre", translational_clearance=clearance),
    )
    system = ReferenceSystem.from_parts(links, joints, name="slider_in_guide", **options)
    q0, qd0 = np.array([0.0, across, tilt]), np.array([velocity[0], velocity[1], spin])
    z0 = q0.tolist()
    for cp in system.contacts:
        if cp.evaluate(z0, z0, 0.0)[4] > 0.0:
            raise ValueError(f"the block starts inside a guide line (across = {across!r} m, tilt = {tilt!r} rad)")
    return system, q0, qd0
