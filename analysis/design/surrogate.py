"""Response surface of a deviation over all joints' clearances, and the cheapest clearances under it.

The surrogate is a quadratic response surface in log-log form with every interaction term:

    log D(c) = b0 + sum_j b_j x_j + sum_{j <= k} b_jk x_j x_k,   x_j = log(c_j / c_ref,j),

with ``c_ref`` the geometric middle of each joint's bounds. It is fitted by least squares to
the deviations measured at a design of points that vary all joints at once (`design_points`:
a Latin hypercube in log space plus the lower corner, the upper corner and the middle), so
the cross terms b_jk measure how joints interact. Its fit error is given as the RMS of the
log residuals (in sample) and of the leave-one-out residuals (out of sample, from the hat
matrix: r_i / (1 - h_ii)), both shown as relative errors exp(rms) - 1.

Cost of a design: sum_j a_j + b_j / (c_j / 1 mm), the manufacturing cost of a joint growing
as its clearance shrinks (default a = 0, b = 1). `cheapest_clearances` minimises it subject
to D_s(c) <= B_s for every speed's surrogate within the bounds (SLSQP in log c, from several
starts, the best feasible end kept), or over a grid of allowed clearance levels (every
combination enumerated); `equal_clearance` finds the largest single clearance for all joints
that meets the budgets.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "CostModel",
    "ResponseSurface",
    "cheapest_clearances",
    "design_points",
    "equal_clearance",
    "fit_response_surface",
    "quadratic_terms",
    "Vector",
]

Vector = Sequence[float] | np.ndarray
"""Values per joint (clearances [m], bounds [m])."""

Deviation = Callable[[np.ndarray], float]
"""Clearances (n,) [m] -> predicted deviation [output unit]."""

_FEASIBLE = 1e-9
"""Slack allowed on a constraint log B - log D(c) at an optimiser's end (relative 1e-9)."""


@dataclass(frozen=True)
class CostModel:
    """Cost of a design: sum_j a_j + b_j / (c_j / 1 mm).

    Attributes:
        a: fixed cost per joint [cost unit].
        b: cost per inverse millimetre of clearance per joint [cost unit mm].
    """

    a: tuple[float, ...]
    b: tuple[float, ...]

    def __post_init__(self) -> None:
        if len(self.a) != len(self.b):
            raise ValueError(f"cost a and b must have one value per joint (got {len(self.a)} and {len(self.b)})")
        if any(not math.isfinite(v) or v < 0 for v in self.a):
            raise ValueError(f"cost a must be finite and >= 0 (got {self.a})")
        if any(not math.isfinite(v) or v <= 0 for v in self.b):
            raise ValueError(f"cost b must be finite and > 0 (got {self.b})")

    def per_joint(self, clearances: Vector) -> np.ndarray:
        """Cost of each joint at clearances [m]."""
        c_mm = np.asarray(clearances, float) * 1e3
        return np.asarray(self.a) + np.asarray(self.b) / c_mm

    def __call__(self, clearances: Vector) -> float:
        """Total cost at clearances [m]."""
        return float(self.per_joint(clearances).sum())


def quadratic_terms(x: np.ndarray) -> np.ndarray:
    """Columns [1, x_j, x_j x_k (j <= k)] of the response surface for rows x (m, n)."""
    x = np.atleast_2d(x)
    n = x.shape[1]
    cols = [np.ones(len(x))] + [x[:, j] for j in range(n)]
    cols += [x[:, j] * x[:, k] for j, k in itertools.combinations_with_replacement(range(n), 2)]
    return np.column_stack(cols)


@dataclass(frozen=True)
class ResponseSurface:
    """A fitted log-log quadratic surface (see the module docstring).

    Attributes:
        reference: c_ref per joint [m].
        coefficients: b0, b_j, b_jk in `quadratic_terms` order.
        points: fitted points (clearances (m, n) [m]), as lists.
        values: fitted deviations (m,) [output unit].
        rms_log_residual: RMS of the in-sample log residuals.
        loo_rms_log_residual: RMS of the leave-one-out log residuals.
        max_abs_log_residual: largest in-sample |log residual|.
    """

    reference: tuple[float, ...]
    coefficients: tuple[float, ...]
    points: tuple[tuple[float, ...], ...]
    values: tuple[float, ...]
    rms_log_residual: float
    loo_rms_log_residual: float
    max_abs_log_residual: float

    def log_predict(self, clearances: np.ndarray) -> np.ndarray:
        """log D at clearances (n,) or (m, n) [m]."""
        c = np.atleast_2d(np.asarray(clearances, float))
        return quadratic_terms(np.log(c / np.asarray(self.reference))) @ np.asarray(self.coefficients)

    def __call__(self, clearances: np.ndarray) -> float:
        """Predicted deviation at clearances (n,) [m]."""
        return float(np.exp(self.log_predict(clearances)[0]))

    def predict(self, clearances: np.ndarray) -> np.ndarray:
        """Predicted deviations at clearances (m, n) [m]."""
        return np.exp(self.log_predict(clearances))

    @property
    def relative_error(self) -> tuple[float, float]:
        """(in-sample, leave-one-out) RMS relative error, exp(rms log residual) - 1."""
        return math.expm1(self.rms_log_residual), math.expm1(self.loo_rms_log_residual)


def fit_response_surface(
    clearances: np.ndarray,
    values: np.ndarray,
    reference: Vector,
    weights: Vector | None = None,
) -> ResponseSurface:
    """Least-squares fit of log D to the quadratic terms of log(c / c_ref).

    Args:
        clearances: (m, n) clearances [m].
        values: (m,) deviations > 0 [output unit].
        reference: c_ref per joint [m].
        weights: (m,) weights of the points (e.g. the runs each value averages); None:
            equal. The residuals reported are unweighted; the leave-one-out ones use the
            weighted fit's hat matrix.

    Raises:
        ValueError: fewer points than terms, or a value that is not > 0.
    """
    c = np.atleast_2d(np.asarray(clearances, float))
    y = np.asarray(values, float)
    if np.any(~np.isfinite(y)) or np.any(y <= 0):
        raise ValueError("every deviation fitted must be finite and > 0")
    a = quadratic_terms(np.log(c / np.asarray(reference, float)))
    if len(y) < a.shape[1]:
        raise ValueError(f"a response surface over {c.shape[1]} joints needs >= {a.shape[1]} points (got {len(y)})")
    ly = np.log(y)
    w = np.ones(len(y)) if weights is None else np.asarray(weights, float)
    if w.shape != y.shape or np.any(~np.isfinite(w)) or np.any(w <= 0):
        raise ValueError("weights must be one finite value > 0 per point")
    sw = np.sqrt(w / w.mean())
    aw = a * sw[:, None]
    coef, *_ = np.linalg.lstsq(aw, ly * sw, rcond=None)
    r = ly - a @ coef
    h = np.einsum("ij,ji->i", aw, np.linalg.pinv(aw))
    loo = r / np.maximum(1.0 - h, 1e-12)
    return ResponseSurface(
        tuple(float(v) for v in reference),
        tuple(float(v) for v in coef),
        tuple(tuple(float(v) for v in row) for row in c),
        tuple(float(v) for v in y),
        float(np.sqrt(np.mean(r**2))),
        float(np.sqrt(np.mean(loo**2))),
        float(np.max(np.abs(r))),
    )


def design_points(lower: Vector, upper: Vector, count: int, seed: int) -> np.ndarray:
    """Design of ``count`` points over the box [lower, upper] [m], log-uniform.

    The lower corner, the upper corner and the geometric middle, then a Latin hypercube
    (`scipy.stats.qmc.LatinHypercube`, the stated seed) in log c for the rest.

    Returns:
        (count, n) clearances [m], rounded to 1 nm.
    """
    from scipy.stats import qmc

    lo, hi = np.log(np.asarray(lower, float)), np.log(np.asarray(upper, float))
    fixed = [lo, hi, 0.5 * (lo + hi)]
    rest = max(0, count - len(fixed))
    unit = qmc.LatinHypercube(d=len(lo), seed=seed).random(rest) if rest else np.zeros((0, len(lo)))
    x = np.vstack([*fixed, lo + unit * (hi - lo)])[:count]
    return np.round(np.exp(x), 9)


def _feasible(c: np.ndarray, deviations: Sequence[Deviation], budgets: Sequence[float]) -> bool:
    return all(
        math.log(b) - math.log(max(f(c), 1e-300)) >= -_FEASIBLE for f, b in zip(deviations, budgets, strict=True)
    )


def cheapest_clearances(
    deviations: Sequence[Deviation],
    budgets: Sequence[float],
    cost: CostModel,
    lower: Vector,
    upper: Vector,
    *,
    levels: Sequence[float] | None = None,
) -> np.ndarray | None:
    """The clearances of least cost with every deviation within its budget.

    Args:
        deviations: one predicted deviation per speed (clearances [m] -> value).
        budgets: their budgets [output unit].
        cost: the `CostModel`.
        lower, upper: bounds per joint [m].
        levels: allowed clearances [m] (each joint takes those within its bounds); None:
            continuous.

    Returns:
        Clearances (n,) [m] (rounded to 1 nm in the continuous case), or None when no
        design within the bounds meets the budgets.
    """
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    if levels is not None:
        return _cheapest_on_grid(deviations, budgets, cost, lo, hi, levels)
    from scipy.optimize import minimize

    if not _feasible(lo, deviations, budgets):
        return None
    b = np.asarray(cost.b, float)

    def objective(x: np.ndarray) -> float:
        return float(np.sum(b / (np.exp(x) * 1e3)))

    def gradient(x: np.ndarray) -> np.ndarray:
        return -b / (np.exp(x) * 1e3)

    cons = [
        {"type": "ineq", "fun": (lambda x, f=f, bud=bud: math.log(bud) - math.log(max(f(np.exp(x)), 1e-300)))}
        for f, bud in zip(deviations, budgets, strict=True)
    ]
    bounds = list(zip(np.log(lo), np.log(hi), strict=True))
    starts = [np.log(lo), 0.5 * (np.log(lo) + np.log(hi)), np.log(hi)]
    best = lo.copy()  # feasible (checked above): the answer when no start ends better
    for x0 in starts:
        res = minimize(objective, x0, jac=gradient, bounds=bounds, constraints=cons, method="SLSQP",
                       options={"maxiter": 500, "ftol": 1e-12})  # fmt: skip
        c = np.clip(np.exp(res.x), lo, hi)
        if _feasible(c, deviations, budgets) and cost(c) < cost(best):
            best = c
    # rounding to 1 nm must keep the design feasible: round down where rounding broke it
    rounded = np.clip(np.round(best, 9), lo, hi)
    return rounded if _feasible(rounded, deviations, budgets) else np.clip(np.floor(best * 1e9) / 1e9, lo, hi)


def _cheapest_on_grid(
    deviations: Sequence[Deviation],
    budgets: Sequence[float],
    cost: CostModel,
    lo: np.ndarray,
    hi: np.ndarray,
    levels: Sequence[float],
) -> np.ndarray | None:
    """Every combination of allowed levels, the cheapest feasible one (ties: the first)."""
    lv = np.asarray(sorted(levels), float)
    per_joint = [lv[(lv >= lo[j] * (1 - 1e-12)) & (lv <= hi[j] * (1 + 1e-12))] for j in range(len(lo))]
    if any(len(p) == 0 for p in per_joint):
        return None
    grid = np.array(list(itertools.product(*per_joint)))
    costs = np.array([cost(row) for row in grid])
    for i in np.argsort(costs, kind="stable"):
        if _feasible(grid[i], deviations, budgets):
            return np.asarray(grid[i], float)
    return None


def equal_clearance(
    deviations: Sequence[Deviation],
    budgets: Sequence[float],
    lower: Vector,
    upper: Vector,
    *,
    levels: Sequence[float] | None = None,
) -> float | None:
    """The largest clearance that all joints may share with every deviation within budget.

    The deviations are taken to grow with the clearance along the diagonal: the answer is
    found by bisection in log c between max(lower) and min(upper) (or as the largest allowed
    level there that meets the budgets).

    Args:
        deviations: per operating point, clearances (n,) [m] -> predicted deviation.
        budgets: per operating point, the budget [SI].
        lower, upper: per joint, the clearance bounds [m].
        levels: allowed clearances [m] (None: any value in the bounds).

    Returns:
        The clearance [m] (rounded down to 1 nm), or None when the bounds share no clearance
        or none of it meets the budgets.
    """
    lo, hi = float(np.max(lower)), float(np.min(upper))
    n = len(lower)

    def ok(c: float) -> bool:
        return _feasible(np.full(n, c), deviations, budgets)

    if lo > hi * (1 + 1e-12):
        return None
    if levels is not None:
        allowed = [v for v in sorted(levels, reverse=True) if lo * (1 - 1e-12) <= v <= hi * (1 + 1e-12)]
        return next((float(v) for v in allowed if ok(v)), None)
    if not ok(lo):
        return None
    if ok(hi):
        return hi
    a, b = math.log(lo), math.log(hi)
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if ok(math.exp(m)) else (a, m)
    return math.floor(math.exp(a) * 1e9) / 1e9
