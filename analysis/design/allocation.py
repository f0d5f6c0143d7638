"""Tolerance allocation: the cheapest clearance per joint whose output stays within its budget.

`allocate` answers the designer's question of the criticality study: how much clearance
may each joint have, so that the output's deviation stays within a budget at the lowest
manufacturing cost (`CostModel`: a + b / c per joint)?

1. Budget. Given, or measured: the ensemble mean of the measure at a reference design with
   every joint at one clearance.
2. Reachability. The lower-bound design (every joint at its lower bound: the tightest, so
   the least deviation the bounds allow) is run as a verification ensemble; when less than
   the target share of its runs (default 90 %) meets the budget at any speed, no design
   within the bounds can, and `BudgetUnreachable` is raised before the design runs.
3. Surrogate. A design of points varying all joints at once (`design_points`) is run, each
   point as a small ensemble (default 2 runs); a log-log quadratic response surface with
   every interaction term is fitted per speed (`fit_response_surface`).
4. Allocation. The cheapest clearances with the surrogate within budget at every speed
   (`cheapest_clearances`), verified by a full ensemble (default 20 runs from start
   offsets within 1 % of each clearance). Where the share of runs within budget falls short
   of the target, the verification ensemble joins the fit (weighted by its runs) and the
   surrogate's budget is tightened to B * S(c) / q (S(c): the refitted surrogate at the
   verified design, q: the verified quantile at the target share) less a margin of 1 %,
   then solved again, up to ``max_iterations`` times.
5. The equal-clearance design that meets the same budget, found and verified the same way
   (`equal_clearance`), is what the allocation saves against.
6. The front: allocation and equal design at budgets of ``front_fractions`` times the
   budget, on the final surrogate with the final tightening, each verified by a small
   ensemble.

Every run is kept in the ensemble store, so a rerun with the same arguments reuses each run
and, every step being deterministic, gives the same allocation; an interrupted allocation
resumes where it stopped.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.design.ensemble import (
    MEASURES,
    EnsembleResult,
    EnsembleSettings,
    EnsembleStopped,
    require_some_run,
    run_ensembles,
)
from clearance.analysis.design.surrogate import (
    CostModel,
    ResponseSurface,
    Vector,
    cheapest_clearances,
    design_points,
    equal_clearance,
    fit_response_surface,
    quadratic_terms,
)
from clearance.analysis.sweeps.executor import open_executor
from clearance.analysis.sweeps.sweep import MechanismFactory

__all__ = [
    "Allocation",
    "AllocationProblem",
    "AllocationSettings",
    "BudgetUnreachable",
    "FrontRow",
    "VerifiedDesign",
    "allocate",
]


class BudgetUnreachable(ValueError):
    """No design within the bounds meets the budget: the lower-bound design already misses it."""


@dataclass(frozen=True)
class AllocationProblem:
    """What is allocated.

    Attributes:
        joints: joints that get a clearance (the factory's point key ``clearances``).
        lower, upper: bounds per joint [m], 0 < lower < upper.
        cost: `CostModel` with one a and b per joint.
        measure: the output measure budgeted (a name of `MEASURES`).
        operating_points: one extra point dict per operating point (``{"speed": w}``, ...);
            ``({},)``: the factory's own.
        budgets: budget per operating point [output unit]; None: measured at
            ``budget_reference``.
        budget_reference: clearance [m] of every joint in the design whose verified mean
            gives the budget (when ``budgets`` is None).
        target_share: share of verification runs that must meet the budget, in (0, 1].
        levels: allowed clearances [m] (a grid of manufacturable values); None: continuous.
    """

    joints: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    cost: CostModel
    measure: str = "mean_deviation"
    operating_points: tuple[dict[str, Any], ...] = ({},)
    budgets: tuple[float, ...] | None = None
    budget_reference: float | None = None
    target_share: float = 0.9
    levels: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        n = len(self.joints)
        if n == 0 or len(set(self.joints)) != n:
            raise ValueError(f"joints must be distinct and not empty (got {list(self.joints)})")
        if len(self.lower) != n or len(self.upper) != n or len(self.cost.a) != n:
            raise ValueError("lower, upper and the cost model need one value per joint")
        for j, lo, hi in zip(self.joints, self.lower, self.upper, strict=True):
            if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
                raise ValueError(
                    f"bounds of joint {j}: expected 0 < lower < upper, got lower {lo * 1e3:g} mm, upper {hi * 1e3:g} mm"
                )
        if self.measure not in MEASURES:
            raise ValueError(f"measure must be one of {list(MEASURES)} (got {self.measure!r})")
        if not self.operating_points:
            raise ValueError("operating_points must not be empty")
        if self.budgets is None and self.budget_reference is None:
            raise ValueError("give budgets or a budget_reference clearance")
        if self.budgets is not None:
            if len(self.budgets) != len(self.operating_points):
                raise ValueError(
                    f"one budget per operating point expected ({len(self.operating_points)}), got {len(self.budgets)}"
                )
            if any(not (math.isfinite(b) and b > 0) for b in self.budgets):
                raise ValueError(f"budgets must be > 0 (got {self.budgets})")
        if self.budget_reference is not None and not (self.budget_reference > 0):
            raise ValueError(f"budget_reference must be > 0 m (got {self.budget_reference!r})")
        if not 0 < self.target_share <= 1:
            raise ValueError(f"target_share must be in (0, 1] (got {self.target_share!r})")
        if self.levels is not None:
            for j, lo, hi in zip(self.joints, self.lower, self.upper, strict=True):
                if not any(lo * (1 - 1e-12) <= v <= hi * (1 + 1e-12) for v in self.levels):
                    raise ValueError(
                        f"no allowed clearance level lies within the bounds of joint {j} "
                        f"[{lo * 1e3:g}, {hi * 1e3:g}] mm"
                    )


@dataclass(frozen=True)
class AllocationSettings:
    """How the allocation is computed.

    Attributes:
        verification: ensemble of every verification (runs, spread, seed, periods, output,
            options, evaluator); the design and front runs use the same but fewer runs.
        design_size: design points; None: twice the surrogate's terms plus 3.
        design_runs: runs per design point.
        design_seed: seed of the Latin hypercube.
        max_iterations: verifications per design (allocation, equal) at most.
        front_fractions: budgets of the front, as fractions of the budget.
        front_runs: runs per front design.
        margin: where a verification falls short, the surrogate's budget is tightened to
            (1 - margin) B S(c) / q, and at least by this fraction, so the next design does
            not land on the edge again.
    """

    verification: EnsembleSettings = field(default_factory=EnsembleSettings)
    design_size: int | None = None
    design_runs: int = 2
    design_seed: int = 0
    max_iterations: int = 4
    front_fractions: tuple[float, ...] = (0.5, 0.7, 1.0, 1.4, 2.0)
    front_runs: int = 5
    margin: float = 0.01

    def __post_init__(self) -> None:
        for name in ("design_runs", "max_iterations", "front_runs"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 1:
                raise ValueError(f"{name} must be a positive integer (got {v!r})")
        if self.design_size is not None and (not isinstance(self.design_size, int) or self.design_size < 4):
            raise ValueError(f"design_size must be an integer >= 4 (got {self.design_size!r})")
        if not 0 <= self.margin < 0.5:
            raise ValueError(f"margin must be in [0, 0.5) (got {self.margin!r})")
        if any(not (f > 0) for f in self.front_fractions):
            raise ValueError(f"front_fractions must be > 0 (got {self.front_fractions})")


@dataclass(frozen=True)
class VerifiedDesign:
    """A design and its verification ensemble at every operating point.

    Attributes:
        clearances: clearance per joint [m].
        cost: its cost.
        surrogate_budgets: the surrogate's budgets it was solved for, per operating point
            (empty for designs not solved for: reference, lower bound).
        predicted: the surrogate's deviation at it per operating point (empty when none).
        mean, sem, std, low, high: the measure over the ensemble per operating point.
        values: per-run values per operating point (failed runs left out).
        runs: runs per operating point.
        share: share of runs within budget per operating point (failed runs outside).
        meets: every share reaches the target.
    """

    clearances: tuple[float, ...]
    cost: float
    surrogate_budgets: tuple[float, ...]
    predicted: tuple[float, ...]
    mean: tuple[float, ...]
    sem: tuple[float, ...]
    std: tuple[float, ...]
    low: tuple[float, ...]
    high: tuple[float, ...]
    values: tuple[tuple[float, ...], ...]
    runs: int
    share: tuple[float, ...]
    meets: bool


@dataclass(frozen=True)
class FrontRow:
    """One budget of the cost-against-budget front.

    Attributes:
        fraction: budget / the budget.
        budgets: budgets per operating point [output unit].
        allocated, equal: the verified allocation and equal design (None: none within the
            bounds meets this budget on the surrogate).
    """

    fraction: float
    budgets: tuple[float, ...]
    allocated: VerifiedDesign | None
    equal: VerifiedDesign | None


@dataclass(frozen=True)
class Allocation:
    """What `allocate` found.

    Attributes:
        problem: the `AllocationProblem`.
        settings: the `AllocationSettings`.
        budgets: budget per operating point [output unit].
        reference: the verified reference design that set the budget (None: given).
        lower_bound: the verified lower-bound design.
        surrogates: final response surface per operating point.
        design: the design points' clearances (m, n) [m].
        allocation_iterations: every verified allocation, in order (the last is the answer).
        equal_iterations: every verified equal-clearance design.
        front: `FrontRow` per front fraction.
        new_runs: runs simulated by this call (the rest came from the store).
        total_runs: runs used in all.
        wall_time_s: wall time of this call [s].
    """

    problem: AllocationProblem
    settings: AllocationSettings
    budgets: tuple[float, ...]
    reference: VerifiedDesign | None
    lower_bound: VerifiedDesign
    surrogates: tuple[ResponseSurface, ...]
    design: tuple[tuple[float, ...], ...]
    allocation_iterations: tuple[VerifiedDesign, ...]
    equal_iterations: tuple[VerifiedDesign, ...]
    front: tuple[FrontRow, ...]
    new_runs: int
    total_runs: int
    wall_time_s: float

    @property
    def allocated(self) -> VerifiedDesign | None:
        """The answer: the last verified allocation (None when none was found)."""
        return self.allocation_iterations[-1] if self.allocation_iterations else None

    @property
    def equal(self) -> VerifiedDesign | None:
        """The equal-clearance design that meets the budget (its last verification)."""
        return self.equal_iterations[-1] if self.equal_iterations else None

    @property
    def saving(self) -> float:
        """1 - cost(allocation) / cost(equal design); NaN when either is missing."""
        a, e = self.allocated, self.equal
        return float("nan") if a is None or e is None else 1.0 - a.cost / e.cost


class _Runner:
    """Runs designs as ensembles through one executor and one store, counting new runs."""

    def __init__(
        self,
        make_mechanism: MechanismFactory,
        problem: AllocationProblem,
        settings: AllocationSettings,
        store: Path,
        executor: Executor,
        slots: int,
        progress: bool,
        stop_after: int | None,
    ) -> None:
        self.make, self.problem, self.settings = make_mechanism, problem, settings
        self.store, self.executor, self.slots, self.progress = store, executor, slots, progress
        self.remaining = stop_after
        self.new = 0
        self.total = 0

    def point(self, c: Vector, op: Mapping[str, Any]) -> dict[str, Any]:
        return {"clearances": {j: round(float(v), 9) for j, v in zip(self.problem.joints, c, strict=True)}, **op}

    def run(self, designs: Sequence[Vector] | np.ndarray, runs: int) -> list[list[EnsembleResult]]:
        """Ensembles of ``runs`` runs of each design at every operating point: [design][op]."""
        ops = self.problem.operating_points
        pts = [self.point(c, op) for c in designs for op in ops]
        before = len(list(self.store.glob("run_*.json")))
        if self.remaining is not None and self.remaining <= 0:  # the last batch used up stop_after
            raise EnsembleStopped(f"stopped after {self.new} runs", self.new)
        try:
            res = run_ensembles(
                self.make,
                pts,
                replace(self.settings.verification, runs=runs),
                store=self.store,
                executor=self.executor,
                max_workers=self.slots,
                progress=self.progress,
                stop_after=self.remaining,
            )
        except EnsembleStopped:
            made = len(list(self.store.glob("run_*.json"))) - before
            raise EnsembleStopped(f"stopped after {self.new + made} runs", self.new + made) from None
        finally:
            made = len(list(self.store.glob("run_*.json"))) - before
            self.new += made
            if self.remaining is not None:
                self.remaining -= made
        require_some_run(res)  # a batch where nothing ran says why, not "nan +- nan"
        self.total += len(pts) * runs
        return [res[i * len(ops) : (i + 1) * len(ops)] for i in range(len(designs))]

    def verify(
        self,
        c: Vector,
        budgets: Sequence[float],
        runs: int,
        surrogate_budgets: Sequence[float] = (),
        surrogates: Sequence[ResponseSurface] = (),
    ) -> VerifiedDesign:
        (ens,) = self.run([c], runs)
        m = self.problem.measure
        sums = [e.summary(m) for e in ens]
        share = tuple(e.share_within(m, b) for e, b in zip(ens, budgets, strict=True))
        c_arr = np.asarray(c, float)
        return VerifiedDesign(
            clearances=tuple(float(v) for v in c),
            cost=self.problem.cost(c_arr),
            surrogate_budgets=tuple(float(b) for b in surrogate_budgets),
            predicted=tuple(s(c_arr) for s in surrogates),
            mean=tuple(s.mean for s in sums),
            sem=tuple(s.sem for s in sums),
            std=tuple(s.std for s in sums),
            low=tuple(s.min for s in sums),
            high=tuple(s.max for s in sums),
            values=tuple(tuple(float(v) for v in e.values(m)) for e in ens),
            runs=runs,
            share=share,
            meets=all(s >= self.problem.target_share for s in share),
        )


@dataclass
class _FitData:
    """Points and values fitted per operating point, with their weights (runs averaged)."""

    points: list[list[float]]
    values: list[list[float]]  # [op][point]
    weights: list[float]

    def add(self, c: Vector, means: Sequence[float], weight: float) -> None:
        self.points.append([float(v) for v in c])
        for k, m in enumerate(means):
            self.values[k].append(float(m))
        self.weights.append(float(weight))

    def fit(self, reference: Vector) -> tuple[ResponseSurface, ...]:
        """One weighted response surface per operating point (points with no value left out)."""
        c = np.asarray(self.points, float)
        w = np.asarray(self.weights, float)
        out = []
        for vals in self.values:
            v = np.asarray(vals, float)
            ok = np.isfinite(v) & (v > 0)
            out.append(fit_response_surface(c[ok], v[ok], reference, w[ok]))
        return tuple(out)


def _quantile(design: VerifiedDesign, op: int, share: float) -> float:
    """The verified value below which ``share`` of the runs lie (a failed run counts as infinite)."""
    vals = np.sort(np.asarray(design.values[op], float))
    vals = np.concatenate([vals, np.full(design.runs - len(vals), np.inf)])
    k = max(0, math.ceil(share * len(vals)) - 1)
    return float(vals[k])


Solver = Callable[[Sequence[ResponseSurface], Sequence[float]], np.ndarray | None]


def _verify_loop(
    runner: _Runner,
    solve: Solver,
    data: _FitData,
    budgets: Sequence[float],
    reference: Vector,
    start: Sequence[float] | None = None,
) -> tuple[list[VerifiedDesign], tuple[ResponseSurface, ...], list[float]]:
    """Solve, verify, and where the share falls short refit and tighten (see the module docstring)."""
    s = runner.settings
    target = runner.problem.target_share
    surrogates = data.fit(reference)
    sb = list(start or budgets)
    done: list[VerifiedDesign] = []
    for _ in range(s.max_iterations):
        c = solve(surrogates, sb)
        if c is None:
            break
        v = runner.verify(c, budgets, s.verification.runs, sb, surrogates)
        done.append(v)
        if v.meets:
            break
        data.add(c, v.mean, s.verification.runs / s.design_runs)
        surrogates = data.fit(reference)
        for k, b in enumerate(budgets):
            q = _quantile(v, k, target)
            if q > b:
                aim = (1 - s.margin) * b * surrogates[k](np.asarray(c)) / q if math.isfinite(q) else 0.5 * sb[k]
                sb[k] = min(aim, (1 - s.margin) * sb[k])
    return done, surrogates, sb


def allocate(
    make_mechanism: MechanismFactory,
    problem: AllocationProblem,
    settings: AllocationSettings | None = None,
    *,
    store: str | Path,
    executor: Executor | None = None,
    scheduler_address: str | None = None,
    max_workers: int | None = None,
    progress: bool = True,
    stop_after: int | None = None,
) -> Allocation:
    """Allocate clearances (see the module docstring); resumable through ``store``.

    Args:
        make_mechanism: picklable design point -> Mechanism, for points
            ``{"clearances": {joint: c [m]}, **operating_point}`` (e.g. `JointClearances`).
        problem: `AllocationProblem`.
        settings: `AllocationSettings` (None: defaults).
        store: folder of the ensemble runs.
        executor, scheduler_address, max_workers: as `open_executor` (one pool for all).
        progress: progress bars.
        stop_after: stop after this many new runs (`EnsembleStopped`), to interrupt on purpose.

    Raises:
        BudgetUnreachable: the lower-bound design misses the budget (a `ValueError`).
        EnsembleStopped: stopped by ``stop_after``.
    """
    t0 = time.perf_counter()
    settings = settings or AllocationSettings()
    p = problem
    lo, hi = np.asarray(p.lower, float), np.asarray(p.upper, float)
    reference = np.sqrt(lo * hi)
    folder = Path(store)
    folder.mkdir(parents=True, exist_ok=True)
    with open_executor(executor, scheduler_address=scheduler_address, max_workers=max_workers) as pool:
        runner = _Runner(make_mechanism, p, settings, folder, pool.executor, pool.slots, progress, stop_after)
        nruns = settings.verification.runs
        ref: VerifiedDesign | None = None
        if p.budgets is None:
            assert p.budget_reference is not None
            c_ref = np.full(len(p.joints), p.budget_reference)
            ref = runner.verify(c_ref, [math.inf] * len(p.operating_points), nruns)
            budgets = ref.mean
            # its share within the budget it sets (about half its runs, by construction)
            share = tuple(sum(v <= b for v in vals) / ref.runs for vals, b in zip(ref.values, budgets, strict=True))
            ref = replace(ref, share=share, meets=all(x >= p.target_share for x in share))
        else:
            budgets = tuple(float(b) for b in p.budgets)
        low = runner.verify(lo, budgets, nruns)
        if not low.meets:
            k = int(np.argmin(low.share))
            raise BudgetUnreachable(
                f"budget {budgets[k]:.4g} of {p.measure} is out of reach: the tightest design the bounds allow "
                f"(every joint at its lower bound) gives {low.mean[k]:.4g} +- {low.std[k]:.2g} over {low.runs} runs, "
                f"{low.share[k]:.0%} of them within budget (target {p.target_share:.0%}); loosen the budget or "
                "lower the lower bounds"
            )
        n_terms = quadratic_terms(np.zeros((1, len(p.joints)))).shape[1]
        size = settings.design_size or 2 * n_terms + 3
        design = design_points(lo, hi, size, settings.design_seed)
        ens = runner.run(design, settings.design_runs)
        data = _FitData([], [[] for _ in p.operating_points], [])
        for c, per_op in zip(design, ens, strict=True):
            data.add(c, [e.summary(p.measure).mean for e in per_op], 1.0)

        def solve_alloc(surr: Sequence[ResponseSurface], sb: Sequence[float]) -> np.ndarray | None:
            return cheapest_clearances(surr, sb, p.cost, lo, hi, levels=p.levels)

        def solve_equal(surr: Sequence[ResponseSurface], sb: Sequence[float]) -> np.ndarray | None:
            c = equal_clearance(surr, sb, lo, hi, levels=p.levels)
            return None if c is None else np.full(len(p.joints), c)

        alloc_its, surrogates, alloc_sb = _verify_loop(runner, solve_alloc, data, budgets, reference)
        equal_its, surrogates, equal_sb = _verify_loop(runner, solve_equal, data, budgets, reference)
        front = _front(runner, surrogates, budgets, alloc_sb, equal_sb, solve_alloc, solve_equal)
    return Allocation(
        p,
        settings,
        tuple(budgets),
        ref,
        low,
        surrogates,
        tuple(tuple(float(v) for v in row) for row in design),
        tuple(alloc_its),
        tuple(equal_its),
        front,
        runner.new,
        runner.total,
        time.perf_counter() - t0,
    )


def _front(
    runner: _Runner,
    surrogates: Sequence[ResponseSurface],
    budgets: Sequence[float],
    alloc_sb: Sequence[float],
    equal_sb: Sequence[float],
    solve_alloc: Solver,
    solve_equal: Solver,
) -> tuple[FrontRow, ...]:
    """Allocation and equal design at each front budget, with the tightening learnt at the budget."""
    s = runner.settings
    rows = []
    for f in s.front_fractions:
        fb = [f * b for b in budgets]
        designs = []
        for solve, sb in ((solve_alloc, alloc_sb), (solve_equal, equal_sb)):
            c = solve(surrogates, [f * x for x in sb])
            designs.append(None if c is None else runner.verify(c, fb, s.front_runs, [f * x for x in sb], surrogates))
        rows.append(FrontRow(float(f), tuple(fb), designs[0], designs[1]))
    return tuple(rows)
