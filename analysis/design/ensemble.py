"""Start-state ensembles: one design run many times from slightly different start states.

A mechanism with clearance is sensitive to where each journal starts inside its bearing, so
one run's deviation is one sample. An ensemble runs the same design ``runs`` times, each
run starting with every clearance joint's journal centre at an offset drawn uniformly in
the disc of radius ``spread * c`` (c: that joint's radial clearance; default spread 1 %),
and reports each output measure's per-run values with their mean, standard error and
scatter.

Draws are reproducible and shared across designs: run ``k`` of seed ``s`` draws one point
``(sqrt(u) cos 2 pi v, sqrt(u) sin 2 pi v)`` of the unit disc per clearance joint (in the
mechanism's joint order) from ``numpy.random.default_rng([s, k])``, scaled by
``spread * c``. Two designs with the same joints thus start their run ``k`` at the same
relative offsets (common random numbers), which keeps differences between designs from
drowning in start-state scatter.

Measures of one run (`MEASURES`), over the steady window after the start-up window (the
first period of the slowest drive, `Mechanism.drive_period`), of the output ``y`` against
the ideal twin's ``y_ideal``:

- ``mean_deviation``: the criticality study's mean deviation, the mean over whole steady
  cycles of the per-cycle mean |y - y_ideal| (`per_cycle_mean_deviation`);
- ``rms_deviation``: sqrt(mean((y - y_ideal)^2));
- ``peak_deviation``: max |y - y_ideal|;
- ``peak_force``: the largest contact force magnitude of any clearance joint or slider with
  play (the net force on it) [N].

A slider with play starts centred in its guide in every run (start states offset journals).

Runs are picklable tasks (a mechanism factory, a point, a start state, the settings) sent
to the sweeps' executor (`open_executor`: a ``spawn`` process pool, a Dask cluster or the
caller's own). With a ``store`` folder each finished run is written at once to
``<store>/run_<hash>.json``, the hash taken over what identifies it (the mechanism, start
state, duration, options, output, evaluation); a later call finds it there and does not
simulate it again, so an interrupted batch resumes and a repeated one gives equal numbers.

This module receives mechanism factories and never builds models.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.sweeps.executor import Progress, open_executor
from clearance.analysis.sweeps.sweep import MechanismFactory
from clearance.model import Mechanism
from clearance.options import ModelOptions
from clearance.results import atomic_write_text

__all__ = [
    "MEASURES",
    "EnsembleResult",
    "EnsembleSettings",
    "EnsembleStopped",
    "EveryRunFailed",
    "MeasureSummary",
    "RunEvaluator",
    "RunMeasures",
    "StartState",
    "draw_start_states",
    "run_ensemble",
    "run_ensembles",
    "simulated_measures",
    "require_some_run",
]

MEASURES = ("mean_deviation", "rms_deviation", "peak_deviation", "peak_force")
"""Names of the measures every run gives (see the module docstring)."""

StartState = dict[str, tuple[float, float]]
"""Clearance joint -> initial journal eccentricity (e_x, e_y) [m] in the bearing frame."""

RunEvaluator = Callable[[Mechanism, StartState, "EnsembleSettings"], dict[str, Any]]
"""Picklable (mechanism, start state, settings) -> ``{measure: value, ...}`` for every name of
`MEASURES` (extra JSON-like fields are kept); default `simulated_measures`."""


@dataclass(frozen=True)
class EnsembleSettings:
    """How each design is run as an ensemble.

    Attributes:
        runs: runs per design (start states), >= 1.
        spread: radius of the start-offset disc as a fraction of each clearance, in [0, 1).
        seed: seed of the start-state draws.
        periods: simulated drive periods per run (the first is the start-up window), >= 2.
        output: output measured; None: the mechanism's first.
        options: `ModelOptions` of every run (None: defaults).
        evaluate: picklable (mechanism, start, settings) -> measures; None:
            `simulated_measures`.
    """

    runs: int = 20
    spread: float = 0.01
    seed: int = 0
    periods: int = 4
    output: str | None = None
    options: ModelOptions | None = None
    evaluate: RunEvaluator | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.runs, int) or self.runs < 1:
            raise ValueError(f"runs must be a positive integer (got {self.runs!r})")
        if not (isinstance(self.spread, (int, float)) and 0.0 <= self.spread < 1.0):
            raise ValueError(f"spread must be in [0, 1) (a fraction of each clearance; got {self.spread!r})")
        if not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"seed must be a non-negative integer (got {self.seed!r})")
        if not isinstance(self.periods, int) or self.periods < 2:
            raise ValueError(f"periods must be an integer >= 2 (the first is start-up; got {self.periods!r})")


@dataclass(frozen=True)
class RunMeasures:
    """One run of an ensemble.

    Attributes:
        index: run index k within the ensemble.
        start: its start state.
        status: ``ok`` or ``error``.
        error: error message ('' when ok).
        values: measure -> value (every name of `MEASURES` when ok) [output unit; N for
            ``peak_force``], plus extra fields of the evaluator (``per_cycle_mean_deviation``,
            ``peak_force_by_joint``).
        wall_time_s: wall time of the run [s] (when it was simulated).
    """

    index: int
    start: StartState
    status: str
    error: str = ""
    values: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = float("nan")


@dataclass(frozen=True)
class MeasureSummary:
    """One measure over an ensemble's successful runs.

    Attributes:
        measure: its name.
        n: runs that gave it.
        mean: mean over runs.
        sem: standard error of the mean, std / sqrt(n) (NaN for one run).
        std: sample standard deviation over runs (the scatter; NaN for one run).
        min, max: extremes over runs.
    """

    measure: str
    n: int
    mean: float
    sem: float
    std: float
    min: float
    max: float


@dataclass(frozen=True)
class EnsembleResult:
    """An ensemble of one design.

    Attributes:
        point: the factory's point of the design.
        runs: `RunMeasures` in run order.
        settings: the `EnsembleSettings` used.
    """

    point: dict[str, Any]
    runs: tuple[RunMeasures, ...]
    settings: EnsembleSettings

    @property
    def failed(self) -> tuple[RunMeasures, ...]:
        """Runs that did not finish."""
        return tuple(r for r in self.runs if r.status != "ok")

    def values(self, measure: str) -> np.ndarray:
        """Per-run values of a measure over the successful runs.

        Raises:
            KeyError: not a name of `MEASURES`.
        """
        if measure not in MEASURES:
            raise KeyError(f"measure must be one of {list(MEASURES)} (got {measure!r})")
        return np.array([float(r.values[measure]) for r in self.runs if r.status == "ok"])

    def summary(self, measure: str) -> MeasureSummary:
        """Mean, standard error and scatter of a measure (NaN when no run succeeded)."""
        v = self.values(measure)
        n = len(v)
        if n == 0:
            nan = float("nan")
            return MeasureSummary(measure, 0, nan, nan, nan, nan, nan)
        std = float(v.std(ddof=1)) if n > 1 else float("nan")
        return MeasureSummary(measure, n, float(v.mean()), std / math.sqrt(n), std, float(v.min()), float(v.max()))

    def share_within(self, measure: str, budget: float) -> float:
        """Share of all runs whose measure is <= budget (a failed run counts as outside)."""
        if not self.runs:
            return float("nan")
        return float(np.count_nonzero(self.values(measure) <= budget) / len(self.runs))


class EveryRunFailed(ValueError):
    """Every run of a batch failed: what the runs share (the time step, the contact), not a design, is at fault.

    The message is the runs' own error, once (the first run's), so the setting it names can be
    changed.
    """


def require_some_run(results: Sequence[EnsembleResult]) -> None:
    """Raise `EveryRunFailed` when not one run of ``results`` finished.

    Raises:
        EveryRunFailed: every run failed; the message gives how many and the first run's error.
    """
    runs = [r for e in results for r in e.runs]
    if runs and all(r.status != "ok" for r in runs):
        raise EveryRunFailed(f"every one of the {len(runs)} runs failed; the first: {runs[0].error}")


class EnsembleStopped(RuntimeError):
    """`run_ensembles` stopped after ``stop_after`` runs; those finished are in the store."""

    def __init__(self, message: str, finished: int) -> None:
        super().__init__(message)
        self.finished = finished


def draw_start_states(mechanism: Mechanism, runs: int, spread: float, seed: int) -> list[StartState]:
    """Start states of an ensemble: offsets uniform in discs of radius spread * c.

    Args:
        mechanism: the design (its clearance joints and their clearances).
        runs: number of start states.
        spread: disc radius as a fraction of each joint's radial clearance.
        seed: seed (run k draws from ``numpy.random.default_rng([seed, k])``).

    Returns:
        One `StartState` per run; empty dicts for a mechanism without clearance joints.
    """
    joints = mechanism.clearance_joints
    out = []
    for k in range(runs):
        rng = np.random.default_rng([seed, k])
        u = rng.random((len(joints), 2))
        state = {}
        for j, (a, b) in zip(joints, u, strict=True):
            r = spread * j.require_clearance().radial_clearance * math.sqrt(a)
            state[j.name] = (float(r * math.cos(2 * math.pi * b)), float(r * math.sin(2 * math.pi * b)))
        out.append(state)
    return out


def simulated_measures(mechanism: Mechanism, start: StartState, settings: EnsembleSettings) -> dict[str, Any]:
    """The measures of one simulated run (see the module docstring); runs in a worker.

    The ideal twin is simulated once per worker and reused (`ideal_run`).

    Args:
        mechanism: the design with its clearances.
        start: clearance joint -> its journal's start offset (e_x, e_y) [m]; empty: centred.
        settings: periods, output, options of the run.

    Raises:
        ValueError: the mechanism has no drive with a set period, or not the output.
    """
    from clearance.analysis.metrics.statistics import deviation_statistics, per_cycle_mean_deviation
    from clearance.analysis.metrics.summary import contact_series
    from clearance.analysis.sweeps.ideal_runs import ideal_run
    from clearance.run.simulation import simulate

    period = mechanism.drive_period
    if period is None:
        raise ValueError(f"mechanism '{mechanism.name}' has no drive with a set period")
    output = settings.output or mechanism.outputs[0].name
    duration = settings.periods * period
    res = simulate(mechanism, duration=duration, options=settings.options, initial_eccentricity=start or None)
    ideal = ideal_run(mechanism, duration, settings.options)
    cycles = per_cycle_mean_deviation(res, ideal, output, period=period, skip=period)
    stats = deviation_statistics(res, ideal, output, skip=period)
    steady = res.times >= res.times[0] + period
    forces = {  # a slider with play: the net contact force on it
        j: float(contact_series(res, j)[1][steady].max()) if steady.any() else 0.0 for j in (*res.joints, *res.sliders)
    }
    return {
        "mean_deviation": float(cycles.mean()),
        "rms_deviation": stats.rms_deviation,
        "peak_deviation": stats.max_deviation,
        "peak_force": max(forces.values(), default=0.0),
        "per_cycle_mean_deviation": cycles.tolist(),
        "peak_force_by_joint": forces,
    }


@dataclass(frozen=True)
class _Task:
    """One run of one design (picklable)."""

    make_mechanism: MechanismFactory
    point: dict[str, Any]
    index: int
    start: StartState
    settings: EnsembleSettings


def _run_task(task: _Task) -> dict[str, Any]:
    """Build and evaluate one run (in a worker); a failure becomes an ``error`` record."""
    t0 = time.perf_counter()
    rec: dict[str, Any] = {"index": task.index, "status": "ok", "error": "", "values": {}}
    try:
        mech = task.make_mechanism(task.point)
        evaluate = task.settings.evaluate or simulated_measures
        values = evaluate(mech, task.start, task.settings)
        missing = [m for m in MEASURES if m not in values or not np.isfinite(float(values[m]))]
        if missing:
            raise ValueError(f"the evaluation gave no finite value of {missing}")
        rec["values"] = json.loads(json.dumps(values, default=float))
    except Exception as err:
        rec["status"] = "error"
        rec["error"] = f"{type(err).__name__}: {err}"
    rec["wall_time_s"] = time.perf_counter() - t0
    return rec


def _describe(obj: object) -> str:
    """A description of a callable stable across processes (no memory addresses)."""
    if obj is None:
        return "None"
    if callable(obj) and hasattr(obj, "__qualname__") and not hasattr(obj, "__dataclass_fields__"):
        return f"{getattr(obj, '__module__', '?')}.{obj.__qualname__}"
    return repr(obj)


def _run_key(mechanism: Mechanism, start: StartState, settings: EnsembleSettings) -> str:
    """What identifies one run's content."""
    return repr(
        (
            mechanism,
            sorted(start.items()),
            settings.periods,
            settings.output,
            settings.options,
            _describe(settings.evaluate),
        )
    )


def _file_name(key: str) -> str:
    return f"run_{hashlib.sha256(key.encode()).hexdigest()[:20]}.json"


def _load(path: Path, key: str) -> dict[str, Any] | None:
    """A stored run record with this key, or None (absent, unreadable or another run's)."""
    try:
        rec = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return rec if isinstance(rec, dict) and rec.get("key") == key else None


def run_ensembles(
    make_mechanism: MechanismFactory,
    points: Sequence[Mapping[str, Any]],
    settings: EnsembleSettings | None = None,
    *,
    store: str | Path | None = None,
    executor: Executor | None = None,
    scheduler_address: str | None = None,
    max_workers: int | None = None,
    progress: bool = True,
    stop_after: int | None = None,
) -> list[EnsembleResult]:
    """Run every design of ``points`` as an ensemble, all runs through one executor.

    Args:
        make_mechanism: picklable point -> `Mechanism` (a design with its clearance joints).
        points: one point per design (JSON-like parameters).
        settings: `EnsembleSettings` (None: defaults, 20 runs within 1 % of c, seed 0).
        store: folder keeping each finished run (resume; see the module docstring); None:
            nothing kept.
        executor, scheduler_address, max_workers: as `open_executor`.
        progress: show a progress bar of runs.
        stop_after: simulate exactly this many runs in this call (no more are started), then
            raise `EnsembleStopped`; to interrupt a batch on purpose.

    Returns:
        One `EnsembleResult` per point, in order.

    Raises:
        ValueError: a bad stop_after.
        EnsembleStopped: stopped by ``stop_after`` before every run finished.
    """
    settings = settings or EnsembleSettings()
    if stop_after is not None and (not isinstance(stop_after, int) or stop_after < 1):
        raise ValueError(f"stop_after must be a positive integer (got {stop_after!r})")
    folder = Path(store) if store is not None else None
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
    pts = [dict(p) for p in points]
    tasks: list[_Task] = []
    keys: list[str] = []
    records: dict[int, dict[str, Any]] = {}
    for p in pts:
        mech = make_mechanism(p)
        for k, start in enumerate(draw_start_states(mech, settings.runs, settings.spread, settings.seed)):
            key = _run_key(mech, start, settings)
            if folder is not None and (rec := _load(folder / _file_name(key), key)) is not None:
                records[len(tasks)] = rec
            tasks.append(_Task(make_mechanism, p, k, start, settings))
            keys.append(key)
    todo = [i for i in range(len(tasks)) if i not in records]
    if todo:
        _run_tasks(tasks, todo, keys, records, folder, executor, scheduler_address, max_workers, progress, stop_after)
    out = []
    for n, p in enumerate(pts):
        mine = range(n * settings.runs, (n + 1) * settings.runs)
        runs = tuple(
            RunMeasures(
                tasks[i].index,
                tasks[i].start,
                records[i]["status"],
                records[i]["error"],
                records[i]["values"],
                float(records[i].get("wall_time_s", float("nan"))),
            )
            for i in mine
        )
        out.append(EnsembleResult(p, runs, settings))
    return out


def _run_tasks(
    tasks: list[_Task],
    todo: list[int],
    keys: list[str],
    records: dict[int, dict[str, Any]],
    folder: Path | None,
    executor: Executor | None,
    scheduler_address: str | None,
    max_workers: int | None,
    progress: bool,
    stop_after: int | None,
) -> None:
    """Simulate the runs ``todo`` (twice the slots in flight), keeping each as it finishes."""
    queue = iter(todo)
    in_flight: dict[Future[dict[str, Any]], int] = {}
    done = 0
    with (
        open_executor(executor, scheduler_address=scheduler_address, max_workers=max_workers) as pool,
        Progress(len(todo), enabled=progress, desc="ensemble", unit="run") as bar,
    ):

        def keep(i: int, rec: dict[str, Any]) -> None:
            nonlocal done
            rec = {"key": keys[i], **rec}
            if folder is not None:
                atomic_write_text(folder / _file_name(keys[i]), json.dumps(rec, indent=1))
            records[i] = rec
            done += 1
            bar.step()

        stopped = False
        while True:
            # never more in flight than stop_after leaves: the stop comes after exactly that many runs
            while (
                not stopped
                and len(in_flight) < 2 * pool.slots
                and (stop_after is None or done + len(in_flight) < stop_after)
            ):
                i = next(queue, None)
                if i is None:
                    break
                in_flight[pool.executor.submit(_run_task, tasks[i])] = i
            if not in_flight:
                break
            finished, _ = wait(list(in_flight), return_when=FIRST_COMPLETED)
            for fut in sorted(finished, key=in_flight.__getitem__):
                keep(in_flight.pop(fut), fut.result())
            if stop_after is not None and done >= stop_after and not stopped:
                stopped = True
                for fut in [f for f in in_flight if f.cancel()]:
                    in_flight.pop(fut)
    if len(records) < len(tasks):
        raise EnsembleStopped(
            f"stopped after {done} runs ({len(tasks) - len(records)} of {len(tasks)} not run); run again to resume",
            done,
        )


def run_ensemble(
    make_mechanism: MechanismFactory,
    point: Mapping[str, Any],
    settings: EnsembleSettings | None = None,
    **kwargs: Any,
) -> EnsembleResult:
    """One design as an ensemble: `run_ensembles` with one point.

    Args:
        make_mechanism: picklable factory, point -> Mechanism (as for `run_ensembles`).
        point: the design.
        settings: the ensemble's settings (default `EnsembleSettings()`).
        kwargs: `run_ensembles`' keyword arguments (store, executor, progress, ...).
    """
    return run_ensembles(make_mechanism, [point], settings, **kwargs)[0]
