"""The report of `clearance optimise`: ``optimise.md`` and ``optimise.json``.

``optimise.md`` puts the optimum against the start design: the design variables with their
bounds, the stroke, the objective of the search and of the confirmation (fresh ensembles,
another seed) with standard errors, the verdict against three standard errors, the
convergence figure, every evaluated design, and links to the two designs' run reports
(written beside it by the command, as ``clearance run`` writes a run's). ``optimise.json``
holds the same numbers in SI units. Both are written atomically.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from clearance.analysis.design.optimise import DesignEstimate, OptimisationResult
from clearance.results import atomic_write_text
from clearance.units import quantity_of

__all__ = ["display_unit", "optimise_json", "optimise_markdown", "write_optimise_report"]

_SHOWN = {"length": ("mm", 1e3), "angle": ("deg", 180.0 / math.pi), "angular_speed": ("rpm", 30.0 / math.pi)}


def display_unit(variable: str) -> tuple[str, float]:
    """(unit, factor from SI) in which a design variable is shown (mm for lengths, deg, rpm)."""
    keyword = variable.split("[")[0]
    q = quantity_of(keyword)
    if q in _SHOWN:
        return _SHOWN[q]
    return {"mass": ("kg", 1.0), "inertia": ("kg m²", 1.0)}.get(q or "", ("", 1.0))


def _value(name: str, x: float) -> str:
    unit, f = display_unit(name)
    return f"{x * f:.5g}" + (f" {unit}" if unit else "")


def _estimate(e: DesignEstimate, scale: float) -> str:
    return f"{e.value * scale:.5g} ± {e.se * scale:.2g}"


def optimise_markdown(
    result: OptimisationResult,
    *,
    title: str,
    scale: float,
    unit: str,
    stroke_scale: float,
    stroke_unit: str,
    command: str = "",
    figure: str = "convergence.png",
    reports: Sequence[tuple[str, str]] = (),
    wall_time_s: float = math.nan,
) -> str:
    """The Markdown of ``optimise.md``.

    Args:
        result: the optimisation.
        title: the report's title.
        scale, unit: factor from the objective's SI unit to the unit shown, and its name.
        stroke_scale, stroke_unit: the same for the output's stroke.
        command: the command line that made it ('' for none).
        figure: the convergence figure's relative path.
        reports: (label, relative path) of the designs' run reports.
        wall_time_s: the optimisation's wall time [s] (NaN: not shown).
    """
    c = result.confirmation
    s, e = result.ensemble, result.search
    trials = e.trials
    start_x = tuple(result.start[v.name] for v in result.variables)
    best_x = e.best.x
    lines = [f"# {title}", ""]
    if command:
        lines += ["```", command, "```", ""]
    verdict = (
        "**lower by more than three standard errors**" if c.significant else "**not** lower by three standard errors"
    )
    lines += [
        f"Objective: **{result.measure}** of the output against its ideal curve, the mean of an ensemble of "
        f"{s.runs} runs per design and operating condition (journals started within {s.spread:.0%} of each "
        f"clearance), {s.periods} drive periods per run, the first skipped; averaged over {len(result.conditions)} "
        f"operating condition(s): {', '.join(_condition(cd) for cd in result.conditions)}.",
        "",
        f"Confirmation by fresh ensembles (seed {c.seed}; the search used seed {s.seed}): start "
        f"{_estimate(c.start, scale)} {unit}, optimum {_estimate(c.optimum, scale)} {unit}; improvement "
        f"{c.improvement * scale:.4g} {unit} = {c.improvement / c.se if c.se > 0 else math.inf:.1f} standard errors "
        f"of the difference ({c.se * scale:.2g} {unit}): the optimum is {verdict}"
        + (f" ({c.improvement / c.start.value:.1%} of the start's value)." if c.start.value else "."),
        "",
        f"Search: {len(trials)} designs tried, {e.evaluations} simulated, {len(trials) - e.evaluations} refused by "
        f"the kinematics; {e.message}." + (f" Wall time {wall_time_s:.0f} s." if math.isfinite(wall_time_s) else ""),
        "",
        "| design variable | low | high | start | optimum |",
        "|---|---:|---:|---:|---:|",
    ]
    for k, v in enumerate(result.variables):
        lines.append(
            f"| {v.name} | {_value(v.name, v.low)} | {_value(v.name, v.high)} | {_value(v.name, start_x[k])} "
            f"| {_value(v.name, best_x[k])} |"
        )
    fs, fb = result.feasibility.get(start_x), result.feasibility.get(best_x)
    lines += [
        "",
        "| | start | optimum |",
        "|---|---:|---:|",
        f"| stroke [{stroke_unit}] | {_stroke(fs, stroke_scale)} | {_stroke(fb, stroke_scale)} |",
        f"| search ({result.measure}, seed {s.seed}) [{unit}] | {_estimate_of(result, start_x, scale)} "
        f"| {_estimate(result.estimates[best_x], scale)} |",
        f"| confirmed (seed {c.seed}) [{unit}] | {_estimate(c.start, scale)} | {_estimate(c.optimum, scale)} |",
        "",
        f"![convergence]({figure})",
        "",
    ]
    if reports:
        lines += [
            "Run reports (one run each, journals centred, the figures of `clearance run`): "
            + ", ".join(f"[{label}]({path})" for label, path in reports)
            + ".",
            "",
        ]
    lines += [
        "## Every design tried",
        "",
        "| # | phase | " + " | ".join(v.name for v in result.variables) + f" | {result.measure} [{unit}] | note |",
        "|---:|---|" + "---:|" * len(result.variables) + "---:|---|",
    ]
    for t in trials:
        values = " | ".join(_value(v.name, x) for v, x in zip(result.variables, t.x, strict=True))
        est = f"{t.estimate.value * scale:.5g} ± {t.estimate.se * scale:.2g}" if t.estimate.feasible else ""
        lines.append(f"| {t.index} | {t.phase} | {values} | {est} | {t.estimate.note[:120]} |")
    return "\n".join(lines) + "\n"


def _condition(cd: dict[str, Any]) -> str:
    if not cd:
        return "the builder's"
    return ", ".join(f"{k} = {_value(k, v)}" if isinstance(v, (int, float)) else f"{k} = {v}" for k, v in cd.items())


def _stroke(f: Any, scale: float) -> str:
    return "n/a" if f is None or not math.isfinite(f.stroke) else f"{f.stroke * scale:.5g}"


def _estimate_of(result: OptimisationResult, x: tuple[float, ...], scale: float) -> str:
    e = result.estimates.get(x)
    return "n/a" if e is None else _estimate(e, scale)


def optimise_json(result: OptimisationResult) -> dict[str, Any]:
    """The optimisation's numbers in SI units, JSON-ready."""
    c = result.confirmation

    def est(e: DesignEstimate) -> dict[str, Any]:
        return {
            "value": e.value,
            "se": e.se,
            "runs": e.runs,
            "failed": e.failed,
            "per_condition": [{"condition": cd, "mean": m, "se": se} for cd, m, se in e.per_condition],
        }

    return {
        "measure": result.measure,
        "variables": [{"name": v.name, "low": v.low, "high": v.high} for v in result.variables],
        "start": result.start,
        "optimum": result.optimum,
        "ensemble": {
            "runs": result.ensemble.runs,
            "spread": result.ensemble.spread,
            "seed": result.ensemble.seed,
            "periods": result.ensemble.periods,
        },
        "conditions": list(result.conditions),
        "search": {
            "message": result.search.message,
            "trials": [
                {
                    "index": t.index,
                    "phase": t.phase,
                    "x": list(t.x),
                    "value": t.estimate.value,
                    "se": t.estimate.se,
                    "feasible": bool(t.estimate.feasible),
                    "note": t.estimate.note,
                    "stroke": result.feasibility[t.x].stroke if t.x in result.feasibility else None,
                    "run_seconds": result.estimates[t.x].wall_time_s if t.x in result.estimates else None,
                    "runs": result.estimates[t.x].runs if t.x in result.estimates else 0,
                }
                for t in result.search.trials
            ],
        },
        "confirmation": {
            "seed": c.seed,
            "start": est(c.start),
            "optimum": est(c.optimum),
            "improvement": c.improvement,
            "se": c.se,
            "significant": c.significant,
        },
    }


def write_optimise_report(out_dir: str | Path, result: OptimisationResult, markdown: str) -> Path:
    """Write ``optimise.md`` and ``optimise.json`` into ``out_dir`` (atomically); the Markdown's path.

    Args:
        out_dir: the folder (it exists).
        result: the optimisation, written as ``optimise.json``.
        markdown: the report's text, written as ``optimise.md``.
    """
    out = Path(out_dir)
    atomic_write_text(out / "optimise.json", json.dumps(optimise_json(result), indent=1, default=float))
    path = out / "optimise.md"
    atomic_write_text(path, markdown)
    return path
