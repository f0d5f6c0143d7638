"""Scenario files that name a catalogue builder: ``[mechanism] builder = "..."`` plus overrides.

Each other key of ``[mechanism]`` is a keyword argument of the builder, with the unit in
its name where the argument has one (``crank_speed_rpm``, ``radial_clearance_mm``,
``start_angle_deg``, ``rocker6_pivot_mm = [270, -20]``); ``clearance_mm`` is an alias of
``radial_clearance_mm``. ``law`` is a contact-law name, ``material`` a table
(youngs_modulus_gpa, poisson_ratio), a ``*_motion`` argument a table (speed_rad_per_s,
harmonics_rad, period_s), ``lubrication`` a table (viscosity_<pa_s|mpa_s>, film = "short" or
"long", transition_thickness_<m|mm|um|nm>; see `read_lubrication`).

A number with a unit must lie in the range `clearance.builders._toml_reader.RANGES` gives its
quantity (or be 0, which the builder then accepts or refuses): a crank of 1e-300 m or a rod
of 1e300 m is refused here, naming file, line, key and range, instead of dividing by zero or
overflowing in the builder.
"""

from __future__ import annotations

import inspect
import math
from typing import Any

from clearance.builders._toml_reader import Table
from clearance.kinematics import AssemblyError
from clearance.lubrication import DEFAULT_TRANSITION_THICKNESS, FilmModel, Lubrication
from clearance.model import ContactLaw, Material, Mechanism, MotionLaw
from clearance.units import UNITS, describe_units, quantity_of

__all__ = ["from_builder", "read_lubrication"]

_ALIASES = {"clearance": "radial_clearance"}


def _match(key: str, params: list[str]) -> tuple[str, float] | None:
    """(parameter, factor to SI) for a key; None if no parameter matches.

    Raises:
        ValueError: the key names a parameter but without a unit or with a wrong one.
    """
    if key in params:
        q = quantity_of(key)
        if q is None:
            return key, 1.0
        raise ValueError(f"needs a unit in its name ({describe_units(key, q)})")
    candidates = [key] + [t + key[len(a) :] for a, t in _ALIASES.items() if key.startswith(a + "_") and t in params]
    bad = None
    for k in candidates:
        for p in sorted(params, key=len, reverse=True):
            q = quantity_of(p)
            if q is not None and k.startswith(p + "_"):
                unit = k[len(p) + 1 :]
                if unit in UNITS[q]:
                    return p, UNITS[q][unit]
                bad = bad or (p, q, unit)
    if bad is not None:
        p, q, unit = bad
        raise ValueError(f"bad unit '{unit}' ({describe_units(p, q)})")
    return None


def read_lubrication(t: Table) -> Lubrication:
    """A ``lubrication`` table as a `Lubrication` (oil viscosity, film model, transition thickness).

    Raises:
        ScenarioError: a missing viscosity, a bad unit or value, an unknown film model or key.
    """
    viscosity = t.number("viscosity", "viscosity")
    film = FilmModel(t.text("film", default=FilmModel.SHORT.value, choices=[f.value for f in FilmModel]))
    ht = t.number("transition_thickness", "film_thickness", DEFAULT_TRANSITION_THICKNESS)
    t.finish(["viscosity_<pa_s|mpa_s>", "film", "transition_thickness_<m|mm|um|nm>"])
    try:
        return Lubrication(viscosity, film, ht)
    except ValueError as e:
        raise t.error(None, str(e)) from None


def _accepted(params: list[str]) -> list[str]:
    out = []
    for p in params:
        q = quantity_of(p)
        out.append(p if q is None else f"{p}_<{'|'.join(UNITS[q])}>")
    return out


def _convert(t: Table, key: str, param: str, factor: float, value: Any) -> Any:
    q = quantity_of(param)
    if q is not None:
        if isinstance(value, list):
            pair = t.convert_pair(key, value, factor)
            t.check_range(key, q, factor, pair)
            return pair
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
            raise t.error(key, f"must be a finite number (got {value!r})")
        t.check_range(key, q, factor, (value * factor,))
        return value * factor
    if param == "law":
        try:
            return ContactLaw(value)
        except ValueError:
            raise t.error(key, f"must be one of {[law.value for law in ContactLaw]} (got {value!r})") from None
    if param == "material":
        sub = Table(value, t.loc + (key,), f"{t.label} [{key}]", t.locator)
        m = Material(
            sub.number("youngs_modulus", "pressure", Material().youngs_modulus),
            sub.plain("poisson_ratio", Material().poisson_ratio),
        )
        sub.finish(["youngs_modulus_<pa|mpa|gpa>", "poisson_ratio"])
        return m
    if param == "lubrication":
        return read_lubrication(Table(value, t.loc + (key,), f"{t.label} [{key}]", t.locator))
    if param.endswith("_motion"):
        sub = Table(value, t.loc + (key,), f"{t.label} [{key}]", t.locator)
        harmonics = tuple(sub.convert_pair("harmonics_rad", h, 1.0) for h in sub.raw("harmonics_rad", []))
        law = MotionLaw(sub.number("speed", "angular_speed"), harmonics, sub.number("period", "time", 0.0) or None)
        sub.finish(["speed_<rad_per_s|rpm>", "harmonics_rad", "period_<s|ms>"])
        return law
    if param == "clearance_at":
        if not (isinstance(value, list) and all(isinstance(v, str) for v in value)):
            raise t.error(key, f"must be a list of joint names (got {value!r})")
        return tuple(value)
    return value


def from_builder(t: Table) -> Mechanism:
    """Build the mechanism of a ``[mechanism]`` table that names a builder.

    Raises:
        ScenarioError: unknown builder, unknown or badly-united key, a value the builder
            rejects, or a linkage that cannot be assembled.
    """
    from clearance.builders.catalogue import CATALOGUE

    name = t.text("builder")
    if name not in CATALOGUE:
        raise t.error("builder", f"unknown builder '{name}' (the catalogue has: {', '.join(CATALOGUE)})")
    builder = CATALOGUE[name].builder
    params = [p for p in inspect.signature(builder).parameters]
    kwargs: dict[str, Any] = {}
    keys: dict[str, str] = {}
    for key, value in t.data.items():
        if key == "builder":
            continue
        try:
            hit = _match(key, params)
        except ValueError as e:
            raise t.error(key, str(e)) from None
        if hit is None:
            raise t.error(key, f"'{name}' has no such argument; expected one of: {', '.join(_accepted(params))}")
        param, factor = hit
        if param in kwargs:
            raise t.error(key, f"{param} is given twice")
        kwargs[param] = _convert(t, key, param, factor, value)
        keys[param] = key
        t.used.add(key)
    speed = CATALOGUE[name].speed_keyword
    if isinstance(kwargs.get(speed), float) and kwargs[speed] < 0:  # as the command line's --rpm
        raise t.error(keys[speed], f"must be > 0: the drive's speed, as --rpm (got {t.data[keys[speed]]!r})")
    try:
        return builder(**kwargs)
    except AssemblyError as e:
        raise t.error(None, f"builder '{name}': the loops cannot be closed: {e}") from None
    except ArithmeticError as e:  # sizes within RANGES that still over- or underflow together
        raise t.error(None, f"builder '{name}': the sizes given cannot be computed with ({e})") from None
    except (ValueError, TypeError) as e:
        named = [k for p, k in keys.items() if p in str(e)]
        raise t.error(named[0] if named else None, f"builder '{name}': {e}") from None
