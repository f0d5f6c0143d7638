"""The search of `clearance optimise`: a small design of experiments, then Nelder-Mead.

The objective of a design with clearance is an ensemble average: costly (tens of runs per
design), noisy (its standard error never vanishes) and of few variables (two to five link
lengths, pivot coordinates or masses). That rules out what needs gradients (finite
differences of a noisy objective point anywhere) and what needs hundreds of evaluations
(differential evolution, a fine grid). The search therefore:

1. evaluates the start design and a Latin-hypercube sample of the bounds in one batch (so
   the executor runs all their ensembles at once, and a start in a poor basin does not
   trap the search);
2. refines from the best design found with Nelder-Mead (`scipy.optimize.minimize`, bounded,
   in coordinates scaled to the unit cube), which compares values only, never
   differences, so noise below the gaps between simplex vertices does not mislead it, and
   needs about one new design per step;
3. stops at a budget of evaluated designs, or when the simplex has shrunk below
   ``xatol`` of the bounds.

Infeasible designs (decided by the kinematics, without a dynamic run) get a penalty worse
than every feasible value seen, and do not count against the budget. Designs already
evaluated are not evaluated again (a simplex revisits points).

The search only sees a batch objective (designs -> estimates), so it runs as well on a
closed-form function as on ensembles of simulations.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from clearance.analysis.design.optimise_space import unit_sample

__all__ = ["BatchObjective", "Estimate", "NoFeasibleDesign", "SearchResult", "SearchSettings", "Trial", "minimise"]


@dataclass(frozen=True)
class Estimate:
    """The objective of one design.

    Attributes:
        value: ensemble mean of the objective (NaN when infeasible or when every run failed).
        se: its standard error (NaN when unknown).
        feasible: the design passed the kinematic checks and ran.
        note: why it is infeasible or failed ('' otherwise).
    """

    value: float
    se: float
    feasible: bool
    note: str = ""


BatchObjective = Callable[[np.ndarray], list[Estimate]]
"""(k, dims) designs [SI] -> one `Estimate` each (evaluated together, e.g. on an executor)."""


@dataclass(frozen=True)
class Trial:
    """One design the search evaluated.

    Attributes:
        index: evaluation order (0 the start design).
        phase: ``start``, ``sample`` (design of experiments) or ``simplex`` (Nelder-Mead).
        x: the design [SI], one value per variable.
        estimate: its objective.
    """

    index: int
    phase: str
    x: tuple[float, ...]
    estimate: Estimate


@dataclass(frozen=True)
class SearchSettings:
    """How the search spends its evaluations.

    Attributes:
        samples: Latin-hypercube designs evaluated with the start design, >= 0.
        budget: most feasible designs evaluated in all (start and samples included),
            > samples + 1.
        seed: seed of the Latin-hypercube sample.
        step: initial simplex edge as a fraction of each variable's range, in (0, 0.5].
        xatol: Nelder-Mead stops when the simplex is within this fraction of the ranges.
    """

    samples: int = 8
    budget: int = 30
    seed: int = 0
    step: float = 0.15
    xatol: float = 0.01

    def __post_init__(self) -> None:
        if not isinstance(self.samples, int) or self.samples < 0:
            raise ValueError(f"samples must be an integer >= 0 (got {self.samples!r})")
        if not isinstance(self.budget, int) or self.budget < self.samples + 2:
            raise ValueError(
                f"budget must be an integer of at least samples + 2 = {self.samples + 2} evaluations, so that the "
                f"simplex gets some (got {self.budget!r})"
            )
        if not 0 < self.step <= 0.5:
            raise ValueError(f"step must be in (0, 0.5] of each range (got {self.step!r})")
        if not 0 < self.xatol < 1:
            raise ValueError(f"xatol must be in (0, 1) (got {self.xatol!r})")


@dataclass(frozen=True)
class SearchResult:
    """What `minimise` found.

    Attributes:
        trials: every evaluated design, in order.
        best: the feasible trial of lowest value.
        message: why the search stopped.
    """

    trials: tuple[Trial, ...]
    best: Trial
    message: str

    @property
    def evaluations(self) -> int:
        """Feasible designs evaluated."""
        return sum(t.estimate.feasible for t in self.trials)


class NoFeasibleDesign(ValueError):
    """No design the search evaluated was feasible; the message gives the designs' reasons (a run's error)."""


class _BudgetSpent(Exception):
    pass


class _Search:
    """The state of one search: scaling, memory of evaluated designs, budget."""

    def __init__(self, objective: BatchObjective, low: np.ndarray, high: np.ndarray, budget: int) -> None:
        self.objective, self.low, self.high, self.budget = objective, low, high, budget
        self.trials: list[Trial] = []
        self.seen: dict[tuple[float, ...], Estimate] = {}

    def design(self, u: np.ndarray) -> tuple[float, ...]:
        """Unit-cube coordinates -> a design [SI], rounded so revisits are found."""
        x = self.low + np.clip(u, 0.0, 1.0) * (self.high - self.low)
        return tuple(float(f"{v:.12g}") for v in x)

    def spent(self) -> int:
        return sum(t.estimate.feasible for t in self.trials)

    def evaluate(self, units: np.ndarray, phase: str) -> list[Estimate]:
        designs = [self.design(u) for u in units]
        new = list(dict.fromkeys(d for d in designs if d not in self.seen))
        if new:
            if self.spent() >= self.budget:
                raise _BudgetSpent
            for d, e in zip(new, self.objective(np.array(new)), strict=True):
                self.seen[d] = e
                self.trials.append(Trial(len(self.trials), phase, d, e))
        return [self.seen[d] for d in designs]

    def penalised(self, e: Estimate) -> float:
        """The value the simplex sees: infeasible designs worse than every feasible one."""
        if e.feasible and math.isfinite(e.value):
            return e.value
        ok = [t.estimate.value for t in self.trials if t.estimate.feasible and math.isfinite(t.estimate.value)]
        if not ok:
            return 1.0
        return max(ok) + (max(ok) - min(ok)) + abs(max(ok))


def minimise(
    objective: BatchObjective,
    low: Sequence[float],
    high: Sequence[float],
    start: Sequence[float],
    settings: SearchSettings | None = None,
) -> SearchResult:
    """Minimise a costly, noisy objective of a few bounded variables (see the module docstring).

    Args:
        objective: batch objective (designs [SI] -> estimates).
        low, high: bounds of each variable [SI], low < high.
        start: the start design [SI], within the bounds.
        settings: `SearchSettings` (None: defaults).

    Returns:
        `SearchResult`.

    Raises:
        ValueError: bounds or start of the wrong length, or the start outside the bounds.
        NoFeasibleDesign: no evaluated design was feasible (a `ValueError`).
    """
    from scipy.optimize import minimize

    s = settings or SearchSettings()
    lo, hi, x0 = (np.asarray(v, dtype=float) for v in (low, high, start))
    if not (lo.shape == hi.shape == x0.shape and lo.ndim == 1 and len(lo)) or not np.all(lo < hi):
        raise ValueError("low, high and start must be equally long, non-empty, with low < high")
    if np.any(x0 < lo) or np.any(x0 > hi):
        raise ValueError(f"start {x0.tolist()} lies outside the bounds {lo.tolist()} .. {hi.tolist()}")
    search = _Search(objective, lo, hi, s.budget)
    dims = len(lo)
    u0 = (x0 - lo) / (hi - lo)
    first = np.vstack([u0[None, :], unit_sample(s.samples, dims, s.seed)]) if s.samples else u0[None, :]
    search.evaluate(first[:1], "start")
    if s.samples:
        search.evaluate(first[1:], "sample")
    best = _best(search.trials)
    ub = (np.array(best.x) - lo) / (hi - lo)
    simplex = [ub]
    for i in range(dims):
        v = ub.copy()
        v[i] = v[i] + s.step if v[i] + s.step <= 1.0 else v[i] - s.step
        simplex.append(v)

    def f(u: np.ndarray) -> float:
        return search.penalised(search.evaluate(u[None, :], "simplex")[0])

    message = ""
    try:
        res = minimize(
            f,
            ub,
            method="Nelder-Mead",
            bounds=[(0.0, 1.0)] * dims,
            options={"initial_simplex": np.array(simplex), "xatol": s.xatol, "fatol": 0.0, "maxfev": 10 * s.budget},
        )
        message = f"simplex converged: {res.message}"
    except _BudgetSpent:
        message = f"budget of {s.budget} evaluated designs spent"
    return SearchResult(tuple(search.trials), _best(search.trials), message)


def _best(trials: Sequence[Trial]) -> Trial:
    ok = [t for t in trials if t.estimate.feasible and math.isfinite(t.estimate.value)]
    if not ok:
        notes = sorted({t.estimate.note for t in trials if t.estimate.note})
        raise NoFeasibleDesign(f"no evaluated design was feasible ({'; '.join(notes[:3]) or 'no reason given'})")
    return min(ok, key=lambda t: t.estimate.value)
