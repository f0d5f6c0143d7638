"""Parameter sweeps: many simulations through a `concurrent.futures` executor, resumable.

A sweep is a list of points (dicts of JSON-serialisable parameters) and a picklable
callable turning a point into a `Mechanism` (a module-level function or a
`functools.partial`; `KeywordFactory` wraps a builder). Each point is simulated (and its
ideal twin when the evaluation needs it) in a worker; the worker returns a row: point
index, parameters, status, per-joint contact summary, deviation statistics, per-cycle
mean deviations and Poincaré points.

Executors: a local `ProcessPoolExecutor` with the ``spawn`` context by default, a Dask
distributed client's executor when a scheduler address is given, or any executor passed
in. Each finished row is written at once to ``<out_dir>/points/point_<index>.json``
(atomically), and ``<out_dir>/sweep.csv`` is rebuilt with the rows sorted by point index.
Running the same sweep again skips the points that have files, so an interrupted sweep
resumes where it stopped. Rows hold no wall times (those go to ``timing`` in the JSON
only), so a resumed sweep's table equals an uninterrupted one's.

Points that share an ideal twin (a criticality grid has one per drive speed) reuse its run
within a worker (`clearance.analysis.sweeps.ideal_runs`); runs are deterministic, so rows do not
change.
"""

from __future__ import annotations

import csv
import io
import json
import os
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from clearance.analysis.sweeps.executor import Pool, Progress, open_executor
from clearance.analysis.sweeps.ideal_runs import ideal_run
from clearance.model import Mechanism
from clearance.options import ModelOptions
from clearance.results import SimulationResult, atomic_write_text

if TYPE_CHECKING:
    from clearance.analysis.metrics.summary import JointSummary

__all__ = [
    "Duration",
    "Evaluation",
    "KeywordFactory",
    "MechanismFactory",
    "SweepEvaluation",
    "SweepOutcome",
    "check_manifest",
    "evaluate_point",
    "load_rows",
    "run_sweep",
]

MechanismFactory = Callable[[Mapping[str, Any]], Mechanism]
"""Picklable point (JSON-like parameters) -> `Mechanism`, as every sweep and batch takes it."""

Duration = float | Callable[[Mechanism], float] | None
"""Simulated time [s], a picklable mechanism -> time [s], or None (3 drive periods)."""

Evaluation = Callable[[SimulationResult, SimulationResult | None, Mechanism], dict[str, Any]]
"""Picklable (result, ideal twin's result or None, mechanism) -> row fields."""


@dataclass(frozen=True)
class KeywordFactory:
    """Picklable point -> Mechanism adapter: ``builder(**fixed, **point)``.

    Attributes:
        builder: a module-level builder function (e.g. ``clearance.builders.slider_crank``).
        fixed: keyword arguments given to every call.
        rename: point key -> builder keyword, for points whose keys differ from the
            builder's (e.g. ``{"clearance": "radial_clearance"}``).
    """

    builder: Callable[..., Mechanism]
    fixed: Mapping[str, Any] = field(default_factory=dict)
    rename: Mapping[str, str] = field(default_factory=dict)

    def __call__(self, point: Mapping[str, Any]) -> Mechanism:
        kw = dict(self.fixed)
        for k, v in point.items():
            kw[self.rename.get(k, k)] = tuple(v) if isinstance(v, list) else v
        return self.builder(**kw)


@dataclass(frozen=True)
class SweepEvaluation:
    """What a worker computes from a point's run (picklable).

    Attributes:
        output: output whose deviation from ideal is measured; None: the mechanism's first.
        poincare: quantities sampled once per drive period (`chaos.quantity_series` names);
            None: the output and its velocity.
        last_periods: Poincaré points kept from the end of the run; None: all after
            ``skip_periods``.
        skip_periods: start-up transient skipped by statistics and sections [periods].
        ideal: also simulate the ideal twin and compute deviation statistics.
    """

    output: str | None = None
    poincare: tuple[str, ...] | None = None
    last_periods: int | None = None
    skip_periods: float = 1.0
    ideal: bool = True

    def __call__(
        self, result: SimulationResult, ideal: SimulationResult | None, mechanism: Mechanism
    ) -> dict[str, Any]:
        """Row fields of one run (see the module docstring)."""
        from clearance.analysis.chaos.poincare import run_section
        from clearance.analysis.metrics.statistics import (
            deviation_statistics,
            per_cycle_mean_deviation,
        )
        from clearance.analysis.metrics.summary import joint_summary

        period = _drive_period(mechanism)
        output = self.output or mechanism.outputs[0].name
        skip = self.skip_periods * period
        row: dict[str, Any] = {"period": period}
        row["summary"] = {j: _summary_dict(joint_summary(result, j)) for j in (*result.joints, *result.sliders)}
        if ideal is not None:
            row["statistics"] = deviation_statistics(result, ideal, output, skip=skip).as_dict()
            row["per_cycle_mean_deviation"] = per_cycle_mean_deviation(
                result, ideal, output, period=period, skip=skip
            ).tolist()
        names = list(self.poincare or (output, f"{output}_vel"))
        sec = run_section(result, names, period=period, skip=skip, last=self.last_periods)
        regime = sec.classification.regime.value if sec.classification else "undetermined"
        row["poincare"] = {
            "quantities": names,
            "times": sec.times.tolist(),
            "points": sec.points.tolist(),
            "scale": sec.scale,
            "regime": regime,
        }
        return row


@dataclass(frozen=True)
class SweepOutcome:
    """What `run_sweep` did.

    Attributes:
        out_dir: the sweep folder.
        csv_path: the combined table.
        rows: all rows on disk, sorted by point index.
        complete: every point has a row.
        new: rows computed by this call.
        wall_time_s: wall time of this call [s].
    """

    out_dir: Path
    csv_path: Path
    rows: list[dict[str, Any]]
    complete: bool
    new: int
    wall_time_s: float


def _drive_period(mechanism: Mechanism) -> float:
    period = mechanism.drive_period
    if period is None:
        raise ValueError(f"mechanism '{mechanism.name}' has no drive with a set period")
    return period


def _summary_dict(s: JointSummary) -> dict[str, Any]:
    from dataclasses import asdict

    d = asdict(s)
    d.pop("joint")
    d.pop("output_rms_deviation")  # given by the deviation statistics instead
    return d


def _json_safe(obj: object) -> Any:
    """Round-trip through JSON so a row read back from disk equals the computed one."""
    return json.loads(json.dumps(obj, default=_json_default))


def _json_default(o: object) -> object:
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if hasattr(o, "value"):
        return o.value
    raise TypeError(f"not JSON-serialisable: {type(o).__name__}")


def evaluate_point(
    index: int,
    point: Mapping[str, Any],
    make_mechanism: MechanismFactory,
    duration: Duration,
    options: ModelOptions | None,
    evaluation: Evaluation,
    needs_ideal: bool,
) -> dict[str, Any]:
    """Simulate one sweep point and return its row (runs in a worker).

    A point whose model cannot be built or whose run diverges gives a row with status
    ``error`` and the message, so one bad point does not stop the sweep.

    Args:
        index: point index.
        point: point parameters.
        make_mechanism: point -> Mechanism.
        duration: simulated time [s], a callable mechanism -> duration, or None (3 periods).
        options: `ModelOptions` (None: defaults).
        evaluation: (result, ideal or None, mechanism) -> row fields.
        needs_ideal: also simulate the ideal twin.

    Returns:
        The row (JSON-compatible dict) with ``timing`` added: ``wall_time_s`` (whole
        point), ``simulate_s`` (model preparation and stepping of the run with
        clearance), ``stepping_s`` (its stepping and sensor readout alone), ``ideal_s``
        (the ideal twin's run, 0 when reused), ``ideal_reused``, ``evaluate_s`` (the
        evaluation), all in seconds, and ``pid``.
    """
    from clearance.run.simulation import default_duration, simulate

    t0 = time.perf_counter()
    timing: dict[str, Any] = {}
    row: dict[str, Any] = {"index": index, "point": dict(point), "status": "ok", "error": ""}
    try:
        mech = make_mechanism(point)
        dur = duration(mech) if callable(duration) else (duration or default_duration(mech))
        t1 = time.perf_counter()
        res = simulate(mech, duration=dur, options=options)
        t2 = time.perf_counter()
        timing.update(simulate_s=t2 - t1, stepping_s=res.metadata.get("wall_time_s"))
        ideal = ideal_run(mech, dur, options, timing) if needs_ideal else None
        t3 = time.perf_counter()
        row.update(evaluation(res, ideal, mech))
        timing["evaluate_s"] = time.perf_counter() - t3
    except Exception as err:
        row["status"] = "error"
        row["error"] = f"{type(err).__name__}: {err}"
    row = _json_safe(row)
    row["timing"] = {"wall_time_s": time.perf_counter() - t0, "pid": os.getpid(), **_json_safe(timing)}
    return row


def _flatten(obj: object, prefix: str, out: dict[str, Any]) -> None:
    if isinstance(obj, dict):
        for k, v in obj.items():
            _flatten(v, f"{prefix}.{k}" if prefix else str(k), out)
    elif isinstance(obj, list):
        out[prefix] = json.dumps(obj, separators=(",", ":"))
    else:
        out[prefix] = obj


def _csv_text(rows: Sequence[Mapping[str, Any]]) -> str:
    flat = []
    for r in rows:
        f: dict[str, Any] = {}
        _flatten({k: v for k, v in r.items() if k != "timing"}, "", f)
        flat.append(f)
    cols: list[str] = []
    for f in flat:
        cols.extend(k for k in f if k not in cols)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    for f in flat:
        w.writerow([repr(v) if isinstance(v, float) else ("" if v is None else v) for v in (f.get(c) for c in cols)])
    return buf.getvalue()


def load_rows(out_dir: str | Path) -> list[dict[str, Any]]:
    """All point rows of a sweep folder, sorted by point index.

    A point file that cannot be read (cut short when a disk filled, say) is left out with a
    `RuntimeWarning` naming it: `run_sweep` then computes that point again and replaces it.
    """
    import warnings

    rows = []
    for p in sorted((Path(out_dir) / "points").glob("point_*.json")):
        try:
            row = json.loads(p.read_text(encoding="utf-8"))
            int(row["index"])
        except (ValueError, TypeError, KeyError) as err:
            warnings.warn(
                f"point file {p} is unreadable ({type(err).__name__}: {err}); that point is treated as not run, "
                "and rerunning the sweep computes it again",
                RuntimeWarning,
                stacklevel=2,
            )
            continue
        rows.append(row)
    return sorted(rows, key=lambda r: r["index"])


def _describe(obj: object) -> str:
    """A description stable across processes (no memory addresses) for the manifest.

    Functions are named by module and qualified name; partials and dataclass instances
    (`KeywordFactory`, `SweepEvaluation`, ...) are described field by field, so two
    factories around different builders never describe alike. Plain values use ``repr``.
    """
    import dataclasses
    import functools

    if isinstance(obj, functools.partial):
        args = ", ".join([*(repr(a) for a in obj.args), *(f"{k}={v!r}" for k, v in sorted(obj.keywords.items()))])
        return f"partial({_describe(obj.func)}, {args})"
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        fields = ", ".join(f"{f.name}={_describe(getattr(obj, f.name))}" for f in dataclasses.fields(obj) if f.repr)
        return f"{type(obj).__qualname__}({fields})"
    if isinstance(obj, Mapping):
        return "{" + ", ".join(f"{k!r}: {_describe(v)}" for k, v in obj.items()) + "}"
    if callable(obj) and hasattr(obj, "__qualname__"):
        return f"{getattr(obj, '__module__', '?')}.{obj.__qualname__}"
    return repr(obj)


_SETTING_NAMES = {
    "mechanism": "mechanism factory",
    "duration": "duration",
    "options": "model options",
    "evaluation": "evaluation",
}


def check_manifest(
    out: Path,
    points: list[dict[str, Any]],
    settings: dict[str, Any],
    *,
    file: str = "sweep.json",
    kind: str = "sweep",
) -> None:
    """Record which points and settings a resumable folder holds, or check that it holds these.

    Args:
        out: the folder (exists).
        points: the points, in order.
        settings: everything else that makes a point's result.
        file: the manifest's file name in ``out``.
        kind: what the folder holds, for messages ("sweep", "ranking").

    Raises:
        ValueError: the folder's manifest is unreadable or records other points or settings;
            the message names what differs and how to go on.
    """
    path = out / file
    manifest = _json_safe({"points": points, "settings": settings})
    if path.exists():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except ValueError as err:
            raise ValueError(
                f"{path} is unreadable ({err}); it records which {kind} {out} holds, so its points cannot be "
                "reused safely: delete that folder to start over, or use another folder"
            ) from None
        if old != manifest:
            old_settings = old.get("settings", {})
            diffs = [
                f"{_SETTING_NAMES.get(k, k)}: {old_settings.get(k, '(not recorded)')!r} there, {v!r} now"
                for k, v in manifest["settings"].items()
                if old_settings.get(k) != v
            ]
            if old.get("points") != manifest["points"]:
                diffs.insert(0, f"points: {len(old.get('points', []))} there, {len(points)} now or values differ")
            raise ValueError(
                f"{out} holds a different {kind} ({'; '.join(diffs) or 'manifest differs'}; see {path}); "
                "use another out_dir or delete that folder"
            )
    else:
        atomic_write_text(path, json.dumps(manifest, indent=1))


def run_sweep(
    points: Sequence[Mapping[str, Any]],
    make_mechanism: MechanismFactory,
    *,
    out_dir: str | Path,
    duration: Duration = None,
    options: ModelOptions | None = None,
    executor: Executor | None = None,
    scheduler_address: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
    evaluation: Evaluation | None = None,
    max_workers: int | None = None,
) -> SweepOutcome:
    """Run (or resume) a sweep; every finished point is written to disk at once.

    Args:
        points: sweep points, dicts of JSON-serialisable parameters.
        make_mechanism: picklable callable point -> Mechanism.
        out_dir: sweep folder (``points/``, ``sweep.csv``, ``sweep.json``).
        duration: simulated time [s], or a picklable callable mechanism -> duration (e.g.
            ``functools.partial(default_duration, revolutions=60)``); None: 3 periods.
        options: `ModelOptions` for every run (None: defaults).
        executor: executor to use (not shut down here).
        scheduler_address: Dask scheduler address; its client's executor is used.
        progress: show a tqdm progress bar (points done, rate, time remaining).
        stop_after: finish exactly this many points in this call, then stop (no more are
            submitted than it leaves: none is computed beyond it); the rest resume on the
            next call.
        evaluation: picklable callable (result, ideal result or None, mechanism) -> row
            fields; default `SweepEvaluation()`. It gets the ideal run when its attribute
            ``ideal`` is true (or absent).
        max_workers: local process count (default: CPU count).

    Returns:
        `SweepOutcome`.

    Raises:
        ValueError: empty points, a bad stop_after, or out_dir holding another sweep
            (other points, mechanism factory, duration, options or evaluation).
    """
    pts = [dict(p) for p in points]
    if not pts:
        raise ValueError("points must not be empty")
    if stop_after is not None and (not isinstance(stop_after, int) or stop_after < 1):
        raise ValueError(f"stop_after must be a positive integer (got {stop_after!r})")
    evaluation = evaluation or SweepEvaluation()
    needs_ideal = bool(getattr(evaluation, "ideal", True))
    out = Path(out_dir)
    (out / "points").mkdir(parents=True, exist_ok=True)
    settings = {
        "mechanism": _describe(make_mechanism),
        "duration": _describe(duration),
        "options": repr(options),
        "evaluation": _describe(evaluation),
    }
    check_manifest(out, _json_safe(pts), settings)
    rows = {r["index"]: r for r in load_rows(out) if 0 <= r["index"] < len(pts)}
    todo = [i for i in range(len(pts)) if i not in rows]
    csv_path = out / "sweep.csv"
    t0 = time.perf_counter()
    in_flight: dict[Future[dict[str, Any]], int] = {}
    queue = iter(todo)
    new = 0
    with (
        open_executor(executor, scheduler_address=scheduler_address, max_workers=max_workers) as pool,
        Progress(len(pts), enabled=progress, desc="sweep", unit="point", initial=len(rows)) as bar,
    ):

        def save(i: int, row: dict[str, Any]) -> None:
            nonlocal new
            atomic_write_text(out / "points" / f"point_{i:06d}.json", json.dumps(row, indent=1))
            rows[i] = row
            atomic_write_text(csv_path, _csv_text([rows[k] for k in sorted(rows)]))
            new += 1
            bar.step()

        _run_window(
            pool,
            2 * pool.slots,
            queue,
            pts,
            in_flight,
            save,
            stop_after,
            lambda: new,
            (make_mechanism, duration, options, evaluation, needs_ideal),
        )
    if rows and not csv_path.exists():
        atomic_write_text(csv_path, _csv_text([rows[k] for k in sorted(rows)]))
    return SweepOutcome(
        out, csv_path, [rows[k] for k in sorted(rows)], len(rows) == len(pts), new, time.perf_counter() - t0
    )


def _run_window(
    pool: Pool,
    window: int,
    queue: Iterator[int],
    pts: list[dict[str, Any]],
    in_flight: dict[Future[dict[str, Any]], int],
    save: Callable[[int, dict[str, Any]], None],
    stop_after: int | None,
    finished_count: Callable[[], int],
    args: tuple[MechanismFactory, Duration, ModelOptions | None, Evaluation, bool],
) -> None:
    """Keep ``window`` points in flight (twice the slots, so workers never wait) until done or stopped.

    Every finished point is saved. With ``stop_after`` no more points are submitted than it
    leaves (finished + in flight <= stop_after), so the stop comes after exactly that many.
    """
    try:
        while True:
            while len(in_flight) < window and (stop_after is None or finished_count() + len(in_flight) < stop_after):
                i = next(queue, None)
                if i is None:
                    break
                in_flight[pool.executor.submit(evaluate_point, i, pts[i], *args)] = i
            if not in_flight:
                break
            finished, _ = wait(list(in_flight), return_when=FIRST_COMPLETED)
            for fut in sorted(finished, key=in_flight.__getitem__):
                save(in_flight.pop(fut), fut.result())
            if stop_after is not None and finished_count() >= stop_after:
                running = [f for f in in_flight if not f.cancel()]
                wait(running)
                for fut in sorted(running, key=in_flight.__getitem__):
                    save(in_flight[fut], fut.result())
                in_flight.clear()
                break
    finally:
        for fut in in_flight:
            fut.cancel()
