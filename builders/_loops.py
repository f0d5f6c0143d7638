"""The loops several catalogue linkages start from: the crank-rocker and the in-line slider-crank.

Both are driven by crank 2 about O2 at the origin. The crank-rocker (the catalogue's
four-bar) closes through coupler 3 and rocker 4 about O4 on the +x axis, the coupler
above the ground line; the slider-crank through rod 3 and slider 4 on the x axis (guide
point G4 on the ground). Joints are named after the points they pin: A (crank 2 - coupler
or rod 3), B (coupler 3 - rocker 4, or rod 3 - slider 4).
"""

from __future__ import annotations

from clearance.builders._contact import ClearanceFactory
from clearance.builders._linkage import Point, angle_of, circle_circle, frame_point, line_circle, polar
from clearance.model import Joint

__all__ = [
    "crank_rocker",
    "crank_rocker_joints",
    "coupler_point",
    "coupler_bars",
    "slider_crank_loop",
    "slider_crank_joints",
]


def crank_rocker(crank: float, coupler: float, rocker: float, ground: float, start_angle: float) -> dict[str, Point]:
    """Points O2, O4, A, B of the crank-rocker loop at crank angle ``start_angle`` [rad].

    Args:
        crank, coupler, rocker, ground: O2-A, A-B, O4-B, O2-O4 [m].
        start_angle: crank angle from +x [rad].

    Returns:
        Point name -> world position [m].

    Raises:
        ValueError: the loop does not close at the start angle.
    """
    o2, o4 = (0.0, 0.0), (ground, 0.0)
    pa = polar(o2, crank, start_angle)
    pb = circle_circle(pa, coupler, o4, rocker, left=True, what="coupler 3 / rocker 4")
    return {"O2": o2, "O4": o4, "A": pa, "B": pb}


def crank_rocker_joints(clr: ClearanceFactory) -> tuple[Joint, ...]:
    """The crank-rocker's revolute joints O2, A, B, O4 (links ground, crank2, coupler3, rocker4)."""
    return (
        clr.pin("O2", "ground", "crank2"),
        clr.pin("A", "crank2", "coupler3"),
        clr.pin("B", "coupler3", "rocker4"),
        clr.pin("O4", "ground", "rocker4"),
    )


def coupler_point(points: dict[str, Point], local: Point) -> Point:
    """World position [m] of the point ``local`` of coupler 3's frame (origin A, x towards B)."""
    return frame_point(points["A"], angle_of(points["A"], points["B"]), local)


def coupler_bars(local: Point) -> list[tuple[str, str]]:
    """Bars of coupler 3 with a third point C at ``local`` in its frame: the bar A-C when C
    lies on the ray from A through B, the triangle A-B-C otherwise."""
    return [("A", "C")] if local[1] == 0 and local[0] >= 0 else [("A", "B"), ("B", "C"), ("C", "A")]


def slider_crank_loop(crank: float, rod: float, start_angle: float, *, pin: str, offset: Point) -> dict[str, Point]:
    """Points O2, A, B of the in-line slider-crank at crank angle ``start_angle`` [rad], and
    the slider's second pin.

    Args:
        crank, rod: O2-A, A-B [m].
        start_angle: crank angle from +x [rad].
        pin: name of the slider's second pin.
        offset: that pin relative to B (x, y) [m].

    Returns:
        Point name -> world position [m]; B is on the x axis, ahead of the crank.

    Raises:
        ValueError: the rod cannot reach the x axis.
    """
    o2 = (0.0, 0.0)
    pa = polar(o2, crank, start_angle)
    pb = line_circle(o2, (1.0, 0.0), pa, rod, forward=True, what="rod 3 / slider 4")
    return {"O2": o2, "A": pa, "B": pb, pin: (pb[0] + offset[0], pb[1] + offset[1])}


def slider_crank_joints(clr: ClearanceFactory) -> tuple[Joint, ...]:
    """The slider-crank's joints O2, A, B and the guide P4 (links ground, crank2, rod3, slider4)."""
    return (
        clr.pin("O2", "ground", "crank2"),
        clr.pin("A", "crank2", "rod3"),
        clr.pin("B", "rod3", "slider4"),
        clr.prismatic("P4", "ground", "G4", "slider4", "B", axis=(1.0, 0.0)),
    )
