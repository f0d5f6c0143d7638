"""What an allocation writes: tables, figures and the Markdown report.

`write_allocation` writes into a folder, each file atomically: ``allocation.md`` (the
report), ``allocation.json`` (every number), ``allocation.csv`` (clearance, cost and share
of the budget per joint), ``front.csv`` (cost against budget), ``design.csv`` (the design
points and their measured values), and the figures ``allocation.png`` (clearance per
joint against the equal design, with the bounds), ``front.png`` (cost against budget,
verified points marked), ``verification.png`` (the verification ensembles against the
budget) and ``surrogate.png`` (the response surface against the runs).

"Share of the budget" of a joint is the part of the budgeted deviation the surrogate
attributes to it: the drop of the surrogate's prediction when that joint alone goes from
its allocated clearance to its lower bound, over the budget (the shares need not add up to
one: the joints interact, and the lower-bound design has a deviation of its own).
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.design.allocation import Allocation, VerifiedDesign
from clearance.results import atomic_write_text

__all__ = ["allocation_dict", "allocation_markdown", "budget_shares", "write_allocation"]


def budget_shares(a: Allocation, op: int = 0) -> list[float]:
    """Share of the budget per joint at operating point ``op`` (see the module docstring)."""
    d = a.allocated
    if d is None:
        return [float("nan")] * len(a.problem.joints)
    s = a.surrogates[op]
    c = np.asarray(d.clearances, float)
    full = s(c)
    out = []
    for j, lo in enumerate(a.problem.lower):
        lower = c.copy()
        lower[j] = lo
        out.append(float((full - s(lower)) / a.budgets[op]))
    return out


def allocation_dict(a: Allocation) -> dict[str, Any]:
    """Every number of the allocation as a JSON-like dict."""
    d = asdict(a)
    d["saving"] = a.saving
    d["budget_shares"] = [budget_shares(a, k) for k in range(len(a.budgets))]
    d["surrogate_relative_error"] = [list(s.relative_error) for s in a.surrogates]
    return json.loads(json.dumps(d, default=_json_default))


def _json_default(o: object) -> object:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if callable(o):
        return f"{getattr(o, '__module__', '?')}.{getattr(o, '__qualname__', type(o).__name__)}"
    return repr(o)


def _csv(rows: list[list[Any]]) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()


def _op_label(a: Allocation, k: int) -> str:
    op = a.problem.operating_points[k]
    if "speed" in op:
        return f"{op['speed'] * 30 / math.pi:.4g} rpm"
    return ", ".join(f"{key}={v}" for key, v in op.items()) or "the mechanism's own"


def _design_row(d: VerifiedDesign | None, budgets: tuple[float, ...], scale: float) -> str:
    if d is None:
        return "none within the bounds | | | |"
    mean = ", ".join(f"{m * scale:.4g} ± {s * scale:.2g}" for m, s in zip(d.mean, d.std, strict=True))
    share = ", ".join(f"{s:.0%}" for s in d.share)
    return f"{d.cost:.4g} | {mean} | {share} | {'yes' if d.meets else 'no'}"


def allocation_markdown(a: Allocation, *, title: str, unit: str, scale: float, command: str = "") -> str:
    """The report.

    Args:
        a: the allocation.
        title: what was allocated (mechanism, output, measure).
        unit: display unit of the measure (µm, µrad, N).
        scale: factor from the measure's SI value to ``unit``.
        command: the command that made it, shown first.
    """
    p, s, v = a.problem, a.settings, a.settings.verification
    lines = [f"# Clearance allocation: {title}", ""]
    if command:
        lines += ["```", command, "```", ""]
    budgets = ", ".join(f"{b * scale:.4g} {unit} at {_op_label(a, k)}" for k, b in enumerate(a.budgets))
    lines.append(f"Budget of the {p.measure.replace('_', ' ')}: {budgets}")
    if a.reference is not None:
        assert p.budget_reference is not None
        lines.append(
            f"(the verified mean of the design with every joint at {p.budget_reference * 1e3:g} mm: "
            f"{_mean_scatter(a.reference, scale)}"
            f" {unit}, mean ± scatter over {a.reference.runs} runs, cost {a.reference.cost:.4g})."
        )
    lines += [
        "",
        f"Cost per joint a + b / (c / 1 mm). Target: {p.target_share:.0%} of the verification runs within budget. "
        f"Verification ensembles: {v.runs} runs, journals' start offsets uniform in discs of {v.spread:.2%} of each "
        "clearance (a slider with play starts centred in its guide), "
        f"seed {v.seed}, {v.periods} drive periods per run (the first is start-up and not measured).",
        "",
        "## Allocation",
        "",
    ]
    d = a.allocated
    if d is None:
        lines.append("No allocation within the bounds meets the budget on the surrogate.")
    else:
        shares = budget_shares(a)
        lines += [
            "| joint | clearance [mm] | bounds [mm] | equal design [mm] | a | b | cost | share of the budget |",
            "|---|---:|---|---:|---:|---:|---:|---:|",
        ]
        per = p.cost.per_joint(d.clearances)
        eq = a.equal
        for j, name in enumerate(p.joints):
            e = f"{eq.clearances[j] * 1e3:.4g}" if eq is not None else "-"
            lines.append(
                f"| {name} | {d.clearances[j] * 1e3:.4g} | [{p.lower[j] * 1e3:g}, {p.upper[j] * 1e3:g}] | {e} | "
                f"{p.cost.a[j]:g} | {p.cost.b[j]:g} | {per[j]:.4g} | {shares[j]:.1%} |"
            )
        lines.append(f"| total | | | | | | {d.cost:.4g} | |")
    lines += [
        "",
        "| design | cost | verified mean ± scatter [" + unit + "] | runs within budget | meets target |",
        "|---|---:|---:|---:|---|",
        f"| allocation | {_design_row(d, a.budgets, scale)} |",
        f"| equal clearance | {_design_row(a.equal, a.budgets, scale)} |",
        f"| lower bounds | {_design_row(a.lower_bound, a.budgets, scale)} |",
    ]
    if not math.isnan(a.saving):
        lines += ["", f"**Saving against the equal-clearance design that meets the same budget: {a.saving:.1%}.**"]
    lines += ["", "## Iterations", ""]
    lines += [
        "| design | step | surrogate budget [" + unit + "] | predicted | verified mean | within budget | cost |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for name, its in (("allocation", a.allocation_iterations), ("equal", a.equal_iterations)):
        for i, it in enumerate(its):
            lines.append(
                f"| {name} | {i + 1} | {_join(it.surrogate_budgets, scale)} | {_join(it.predicted, scale)} | "
                f"{_join(it.mean, scale)} | {', '.join(f'{x:.0%}' for x in it.share)} | {it.cost:.4g} |"
            )
    lines += ["", "## Surrogate", ""]
    n = len(p.joints)
    lines.append(
        f"log D = b0 + sum b_j x_j + sum_(j<=k) b_jk x_j x_k with x_j = log(c_j / c_ref,j) (a log-log quadratic "
        f"response surface with every interaction: {1 + n + n * (n + 1) // 2} terms), fitted by weighted least "
        f"squares to {len(a.design)} design points (a Latin hypercube in log c, seed {s.design_seed}, plus the "
        f"lower corner, the upper corner and the middle; all joints varied at once), {s.design_runs} runs each, "
        "and the verification ensembles of failed iterations."
    )
    lines += [
        "",
        "| operating point | points | RMS relative error (fit) | (leave-one-out) | largest |",
        "|---|---:|---:|---:|---:|",
    ]
    for k, sur in enumerate(a.surrogates):
        fit, loo = sur.relative_error
        lines.append(
            f"| {_op_label(a, k)} | {len(sur.values)} | {fit:.1%} | {loo:.1%} "
            f"| {math.expm1(sur.max_abs_log_residual):.1%} |"
        )
    lines += ["", "## Front: cost against budget", ""]
    lines += [
        f"| budget / B | budget [{unit}] | allocation cost | verified mean | within | equal cost | verified mean "
        "| within | saving |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in a.front:
        al, eq2 = r.allocated, r.equal
        saving = f"{1 - al.cost / eq2.cost:.1%}" if al is not None and eq2 is not None else "-"
        lines.append(
            f"| {r.fraction:g} | {_join(r.budgets, scale)} | {_cell(al, scale)} | {_cell(eq2, scale)} | {saving} |"
        )
    lines += [
        "",
        f"Front designs are verified with {s.front_runs} runs each (fewer than the main verification).",
        "",
        f"Runs: {a.total_runs} used, {a.new_runs} simulated by this call; wall time {a.wall_time_s:.1f} s.",
        "",
        "![allocation](allocation.png)",
        "",
        "![front](front.png)",
        "",
        "![verification](verification.png)",
        "",
        "![surrogate](surrogate.png)",
        "",
    ]
    return "\n".join(lines)


def _mean_scatter(d: VerifiedDesign, scale: float) -> str:
    return ", ".join(f"{m * scale:.4g} ± {sd * scale:.2g}" for m, sd in zip(d.mean, d.std, strict=True))


def _join(values: tuple[float, ...], scale: float) -> str:
    return ", ".join(f"{x * scale:.4g}" for x in values) or "-"


def _cell(d: VerifiedDesign | None, scale: float) -> str:
    if d is None:
        return "- | - | -"
    return f"{d.cost:.4g} | {_join(d.mean, scale)} | {', '.join(f'{x:.0%}' for x in d.share)}"


def _tables(a: Allocation, scale: float) -> dict[str, str]:
    p = a.problem
    alloc: list[list[Any]] = [["joint", "clearance_mm", "lower_mm", "upper_mm", "a", "b", "cost", "budget_share"]]
    if a.allocated is not None:
        per = p.cost.per_joint(a.allocated.clearances)
        for j, name in enumerate(p.joints):
            alloc.append(
                [name, a.allocated.clearances[j] * 1e3, p.lower[j] * 1e3, p.upper[j] * 1e3, p.cost.a[j], p.cost.b[j],
                 per[j], budget_shares(a)[j]]
            )  # fmt: skip
    head = ["fraction", "budget", "allocation_cost", "allocation_mean", "allocation_share", "equal_cost", "equal_mean"]
    front: list[list[Any]] = [[*head, "equal_share"]]
    for r in a.front:
        row: list[Any] = [r.fraction, r.budgets[0] * scale]
        for d in (r.allocated, r.equal):
            row += ["", "", ""] if d is None else [d.cost, d.mean[0] * scale, min(d.share)]
        front.append(row)
    design: list[list[Any]] = [[*(f"{j}_mm" for j in p.joints), *(f"value_{k}" for k in range(len(a.budgets)))]]
    for i, c in enumerate(a.design):
        design.append([*(x * 1e3 for x in c), *(s.values[i] * scale for s in a.surrogates)])
    return {"allocation.csv": _csv(alloc), "front.csv": _csv(front), "design.csv": _csv(design)}


def write_allocation(
    a: Allocation, out: str | Path, *, title: str, unit: str, scale: float, command: str = ""
) -> list[Path]:
    """Write the report, tables and figures into ``out`` (see the module docstring); returns the paths.

    Args:
        a: the allocation.
        out: the folder (made if missing).
        title: the report's title line.
        unit: the output measure's unit as shown (e.g. "µrad").
        scale: factor from the measure's SI value to ``unit``.
        command: the command line that made it, quoted in the report ("" for none).
    """
    from clearance.analysis.design.allocation_figures import (
        plot_allocation,
        plot_front,
        plot_surrogate,
        plot_verification,
    )

    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, text in {
        "allocation.md": allocation_markdown(a, title=title, unit=unit, scale=scale, command=command),
        "allocation.json": json.dumps(allocation_dict(a), indent=1),
        **_tables(a, scale),
    }.items():
        atomic_write_text(folder / name, text)
        written.append(folder / name)
    for fn, name in (
        (plot_allocation, "allocation.png"),
        (plot_front, "front.png"),
        (plot_verification, "verification.png"),
        (plot_surrogate, "surrogate.png"),
    ):
        fn(a, folder / name, unit=unit, scale=scale)
        written.append(folder / name)
    return written
