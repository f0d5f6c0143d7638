"""Speed against error: MuJoCo settings against the reference solver on the same scenarios.

A `Scenario` is a picklable mechanism factory with run lengths and the `Setting`s to try
(time step, segment count, geom pair, contact mode). Two stages, both resumable:

* accuracy (`accuracy_task`): one long run per setting and one reference run per scenario.
  Each task keeps only what the comparison needs: the first impact of every clearance
  joint, the steady-state statistics with their batch-means scatter
  (`clearance.analysis.metrics.accuracy`), and the first periods of the journal orbits (to find
  when the run separates from the reference). Tasks are independent, so they run through
  any `concurrent.futures` executor; each result is written to disk at once.
* timing (`timing_task`): short runs, one at a time in this process, one thread, so their
  times compare; the reference is timed the same way, in the same call.

`clearance.bench.speed_error_report` turns the files into errors, the Pareto front,
the chosen defaults, a table and a figure.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.metrics.accuracy import (
    distributions,
    first_impact,
    run_statistics,
    statistics_as_dict,
)
from clearance.analysis.sweeps.executor import Progress, open_executor
from clearance.model import Mechanism
from clearance.options import ContactMode, GeomType, ModelOptions
from clearance.results import atomic_write_bytes, atomic_write_text

__all__ = [
    "REFERENCE",
    "Scenario",
    "Setting",
    "accuracy_task",
    "ideal_output_function",
    "run_speed_error",
    "timing_task",
]

REFERENCE = "reference"
"""Key of the reference solver's files."""

_HEAD_ROWS = 20_000
"""Rows of the journal orbits kept for the separation time (at most two drive periods)."""


@dataclass(frozen=True)
class Setting:
    """One MuJoCo setting of the grid.

    Attributes:
        timestep: time step h [s].
        segments: bearing segment count N, or None for the ripple rule.
        journal_geom: journal geom type (`clearance.options.GeomType` value).
        segment_geom: bearing segment geom type.
        contact_mode: `clearance.options.ContactMode` value.
    """

    timestep: float
    segments: int | None = None
    journal_geom: str = "sphere"
    segment_geom: str = "sphere"
    contact_mode: str = "nominal"

    def options(self) -> ModelOptions:
        """The `ModelOptions` of this setting.

        Raises:
            ValueError: a geom type or contact mode that is not a value of its enum.
        """
        return ModelOptions(
            timestep=self.timestep,
            segments=self.segments,
            journal_geom=GeomType(self.journal_geom),
            segment_geom=GeomType(self.segment_geom),
            contact_mode=ContactMode(self.contact_mode),
        )

    @property
    def label(self) -> str:
        """Human-readable label, e.g. ``calibrated, h = 2 µs, N = rule, sphere/sphere``."""
        n = "rule" if self.segments is None else str(self.segments)
        return f"{self.contact_mode}, h = {self.timestep * 1e6:g} µs, N = {n}, {self.journal_geom}/{self.segment_geom}"

    @property
    def key(self) -> str:
        """File-name-safe key."""
        n = "rule" if self.segments is None else str(self.segments)
        return f"{self.contact_mode}_h{self.timestep * 1e6:g}us_N{n}_{self.journal_geom}-{self.segment_geom}"


@dataclass(frozen=True)
class Scenario:
    """A benchmark scenario.

    Attributes:
        name: short name (file-name safe).
        factory: picklable callable () -> Mechanism (e.g. a `functools.partial` of a builder).
        revolutions: length of the accuracy runs [drive periods].
        timing_revolutions: length of the timing runs [drive periods].
        settings: MuJoCo settings to compare.
        skip_revolutions: start-up transient left out of the statistics [periods].
        blocks: blocks of whole revolutions for the statistics' scatter.
        output_interval: sampling of the accuracy runs [s]: the reference's output grid,
            and MuJoCo's stored rows (every step where the step is longer).
        description: one line for the report.
    """

    name: str
    factory: Callable[[], Mechanism]
    revolutions: float
    timing_revolutions: float
    settings: tuple[Setting, ...]
    skip_revolutions: float = 1.0
    blocks: int = 8
    output_interval: float = 1e-6
    description: str = ""

    def __post_init__(self) -> None:
        if not self.name or any(ch in self.name for ch in "/\\ "):
            raise ValueError(f"Scenario.name must be a non-empty file-name-safe word (got {self.name!r})")
        if not self.revolutions >= self.skip_revolutions + self.blocks:
            raise ValueError(
                f"Scenario '{self.name}': revolutions must be >= skip_revolutions + blocks = "
                f"{self.skip_revolutions + self.blocks:g} (got {self.revolutions!r})"
            )
        if not self.timing_revolutions > 0:
            raise ValueError(
                f"Scenario '{self.name}': timing_revolutions must be > 0 (got {self.timing_revolutions!r})"
            )
        keys = [s.key for s in self.settings]
        if len(set(keys)) != len(keys):
            raise ValueError(
                f"Scenario '{self.name}': settings repeat ({sorted(k for k in keys if keys.count(k) > 1)})"
            )


def _period(mechanism: Mechanism) -> float:
    period = mechanism.drive_period
    if period is None:
        raise ValueError(f"mechanism '{mechanism.name}' has no prescribed drive: no drive period")
    return period


def ideal_output_function(
    mechanism: Mechanism, duration: float, *, per_period: int = 2000
) -> Callable[[np.ndarray], np.ndarray]:
    """Exact ideal position of the mechanism's first output as a function of time.

    Solved by `clearance.kinematics.solve_kinematics` on a grid of ``per_period`` points
    per drive period and interpolated by a cubic spline (periodically when every drive
    shares one period, over the whole duration otherwise).

    Args:
        mechanism: the mechanism (its ideal twin is solved).
        duration: longest time needed [s].
        per_period: grid points per period.
    """
    from scipy.interpolate import CubicSpline

    from clearance.kinematics import solve_kinematics
    from clearance.model import DriveKind

    name = mechanism.outputs[0].name
    periods = {round(d.period, 12) for d in mechanism.drives if d.kind is DriveKind.CONSTANT_SPEED}
    prescribed = [d for d in mechanism.drives if d.kind is not DriveKind.TORQUE]
    period = _period(mechanism)
    if (
        len(periods) == 1
        and len(prescribed) == len(mechanism.drives)
        and all(d.kind is DriveKind.CONSTANT_SPEED for d in prescribed)
    ):
        t = np.linspace(0.0, period, per_period + 1)
        y = solve_kinematics(mechanism, t).outputs[name]
        y[-1] = y[0]
        spline = CubicSpline(t, y, bc_type="periodic")
        return lambda times: spline(np.mod(times, period))
    t = np.linspace(0.0, duration, int(np.ceil(duration / period * per_period)) + 1)
    spline = CubicSpline(t, solve_kinematics(mechanism, t).outputs[name])
    return lambda times: spline(times)


def _task_path(out_dir: Path, stage: str, scenario: str, key: str) -> Path:
    return out_dir / stage / scenario / f"{key}.json"


def accuracy_task(scenario: Scenario, setting: Setting | None, out_dir: str | Path) -> dict[str, Any]:
    """Run one accuracy case (a MuJoCo setting, or the reference for None) and save it.

    Writes ``<out_dir>/accuracy/<scenario>/<key>.json`` (statistics, first impacts, wall
    time, status) and ``<key>.npz`` (times and eccentricity of the first two drive
    periods, at most 20,000 rows, for the separation time). A run that fails records its error message; a
    diverged MuJoCo run keeps no statistics.

    Returns:
        The record written to the JSON file.
    """
    from clearance.run.simulation import simulate

    out = Path(out_dir)
    key = REFERENCE if setting is None else setting.key
    rec: dict[str, Any] = {
        "scenario": scenario.name,
        "key": key,
        "setting": None if setting is None else asdict(setting),
        "status": "ok",
        "error": "",
    }
    t0 = time.perf_counter()
    try:
        mech = scenario.factory()
        period = _period(mech)
        duration = scenario.revolutions * period
        if setting is None:
            from clearance.reference import run_reference

            result = run_reference(mech, duration, output_interval=scenario.output_interval)
        else:
            every = scenario.output_interval if scenario.output_interval > setting.timestep else None
            result = simulate(mech, duration=duration, options=setting.options(), output_interval=every)
        stats = run_statistics(
            result,
            period=period,
            skip=scenario.skip_revolutions * period,
            blocks=scenario.blocks,
            ideal_output=ideal_output_function(mech, duration),
        )
        rec["statistics"] = statistics_as_dict(stats)
        result.metadata["clearance"] = {j.name: j.require_clearance().radial_clearance for j in mech.clearance_joints}
        rec["distributions"] = distributions(result, skip=scenario.skip_revolutions * period)
        rec["first_impact"] = {j: (asdict(fi) if (fi := first_impact(result, j)) else None) for j in result.joints}
        rec["period"] = period
        rec["clearance"] = {j.name: j.require_clearance().radial_clearance for j in mech.clearance_joints}
        rec["metadata"] = {
            k: result.metadata.get(k)
            for k in ("segments", "contact", "steps", "wall_time_s", "steps_per_second", "solver")
        }
        head = (result.times < 2 * period) & (np.arange(len(result.times)) < _HEAD_ROWS)
        arrays = {"times": result.times[head]}
        for j, jr in result.joints.items():
            arrays[f"{j}/eccentricity"] = jr.eccentricity[head]
        import io

        buf = io.BytesIO()
        # numpy's stubs type **kwds against the allow_pickle keyword (absent before numpy 2.1) too
        np.savez_compressed(buf, **arrays)  # type: ignore[arg-type]
        atomic_write_bytes(_task_path(out, "accuracy", scenario.name, key).with_suffix(".npz"), buf.getvalue())
    except Exception as err:
        rec["status"], rec["error"] = "error", f"{type(err).__name__}: {err}"
    rec["wall_time_s"] = time.perf_counter() - t0
    path = _task_path(out, "accuracy", scenario.name, key)
    atomic_write_text(path, json.dumps(rec, indent=1, default=float))
    return rec


def timing_task(scenario: Scenario, setting: Setting | None, *, repeats: int = 2) -> dict[str, Any]:
    """Time per drive revolution of a short run, in this process (best of ``repeats``).

    Both the wall time and the CPU time of this process are measured: on a quiet machine
    they agree (every run is single-threaded); on a shared one the CPU time is the
    steadier measure, and the report compares CPU times. MuJoCo: stepping and sensor
    readout (`simulate_prepared`), model preparation (build, sizing, calibration) timed
    apart. Reference: the whole `run_reference` call at its default output interval (1e-5 s).

    Returns:
        ``{"wall_per_rev_s", "cpu_per_rev_s", "prepare_s", "load_average", "revolutions",
        "status", "error"}``.
    """
    from clearance.run.preparation import prepare
    from clearance.run.simulation import simulate_prepared

    rec: dict[str, Any] = {"status": "ok", "error": "", "revolutions": scenario.timing_revolutions}
    try:
        mech = scenario.factory()
        period = _period(mech)
        duration = scenario.timing_revolutions * period
        wall, cpu, prep = float("inf"), float("inf"), 0.0
        for _ in range(repeats):
            if setting is None:
                from clearance.reference import run_reference

                w0, c0 = time.perf_counter(), time.process_time()
                run_reference(mech, duration)
            else:
                p0 = time.perf_counter()
                prepared = prepare(mech, setting.options())
                prep = time.perf_counter() - p0
                w0, c0 = time.perf_counter(), time.process_time()
                simulate_prepared(prepared, duration=duration)
            wall = min(wall, time.perf_counter() - w0)
            cpu = min(cpu, time.process_time() - c0)
        rec["wall_per_rev_s"] = wall / scenario.timing_revolutions
        rec["cpu_per_rev_s"] = cpu / scenario.timing_revolutions
        rec["prepare_s"] = prep
        rec["load_average"] = os.getloadavg()[0]  # other work on the machine while timing
    except Exception as err:
        rec["status"], rec["error"] = "error", f"{type(err).__name__}: {err}"
    return rec


def _cost(job: tuple[Scenario, Setting | None]) -> float:
    """Rough relative cost of an accuracy run: steps, /2 for the compiled exact contact; references first."""
    sc, st = job
    if st is None:
        return math.inf
    ring = 0.5 if ContactMode(st.contact_mode) is ContactMode.EXACT else 1.0
    return sc.revolutions * _period(sc.factory()) / st.timestep * ring


def _todo(out: Path, stage: str, scenarios: Sequence[Scenario]) -> list[tuple[Scenario, Setting | None]]:
    jobs = []
    for sc in scenarios:
        for st in (None, *sc.settings):
            if not _task_path(out, stage, sc.name, REFERENCE if st is None else st.key).exists():
                jobs.append((sc, st))
    return jobs


def run_speed_error(
    scenarios: Sequence[Scenario],
    out_dir: str | Path,
    *,
    stages: Sequence[str] = ("accuracy", "timing"),
    executor: Executor | None = None,
    max_workers: int | None = None,
    progress: bool = True,
) -> Path:
    """Run (or resume) the accuracy and timing stages; every finished run is on disk at once.

    Args:
        scenarios: the scenarios.
        out_dir: folder for ``accuracy/`` and ``timing/`` files.
        stages: any of ``accuracy``, ``timing``.
        executor: executor for the accuracy runs (default: a spawn process pool of
            ``max_workers``); timing runs always run here, one at a time.
        max_workers: processes of the default pool (default: CPU count).
        progress: progress bars.

    Returns:
        ``out_dir``.

    Raises:
        ValueError: an unknown stage, or scenario names repeating.
    """
    bad = set(stages) - {"accuracy", "timing"}
    if bad:
        raise ValueError(f"stages must be among 'accuracy', 'timing' (got {sorted(bad)})")
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        raise ValueError(f"scenario names repeat: {names}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if "accuracy" in stages:
        jobs = _todo(out, "accuracy", scenarios)
        jobs.sort(key=_cost, reverse=True)  # longest first, so the pool ends together
        if jobs:
            with (
                open_executor(executor, max_workers=max_workers) as pool,
                Progress(len(jobs), enabled=progress, desc="accuracy") as bar,
            ):
                futs = {pool.executor.submit(accuracy_task, sc, st, out): (sc, st) for sc, st in jobs}
                for fut in as_completed(futs):
                    sc, st = futs[fut]
                    fut.result()
                    bar.step(label=f"{sc.name}: {REFERENCE if st is None else st.label}")
    if "timing" in stages:
        jobs = _todo(out, "timing", scenarios)
        with Progress(len(jobs), enabled=progress, desc="timing") as bar:
            for sc, st in jobs:
                rec = timing_task(sc, st)
                rec.update(scenario=sc.name, key=REFERENCE if st is None else st.key)
                atomic_write_text(_task_path(out, "timing", sc.name, rec["key"]), json.dumps(rec, indent=1))
                bar.step(label=f"{sc.name}: {REFERENCE if st is None else st.label}")
    return out
