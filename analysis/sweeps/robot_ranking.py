"""Which hinge's play costs a robot's end effector most: one hinge at a time, ranked with confidence.

The robot's counterpart of the mechanism ranking (`clearance.analysis.sweeps.criticality`).
Every candidate hinge is given one kind of play alone -- radial play of clearance c, or
backlash of half-width b -- and run against the unmodified twin under a sinusoid on every
actuator, over a grid of control amplitudes and frequencies (a robot's counterpart of crank
speeds). A run is scored by the end effector's distance from the twin's: its mean over each
whole control period after the start-up window (`per_period_deviation`), so a run gives
per-period values as a mechanism's run gives per-cycle ones.

The ranking is `rank_joints`'s, unchanged: per kind of play, a hinge's score is the mean over
grid cells of (mean deviation / play) -- dimensionless (m/m) for radial play, m/rad for
backlash (shown as µm per arc-minute) -- with its 95 % interval and the probability that it
exceeds the next; across kinds, the candidates (hinge, kind) are ranked by the mean deviation
itself [m] at the plays given. Per-period values of one run are correlated, so the intervals
are indicative, as the mechanism ranking's are.

The runs go through the sweeps' executor (`open_executor`: local processes, a Dask cluster or
the caller's), one task per point, each finished point written at once to
``<out>/points/point_<index>.json``; running the same ranking again skips the points on disk
(``<out>/robot_ranking.json`` records which ranking a folder holds). The runs themselves come
from a picklable point -> (run, twin run) callable the caller passes in
(`clearance.run.play_candidates.PlayAtHinge`): this module never builds or retrofits a model.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.metrics.site_deviation import site_deviation
from clearance.analysis.sweeps.criticality import CriticalityRanking, rank_joints
from clearance.analysis.sweeps.executor import Progress, open_executor
from clearance.analysis.sweeps.sweep import check_manifest, load_rows
from clearance.results import SimulationResult, atomic_write_text

__all__ = [
    "ARCMIN",
    "MIN_PERIODS",
    "PlayRunner",
    "RobotRanking",
    "check_grid",
    "evaluate_play_point",
    "per_period_deviation",
    "play_points",
    "rank_plays",
    "robot_ranking_markdown",
    "run_robot_ranking",
]

PlayRunner = Callable[[Mapping[str, Any]], tuple[SimulationResult, SimulationResult]]
"""Picklable point ``{"joint", "play", "size", "amplitude", "frequency"}`` -> (the run with that play,
the unmodified twin's run), both carrying the end effector's position outputs."""

MIN_PERIODS = 2
"""Whole control periods a run must hold after its start-up window (a standard error needs two)."""

ARCMIN = math.pi / 10800
"""One arc-minute [rad]."""

_MANIFEST = "robot_ranking.json"


def check_grid(amplitudes: Sequence[float], frequencies: Sequence[float], duration: float, startup: float) -> None:
    """Refuse a grid a ranking cannot score (before any work).

    Args:
        amplitudes: fractions of each actuator's control half-range.
        frequencies: sinusoid frequencies [Hz].
        duration: simulated time of each run [s].
        startup: start-up window the score skips [s].

    Raises:
        ValueError: an empty grid, an amplitude outside (0, 1] (a fraction of each actuator's
            control half-range), a frequency not finite and > 0, a start-up window not shorter
            than the run, or a frequency whose period fits fewer than `MIN_PERIODS` times after it.
    """
    if not len(amplitudes) or not len(frequencies):
        raise ValueError("the grid needs at least one amplitude and one frequency")
    for a in amplitudes:
        if not (math.isfinite(a) and 0 < a <= 1):
            raise ValueError(f"amplitude {a:g} must be in (0, 1]: a fraction of each actuator's control half-range")
    for f in frequencies:
        if not (math.isfinite(f) and f > 0):
            raise ValueError(f"frequency {f:g} Hz must be a finite number > 0")
    if not (0 <= startup < duration):
        raise ValueError(f"the start-up window {startup:g} s must be >= 0 and shorter than the run {duration:g} s")
    for f in frequencies:
        periods = math.floor((duration - startup) * f + 1e-9)
        if periods < MIN_PERIODS:
            raise ValueError(
                f"frequency {f:g} Hz: {duration - startup:g} s after the start-up window hold {periods} whole "
                f"period(s) of {1 / f:g} s; the score needs at least {MIN_PERIODS}: run longer than "
                f"{startup + MIN_PERIODS / f:g} s or raise the frequency"
            )


def play_points(
    joints: Sequence[str], plays: Mapping[str, float], amplitudes: Sequence[float], frequencies: Sequence[float]
) -> list[dict[str, Any]]:
    """Points ``{"joint", "play", "size", "amplitude", "frequency"}``, kind-major then joint-major.

    Args:
        joints: the candidate hinges.
        plays: kind of play ('radial', 'backlash') -> its size (c [m], b [rad]).
        amplitudes: fractions of each actuator's control half-range.
        frequencies: sinusoid frequencies [Hz].
    """
    return [
        {"joint": j, "play": kind, "size": float(size), "amplitude": float(a), "frequency": float(f)}
        for kind, size in plays.items()
        for j in joints
        for a in amplitudes
        for f in frequencies
    ]


def per_period_deviation(
    result: SimulationResult, twin: SimulationResult, site: str, frequency: float, startup: float
) -> np.ndarray:
    """Mean distance [m] of ``site`` from the twin's over each whole period of ``frequency`` after ``startup``.

    Args:
        result: the run with play (the site's outputs ``site/<name>/x|y|z``).
        twin: the unmodified twin's run.
        site: the site (or body).
        frequency: the control frequency [Hz]; one period is 1 / frequency.
        startup: start-up window skipped [s].

    Raises:
        ValueError: fewer than one whole period after the start-up window.
    """
    dev = site_deviation(result, twin, site, skip=startup)
    period = 1.0 / frequency
    h = float(result.metadata.get("timestep", 0.0))
    start = float(result.times[0]) + startup
    end = float(result.times[-1]) + h  # the last row stands for the step after it
    # periods start at t0 + startup; a step that does not divide the run leaves it up to half a step short of
    # its last period: rounding, not a lost period
    slack = 0.5 * h / period + 1e-9
    periods = math.floor((end - start) / period + slack) if len(dev.times) else 0
    if periods < 1:
        raise ValueError(f"no whole period of {period:g} s after the start-up window {startup:g} s")
    k = np.floor((dev.times - start) / period + slack).astype(int)
    return np.array([float(dev.distance[k == i].mean()) for i in range(periods)])


def evaluate_play_point(
    index: int, point: Mapping[str, Any], runner: PlayRunner, site: str, startup: float
) -> dict[str, Any]:
    """Run one point and score it (in a worker); a point that fails gives a row with status ``error``.

    Args:
        index: the point's index.
        point: ``{"joint", "play", "size", "amplitude", "frequency"}``.
        runner: point -> (run, twin run).
        site: the end effector.
        startup: start-up window the score skips [s].

    Returns:
        ``{"index", "point", "status", "error", "per_period_mean_deviation" [m] (list),
        "mean_deviation" [m], "timestep" [s], "timing": {"wall_time_s", "pid"}}``.
    """
    t0 = time.perf_counter()
    row: dict[str, Any] = {"index": index, "point": dict(point), "status": "ok", "error": ""}
    try:
        result, twin = runner(point)
        values = per_period_deviation(result, twin, site, float(point["frequency"]), startup)
        row["per_period_mean_deviation"] = [float(v) for v in values]
        row["mean_deviation"] = float(values.mean())
        row["timestep"] = float(result.metadata.get("timestep", float("nan")))
    except Exception as err:
        row["status"] = "error"
        row["error"] = f"{type(err).__name__}: {err}"
    row["timing"] = {"wall_time_s": time.perf_counter() - t0, "pid": os.getpid()}
    return row


@dataclass(frozen=True)
class RobotRanking:
    """The plays ranked.

    Attributes:
        by_kind: kind of play -> its hinges ranked by mean deviation / play (`rank_joints`;
            cells keyed by the grid cell's index in ``cells``).
        overall: the candidates '<hinge> (<kind>)' ranked by the mean deviation itself [m].
        cells: the grid cells (amplitude, frequency [Hz]), in index order.
        sizes: kind -> its play (c [m], b [rad]).
        site: the end effector scored.
        startup: the start-up window [s].
        failed: (point, error) of the points that did not run.
    """

    by_kind: dict[str, CriticalityRanking]
    overall: CriticalityRanking
    cells: tuple[tuple[float, float], ...]
    sizes: dict[str, float]
    site: str
    startup: float
    failed: tuple[tuple[dict[str, Any], str], ...]


def rank_plays(rows: Sequence[Mapping[str, Any]], *, site: str, startup: float) -> RobotRanking:
    """Rank the rows of a robot ranking (see the module docstring).

    Args:
        rows: the rows of `evaluate_play_point` (``load_rows`` of a ranking's folder).
        site: the end effector, recorded in the ranking.
        startup: the start-up window [s], recorded in the ranking.

    Raises:
        NothingToRankError: no point ran (a `ValueError`).
    """
    cells = tuple(sorted({(float(r["point"]["amplitude"]), float(r["point"]["frequency"])) for r in rows}))
    index = {c: i for i, c in enumerate(cells)}

    def as_cell(r: Mapping[str, Any], joint: str, size: float) -> dict[str, Any]:
        p = r["point"]
        return {
            "status": r["status"],
            "error": r.get("error", ""),
            "per_cycle_mean_deviation": r.get("per_period_mean_deviation"),
            "point": {
                "joint": joint,
                "clearance": size,
                "speed": index[(float(p["amplitude"]), float(p["frequency"]))],
            },
        }

    kinds = list(dict.fromkeys(str(r["point"]["play"]) for r in rows))
    by_kind = {
        k: rank_joints(
            [as_cell(r, r["point"]["joint"], float(r["point"]["size"])) for r in rows if r["point"]["play"] == k]
        )
        for k in kinds
        if any(r["point"]["play"] == k and r["status"] == "ok" for r in rows)
    }
    overall = rank_joints([as_cell(r, f"{r['point']['joint']} ({r['point']['play']})", 1.0) for r in rows])
    sizes = {str(r["point"]["play"]): float(r["point"]["size"]) for r in rows}
    failed = tuple((dict(r["point"]), str(r.get("error", ""))) for r in rows if r["status"] != "ok")
    return RobotRanking(by_kind, overall, cells, sizes, site, startup, failed)


def run_robot_ranking(
    runner: PlayRunner,
    points: Sequence[Mapping[str, Any]],
    *,
    site: str,
    startup: float,
    out_dir: str | Path,
    executor: Executor | None = None,
    scheduler_address: str | None = None,
    progress: bool = True,
    max_workers: int | None = None,
) -> RobotRanking:
    """Run (or resume) the points through the sweeps' executor and rank them.

    Args:
        runner: picklable point -> (run, twin run) (`clearance.run.play_candidates.PlayAtHinge`).
        points: `play_points`.
        site: the end effector (its outputs are in both runs).
        startup: start-up window skipped by the score [s].
        out_dir: the ranking's folder (``points/``, ``robot_ranking.json``).
        executor, scheduler_address, progress, max_workers: as `open_executor` and `Progress` take them.

    Raises:
        ValueError: no points, or ``out_dir`` holding another ranking; `NothingToRankError` when
            no point ran; `SchedulerError` a Dask scheduler that cannot be used.
    """
    pts = [dict(p) for p in points]
    if not pts:
        raise ValueError("a ranking needs at least one point")
    out = Path(out_dir)
    (out / "points").mkdir(parents=True, exist_ok=True)
    settings = {"runner": repr(runner), "site": site, "startup": startup}
    check_manifest(out, pts, settings, file=_MANIFEST, kind="ranking")
    rows = {r["index"]: r for r in load_rows(out) if 0 <= r["index"] < len(pts)}
    todo = [i for i in range(len(pts)) if i not in rows]
    with (
        open_executor(executor, scheduler_address=scheduler_address, max_workers=max_workers) as pool,
        Progress(len(pts), enabled=progress, desc="ranking", unit="run", initial=len(rows)) as bar,
    ):
        running: dict[Future[dict[str, Any]], int] = {
            pool.executor.submit(evaluate_play_point, i, pts[i], runner, site, startup): i for i in todo
        }
        try:
            while running:
                finished, _ = wait(list(running), return_when=FIRST_COMPLETED)
                for fut in finished:
                    i = running.pop(fut)
                    row = fut.result()
                    atomic_write_text(out / "points" / f"point_{i:06d}.json", json.dumps(row, indent=1))
                    rows[i] = row
                    p = pts[i]
                    bar.step(label=f"{p['joint']} {p['play']}")
        finally:
            for fut in running:
                fut.cancel()
    return rank_plays([rows[k] for k in sorted(rows)], site=site, startup=startup)


def _score_label(kind: str) -> tuple[str, float]:
    """(unit, factor from SI) of a kind's score."""
    return ("µm/arcmin", 1e6 * ARCMIN) if kind == "backlash" else ("µm/µm", 1.0)


def robot_ranking_markdown(ranking: RobotRanking) -> str:
    """Markdown: the overall ranking, each kind's ranking, and the per-cell mean deviations."""
    lines = [
        f"End effector: `{ranking.site}`; score window: after the first {ranking.startup:g} s, per whole control "
        "period. Grid cells: "
        + ", ".join(f"#{i} amplitude {a:g}, {f:g} Hz" for i, (a, f) in enumerate(ranking.cells))
        + ".",
        "",
        "### All candidates, by mean deviation from the twin at the plays given",
        "",
        "| rank | hinge (play) | mean deviation [µm] | 95 % interval | cells | mean cell rank | P(above next) |",
        "|---:|---|---:|---|---:|---:|---:|",
    ]
    lines += _score_rows(ranking.overall, 1e6)
    lines += _resolution(ranking.overall, 1e6, "µm")
    for kind, r in ranking.by_kind.items():
        unit, scale = _score_label(kind)
        size = ranking.sizes[kind]
        play = f"c = {size * 1e3:g} mm" if kind != "backlash" else f"b = {size / ARCMIN:g} arcmin"
        lines += [
            "",
            f"### {kind.capitalize()} play ({play}): score = mean deviation / play",
            "",
            f"| rank | hinge | score [{unit}] | 95 % interval | cells | mean cell rank | P(above next) |",
            "|---:|---|---:|---|---:|---:|---:|",
        ]
        lines += _score_rows(r, scale)
        lines += _resolution(r, scale, unit)
    lines += [
        "",
        "### Per cell",
        "",
        "| hinge (play) | amplitude | frequency [Hz] | mean deviation [µm] | s.e. [µm] | periods | rank in cell |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for c in ranking.overall.cells:
        a, f = ranking.cells[int(c.speed)]
        lines.append(
            f"| {c.joint} | {a:g} | {f:g} | {c.mean_deviation * 1e6:.4g} | {c.sem * 1e6:.2g} | {c.cycles} | {c.rank} |"
        )
    for p, e in ranking.failed:
        lines.append(f"\nfailed: {p}: {e}")
    return "\n".join(lines) + "\n"


RESOLVED = 0.95
"""A candidate is told apart from the next where it exceeds it with this probability (`rank_joints`'s)."""


def _resolution(r: CriticalityRanking, scale: float, unit: str) -> list[str]:
    """A line under a ranking table where its order is not a ranking: adjacent candidates not told apart at
    `RESOLVED`, the widest interval and what would narrow them."""
    pairs = [s for s in r.scores if np.isfinite(s.confidence_above_next)]
    unresolved = [s for s in pairs if s.confidence_above_next < RESOLVED]
    if not unresolved:
        return []
    widest = max(r.scores, key=lambda s: s.ci_high - s.ci_low)
    cells = max(s.cells for s in r.scores)
    periods = min((c.cycles for c in r.cells), default=0)
    return [
        "",
        f"**Not a ranking:** {len(unresolved)} of {len(pairs)} candidates are not told apart from the next at "
        f"{RESOLVED:.0%} (the widest interval, {widest.joint}'s, spans {(widest.ci_high - widest.ci_low) * scale:.3g} "
        f"{unit} from {cells} grid cell{'s' * (cells > 1)} of {periods} or more whole periods each): the order "
        "above is the means' only. More cells (--amplitudes, --frequencies-hz) or longer runs (--duration-ms) "
        "narrow the intervals.",
    ]


def _score_rows(r: CriticalityRanking, scale: float) -> list[str]:
    out = []
    for s in r.scores:
        conf = "" if not np.isfinite(s.confidence_above_next) else f"{s.confidence_above_next:.3f}"
        out.append(
            f"| {s.rank} | {s.joint} | {s.score * scale:.4g} | [{s.ci_low * scale:.4g}, {s.ci_high * scale:.4g}] "
            f"| {s.cells} | {s.mean_cell_rank:.2f} | {conf} |"
        )
    return out
