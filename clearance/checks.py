"""Checks of user-given numbers, with messages that name the field, the value and what was expected.

One place for the checks every floor makes on its inputs (the data model, the builders, the
contact laws and impacts, the reference solver), so the same mistake reads the same wherever
it is caught.
"""

from __future__ import annotations

import math
import numbers

__all__ = ["NotANumberError", "finite", "positive"]


class NotANumberError(TypeError, ValueError):
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
