"""The design space of `clearance optimise`: design variables, the design factory, feasibility.

A design variable is a keyword of a mechanism builder (a link length, a pivot position, a
mass), or one component of a keyword whose value is a pair (``crank7_pivot[1]``: the y of
a pivot), with its bounds in SI units. `DesignFactory` turns a design point (variable ->
value) into a `Mechanism` by calling ``builder(**fixed, <keywords of the point>)``; it is
picklable when its builder is a module-level function, so the sweeps' executor can run it.

Feasibility is decided with the kinematics alone, before any dynamic run: a design is
feasible when its builder accepts it, its ideal linkage assembles and can be followed over
one whole period of its slowest drive without a singular position, and the stroke of the
output (its largest minus its smallest value over that period) stays within the stated
limits. `scan_bounds` checks a space-filling sample of the bounds up front, so that a
design that cannot assemble anywhere in its bounds is refused before any simulation.
"""

from __future__ import annotations

import inspect
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from clearance.model import Mechanism, OutputKind

__all__ = [
    "DesignFactory",
    "DesignVariable",
    "Feasibility",
    "InfeasibleSpaceError",
    "StrokeLimits",
    "check_design",
    "scan_bounds",
    "unit_sample",
]

_COMPONENT = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\[([0-9]+)\]$")


def _split(name: str) -> tuple[str, int | None]:
    """(keyword, component index or None) of a variable name (``crank7_pivot[1]``)."""
    m = _COMPONENT.match(name)
    return (m.group(1), int(m.group(2))) if m else (name, None)


@dataclass(frozen=True)
class DesignVariable:
    """One design variable: a builder keyword (or one component of a pair) within bounds.

    Attributes:
        name: builder keyword, or ``keyword[i]`` for component i of a pair keyword.
        low, high: bounds, low < high [SI unit of the keyword].
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        keyword, _ = _split(self.name)
        if not keyword.isidentifier():
            raise ValueError(f"design variable {self.name!r} must be a builder keyword, or keyword[i] for a pair")
        if not (math.isfinite(self.low) and math.isfinite(self.high)):
            raise ValueError(f"design variable {self.name}: bounds must be finite (got {self.low!r}, {self.high!r})")
        if not self.low < self.high:
            raise ValueError(
                f"design variable {self.name}: contradictory bounds, low {self.low:g} must be below high {self.high:g}"
            )

    @property
    def keyword(self) -> str:
        """The builder keyword the variable sets."""
        return _split(self.name)[0]

    @property
    def component(self) -> int | None:
        """Index of the component of a pair keyword it sets (None: the whole keyword)."""
        return _split(self.name)[1]


@dataclass(frozen=True)
class DesignFactory:
    """Picklable design point -> `Mechanism`: ``builder(**fixed, <the point's keywords>)``.

    A point maps variable names to values; a name ``keyword[i]`` replaces component i of
    the pair ``keyword`` (its value in ``fixed``, else the builder's default). Point keys
    that name no variable are passed to the builder as they are (a drive speed, say).

    Attributes:
        builder: a module-level builder function.
        fixed: keyword arguments given to every call (clearances, speeds, ...).
        variables: the design variables' names.
    """

    builder: Callable[..., Mechanism]
    fixed: Mapping[str, Any] = field(default_factory=dict)
    variables: tuple[str, ...] = ()

    def keywords(self, point: Mapping[str, Any]) -> dict[str, Any]:
        """The builder's keyword arguments for a point.

        Raises:
            ValueError: a component of a keyword that is not a pair, or out of its range.
        """
        kw = dict(self.fixed)
        for name, value in point.items():
            keyword, index = _split(name)
            if index is None:
                kw[keyword] = value
                continue
            base = kw.get(keyword, self.default(keyword))
            if not isinstance(base, (tuple, list)) or index >= len(base):
                raise ValueError(f"design variable {name}: {keyword} is not a pair with a component {index}")
            pair = [float(v) for v in base]
            pair[index] = float(value)
            kw[keyword] = tuple(pair)
        return kw

    def default(self, keyword: str) -> Any:
        """The builder's default value of a keyword (None when it has none).

        Raises:
            ValueError: the builder takes no such keyword.
        """
        params = inspect.signature(self.builder).parameters
        if keyword not in params:
            raise ValueError(
                f"design variable {keyword!r}: the builder {getattr(self.builder, '__name__', self.builder)} takes "
                f"no such keyword; it takes {', '.join(p for p in params if p != 'contact')}"
            )
        value = params[keyword].default
        return None if value is inspect.Parameter.empty else value

    def start_value(self, name: str) -> float:
        """A variable's value in ``fixed`` (else the builder's default) [SI].

        Raises:
            ValueError: the builder takes no such keyword, or it has no number there.
        """
        keyword, index = _split(name)
        base = self.fixed.get(keyword, self.default(keyword))
        value = base[index] if index is not None and isinstance(base, (tuple, list)) and index < len(base) else base
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"design variable {name}: the builder's value there is not a number ({value!r})")
        return float(value)

    def __call__(self, point: Mapping[str, Any]) -> Mechanism:
        return self.builder(**self.keywords(point))


@dataclass(frozen=True)
class StrokeLimits:
    """Allowed stroke of the output over one cycle (max - min of its ideal value).

    Attributes:
        low, high: limits [m for a position output, rad for an angle]; None: no limit.
    """

    low: float | None = None
    high: float | None = None

    def __post_init__(self) -> None:
        for v in (self.low, self.high):
            if v is not None and not (math.isfinite(v) and v >= 0):
                raise ValueError(f"stroke limits must be finite and >= 0 (got {v!r})")
        if self.low is not None and self.high is not None and not self.low < self.high:
            raise ValueError(f"contradictory stroke limits: low {self.low:g} must be below high {self.high:g}")

    def violation(self, stroke: float, *, angular: bool = False) -> str:
        """'' when ``stroke`` is within the limits, else why not (in mm, or deg for an angle)."""
        unit, f = ("deg", 180.0 / math.pi) if angular else ("mm", 1e3)
        if self.low is not None and stroke < self.low:
            return f"stroke {stroke * f:.4g} {unit} below its lower limit {self.low * f:.4g} {unit}"
        if self.high is not None and stroke > self.high:
            return f"stroke {stroke * f:.4g} {unit} above its upper limit {self.high * f:.4g} {unit}"
        return ""


@dataclass(frozen=True)
class Feasibility:
    """What the kinematics say of one design.

    Attributes:
        feasible: it assembles over its whole cycle and its stroke is within limits.
        reason: why not ('' when feasible).
        stroke: the output's stroke over one cycle (NaN when it does not assemble).
    """

    feasible: bool
    reason: str
    stroke: float


def check_design(
    factory: Callable[[Mapping[str, Any]], Mechanism],
    point: Mapping[str, Any],
    *,
    output: str | None = None,
    stroke: StrokeLimits | None = None,
    samples: int = 181,
) -> Feasibility:
    """Decide a design's feasibility with the kinematics (cheap: no dynamic run).

    Args:
        factory: design point -> `Mechanism`.
        point: the design point.
        output: the output whose stroke is limited (None: the mechanism's first).
        stroke: limits of its stroke (None: none).
        samples: times over one period of the slowest drive.

    Returns:
        `Feasibility`; a builder that refuses the point (a loop that cannot close at the
        start angles) or a singular position over the cycle makes it infeasible.
    """
    from clearance.kinematics import AssemblyError, solve_kinematics

    try:
        mech = factory(point)
        period = mech.drive_period
        if period is None:
            return Feasibility(False, f"mechanism '{mech.name}' has no drive with a set period", math.nan)
        kin = solve_kinematics(mech, np.linspace(0.0, period, samples))
    except (AssemblyError, ValueError, ArithmeticError) as err:
        return Feasibility(False, f"does not assemble over its cycle: {err}", math.nan)
    out = next((o for o in mech.outputs if o.name == output), None) if output else mech.outputs[0]
    if out is None:
        raise ValueError(f"output {output!r} is not an output of mechanism '{mech.name}'")
    y = kin.outputs[out.name]
    travel = float(np.max(y) - np.min(y))
    why = stroke.violation(travel, angular=out.kind is OutputKind.ANGLE) if stroke is not None else ""
    return Feasibility(not why, why, travel)


def unit_sample(count: int, dims: int, seed: int) -> np.ndarray:
    """A Latin-hypercube sample of the unit cube, reproducible: (count, dims) in [0, 1) from ``seed``."""
    from scipy.stats import qmc

    return np.asarray(qmc.LatinHypercube(d=dims, seed=seed).random(count))


class InfeasibleSpaceError(ValueError):
    """No design of a space-filling sample of the bounds is feasible."""


def scan_bounds(
    factory: Callable[[Mapping[str, Any]], Mechanism],
    variables: Sequence[DesignVariable],
    *,
    output: str | None = None,
    stroke: StrokeLimits | None = None,
    count: int = 32,
    seed: int = 0,
) -> dict[str, float]:
    """Check that some design within the bounds is feasible, before any dynamic run.

    The centre of the bounds, their corners (up to 16) and a Latin-hypercube sample of
    ``count`` designs are checked with `check_design`, stopping at the first feasible one.

    Args:
        factory: picklable design point -> Mechanism.
        variables: the design variables and their bounds.
        output: the output whose stroke is checked (default the mechanism's first).
        stroke: the stroke's limits (None: not checked).
        count: size of the Latin-hypercube sample.
        seed: the sample's seed.

    Returns:
        The first feasible design point found (variable -> value [SI]).

    Raises:
        InfeasibleSpaceError: none is feasible; the message gives the bounds and the reason
            of the centre design.
    """
    dims = len(variables)
    lo = np.array([v.low for v in variables])
    hi = np.array([v.high for v in variables])
    corners = np.array(np.meshgrid(*[[0.0, 1.0]] * dims)).reshape(dims, -1).T[:16]
    unit = np.vstack([np.full((1, dims), 0.5), corners, unit_sample(count, dims, seed)])
    first = ""
    for u in unit:
        point = {v.name: float(x) for v, x in zip(variables, lo + u * (hi - lo), strict=True)}
        f = check_design(factory, point, output=output, stroke=stroke)
        if f.feasible:
            return point
        first = first or f.reason
    bounds = ", ".join(f"{v.name} in [{v.low:g}, {v.high:g}]" for v in variables)
    raise InfeasibleSpaceError(
        f"no design within the bounds ({bounds}) is feasible: none of {len(unit)} designs checked (centre, corners, "
        f"a Latin-hypercube sample) assembles over its cycle with its stroke within limits; the centre: {first}"
    )
