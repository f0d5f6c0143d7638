"""Design optimisation of a mechanism with clearance (`clearance optimise`).

The press paper's sizing in general form: design variables (builder keywords: link
lengths, pivot positions, masses) within bounds; feasibility from the kinematics (the
linkage assembles over its whole cycle, its stroke within limits;
`clearance.analysis.design.optimise_space`); an objective of the mechanism *with*
clearance, one measure of `clearance.analysis.design.ensemble` (``rms_deviation``: the
fluctuation of the output about its ideal curve; ``mean_deviation``; ``peak_deviation``;
``peak_force``: the peak bearing force) averaged over a start-state ensemble and over the
operating conditions given (drive speeds, say); the search of
`clearance.analysis.design.optimise_search`.

Every design of the search is run with the same ensemble seed (common random numbers:
designs are compared from the same start states, so their differences are not drowned in
start-state scatter). The optimum found that way is then **confirmed** by fresh ensembles,
with another seed, at the optimum and at the start design: the objective with its standard
error for both, and whether the optimum is lower by more than three standard errors of the
difference.

Every run is kept in a store folder as it finishes (`run_ensembles`), keyed by the design
and its start state: an interrupted optimisation run again replays its search from the
store (the search is deterministic) and simulates only what is missing.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.design.ensemble import MEASURES, EnsembleResult, EnsembleSettings, run_ensembles
from clearance.analysis.design.optimise_search import Estimate, SearchResult, SearchSettings, Trial, minimise
from clearance.analysis.design.optimise_space import (
    DesignFactory,
    DesignVariable,
    Feasibility,
    StrokeLimits,
    check_design,
    scan_bounds,
)
from clearance.analysis.sweeps.executor import open_executor

__all__ = [
    "Confirmation",
    "DesignEstimate",
    "EnsembleObjective",
    "OptimisationResult",
    "optimise_design",
]


@dataclass(frozen=True)
class DesignEstimate:
    """The objective of one design over every operating condition, from ensembles.

    Attributes:
        value: mean over conditions of the ensemble means [output unit, or N].
        se: its standard error, sqrt(sum se_i^2) / n over the n conditions.
        per_condition: (condition, mean, se) per operating condition.
        runs: runs that gave a value, over all conditions.
        failed: runs that failed.
        wall_time_s: simulated runs' wall time, summed [s] (NaN for runs read from the store).
        error: the first failed run's error ('' when none failed).
    """

    value: float
    se: float
    per_condition: tuple[tuple[dict[str, Any], float, float], ...]
    runs: int
    failed: int
    wall_time_s: float
    error: str = ""


def combine(
    ensembles: Sequence[EnsembleResult], conditions: Sequence[Mapping[str, Any]], measure: str
) -> DesignEstimate:
    """One design's `DesignEstimate` from its ensembles, one per condition (in order)."""
    rows = []
    for cond, ens in zip(conditions, ensembles, strict=True):
        s = ens.summary(measure)
        rows.append((dict(cond), s.mean, s.sem))
    n = len(rows)
    value = float(np.mean([r[1] for r in rows]))
    se = math.sqrt(sum(r[2] ** 2 for r in rows)) / n
    runs = sum(len(e.runs) - len(e.failed) for e in ensembles)
    failed = sum(len(e.failed) for e in ensembles)
    wall = float(np.nansum([r.wall_time_s for e in ensembles for r in e.runs]))
    error = next((r.error for e in ensembles for r in e.failed), "")
    return DesignEstimate(value, se, tuple(rows), runs, failed, wall, error)


@dataclass
class EnsembleObjective:
    """The batch objective of the search: designs -> ensemble estimates, infeasible ones skipped.

    Attributes:
        factory: design point -> `Mechanism`.
        variables: the design variables (order of the design vectors).
        measure: the objective, a name of `MEASURES`.
        ensemble: settings of every ensemble (its seed: the search's common random numbers).
        conditions: operating conditions, each extra keywords of the factory's point.
        stroke: limits of the output's stroke (None: none).
        store: folder keeping every run (None: nothing kept).
        executor: the executor every ensemble runs on.
        on_trial: called with (design point, feasibility, estimate or None) after each design.
        details: design vector -> (feasibility, estimate or None), filled as it goes.
    """

    factory: DesignFactory
    variables: tuple[DesignVariable, ...]
    measure: str
    ensemble: EnsembleSettings
    conditions: tuple[dict[str, Any], ...] = ({},)
    stroke: StrokeLimits | None = None
    store: Path | None = None
    executor: Executor | None = None
    on_trial: Callable[[dict[str, float], Feasibility, DesignEstimate | None], None] | None = None
    details: dict[tuple[float, ...], tuple[Feasibility, DesignEstimate | None]] = field(default_factory=dict)

    def point(self, x: Sequence[float]) -> dict[str, float]:
        """The factory's point of a design vector [SI]."""
        return {v.name: float(value) for v, value in zip(self.variables, x, strict=True)}

    def feasibility(self, x: Sequence[float]) -> Feasibility:
        """The kinematic feasibility of a design vector (at the first condition)."""
        return check_design(
            self.factory, {**self.point(x), **self.conditions[0]}, output=self.ensemble.output, stroke=self.stroke
        )

    def estimates(self, designs: Sequence[Sequence[float]], seed: int | None = None) -> list[DesignEstimate]:
        """Ensemble estimates of feasible designs (all conditions, one batch on the executor).

        Args:
            designs: design vectors [SI].
            seed: ensemble seed (None: the settings').
        """
        settings = self.ensemble if seed is None else replace(self.ensemble, seed=seed)
        points = [{**self.point(x), **c} for x in designs for c in self.conditions]
        results = run_ensembles(
            self.factory, points, settings, store=self.store, executor=self.executor, progress=False
        )
        n = len(self.conditions)
        return [combine(results[k * n : (k + 1) * n], self.conditions, self.measure) for k in range(len(designs))]

    def __call__(self, designs: np.ndarray) -> list[Estimate]:
        checks = [self.feasibility(x) for x in designs]
        ok = [k for k, c in enumerate(checks) if c.feasible]
        found = dict(zip(ok, self.estimates([designs[k] for k in ok]), strict=True)) if ok else {}
        out = []
        for k, (x, check) in enumerate(zip(designs, checks, strict=True)):
            est = found.get(k)
            self.details[tuple(float(v) for v in x)] = (check, est)
            if self.on_trial is not None:
                self.on_trial(self.point(x), check, est)
            if est is None:
                out.append(Estimate(math.nan, math.nan, False, check.reason))
            elif est.failed:
                failed = f"{est.failed} of {est.runs + est.failed} runs failed"
                out.append(Estimate(math.nan, math.nan, False, f"{failed}: {est.error}" if est.error else failed))
            else:
                out.append(Estimate(est.value, est.se, True))
        return out


@dataclass(frozen=True)
class Confirmation:
    """Fresh ensembles (a new seed) at the start design and at the optimum.

    Attributes:
        seed: their seed.
        start, optimum: their estimates.
        improvement: start value - optimum value.
        se: standard error of the improvement, sqrt(se_start^2 + se_optimum^2).
    """

    seed: int
    start: DesignEstimate
    optimum: DesignEstimate
    improvement: float
    se: float

    @property
    def significant(self) -> bool:
        """The optimum is lower by more than three standard errors of the difference."""
        return self.improvement > 3.0 * self.se


@dataclass(frozen=True)
class OptimisationResult:
    """What `optimise_design` found.

    Attributes:
        variables: the design variables.
        measure: the objective's measure.
        start: the start design [SI] (variable -> value).
        optimum: the best design found [SI].
        search: the search (every trial, in order).
        confirmation: the fresh ensembles at start and optimum.
        feasibility: design vector -> its kinematic check, for every design tried.
        estimates: design vector -> its search estimate (feasible designs only).
        ensemble: the ensembles' settings (the search's seed).
        conditions: the operating conditions.
    """

    variables: tuple[DesignVariable, ...]
    measure: str
    start: dict[str, float]
    optimum: dict[str, float]
    search: SearchResult
    confirmation: Confirmation
    feasibility: dict[tuple[float, ...], Feasibility]
    estimates: dict[tuple[float, ...], DesignEstimate]
    ensemble: EnsembleSettings
    conditions: tuple[dict[str, Any], ...]

    @property
    def best(self) -> Trial:
        """The search's best trial."""
        return self.search.best


def optimise_design(
    factory: DesignFactory,
    variables: Sequence[DesignVariable],
    *,
    measure: str = "rms_deviation",
    ensemble: EnsembleSettings | None = None,
    search: SearchSettings | None = None,
    conditions: Sequence[Mapping[str, Any]] = ({},),
    stroke: StrokeLimits | None = None,
    start: Mapping[str, float] | None = None,
    confirm_seed: int | None = None,
    store: str | Path | None = None,
    executor: Executor | None = None,
    scheduler_address: str | None = None,
    max_workers: int | None = None,
    on_trial: Callable[[dict[str, float], Feasibility, DesignEstimate | None], None] | None = None,
) -> OptimisationResult:
    """Search the design space for the lowest ensemble objective, then confirm it with fresh runs.

    Args:
        factory: design point -> `Mechanism` (picklable).
        variables: the design variables, with bounds.
        measure: the objective, one of `MEASURES`.
        ensemble: ensemble settings of the search (None: 20 runs within 1 % of c, seed 0).
        search: `SearchSettings` (None: defaults).
        conditions: operating conditions averaged over, each extra point keywords.
        stroke: limits of the output's stroke.
        start: the start design (None: the factory's values of the variables).
        confirm_seed: seed of the confirmation ensembles (None: the search's + 1).
        store: folder keeping every run (resume); None: nothing kept.
        executor, scheduler_address, max_workers: as `open_executor`.
        on_trial: called after each design the search tries.

    Returns:
        `OptimisationResult`.

    Raises:
        ValueError: an unknown measure, no variables, a variable the builder does not
            take, a start outside the bounds or infeasible, a confirmation seed equal to
            the search's.
        InfeasibleSpaceError: no design in the bounds assembles (a `ValueError`), raised
            before any dynamic run.
    """
    if measure not in MEASURES:
        raise ValueError(f"objective must be one of {list(MEASURES)} (got {measure!r})")
    variables = tuple(variables)
    if not variables:
        raise ValueError("give at least one design variable")
    names = [v.name for v in variables]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"design variable(s) {', '.join(twice)} given more than once")
    ens = ensemble or EnsembleSettings()
    seed = ens.seed + 1 if confirm_seed is None else confirm_seed
    if seed == ens.seed:
        raise ValueError(f"the confirmation seed must differ from the search's ({seed}): confirmation takes fresh runs")
    conds = tuple(dict(c) for c in conditions) or ({},)
    x0 = _start_design(factory, variables, start)
    first = check_design(factory, {**dict(zip(names, x0, strict=True)), **conds[0]}, output=ens.output, stroke=stroke)
    if not first.feasible:
        scan_bounds(factory, variables, output=ens.output, stroke=stroke)
        raise ValueError(f"the start design {dict(zip(names, x0, strict=True))} is infeasible: {first.reason}")
    folder = Path(store) if store is not None else None
    with open_executor(executor, scheduler_address=scheduler_address, max_workers=max_workers) as pool:
        objective = EnsembleObjective(factory, variables, measure, ens, conds, stroke, folder, pool.executor, on_trial)
        found = minimise(objective, [v.low for v in variables], [v.high for v in variables], x0, search)
        first_x = found.trials[0].x  # the start design as the search rounded it
        best = found.best.x
        est_start, est_best = objective.estimates([first_x, best], seed=seed)
    confirmation = Confirmation(
        seed, est_start, est_best, est_start.value - est_best.value, math.hypot(est_start.se, est_best.se)
    )
    return OptimisationResult(
        variables,
        measure,
        objective.point(first_x),
        objective.point(best),
        found,
        confirmation,
        {k: v[0] for k, v in objective.details.items()},
        {k: v[1] for k, v in objective.details.items() if v[1] is not None},
        ens,
        conds,
    )


def _start_design(
    factory: DesignFactory, variables: Sequence[DesignVariable], start: Mapping[str, float] | None
) -> list[float]:
    """The start design vector [SI], checked within the bounds."""
    given = dict(start or {})
    unknown = sorted(set(given) - {v.name for v in variables})
    if unknown:
        raise ValueError(f"start values of {unknown}, which are not design variables")
    x0 = []
    for v in variables:
        value = given[v.name] if v.name in given else factory.start_value(v.name)
        if not v.low <= value <= v.high:
            raise ValueError(
                f"design variable {v.name}: the start design's value {value:g} lies outside its bounds "
                f"[{v.low:g}, {v.high:g}]; widen the bounds or give a start value inside them"
            )
        x0.append(float(value))
    return x0
