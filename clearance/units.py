"""Units in scenario-file key names (``clearance_mm``, ``speed_rpm``, ``length_m``), and
quantities written for people (an SI prefix chosen by size: ``44 N``, ``1.33 kN``, ``6 s``).

Scenario files carry the unit in each key's name; values are converted to SI here, once,
at the edge. A key without a unit, or with a unit of the wrong kind, is an error.

`scaled_unit` picks the prefix that puts a magnitude between 1 and 1000 (an axis's unit from
its largest value); `format_quantity` writes one value that way.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["UNITS", "SI_UNIT", "quantity_of", "describe_units", "format_quantity", "scaled_unit"]

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
    "viscosity": {"pa_s": 1.0, "mpa_s": 1e-3},
    "film_thickness": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9},
    "contact_stiffness": {"n_per_m1_5": 1.0},
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
    "viscosity": "a dynamic viscosity",
    "film_thickness": "a film thickness",
    "contact_stiffness": "a contact stiffness (force per penetration^1.5)",
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
    if param in ("radial_clearance", "bearing_radius", "guide_height", "guide_x", "slider_height") or param.endswith(
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
    if param.endswith("_stiffness"):
        return "contact_stiffness"
    return None


_PREFIXES = (("G", 1e9), ("M", 1e6), ("k", 1e3), ("", 1.0), ("m", 1e-3), ("µ", 1e-6), ("n", 1e-9))
"""SI prefixes, largest first, with their factors."""

_LARGEST_PREFIX = {"s": "", "rad": "", "%": "", "-": "", "rpm": ""}
"""Units that take no prefix above 1 (no ks, krad); other units go up to G."""


def scaled_unit(magnitude: float, unit: str) -> tuple[str, float]:
    """The prefixed unit in which ``magnitude`` reads between 1 and 1000, and its factor.

    Args:
        magnitude: the largest value to be shown, in ``unit`` (its sign is ignored).
        unit: an SI unit (``N``, ``N m``, ``m/s²``, ``s``, ``J``, ...); the prefix goes before
            it (``kN m``, ``km/s²``, ``ms``). Units without a prefix above 1 (``s``, ``rad``,
            ``rpm``, ``%``, ``-``) stay as they are from 1 up.

    Returns:
        (prefixed unit, factor): ``value * factor`` is the value in the prefixed unit. A zero
        or non-finite magnitude keeps ``unit`` (factor 1).
    """
    m = abs(float(magnitude))
    if not np.isfinite(m) or m == 0.0 or unit in ("%", "-", "rpm"):
        return unit, 1.0
    top = _LARGEST_PREFIX.get(unit, "G")
    allowed = [p for p in _PREFIXES if p[1] <= dict(_PREFIXES)[top]]
    for prefix, factor in allowed:
        if m >= factor:
            return prefix + unit, 1.0 / factor
    prefix, factor = allowed[-1]
    return prefix + unit, 1.0 / factor


def format_quantity(value: float, unit: str, *, digits: int = 3) -> str:
    """``value`` written for people: ``digits`` significant digits in the unit chosen by size.

    Args:
        value: the value in ``unit`` (SI).
        unit: its unit (see `scaled_unit`).
        digits: significant digits (trailing zeros dropped).

    Returns:
        For example ``44 N``, ``1.33 kN``, ``-1.01 kN m``, ``6 s``, ``250 µs``; ``n/a`` for a
        non-finite value.
    """
    v = float(value)
    if not np.isfinite(v):
        return "n/a"
    unit_out, factor = scaled_unit(v, unit)
    text = f"{v * factor:.{digits}g}"
    if "e" in text:  # rounding reached 1000 (999.7 N -> 1e+03): one prefix up
        unit_out, factor = scaled_unit(float(text) / factor, unit)
        text = f"{v * factor:.{digits}g}"
    if "e" in text:  # no prefix above (6000 s): the whole number
        text = f"{v * factor:.0f}"
    return f"{text} {unit_out}" if unit_out not in ("%", "-") else (f"{text} %" if unit_out == "%" else text)
