"""Validated reading of scenario TOML tables, with errors that name the table, key and line.

`tomllib` gives no positions for keys, so `Locator` finds them in the text: the header of
the table (the n-th ``[[joints]]`` for item n) and the first line in it that assigns the
key. Every error is a `ScenarioError` naming the file, the line where found, the table
and the key.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any, Literal, TypeVar, overload

from clearance.checks import MAX_DRIVE_SPEED
from clearance.units import UNITS, describe_units

__all__ = ["RANGES", "ScenarioError", "Locator", "Table"]

RANGES: dict[str, tuple[float, float]] = {
    "length": (1e-6, 1e3),
    "mass": (1e-6, 1e6),
    "inertia": (1e-15, 1e6),
    "linear_density": (1e-6, 1e6),
    "angular_speed": (1e-3, MAX_DRIVE_SPEED),
    "angle": (0.0, 1e4),
    "acceleration": (0.0, 1e4),
    "time": (1e-6, 1e6),
    "pressure": (1e3, 1e13),
    "torque": (0.0, 1e7),
    "viscosity": (1e-6, 1e4),
    "film_thickness": (1e-9, 1e-2),
    "contact_stiffness": (1e3, 1e16),
}
"""Quantity -> (smallest, largest) magnitude [SI] of a scenario number other than 0.

Lengths from 1 µm to 1 km, masses from 1 mg to 1000 t, drive speeds from 0.01 rpm to
`clearance.checks.MAX_DRIVE_RPM`, Young's moduli from 1 kPa (a gel) to 10 TPa (beyond
diamond); angles and accelerations up to 10^4 (rad, m/s^2); oil viscosities from 1 uPa s (a
gas) to 10 kPa s (a bitumen); film thicknesses from 1 nm to 1 cm; contact stiffnesses from 1e3 to
1e16 N/m^1.5. 0 is left to the mechanism's own checks (a ground link has no mass). A
coordinate pair (a point, a pivot, a centre of mass) is held to the largest magnitude only: a
coordinate may be 0 or tiny.
"""


class ScenarioError(ValueError):
    """A scenario file is malformed or describes an impossible mechanism.

    Attributes:
        path: the file (or ``<string>``).
        key: dotted key path of the offending entry, when known.
        line: 1-based line number, when found.
    """

    def __init__(self, message: str, *, path: str = "<string>", key: str | None = None, line: int | None = None):
        where = f"{path}, line {line}" if line else path
        super().__init__(f"{where}: {message}")
        self.path, self.key, self.line = path, key, line


_T = TypeVar("_T")

_HEADER = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")


class Locator:
    """Finds the line of a table or key in the scenario text (best effort)."""

    def __init__(self, text: str, path: str) -> None:
        self.path = path
        self.lines = text.splitlines()
        self.headers = [(i, m.group(2).replace(" ", "")) for i, ln in enumerate(self.lines) if (m := _HEADER.match(ln))]

    def line(self, loc: Sequence[str | int]) -> int | None:
        """1-based line of ``loc`` = (table, [index], [subtable...], key), or None."""
        start, end, prefix = 0, len(self.lines), ""
        parts = list(loc)
        key = None
        if parts and isinstance(last := parts[-1], str):
            key = last
            parts.pop()
        i = 0
        while i < len(parts):
            name = f"{prefix}.{parts[i]}" if prefix else str(parts[i])
            index = parts[i + 1] if i + 1 < len(parts) else None
            if isinstance(index, int):
                hits = [h for h, n in self.headers if n == name and start <= h < end]
                if len(hits) <= index:
                    return None
                start = hits[index]
                i += 2
            else:
                hits = [h for h, n in self.headers if n == name and start <= h < end]
                if hits:
                    start = hits[0]
                i += 1
            prefix = name
            end = next((h for h, n in self.headers if h > start and not n.startswith(prefix + ".")), len(self.lines))
        if key is None:
            return start + 1 if parts else None
        pat = re.compile(rf"(^|[{{,\s]){re.escape(key)}\s*=")
        for j in range(start, end):
            if pat.search(self.lines[j]) and not self.lines[j].lstrip().startswith("#"):
                return j + 1
        return start + 1 if parts else None


def _is_number(v: Any) -> bool:
    """A finite int or float (TOML also reads ``inf`` and ``nan``, which no scenario value may be)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


class Table:
    """One TOML table being read; keys read are marked, `finish` rejects the others.

    Args:
        data: the table.
        loc: its location, e.g. ("joints", 2, "clearance").
        label: how errors name it, e.g. "[[joints]] 'A'".
        locator: line finder.
    """

    def __init__(self, data: Any, loc: tuple[str | int, ...], label: str, locator: Locator) -> None:
        self.loc, self.label, self.locator = loc, label, locator
        if not isinstance(data, dict):
            raise self.error(None, f"must be a table (got {type(data).__name__})")
        self.data: dict[str, Any] = data
        self.used: set[str] = set()

    def error(self, key: str | None, message: str) -> ScenarioError:
        """A `ScenarioError` for ``key`` of this table (or the table itself)."""
        loc = self.loc + ((key,) if key else ())
        what = f"{self.label}: key '{key}'" if key else self.label
        dotted = ".".join(str(p) for p in loc)
        return ScenarioError(f"{what}: {message}", path=self.locator.path, key=dotted, line=self.locator.line(loc))

    def has(self, key: str) -> bool:
        """Whether ``key`` is present."""
        return key in self.data

    def raw(self, key: str, default: Any = None) -> Any:
        """The value of ``key`` as read, or ``default``."""
        if key in self.data:
            self.used.add(key)
            return self.data[key]
        return default

    def _default(self, default: _T | None, missing: str) -> _T:
        """``default`` for an absent key, which is required without one (``missing`` names it)."""
        if default is None:
            raise self.error(None, f"missing key {missing}")
        return default

    def text(self, key: str, *, default: str | None = None, choices: Sequence[str] | None = None) -> str:
        """A string value; required unless ``default`` is given."""
        if key not in self.data:
            return self._default(default, f"'{key}'")
        v = self.raw(key)
        if not isinstance(v, str):
            raise self.error(key, f"must be a string (got {v!r})")
        if choices is not None and v not in choices:
            raise self.error(key, f"must be one of {list(choices)} (got {v!r})")
        return v

    def plain(self, key: str, default: float | None = None) -> float:
        """A number without unit (restitution, friction, Poisson's ratio)."""
        if key not in self.data:
            return self._default(default, f"'{key}'")
        v = self.raw(key)
        if not _is_number(v):
            raise self.error(key, f"must be a finite number (got {v!r})")
        return v

    def _unit_key(self, base: str, quantity: str) -> tuple[str, float] | None:
        """(key, factor to SI) of the one key ``<base>_<unit>``; None when there is none."""
        units = UNITS[quantity]
        found = [k for k in self.data if k == base or k.startswith(base + "_")]
        if base in found:
            self.used.add(base)
            raise self.error(base, f"needs a unit in its name ({describe_units(base, quantity)})")
        good = [k for k in found if k[len(base) + 1 :] in units]
        bad = [k for k in found if k not in good]
        if bad:
            self.used.update(bad)
            raise self.error(bad[0], f"bad unit '{bad[0][len(base) + 1 :]}' ({describe_units(base, quantity)})")
        if len(good) > 1:
            raise self.error(good[1], f"{base} is given twice ({', '.join(good)})")
        if not good:
            return None
        self.used.add(good[0])
        return good[0], units[good[0][len(base) + 1 :]]

    def number(self, base: str, quantity: str, default: float | None = None) -> float:
        """A number with a unit in its key name, converted to SI; required unless defaulted."""
        hit = self._unit_key(base, quantity)
        if hit is None:
            return self._default(default, f"'{base}_<unit>' ({describe_units(base, quantity)})")
        key, factor = hit
        v = self.data[key]
        if not _is_number(v):
            raise self.error(key, f"must be a finite number (got {v!r})")
        self.check_range(key, quantity, factor, (v * factor,))
        return v * factor if factor != 1.0 else v

    def pair(self, base: str, quantity: str, default: tuple[float, float] | None = None) -> tuple[float, float]:
        """An (x, y) pair with a unit in its key name, converted to SI."""
        hit = self._unit_key(base, quantity)
        if hit is None:
            return self._default(default, f"'{base}_<unit>' ({describe_units(base, quantity)})")
        key, factor = hit
        pair = self.convert_pair(key, self.data[key], factor)
        self.check_range(key, quantity, factor, pair)
        return pair

    def check_range(
        self, key: str, quantity: str, factor: float, values: tuple[float, ...], unit: str | None = None
    ) -> None:
        """Refuse SI values of ``key`` outside `RANGES` of their quantity (one value: the range;
        a pair: its largest magnitude); the message gives ``unit``, by default the key's own."""
        if quantity not in RANGES:
            return
        lo, hi = RANGES[quantity]
        if unit is None:
            unit = next((u for u in sorted(UNITS[quantity], key=len, reverse=True) if key.endswith("_" + u)), "")
        single = len(values) == 1
        for v in values:
            m = abs(v)
            if (single and m != 0 and m < lo) or m > hi:
                expected = (
                    f"0 or between {lo / factor:g} and {hi / factor:g} {unit} in magnitude"
                    if single and lo > 0
                    else f"at most {hi / factor:g} {unit} in magnitude"
                )
                raise self.error(key, f"must be {expected} (got {v / factor:g} {unit})")

    def convert_pair(self, key: str, v: Any, factor: float) -> tuple[float, float]:
        """Check and convert an (x, y) value read from ``key``."""
        if not (isinstance(v, list) and len(v) == 2 and all(_is_number(x) for x in v)):
            raise self.error(key, f"must be a pair of finite numbers [x, y] (got {v!r})")
        return tuple(x * factor if factor != 1.0 else x for x in v)

    @overload
    def sub(self, key: str, label: str, *, required: Literal[True]) -> Table: ...

    @overload
    def sub(self, key: str, label: str, *, required: bool = False) -> Table | None: ...

    def sub(self, key: str, label: str, *, required: bool = False) -> Table | None:
        """The sub-table ``key`` (None when absent and not required)."""
        if key not in self.data:
            if required:
                raise self.error(None, f"missing table '{key}'")
            return None
        self.used.add(key)
        return Table(
            self.data[key], self.loc + (key,), f"{self.label} [{key}]" if self.label else f"[{key}]", self.locator
        )

    def array(self, key: str) -> list[Table]:
        """The array of tables ``[[key]]`` (empty when absent)."""
        items = self.data.get(key, [])
        self.used.add(key)
        if not isinstance(items, list):
            raise self.error(key, "must be an array of tables [[...]]")
        out = []
        for i, item in enumerate(items):
            name = item.get("name") if isinstance(item, dict) else None
            label = f"[[{key}]] #{i + 1}" + (f" '{name}'" if isinstance(name, str) else "")
            out.append(Table(item, (key, i), label, self.locator))
        return out

    def finish(self, accepted: Sequence[str]) -> None:
        """Reject keys that were not read (a misspelt key is never silently ignored).

        Args:
            accepted: the keys this table accepts, for the message (units as ``_<unit>``).
        """
        extra = [k for k in self.data if k not in self.used]
        if extra:
            raise self.error(extra[0], f"unknown key; expected one of: {', '.join(accepted)}")
