"""Speed against error: errors from the saved runs, the Pareto front, defaults, table and figure.

Reads the files of `clearance.bench.speed_error.run_speed_error`. For each MuJoCo
setting of a scenario:

* speed: wall time per drive revolution, and the speed-up against the reference solver
  timed in the same call (and against a fixed time per revolution, where given);
* first impacts (deterministic): relative errors of peak contact force, maximum
  penetration and impulse of each joint's first impact, and the time the run separates
  from the reference (journal centres more than 10 % of the clearance apart);
* statistics (chaotic part): error of each statistic of
  `clearance.analysis.metrics.accuracy.STATISTICS` on the scale of
  `clearance.analysis.metrics.accuracy.statistic_errors` (relative; eccentricity in units of the
  clearance; impacts relative to at least one per revolution), with the reference's own
  scatter and the combined scatter of the error beside it.

A setting's *statistics error* is its worst |error| over statistics and joints; its
*first-impact error* the worst over the three first-impact quantities and joints.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.metrics.accuracy import (
    STATISTICS,
    FirstImpact,
    Statistic,
    first_impact_errors,
    statistic_errors,
)
from clearance.bench.speed_error import REFERENCE, Scenario

__all__ = [
    "SEPARATION_FRACTION",
    "SettingRow",
    "choose_defaults",
    "compare_scenario",
    "pareto_front",
    "reference_scatter",
    "speed_error_markdown",
]

SEPARATION_FRACTION = 0.1
"""Runs have separated once their journal centres are this fraction of the clearance apart."""

_FIRST = ("peak_force", "max_penetration", "impulse")


@dataclass
class SettingRow:
    """One MuJoCo setting of a scenario against the reference.

    Attributes:
        scenario: scenario name.
        key, label: the setting's key and label.
        setting: the setting's fields.
        status: ``ok`` or ``error`` (accuracy or timing run failed).
        error_message: the error a user sees, for failed settings.
        wall_per_rev: wall time per drive revolution [s] (one thread).
        cpu_per_rev: CPU time per drive revolution [s] (equal to the wall time on a quiet
            machine; steadier on a shared one).
        speedup: reference CPU time / this one (same call).
        speedup_fixed: fixed time per revolution / this setting's CPU time (NaN where none
            is given).
        first_impact: joint -> quantity -> relative error (``onset``: difference [s]).
        first_impact_error: worst |relative error| of the first-impact quantities.
        separation: joint -> separation time from the reference [s]; negative where the
            run had not separated by the end of the kept rows (the value is minus that end,
            a lower bound).
        statistics: joint -> statistic -> {error, ref_scatter, scatter}.
        statistics_error: worst |error| over statistics and joints.
        worst_statistic: ``joint: statistic`` of that worst error.
        segments: joint -> segment count used.
    """

    scenario: str
    key: str
    label: str
    setting: dict[str, Any]
    status: str
    error_message: str = ""
    wall_per_rev: float = math.nan
    cpu_per_rev: float = math.nan
    speedup: float = math.nan
    speedup_fixed: float = math.nan
    first_impact: dict[str, dict[str, float]] = field(default_factory=dict)
    first_impact_error: float = math.nan
    separation: dict[str, float] = field(default_factory=dict)
    statistics: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)
    statistics_error: float = math.nan
    worst_statistic: str = ""
    segments: dict[str, int] = field(default_factory=dict)


def _load(path: Path) -> dict[str, Any] | None:
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None


def _stats(rec: Mapping[str, Any]) -> dict[str, dict[str, Statistic]]:
    return {
        j: {k: Statistic(s["value"], s["scatter"], s["blocks"], tuple(s.get("block_values", ()))) for k, s in d.items()}
        for j, d in rec["statistics"].items()
    }


def _first(rec: Mapping[str, Any], joint: str) -> FirstImpact | None:
    fi = rec["first_impact"].get(joint)
    return FirstImpact(**fi) if fi else None


def _separation(out: Path, scenario: str, key: str, ref: Mapping[str, Any]) -> dict[str, float]:
    base = out / "accuracy" / scenario
    try:
        a, b = np.load(base / f"{key}.npz"), np.load(base / f"{REFERENCE}.npz")
    except OSError:
        return {}
    sep = {}
    for j, c in ref["clearance"].items():
        t = a["times"][a["times"] <= b["times"][-1]]
        ea = a[f"{j}/eccentricity"][: len(t)]
        eb = np.column_stack([np.interp(t, b["times"], b[f"{j}/eccentricity"][:, k]) for k in range(2)])
        apart = np.flatnonzero(np.hypot(*(ea - eb).T) > SEPARATION_FRACTION * c)
        # never apart within the kept rows: the separation is at least their end (stored negative)
        sep[j] = float(t[apart[0]]) if len(apart) else -float(t[-1])
    return sep


def compare_scenario(
    scenario: Scenario, out_dir: str | Path, *, fixed_per_rev: float | None = None
) -> list[SettingRow]:
    """Rows of every setting of ``scenario`` that has accuracy and timing files.

    Args:
        scenario: the scenario.
        out_dir: the folder `run_speed_error` wrote.
        fixed_per_rev: a fixed reference wall time per revolution [s] for a second
            speed-up (e.g. a published solver's), or None.

    Raises:
        FileNotFoundError: the reference's accuracy or timing file is missing.
        RuntimeError: the reference run failed (its message is given).
    """
    out = Path(out_dir)
    ref = _load(out / "accuracy" / scenario.name / f"{REFERENCE}.json")
    ref_t = _load(out / "timing" / scenario.name / f"{REFERENCE}.json")
    if ref is None or ref_t is None:
        raise FileNotFoundError(f"no reference files for scenario '{scenario.name}' in {out}: run the bench first")
    for r in (ref, ref_t):
        if r["status"] != "ok":
            raise RuntimeError(f"the reference run of scenario '{scenario.name}' failed: {r['error']}")
    ref_stats = _stats(ref)
    rows = []
    for st in scenario.settings:
        acc = _load(out / "accuracy" / scenario.name / f"{st.key}.json")
        tim = _load(out / "timing" / scenario.name / f"{st.key}.json")
        if acc is None or tim is None:
            continue
        row = SettingRow(scenario.name, st.key, st.label, dict(acc["setting"]), "ok")
        bad = [r["error"] for r in (acc, tim) if r["status"] != "ok"]
        if bad:
            row.status, row.error_message = "error", bad[0]
            rows.append(row)
            continue
        row.segments = dict(acc["metadata"].get("segments") or {})
        row.wall_per_rev = tim["wall_per_rev_s"]
        row.cpu_per_rev = tim.get("cpu_per_rev_s", row.wall_per_rev)
        row.speedup = ref_t.get("cpu_per_rev_s", ref_t["wall_per_rev_s"]) / row.cpu_per_rev
        if fixed_per_rev:
            row.speedup_fixed = fixed_per_rev / row.cpu_per_rev
        row.first_impact = {j: first_impact_errors(_first(acc, j), _first(ref, j)) for j in ref["first_impact"]}
        # a first impact missing on either side (NaN) is the worst error, not one max() may skip
        row.first_impact_error = max(
            math.inf if math.isnan(e[k]) else abs(e[k]) for e in row.first_impact.values() for k in _FIRST
        )
        row.separation = _separation(out, scenario.name, st.key, ref)
        row.statistics = statistic_errors(_stats(acc), ref_stats, clearance=ref["clearance"])
        worst = max(
            ((abs(v["error"]), f"{j}: {k}") for j, d in row.statistics.items() for k, v in d.items()),
            key=lambda x: -1.0 if math.isnan(x[0]) else x[0],
        )
        row.statistics_error, row.worst_statistic = worst
        rows.append(row)
    return rows


def reference_scatter(scenario: Scenario, out_dir: str | Path) -> dict[str, float]:
    """The reference's standard error of each statistic on its error scale (worst joint).

    The scales are those of `clearance.analysis.metrics.accuracy.statistic_errors`.

    Raises:
        FileNotFoundError: no usable reference accuracy file.
    """
    ref = _load(Path(out_dir) / "accuracy" / scenario.name / f"{REFERENCE}.json")
    if ref is None or ref["status"] != "ok":
        raise FileNotFoundError(f"no usable reference accuracy file for scenario '{scenario.name}'")
    stats = _stats(ref)
    errs = statistic_errors(stats, stats, clearance=ref["clearance"])
    out: dict[str, float] = {}
    for d in errs.values():
        for k, e in d.items():
            out[k] = max(out.get(k, 0.0), e["ref_scatter"])
    return out


def pareto_front(rows: Sequence[SettingRow], error: str) -> list[SettingRow]:
    """Settings not beaten by a faster one with a smaller error (fastest first).

    Args:
        rows: settings of one scenario.
        error: ``statistics_error`` or ``first_impact_error``.
    """
    ok = [r for r in rows if r.status == "ok" and math.isfinite(getattr(r, error))]
    front: list[SettingRow] = []
    for r in sorted(ok, key=lambda r: (r.cpu_per_rev, getattr(r, error))):
        if not front or getattr(r, error) < getattr(front[-1], error):
            front.append(r)
    return front


def choose_defaults(
    rows: Sequence[SettingRow], *, statistics_tol: float = 0.05, first_impact_tol: float = 0.01
) -> dict[str, SettingRow | None]:
    """The fastest setting within each tolerance.

    Returns:
        ``{"statistics": fastest with every statistic within statistics_tol,
        "first_impact": fastest with every first-impact quantity within first_impact_tol,
        "both": fastest within both}`` (None where no setting qualifies).
    """
    ok = [r for r in rows if r.status == "ok"]

    def fastest(pred: Callable[[SettingRow], bool]) -> SettingRow | None:
        good = [r for r in ok if pred(r)]
        return min(good, key=lambda r: r.cpu_per_rev) if good else None

    return {
        "statistics": fastest(lambda r: r.statistics_error <= statistics_tol),
        "first_impact": fastest(lambda r: r.first_impact_error <= first_impact_tol),
        "both": fastest(lambda r: r.statistics_error <= statistics_tol and r.first_impact_error <= first_impact_tol),
    }


def _pct(x: float) -> str:
    return "–" if not math.isfinite(x) else f"{100 * x:+.1f}"


def _speed(x: float) -> str:
    return "–" if not math.isfinite(x) else (f"{x:.0f}×" if x >= 10 else f"{x:.1f}×")


def speed_error_markdown(
    scenario: Scenario,
    rows: Sequence[SettingRow],
    *,
    reference_per_rev: float,
    fixed_per_rev: float | None = None,
    ref_scatter: Mapping[str, float] | None = None,
) -> str:
    """Markdown section of one scenario: its settings, front and chosen settings.

    Args:
        scenario: the scenario.
        rows: `compare_scenario` rows.
        reference_per_rev: the reference's wall time per revolution [s].
        fixed_per_rev: the fixed time per revolution used for ``speedup_fixed`` [s].
        ref_scatter: statistic -> the reference's relative scatter (worst over joints).
    """
    stats = list(STATISTICS)
    lines = [
        f"## {scenario.name}",
        "",
        scenario.description,
        "",
        f"Reference: {reference_per_rev:.3g} s CPU time per revolution. "
        f"Accuracy runs: {scenario.revolutions:g} revolutions, "
        f"statistics over revolutions {scenario.skip_revolutions:g}–{scenario.revolutions:g} in "
        f"{scenario.blocks} blocks; timing runs: {scenario.timing_revolutions:g} revolutions.",
        "",
    ]
    if ref_scatter:
        lines += [
            "Reference scatter (relative standard error of each statistic, worst joint): "
            + ", ".join(f"{k} {100 * v:.1f} %" for k, v in ref_scatter.items())
            + ".",
            "",
        ]
    head = (
        ["setting", "N", "CPU/rev [ms]", "wall/rev [ms]", "× ref"]
        + (["× fixed"] if fixed_per_rev else [])
        + ["first impact: F, δ, impulse [%]", "separates [ms]"]
        + [f"{s} [%]" for s in stats]
        + ["worst stat [%]"]
    )
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in sorted(rows, key=lambda r: (r.status != "ok", r.cpu_per_rev)):
        if r.status != "ok":
            lines.append(
                f"| {r.label} | | | | | "
                + ("| " if fixed_per_rev else "")
                + f"{r.error_message.splitlines()[0][:160]} |"
                + " |" * (len(head) - 6 - bool(fixed_per_rev))
            )
            continue
        fi = "; ".join(", ".join(_pct(e[k]) for k in _FIRST) for e in r.first_impact.values())
        sep = ", ".join(f"{1e3 * v:.2f}" if v >= 0 else f"≥ {-1e3 * v:.2f}" for v in r.separation.values())
        cells = []
        for s in stats:
            worst = max(r.statistics.values(), key=lambda d: abs(d.get(s, {}).get("error", 0.0)))
            e = worst.get(s)
            cells.append("–" if e is None else f"{_pct(e['error'])} ±{100 * e['scatter']:.1f}")
        segs = ", ".join(str(v) for v in r.segments.values())
        row = (
            [r.label, segs, f"{1e3 * r.cpu_per_rev:.2f}", f"{1e3 * r.wall_per_rev:.2f}", _speed(r.speedup)]
            + ([_speed(r.speedup_fixed)] if fixed_per_rev else [])
            + [fi, sep]
            + cells
            + [f"{100 * r.statistics_error:.1f}"]
        )
        lines.append("| " + " | ".join(row) + " |")
    lines.append("")
    for name, err in (("statistics", "statistics_error"), ("first impact", "first_impact_error")):
        front = pareto_front(rows, err)
        lines.append(
            f"Pareto front ({name} error): "
            + "; ".join(f"{r.label} ({_speed(r.speedup)}, {100 * getattr(r, err):.1f} %)" for r in front)
            + "."
        )
    d = choose_defaults(rows)
    lines += ["", "Fastest within the tolerances:", ""]
    for k, text in (
        ("statistics", "every statistic within 5 %"),
        ("first_impact", "first impact within 1 %"),
        ("both", "both"),
    ):
        best = d[k]
        lines.append(
            f"- {text}: "
            + (
                "none of the settings"
                if best is None
                else f"{best.label}: {_speed(best.speedup)} faster than the reference"
                + (f", {_speed(best.speedup_fixed)} than the fixed baseline" if fixed_per_rev else "")
                + f" (statistics {100 * best.statistics_error:.1f} %, first impact "
                f"{100 * best.first_impact_error:.1f} %)"
            )
        )
    return "\n".join(lines) + "\n"
