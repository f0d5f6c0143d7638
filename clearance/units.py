"""Units in scenario-file key names (``clearance_mm``, ``speed_rpm``, ``length_m``).

Scenario files carry the unit in each key's name; values are converted to SI here, once,
at the edge. A key without a unit, or with a unit of the wrong kind, is an error.
"""

from __future__ import annotations

import math

__all__ = ["UNITS", "SI_UNIT", "quantity_of", "describe_units"]

UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6},
    "angle": {"rad": 1.0, "deg": math.pi / 180.0},
    "angular_speed": {"rad_per_s": 1.0, "rpm": 2.0 * math.pi / 60.0, "deg_per_s": math.pi / 180.0},
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6},
    "mass": {"kg": 1.0, "g": 1e-3},
    "inertia": {"kg_m2": 1.0, "g_mm2": 1e-9},
    "linear_density": {"kg_per_m": 1.0},
    "acceleration": {"m_per_s2": 1.0},
    "pressure": {"pa": 1.0, "mpa": 1e6, "gpa": 1e9},
    "torque": {"n_m": 1.0},
}
"""Quantity -> unit suffix -> factor to SI."""

SI_UNIT = {q: next(iter(u)) for q, u in UNITS.items()}
"""The SI suffix of each quantity (what `dump_scenario` writes)."""

_NAMES = {
    "length": "a length",
    "angle": "an angle",
    "angular_speed": "an angular speed",
    "time": "a time",
    "mass": "a mass",
    "inertia": "a moment of inertia",
    "linear_density": "a mass per length",
    "acceleration": "an acceleration",
    "pressure": "a pressure",
    "torque": "a torque",
}


def describe_units(base: str, quantity: str) -> str:
    """'radial_clearance is a length: use radial_clearance_m, radial_clearance_mm, ...'."""
    keys = ", ".join(f"{base}_{u}" for u in UNITS[quantity])
    return f"{base} is {_NAMES[quantity]}: use {keys}"


def quantity_of(param: str) -> str | None:
    """The quantity of a builder keyword argument, from its name (None: no unit)."""
    if param.endswith("_angle"):
        return "angle"
    if param.endswith("_speed"):
        return "angular_speed"
    if param in ("radial_clearance", "bearing_radius", "guide_height", "guide_x") or param.endswith(
        ("_length", "_arm", "_offset", "_point", "_pivot")
    ):
        return "length"
    if param.endswith("_mass"):
        return "mass"
    if param.endswith("_inertia"):
        return "inertia"
    if param == "linear_density":
        return "linear_density"
    if param == "gravity":
        return "acceleration"
    return None
