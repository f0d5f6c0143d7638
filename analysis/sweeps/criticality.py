"""Criticality of clearance joints: clearance at one joint at a time, ranked by deviation.

Following Alok, Chaudhary and Guha 2020 (docs/references.md), the candidates are all
revolute joints except the driven crank's ground pivot and the output link's ground
pivot; asked to, every slider's play in its guide is a candidate too (`clearance rank`). Each
candidate gets the clearance alone, over a grid of clearances and drive speeds; the
deviation of the first output from the ideal mechanism's is measured per drive period after
the first (`statistics.per_cycle_mean_deviation`).

Score of a joint: the mean over grid cells of (mean deviation / clearance), so every cell
weighs alike whatever its clearance. Its unit follows the output's kind: dimensionless
(m/m) for a position output, rad/m for an angle output. Confidence: each cell's standard
error comes from the scatter of its per-cycle values; the score's 95 % interval uses
Student's t with the pooled degrees of freedom, and "confidence above next" is the normal
probability that the joint's score truly exceeds the next-ranked one's,
Phi((s_i - s_j) / sqrt(se_i^2 + se_j^2)). Cycles of one run are correlated, so these
intervals are indicative.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.sweeps.sweep import MechanismFactory, SweepEvaluation, run_sweep
from clearance.model import Mechanism, OutputKind
from clearance.options import ModelOptions

__all__ = [
    "CellDeviation",
    "ClearanceAtJoint",
    "CriticalityRanking",
    "JointScore",
    "NothingToRankError",
    "criticality_candidates",
    "criticality_points",
    "rank_joints",
    "ranking_markdown",
    "run_criticality",
]


def criticality_candidates(mechanism: Mechanism, *, sliders: bool = False) -> list[str]:
    """Revolute joints eligible for clearance: all but the driven and the output's ground pivot.

    Args:
        mechanism: a `Mechanism` (its first output defines the output link).
        sliders: also every prismatic joint (a slider's play in its guide, a translational
            clearance), in declaration order among the hinges.
    """
    from clearance.model import JointType

    driven = {d.joint for d in mechanism.drives}
    out_link = mechanism.outputs[0].link if mechanism.outputs else None
    out = []
    for j in mechanism.joints:
        if j.kind is JointType.PRISMATIC and sliders:
            out.append(j.name)
            continue
        if j.kind is not JointType.REVOLUTE or j.name in driven:
            continue
        if out_link is not None and {j.link_a, j.link_b} == {mechanism.ground, out_link}:
            continue
        out.append(j.name)
    return out


@dataclass(frozen=True)
class ClearanceAtJoint:
    """Picklable point -> Mechanism for criticality points ``{"joint", "clearance", "speed"}``.

    Calls ``builder(**fixed, <joint_key>=(joint,), <clearance_key>=clearance,
    <speed_key>=speed)``; ``joint`` None gives the ideal mechanism (``<joint_key>=()``).

    Attributes:
        builder: module-level builder function.
        fixed: other keyword arguments.
        joint_key, clearance_key, speed_key: the builder's keyword names (the press's speed
            keyword is ``crank2_speed``: see `CatalogueEntry.speed_keyword`).
    """

    builder: Callable[..., Mechanism]
    fixed: Mapping[str, Any] = field(default_factory=dict)
    joint_key: str = "clearance_at"
    clearance_key: str = "radial_clearance"
    speed_key: str = "crank_speed"

    def __call__(self, point: Mapping[str, Any]) -> Mechanism:
        kw = dict(self.fixed)
        joint = point.get("joint")
        kw[self.joint_key] = () if joint is None else (joint,)
        if "clearance" in point:
            kw[self.clearance_key] = point["clearance"]
        if "speed" in point:
            kw[self.speed_key] = point["speed"]
        return self.builder(**kw)


def criticality_points(
    joints: Sequence[str], clearances: Sequence[float], speeds: Sequence[float]
) -> list[dict[str, Any]]:
    """Grid points ``{"joint", "clearance" [m], "speed" [rad/s]}`` in joint-major order.

    Args:
        joints: joint names.
        clearances: radial clearances [m].
        speeds: drive speeds [rad/s].
    """
    return [{"joint": j, "clearance": float(c), "speed": float(s)} for j in joints for c in clearances for s in speeds]


@dataclass(frozen=True)
class CellDeviation:
    """Mean deviation of one grid cell.

    Attributes:
        joint, clearance [m], speed [rad/s]: the cell.
        mean_deviation: mean over cycles of the per-cycle mean |y - y_ideal| [output unit].
        sem: its standard error from the per-cycle scatter (NaN for one cycle).
        cycles: number of cycles.
        rank: rank of the joint within the cell (1 = most critical).
    """

    joint: str
    clearance: float
    speed: float
    mean_deviation: float
    sem: float
    cycles: int
    rank: int


@dataclass(frozen=True)
class JointScore:
    """A joint's criticality.

    Attributes:
        joint: joint name.
        rank: overall rank (1 = most critical).
        score: mean over cells of mean deviation / clearance [output unit / m: 1 for a
            position output, rad/m for an angle output; see `CriticalityRanking.score_unit`].
        se: standard error of the score [same unit].
        ci_low, ci_high: 95 % interval of the score [same unit].
        cells: number of cells that ran.
        mean_cell_rank: mean of the per-cell ranks.
        confidence_above_next: probability the score exceeds the next joint's (NaN for the
            last).
    """

    joint: str
    rank: int
    score: float
    se: float
    ci_low: float
    ci_high: float
    cells: int
    mean_cell_rank: float
    confidence_above_next: float


@dataclass(frozen=True)
class CriticalityRanking:
    """Joints ranked by criticality, with the per-cell table.

    Attributes:
        scores: `JointScore` in rank order.
        cells: `CellDeviation` rows.
        failed: (point, error) of points that did not run.
        output: name of the measured output ('' when not known).
        output_kind: its `OutputKind` (None when not known); sets the units.
        complete: every point of the grid has run (False: stopped by ``stop_after``, the
            ranking is of the points run so far).
    """

    scores: tuple[JointScore, ...]
    cells: tuple[CellDeviation, ...]
    failed: tuple[tuple[dict[str, Any], str], ...] = ()
    output: str = ""
    output_kind: OutputKind | None = None
    complete: bool = True

    @property
    def score_unit(self) -> str:
        """Unit of the scores: ``-`` (m/m) for a position output, ``rad/m`` for an angle output."""
        if self.output_kind is None:
            return "output unit/m"
        return "rad/m" if self.output_kind is OutputKind.ANGLE else "-"

    @property
    def deviation_unit(self) -> str:
        """Unit in which `ranking_markdown` shows the cells' mean deviations (µm or µrad)."""
        if self.output_kind is None:
            return "µm or µrad"
        return "µrad" if self.output_kind is OutputKind.ANGLE else "µm"


class NothingToRankError(ValueError):
    """No criticality point ran; ``failed`` holds (point, error) of every point that failed."""

    def __init__(self, message: str, failed: tuple[tuple[dict[str, Any], str], ...]) -> None:
        super().__init__(message)
        self.failed = failed


def rank_joints(
    rows: Sequence[Mapping[str, Any]], *, output: str = "", output_kind: OutputKind | None = None
) -> CriticalityRanking:
    """Rank joints from criticality sweep rows (see the module docstring).

    Args:
        rows: criticality sweep rows (`run_sweep` output or `load_rows`).
        output: name of the measured output, recorded in the ranking.
        output_kind: its kind, which sets the score unit (None: unknown).

    Raises:
        NothingToRankError: no row ran (a `ValueError`).
    """
    ok = [r for r in rows if r["status"] == "ok" and r.get("per_cycle_mean_deviation")]
    failed = tuple((dict(r["point"]), r.get("error", "")) for r in rows if r not in ok)
    if not ok:
        first = f"; first error: {failed[0][1]}" if failed else ""
        raise NothingToRankError(f"no criticality point ran ({len(failed)} failed{first}): nothing to rank", failed)
    raw = []
    for r in ok:
        v = np.asarray(r["per_cycle_mean_deviation"], float)
        sem = float(v.std(ddof=1) / np.sqrt(len(v))) if len(v) > 1 else float("nan")
        p = r["point"]
        raw.append((p["joint"], float(p["clearance"]), float(p["speed"]), float(v.mean()), sem, len(v)))
    cells = []
    for key in sorted({(c, s) for _, c, s, *_ in raw}):
        group = sorted((x for x in raw if (x[1], x[2]) == key), key=lambda x: -x[3])
        cells += [CellDeviation(*x, rank=i + 1) for i, x in enumerate(group)]
    from scipy import stats  # here, not at import: scipy.stats takes about 0.4 s to import

    joints = list(dict.fromkeys(c.joint for c in cells))
    tmp = []
    for j in joints:
        mine = [c for c in cells if c.joint == j]
        ratio = np.array([c.mean_deviation / c.clearance for c in mine])
        sems = np.array([c.sem / c.clearance if np.isfinite(c.sem) else 0.0 for c in mine])
        score = float(ratio.mean())
        se = float(np.sqrt(np.sum(sems**2)) / len(mine))
        dof = max(1, sum(c.cycles - 1 for c in mine))
        half = float(stats.t.ppf(0.975, dof) * se)
        tmp.append((j, score, se, score - half, score + half, len(mine), float(np.mean([c.rank for c in mine]))))
    tmp.sort(key=lambda x: -x[1])
    scores = []
    for i, x in enumerate(tmp):
        if i + 1 < len(tmp):
            nxt = tmp[i + 1]
            den = np.hypot(x[2], nxt[2])
            conf = float(stats.norm.cdf((x[1] - nxt[1]) / den)) if den > 0 else float(x[1] > nxt[1])
        else:
            conf = float("nan")
        scores.append(JointScore(x[0], i + 1, x[1], x[2], x[3], x[4], x[5], x[6], conf))
    return CriticalityRanking(tuple(scores), tuple(cells), failed, output, output_kind)


def ranking_markdown(ranking: CriticalityRanking) -> str:
    """Markdown tables: the ranking, then the per-cell mean deviations."""
    unit = ranking.score_unit
    lines = [
        f"| rank | joint | score (mean dev. / c) [{unit}] | 95 % interval | cells | mean cell rank | P(above next) |",
        "|---:|---|---:|---|---:|---:|---:|",
    ]
    for s in ranking.scores:
        conf = "" if not np.isfinite(s.confidence_above_next) else f"{s.confidence_above_next:.3f}"
        lines.append(
            f"| {s.rank} | {s.joint} | {s.score:.4g} | [{s.ci_low:.4g}, {s.ci_high:.4g}] | {s.cells} "
            f"| {s.mean_cell_rank:.2f} | {conf} |"
        )
    lines += [
        "",
        f"| joint | clearance [mm] | speed [rpm] | mean deviation [{ranking.deviation_unit}] | s.e. | cycles "
        "| rank in cell |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for c in ranking.cells:
        lines.append(
            f"| {c.joint} | {c.clearance * 1e3:.4g} | {c.speed * 30 / np.pi:.4g} | "
            f"{c.mean_deviation * 1e6:.4g} | {c.sem * 1e6:.2g} | {c.cycles} | {c.rank} |"
        )
    for p, e in ranking.failed:
        lines.append(f"\nfailed: {p}: {e}")
    return "\n".join(lines) + "\n"


def run_criticality(
    make_mechanism: MechanismFactory,
    *,
    clearances: Sequence[float],
    speeds: Sequence[float],
    out_dir: str | Path,
    joints: Sequence[str] | None = None,
    sliders: bool = False,
    periods: int = 6,
    output: str | None = None,
    options: ModelOptions | None = None,
    executor: Executor | None = None,
    scheduler_address: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
    max_workers: int | None = None,
) -> CriticalityRanking:
    """Run the one-joint-at-a-time criticality sweep and rank the joints (resumable).

    Args:
        make_mechanism: picklable point -> Mechanism for points ``{"joint", "clearance",
            "speed"}`` (e.g. `ClearanceAtJoint`); ``joint`` None must give the ideal
            mechanism (built once here to find the output's kind, and the candidates when
            ``joints`` is None).
        clearances: radial clearances [m].
        speeds: drive speeds [rad/s].
        out_dir: sweep folder.
        joints: joints to test; default `criticality_candidates`.
        sliders: with ``joints`` None, also every slider's play in its guide (the revolute
            rule alone is the published one: Alok, Chaudhary and Guha 2020).
        periods: drive periods per run (the first is skipped; the rest give the per-cycle
            values).
        output: output measured (default the mechanism's first).
        options, executor, scheduler_address, progress, stop_after, max_workers: as in
            `run_sweep`.

    Raises:
        ValueError: empty grid, fewer than 3 periods, an output the mechanism does not
            have, or out_dir holding another sweep.
        NothingToRankError: no point ran (a `ValueError`).
    """
    from clearance.run.simulation import default_duration

    if not len(clearances) or not len(speeds):
        raise ValueError("clearances and speeds must not be empty")
    if not isinstance(periods, int) or periods < 3:
        raise ValueError(f"periods must be an integer >= 3 (got {periods!r})")
    probe = make_mechanism({"joint": None, "clearance": clearances[0], "speed": speeds[0]})
    kinds = {o.name: o.kind for o in probe.outputs}
    measured = output or next(iter(kinds), None)
    if measured is None or measured not in kinds:
        raise ValueError(
            f"output must be one of the outputs of mechanism '{probe.name}', {list(kinds)} (got {output!r})"
        )
    if joints is None:
        joints = criticality_candidates(probe, sliders=sliders)
    points = criticality_points(joints, clearances, speeds)
    out = run_sweep(
        points,
        make_mechanism,
        out_dir=out_dir,
        duration=functools.partial(default_duration, revolutions=float(periods)),
        options=options,
        executor=executor,
        scheduler_address=scheduler_address,
        progress=progress,
        stop_after=stop_after,
        evaluation=SweepEvaluation(output=output, ideal=True),
        max_workers=max_workers,
    )
    return replace(rank_joints(out.rows, output=measured, output_kind=kinds[measured]), complete=out.complete)
