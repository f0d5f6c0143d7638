"""Shared parts of the catalogue builders: geometry, link mass properties, the finished mechanism.

Links of the catalogue are steel bars: every link is a set of straight bars between its
named points (a binary link is one bar, a ternary plate is a triangle of three bars), with
a linear density of ``DEFAULT_LINEAR_DENSITY``; sliders are blocks of given mass. Link
frames have their origin at the link's first point and their x axis towards its second
point. Builders construct the pose at the drive start angles exactly (circle
intersections), and `finish` re-assembles it with the generic solver so that every link's
``pose_guess`` is the exact assembled pose at t = 0.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from clearance import checks
from clearance.builders._contact import ClearanceFactory
from clearance.kinematics import TransmissionAngle, assemble, solve_kinematics
from clearance.model import (
    Drive,
    DriveKind,
    Joint,
    Link,
    Mechanism,
    Output,
)

__all__ = [
    "DEFAULT_LINEAR_DENSITY",
    "LinkageInfo",
    "Point",
    "polar",
    "angle_of",
    "frame_point",
    "circle_circle",
    "line_circle",
    "bar_link",
    "slider_link",
    "finish",
    "make_mechanism",
    "crank_mechanism",
    "advance",
    "positive",
    "lengths",
]

Point = tuple[float, float]

DEFAULT_LINEAR_DENSITY = 1.57
"""Linear density of the catalogue's bars [kg/m]: steel (7850 kg/m^3), 20 mm x 10 mm."""


@dataclass(frozen=True)
class LinkageInfo:
    """What the catalogue records about a builder besides the `Mechanism` itself.

    Attributes:
        topology: one-paragraph description: chain, ground, input, output, slider.
        driven: driven joint(s) (ground pivots of the cranks).
        output_pivot: ground pivot or guide of the output link.
        clearable: revolute joints that may carry a clearance (all but the driven ones).
        criticality: joints of a criticality ranking (Alok, Chaudhary and Guha 2020; docs/references.md): every
            revolute joint but the driven crank's and the output link's ground pivots.
        transmission: where the transmission angles are measured.
        provenance: where the dimensions come from.
        sliders: prismatic joints whose slider may have play in its guide (a translational
            clearance; `clearance_at` may name them besides ``clearable``).
    """

    topology: str
    driven: tuple[str, ...]
    output_pivot: str
    clearable: tuple[str, ...]
    criticality: tuple[str, ...]
    transmission: tuple[TransmissionAngle, ...]
    provenance: str
    sliders: tuple[str, ...] = ()


def positive(name: str, value: float, unit: str = "m") -> float:
    """Check that a builder argument is a finite number > 0 (metres unless ``unit``); return it as float."""
    return checks.positive(name, value, unit)


def lengths(**values: float) -> dict[str, Any]:
    """The builder arguments ``values`` checked as lengths (finite, > 0) [m], as floats by name."""
    return {name: positive(name, value) for name, value in values.items()}


def polar(origin: Point, length: float, angle: float) -> Point:
    """origin + length (cos angle, sin angle) [m]."""
    return (origin[0] + length * math.cos(angle), origin[1] + length * math.sin(angle))


def angle_of(p: Point, q: Point) -> float:
    """Angle of the line p -> q from +x [rad]."""
    return math.atan2(q[1] - p[1], q[0] - p[0])


def frame_point(origin: Point, angle: float, local: Point) -> Point:
    """World position [m] of the point ``local`` of a frame at ``origin`` turned by ``angle`` [rad]."""
    u, v = local
    return (
        origin[0] + u * math.cos(angle) - v * math.sin(angle),
        origin[1] + u * math.sin(angle) + v * math.cos(angle),
    )


def circle_circle(p1: Point, r1: float, p2: Point, r2: float, *, left: bool, what: str) -> Point:
    """Intersection of circles (p1, r1) and (p2, r2): the one left of p1 -> p2 if ``left``.

    Raises:
        ValueError: the circles do not meet (the dyad ``what`` cannot close).
    """
    dx, dy = p2[0] - p1[0], p2[1] - p1[1]
    d = math.hypot(dx, dy)
    a = (r1**2 - r2**2 + d**2) / (2 * d) if d > 0 else math.inf
    h2 = r1**2 - a**2
    if not h2 >= 0:
        raise ValueError(
            f"{what} cannot be assembled: links of {r1:.4g} m and {r2:.4g} m cannot span "
            f"{d:.4g} m at the start angle (check the link lengths)"
        )
    h = math.sqrt(h2) * (1 if left else -1)
    mx, my = p1[0] + a * dx / d, p1[1] + a * dy / d
    return (mx - h * dy / d, my + h * dx / d)


def line_circle(p0: Point, direction: Point, centre: Point, r: float, *, forward: bool, what: str) -> Point:
    """Point of the line p0 + s direction at distance r from centre (larger s if ``forward``).

    Raises:
        ValueError: the line does not come within r of the centre.
    """
    n = math.hypot(*direction)
    ux, uy = direction[0] / n, direction[1] / n
    wx, wy = p0[0] - centre[0], p0[1] - centre[1]
    b = wx * ux + wy * uy
    disc = b**2 - (wx**2 + wy**2 - r**2)
    if disc < 0:
        raise ValueError(f"{what} cannot be assembled: a {r:.4g} m link cannot reach the guide")
    s = -b + math.sqrt(disc) if forward else -b - math.sqrt(disc)
    return (p0[0] + s * ux, p0[1] + s * uy)


def _mass_properties(
    local: Mapping[str, Point], bars: Sequence[tuple[str, str]], density: float
) -> tuple[float, float, Point]:
    """(mass [kg], inertia about the com [kg m^2], com [m]) of slender bars."""
    parts = []
    for a, b in bars:
        (xa, ya), (xb, yb) = local[a], local[b]
        length = math.hypot(xb - xa, yb - ya)
        m = density * length
        parts.append((m, m * length**2 / 12.0, ((xa + xb) / 2, (ya + yb) / 2)))
    mass = sum(p[0] for p in parts)
    cx = sum(p[0] * p[2][0] for p in parts) / mass
    cy = sum(p[0] * p[2][1] for p in parts) / mass
    inertia = sum(j + m * ((c[0] - cx) ** 2 + (c[1] - cy) ** 2) for m, j, c in parts)
    return mass, inertia, (cx, cy)


def _local(world: Mapping[str, Point], x0: float, y0: float, th: float) -> dict[str, Point]:
    """World points -> frame (x0, y0, th), rounded to 1e-12 m so that lengths read cleanly."""
    c, s = math.cos(th), math.sin(th)
    return {
        k: (round(c * (p[0] - x0) + s * (p[1] - y0), 12) + 0.0, round(-s * (p[0] - x0) + c * (p[1] - y0), 12) + 0.0)
        for k, p in world.items()
    }


def bar_link(
    name: str,
    world: Mapping[str, Point],
    *,
    density: float,
    bars: Sequence[tuple[str, str]] | None = None,
) -> Link:
    """A link of steel bars between its points, given at their world positions at t = 0.

    Args:
        name: link name.
        world: point name -> world position [m]; the frame origin is the first point and its
            x axis points to the second.
        density: linear density of the bars [kg/m].
        bars: bars as pairs of point names; default one bar for two points, a closed
            polygon (in the given order) for more.

    Returns:
        The link, with its pose at t = 0 as ``pose_guess``.
    """
    names = list(world)
    (x0, y0), (x1, y1) = world[names[0]], world[names[1]]
    th = math.atan2(y1 - y0, x1 - x0)
    local = _local(world, x0, y0, th)
    if bars is None:
        bars = [(names[0], names[1])] if len(names) == 2 else list(zip(names, names[1:] + names[:1]))
    mass, inertia, com = _mass_properties(local, bars, density)
    return Link(name, mass, inertia, com=com, points=local, pose_guess=(x0, y0, th))


def slider_link(name: str, world: Mapping[str, Point], *, mass: float, inertia: float, theta: float = 0.0) -> Link:
    """A slider block with its frame origin at its first point, rotated by ``theta`` [rad]."""
    names = list(world)
    x0, y0 = world[names[0]]
    return Link(name, mass, inertia, points=_local(world, x0, y0, theta), pose_guess=(x0, y0, theta))


def _posed(mechanism: Mechanism, q: np.ndarray) -> Mechanism:
    """The mechanism with every moving link's ``pose_guess`` read from the coordinates ``q``."""
    names = [m.name for m in mechanism.moving_links]

    def pose(lk: Link) -> Link:
        if lk.name == mechanism.ground:
            return lk
        i = 3 * names.index(lk.name)
        return dataclasses.replace(lk, pose_guess=(float(q[i]), float(q[i + 1]), float(q[i + 2])))

    return dataclasses.replace(mechanism, links=tuple(pose(lk) for lk in mechanism.links))


def finish(mechanism: Mechanism) -> Mechanism:
    """Re-assemble a built mechanism at t = 0 and store the exact poses as pose guesses.

    Raises:
        AssemblyError: the loops cannot be closed at the start angles, or the start
            position is singular.
    """
    return _posed(mechanism, assemble(mechanism))


def make_mechanism(
    clr: ClearanceFactory,
    links: Sequence[Link],
    joints: Sequence[Joint],
    drives: Sequence[Drive],
    outputs: Sequence[Output],
    parameters: Mapping[str, Any],
) -> Mechanism:
    """The `finish`-ed mechanism of a builder call, with the call's name and gravity (``clr``).

    Raises:
        ValueError: the parts do not make a valid `Mechanism`.
        AssemblyError: see `finish`.
    """
    return finish(
        Mechanism(
            name=clr.name,
            links=tuple(links),
            joints=tuple(joints),
            drives=tuple(drives),
            outputs=tuple(outputs),
            gravity=(0.0, -clr.gravity),
            parameters=parameters,
        )
    )


def crank_mechanism(
    clr: ClearanceFactory,
    links: Sequence[Link],
    joints: Sequence[Joint],
    output: Output,
    dimensions: Mapping[str, Any],
    *,
    linear_density: float,
    crank_speed: float,
    start_angle: float,
) -> Mechanism:
    """The mechanism of a builder whose one drive is a constant-speed crank on joint ``O2``.

    Args:
        clr: the call's contact keywords.
        links, joints: the mechanism's links and joints.
        output: its one output.
        dimensions: the builder's own parameters (JSON-friendly), first in ``parameters``.
        linear_density: mass per length of the bars [kg/m].
        crank_speed: constant crank speed [rad/s].
        start_angle: crank angle at t = 0 [rad].

    Raises:
        ValueError, AssemblyError: see `make_mechanism`.
    """
    parameters = {
        **dimensions,
        "linear_density": linear_density,
        "crank_speed": float(crank_speed),
        "start_angle": float(start_angle),
        **clr.parameters(),
    }
    drive = Drive("crank", "O2", speed=crank_speed, start_angle=start_angle)
    return make_mechanism(clr, links, joints, (drive,), (output,), parameters)


def advance(mechanism: Mechanism, start_angle: float) -> Mechanism:
    """Move a 1-DOF mechanism assembled at drive angle 0 to drive angle ``start_angle`` [rad].

    The assembly branch is followed by continuation; the drive's ``start_angle`` and every
    link's ``pose_guess`` are updated.

    Raises:
        SingularPositionError: a dead point lies between 0 and ``start_angle``.
    """
    (drive,) = mechanism.drives
    if start_angle == 0:
        return mechanism
    probe = dataclasses.replace(
        mechanism,
        drives=(
            dataclasses.replace(
                drive, kind=DriveKind.CONSTANT_SPEED, speed=math.copysign(1.0, start_angle), start_angle=0.0
            ),
        ),
    )
    q = solve_kinematics(probe, np.array([0.0, abs(start_angle)])).q[-1]
    return dataclasses.replace(_posed(mechanism, q), drives=(dataclasses.replace(drive, start_angle=start_angle),))
