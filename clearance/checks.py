"""Checks of user-given numbers, with messages that name the field, the value and what was expected.

One place for the checks every floor makes on its inputs (the data model, the builders, the
contact laws and impacts, the reference solver), so the same mistake reads the same wherever
it is caught.
"""

from __future__ import annotations

import math
import numbers

__all__ = [
    "MAX_DRIVE_RPM",
    "MAX_DRIVE_SPEED",
    "NotANumberError",
    "WrongTypeError",
    "finite",
    "in_range",
    "of_type",
    "positive",
]

MAX_DRIVE_RPM = 60_000.0
"""Fastest drive speed accepted from a user [rpm] (1000 revolutions per second).

The catalogue's mechanisms run at up to 10,000 rpm in the benchmarks; at 50,000 rpm the
default slider-crank's journal is already pressed deeper into its bearing than its whole
radial clearance (634 µm into a 0.5 mm clearance), far outside what an elastic contact law of
a pin joint describes; at 10^6 rpm its run diverges at the default step, and at 10^9 rpm
still at a 10^-12 s step. Commands and scenario files refuse faster drives with this bound
named.
"""

MAX_DRIVE_SPEED = MAX_DRIVE_RPM * 2.0 * math.pi / 60.0
"""`MAX_DRIVE_RPM` in rad/s."""


class WrongTypeError(TypeError, ValueError):
    """An argument of the wrong type (a file name where a model is wanted, a dict for an options record).

    Both a `TypeError` and a `ValueError`, so callers catching either see it.
    """


def of_type(name: str, value: object, expected: type | tuple[type, ...], what: str) -> None:
    """Refuse ``value`` unless it is an instance of ``expected``, naming the argument.

    Args:
        name: the argument, for the message.
        value: what was given.
        expected: the type(s) accepted.
        what: the expected type for people, with how to get one (``a Mechanism (from a builder,
            e.g. clearance.builders.slider_crank())``).

    Raises:
        WrongTypeError: ``value`` is not an ``expected``.
    """
    if not isinstance(value, expected):
        shown = repr(value)
        shown = shown if len(shown) <= 60 else shown[:57] + "..."
        raise WrongTypeError(f"{name} must be {what} (got {type(value).__name__} {shown})")


class NotANumberError(WrongTypeError):
    """A number was expected and something else was given (a string, None, a bool).

    Both a `TypeError` and a `ValueError`, so callers catching either see it.
    """


def finite(name: str, value: object) -> float:
    """``value`` as a float if it is a finite real number (not a bool).

    Args:
        name: the field or argument, for the message.
        value: what was given.

    Returns:
        ``float(value)``.

    Raises:
        NotANumberError: not a real number (a string, None, a bool).
        ValueError: NaN or infinite.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise NotANumberError(f"{name} must be a finite number (got {value!r})")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be a finite number (got {value!r})")
    return v


def positive(name: str, value: object, unit: str = "") -> float:
    """``value`` as a float if it is a finite real number > 0.

    Args:
        name: the field or argument, for the message.
        value: what was given.
        unit: its unit, shown after the value in the message ('m', 'kg', 'N/m^n', ...).

    Returns:
        ``float(value)``.

    Raises:
        NotANumberError: not a real number.
        ValueError: NaN, infinite, or <= 0.
    """
    v = finite(name, value)
    if v <= 0:
        raise ValueError(f"{name} must be > 0 and finite (got {value!r}{' ' + unit if unit else ''})")
    return v


def in_range(name: str, value: object, lo: float, hi: float, unit: str = "") -> float:
    """``value`` as a float if it is a finite real number with ``lo <= value <= hi``.

    Args:
        name: the field or argument, for the message.
        value: what was given.
        lo, hi: the accepted range (inclusive).
        unit: the unit of value and bounds, for the message.

    Returns:
        ``float(value)``.

    Raises:
        NotANumberError: not a real number.
        ValueError: NaN, infinite, or outside [lo, hi].
    """
    v = finite(name, value)
    if not lo <= v <= hi:
        u = f" {unit}" if unit else ""
        raise ValueError(f"{name} must be between {lo:g} and {hi:g}{u} (got {value!r}{u})")
    return v
