"""``clearance allocate``: the cheapest clearance per joint whose output stays within a budget (resumable).

A catalogue mechanism (``--mechanism``) or a scenario file (``--scenario``) gives the
design; its joints (``--joints``, default the criticality candidates) get a clearance each
within bounds; the budget of an output measure (``--measure mean|rms|peak`` of
``--output``) is given (``--budget``, in µm for a position output, µrad for an angle) or
measured (``--budget-equal-mm C``: the verified mean of the design with every joint at C).
Cost per joint a + b / (c / 1 mm), a = 0 and b = 1 unless the scenario file says otherwise::

    [allocation.cost.A]
    a = 0.5
    b = 2.0

Everything is checked before any run: unknown joints, outputs or measures, contradictory
bounds, levels outside the bounds, then the bounds built at every speed; then the
lower-bound design is run as a verification ensemble, and a budget it misses is refused
(exit 2) before the design runs. Every run is kept in ``<out>/runs``; a rerun of the same
command reuses them and gives the same allocation.
"""

from __future__ import annotations

import argparse
import math
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from clearance.cli.arg_types import bounded, positive, rpm_option
from clearance.cli.limits import MIN_CLEARANCE
from clearance.cli.options import add_sweep_args, si, sweep_options
from clearance.cli.parser import CommandParser
from clearance.cli.paths import check_folder, folder_lock, staged_outputs
from clearance.cli.scenario_sections import split_section
from clearance.cli.sweep_common import (
    INTERRUPTED,
    UsageError,
    catalogue_entry,
    check_prepares,
    check_scheduler,
    probe,
    stopped,
    usage_error,
)
from clearance.model import JointType, Mechanism, OutputKind

if TYPE_CHECKING:
    from clearance.analysis.design.allocation import Allocation, AllocationProblem, AllocationSettings
    from clearance.analysis.sweeps.sweep import MechanismFactory

__all__ = ["allocate_parser", "main_allocate"]

MEASURE_NAMES = {"mean": "mean_deviation", "rms": "rms_deviation", "peak": "peak_deviation"}
"""--measure -> the ensemble's measure."""


def allocate_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance allocate``."""
    p = CommandParser(
        prog="clearance allocate",
        description="Allocate the cheapest clearance per joint whose output deviation stays within a budget.",
    )
    p.add_argument("--scenario", default=None, help="scenario file (.toml), instead of --mechanism (default: none)")
    p.add_argument(
        "--joints",
        nargs="+",
        default=None,
        help="joints given a clearance, a slider's prismatic joint among them (its play in its guide) "
        "(default: criticality candidates)",
    )
    p.add_argument("--output", default=None, help="output measured (default the mechanism's first)")
    p.add_argument("--measure", default="mean", help="mean, rms or peak deviation from the ideal output (default mean)")
    budget = p.add_mutually_exclusive_group(required=True)
    budget.add_argument(
        "--budget", type=positive(float, "--budget"), nargs="+", default=None,
        help="budget [µm for a position output, µrad for an angle]: one, or one per --rpm (this or --budget-equal-mm "
        "is required)",
    )  # fmt: skip
    budget.add_argument(
        "--budget-equal-mm", type=positive(float, "--budget-equal-mm"), default=None,
        help="budget = the verified mean of the design with every joint at this clearance [mm] (this or --budget "
        "is required)",
    )  # fmt: skip
    p.add_argument(
        "--rpm",
        type=rpm_option("--rpm"),
        nargs="+",
        default=None,
        help="drive speeds [rpm] (default: the mechanism's own speed)",
    )
    p.add_argument("--min-mm", type=positive(float, "--min-mm"), default=0.02, help="lower bound [mm] (default 0.02)")
    p.add_argument("--max-mm", type=positive(float, "--max-mm"), default=0.3, help="upper bound [mm] (default 0.3)")
    p.add_argument(
        "--bounds",
        nargs="+",
        default=[],
        metavar="JOINT:LO:HI",
        help="bounds of one joint [mm] (default: --min-mm and --max-mm)",
    )
    p.add_argument(
        "--cost",
        nargs="+",
        default=[],
        metavar="JOINT:A:B",
        help="cost a + b/c[mm] of one joint (default a = 0, b = 1)",
    )
    p.add_argument("--levels-mm", type=positive(float, "--levels-mm"), nargs="+", default=None,
                   help="allowed clearances [mm] (a grid; default continuous)")  # fmt: skip
    p.add_argument("--target-share", type=bounded(float, "--target-share", 0.01, 1.0), default=0.9,
                   help="share of verification runs that must meet the budget (default 0.9)")  # fmt: skip
    p.add_argument("--runs", type=bounded(int, "--runs", 2), default=20, help="verification runs (default 20)")
    p.add_argument("--spread", type=bounded(float, "--spread", 0.0, 0.5), default=0.01,
                   help="start offsets within this fraction of each clearance (default 0.01)")  # fmt: skip
    p.add_argument("--seed", type=bounded(int, "--seed", 0), default=0, help="seed of the start states (default 0)")
    p.add_argument("--periods", type=bounded(int, "--periods", 2), default=4,
                   help="drive periods per run, the first not measured (default 4)")  # fmt: skip
    p.add_argument("--design-size", type=bounded(int, "--design-size", 4), default=None,
                   help="design points (default twice the surrogate's terms plus 3)")  # fmt: skip
    p.add_argument(
        "--design-runs", type=positive(int, "--design-runs"), default=2, help="runs per design point (default 2)"
    )
    p.add_argument(
        "--iterations", type=positive(int, "--iterations"), default=4, help="verifications at most (default 4)"
    )
    p.add_argument("--front", type=positive(float, "--front"), nargs="+", default=[0.5, 0.7, 1.0, 1.4, 2.0],
                   help="budgets of the front, as fractions of the budget (default 0.5 0.7 1 1.4 2)")  # fmt: skip
    p.add_argument(
        "--front-runs", type=positive(int, "--front-runs"), default=5, help="runs per front design (default 5)"
    )
    add_sweep_args(p, "allocate")
    p.set_defaults(mechanism=None)
    return p


def main_allocate(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance allocate``; writes ``allocation.md``, tables and figures; returns the exit code.

    Exit codes: 0 the allocation meets the target share, 1 it does not, 2 a usage error (also a
    budget the lower bounds miss), 3 stopped by --stop-after (rerun to resume), 130 interrupted.
    """
    args = allocate_parser().parse_args(argv)
    command = "clearance allocate " + shlex.join(list(argv) if argv is not None else sys.argv[1:])
    try:
        check_scheduler(args.scheduler)
        name, base, mech = _mechanism(args)
        out = check_folder(Path(args.out or f"clearance-allocate-{name}"))
        make, problem, settings, unit, scale = _problem(args, name, base, mech)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    from clearance.analysis.design.allocation import BudgetUnreachable
    from clearance.analysis.design.ensemble import EnsembleStopped

    try:
        with folder_lock(out):
            a = _run(args, make, problem, settings, out)
            title = f"{name}, {problem.measure.replace('_', ' ')} of {settings.verification.output}"
            from clearance.analysis.design.allocation_report import write_allocation

            with staged_outputs(out) as stage:  # the report, tables and figures together, or none
                write_allocation(a, stage, title=title, unit=unit, scale=scale, command=command)
    except BudgetUnreachable as err:
        return usage_error(f"--budget: {err}")
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    except EnsembleStopped as err:
        return stopped(
            args.stop_after, f"{err.finished} runs", out / "runs", "allocation.md and its tables are written"
        )
    except KeyboardInterrupt:
        kept = len(list((out / "runs").glob("run_*.json"))) if (out / "runs").is_dir() else 0
        print(f"interrupted; {kept} runs kept in {out / 'runs'}, rerun to resume", file=sys.stderr)
        return INTERRUPTED
    d = a.allocated
    print((out / "allocation.md").read_text(encoding="utf-8").split("## Iterations")[0])
    if d is None or not d.meets:
        print(
            f"error: no allocation met the budget in {problem.target_share:.0%} of the verification runs after "
            f"{len(a.allocation_iterations)} verifications; see {out / 'allocation.md'}",
            file=sys.stderr,
        )
        return 1
    return 0


def _run(
    args: argparse.Namespace,
    make: MechanismFactory,
    problem: AllocationProblem,
    settings: AllocationSettings,
    out: Path,
) -> Allocation:
    from clearance.analysis.design.allocation import allocate
    from clearance.analysis.sweeps.executor import SchedulerError

    try:
        return allocate(
            make,
            problem,
            settings,
            store=out / "runs",
            scheduler_address=args.scheduler,
            max_workers=args.workers,
            progress=not args.no_progress,
            stop_after=args.stop_after,
        )
    except SchedulerError as err:
        raise UsageError(f"--scheduler {args.scheduler}: {err}") from None


def _mechanism(args: argparse.Namespace) -> tuple[str, MechanismFactory, Mechanism]:
    """(name, base factory point -> Mechanism without clearances, its mechanism at the first point)."""
    from clearance.analysis.design.factories import FixedMechanism
    from clearance.analysis.sweeps.sweep import KeywordFactory

    if args.scenario is not None:
        if args.mechanism is not None:
            raise UsageError(f"--scenario {args.scenario} cannot be given with --mechanism {args.mechanism}")
        from clearance.builders.scenario import ScenarioError, loads_scenario

        path = Path(args.scenario)
        split = split_section(path, "allocation")
        text, args.allocation_table = split.scenario_text, split.section
        try:
            mech = loads_scenario(text, source=str(path))
        except ScenarioError as err:
            raise UsageError(str(err)) from None
        return path.stem, FixedMechanism(mech), mech
    name = args.mechanism or "slider_crank"
    entry = catalogue_entry(name)
    args.allocation_table = {}
    clearable = (*entry.info.clearable, *entry.info.sliders)  # a slider's play in its guide: c like a hinge's
    joints = tuple(args.joints) if args.joints else tuple(entry.info.clearable)
    unknown = [j for j in joints if j not in clearable]
    if unknown:
        raise UsageError(f"--joints: {unknown} cannot carry a clearance in {name}; choose from {list(clearable)}")
    base = KeywordFactory(entry.builder, {"clearance_at": joints}, rename={"speed": entry.speed_keyword})
    return name, base, entry.builder()


def _candidates(mech: Mechanism) -> list[str]:
    from clearance.analysis.sweeps.criticality import criticality_candidates

    return criticality_candidates(mech)


def _problem(
    args: argparse.Namespace, name: str, base: MechanismFactory, mech: Mechanism
) -> tuple[MechanismFactory, AllocationProblem, AllocationSettings, str, float]:
    """The allocation of checked arguments: (factory, problem, settings, display unit, SI -> unit)."""
    from clearance.analysis.design.allocation import AllocationProblem, AllocationSettings
    from clearance.analysis.design.ensemble import EnsembleSettings
    from clearance.analysis.design.factories import JointClearances

    revolute = [j.name for j in mech.joints if j.kind is JointType.REVOLUTE]
    driven = {d.joint for d in mech.drives}
    sliders = [j.name for j in base({}).translational_joints]  # sliders given play by the base
    joints = tuple(args.joints) if args.joints else tuple(_candidates(mech))
    bad = [j for j in joints if (j not in revolute or j in driven) and j not in sliders]
    if bad or len(set(joints)) != len(joints) or not joints:
        raise UsageError(
            f"--joints {list(joints)}: give distinct revolute, undriven joints of {name}: "
            f"{[j for j in revolute if j not in driven]}{', or its sliders ' + str(sliders) if sliders else ''}"
        )
    outputs = {o.name: o.kind for o in mech.outputs}
    output = args.output or next(iter(outputs), None)
    if output not in outputs:
        raise UsageError(f"--output {args.output}: not an output of {name}; choose from {list(outputs)}")
    if args.measure not in MEASURE_NAMES:
        raise UsageError(f"--measure {args.measure}: choose one of {list(MEASURE_NAMES)}")
    angle = outputs[output] is OutputKind.ANGLE
    unit, scale = ("µrad", 1e6) if angle else ("µm", 1e6)
    speeds = [si(r, "rpm") for r in args.rpm] if args.rpm else []
    ops: tuple[dict[str, Any], ...] = tuple({"speed": w} for w in speeds) or ({},)
    if args.budget is not None and len(args.budget) not in (1, len(ops)):
        raise UsageError(f"--budget: give one value or one per --rpm ({len(ops)}); got {len(args.budget)}")
    lower, upper = _bounds(args, joints)
    cost = _cost(args, joints)
    levels = _levels(args, lower, upper)
    budgets = None
    if args.budget is not None:
        budgets = tuple(b / scale for b in (args.budget * len(ops) if len(args.budget) == 1 else args.budget))
    try:
        problem = AllocationProblem(
            joints,
            lower,
            upper,
            cost,
            measure=MEASURE_NAMES[args.measure],
            operating_points=ops,
            budgets=budgets,
            budget_reference=None if args.budget_equal_mm is None else si(args.budget_equal_mm, "mm"),
            target_share=args.target_share,
            levels=levels,
        )
    except ValueError as err:
        raise UsageError(f"{err}") from None
    make = JointClearances(base)
    options = sweep_options(args)
    for op in ops:
        for side, c in (("--min-mm", lower), ("--max-mm", upper)):
            pt = {"clearances": dict(zip(joints, c, strict=True)), **op}
            where = f"{name} with {side} bounds {[x * 1e3 for x in c]} mm at {op or 'its speed'}"
            mech = probe(make, pt, name, source=where, periods=args.periods, timestep=options.timestep)
            if side == "--min-mm":  # the stiffest contact: the time step every run shares is checked once
                check_prepares(mech, options, where, f"--timestep-us {args.timestep_us:g}")
    settings = AllocationSettings(
        verification=EnsembleSettings(
            runs=args.runs, spread=args.spread, seed=args.seed, periods=args.periods, output=output, options=options
        ),
        design_size=args.design_size,
        design_runs=args.design_runs,
        max_iterations=args.iterations,
        front_fractions=tuple(args.front),
        front_runs=args.front_runs,
    )
    return make, problem, settings, unit, scale


def _split(text: str, option: str, parts: int) -> list[str]:
    bits = text.split(":")
    if len(bits) != parts:
        raise UsageError(f"{option} {text}: expected {'JOINT:LO:HI' if option == '--bounds' else 'JOINT:A:B'}")
    return bits


def _number(text: str, option: str, whole: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise UsageError(f"{option} {whole}: {text!r} is not a number") from None
    if v != v or v in (float("inf"), float("-inf")):
        raise UsageError(f"{option} {whole}: {text!r} is not a finite number")
    return v


def _bounds(args: argparse.Namespace, joints: tuple[str, ...]) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Bounds per joint [m] from --min-mm/--max-mm and --bounds JOINT:LO:HI [mm]."""
    lo = {j: args.min_mm for j in joints}
    hi = {j: args.max_mm for j in joints}
    given = dict.fromkeys(joints, f"--min-mm {args.min_mm:g} --max-mm {args.max_mm:g}")
    for text in args.bounds:
        j, a, b = _split(text, "--bounds", 3)
        if j not in lo:
            raise UsageError(f"--bounds {text}: joint {j!r} is not one of --joints {list(joints)}")
        if given[j].startswith("--bounds"):
            raise UsageError(f"--bounds {text}: joint {j!r} has bounds already ({given[j]}); give each joint once")
        lo[j], hi[j] = _number(a, "--bounds", text), _number(b, "--bounds", text)
        given[j] = f"--bounds {text}"
    smallest = MIN_CLEARANCE * 1e3
    for j in joints:
        if not 0 < lo[j] < hi[j]:
            raise UsageError(
                f"{given[j]}: joint {j}'s lower bound {lo[j]:g} mm must be above 0 and below its upper bound "
                f"{hi[j]:g} mm"
            )
        if lo[j] < smallest:
            raise UsageError(
                f"{given[j]}: joint {j}'s lower bound {lo[j]:g} mm is below the smallest clearance accepted, "
                f"{smallest:g} mm (1 µm)"
            )
    return tuple(si(lo[j], "mm") for j in joints), tuple(si(hi[j], "mm") for j in joints)


def _levels(args: argparse.Namespace, lower: tuple[float, ...], upper: tuple[float, ...]) -> tuple[float, ...] | None:
    """--levels-mm [m], each within some joint's bounds (none is dropped without a word)."""
    if not args.levels_mm:
        return None
    lo_mm, hi_mm = min(lower) * 1e3, max(upper) * 1e3
    for v in args.levels_mm:
        if not any(a * (1 - 1e-12) <= si(v, "mm") <= b * (1 + 1e-12) for a, b in zip(lower, upper, strict=True)):
            raise UsageError(
                f"--levels-mm {v:g}: outside every joint's bounds (from {lo_mm:g} to {hi_mm:g} mm; --min-mm, "
                "--max-mm, --bounds); give levels within them"
            )
    twice = sorted({v for v in args.levels_mm if args.levels_mm.count(v) > 1})
    if twice:
        raise UsageError(f"--levels-mm {twice[0]:g} is given twice")
    return tuple(si(v, "mm") for v in args.levels_mm)


def _cost(args: argparse.Namespace, joints: tuple[str, ...]) -> Any:
    """The `CostModel`: a = 0, b = 1, then the scenario's [allocation.cost.<joint>], then --cost."""
    from clearance.analysis.design.surrogate import CostModel

    a = dict.fromkeys(joints, 0.0)
    b = dict.fromkeys(joints, 1.0)
    table = getattr(args, "allocation_table", {}) or {}
    extra = sorted(set(table) - {"cost"})
    if extra:
        raise UsageError(f"--scenario {args.scenario}: [allocation] takes only 'cost' tables (got {extra})")
    source = {j: "the default cost a = 0, b = 1" for j in joints}
    for j, entry in dict(table.get("cost", {})).items():
        where = f"--scenario {args.scenario}: [allocation.cost.{j}]"
        if j not in a:
            raise UsageError(f"{where}: joint {j!r} is not one of the joints {list(joints)}")
        if not isinstance(entry, dict) or set(entry) - {"a", "b"}:
            raise UsageError(f"{where}: expected keys a and b (numbers)")
        for key, store in (("a", a), ("b", b)):
            if key in entry:
                if not isinstance(entry[key], (int, float)) or isinstance(entry[key], bool):
                    raise UsageError(f"{where}: {key} must be a number (got {entry[key]!r})")
                store[j] = float(entry[key])
        source[j] = where
    for text in args.cost:
        j, x, y = _split(text, "--cost", 3)
        if j not in a:
            raise UsageError(f"--cost {text}: joint {j!r} is not one of --joints {list(joints)}")
        a[j], b[j] = _number(x, "--cost", text), _number(y, "--cost", text)
        source[j] = f"--cost {text}"
    for j in joints:  # each joint's own refusal, naming where its values came from
        if not (math.isfinite(a[j]) and a[j] >= 0):
            raise UsageError(f"{source[j]}: joint {j}'s fixed cost a must be finite and >= 0 (got {a[j]:g})")
        if not (math.isfinite(b[j]) and b[j] > 0):
            raise UsageError(f"{source[j]}: joint {j}'s cost b (of b/c[mm]) must be finite and > 0 (got {b[j]:g})")
    try:
        return CostModel(tuple(a[j] for j in joints), tuple(b[j] for j in joints))
    except ValueError as err:
        raise UsageError(f"--cost: {err}") from None
