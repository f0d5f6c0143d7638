"""``clearance optimise``: design variables of a catalogue mechanism sized for its behaviour with clearance.

The design variables are keywords of the mechanism's builder, given with their unit in the
name as in scenario files (``--vary rod_length_mm=100:200``, ``--vary slider_mass_kg=0.05:0.4``,
a component of a pivot ``--vary crank7_pivot_mm[1]=-30:30``), an optional third number the
start value. Feasibility (the linkage assembles over its whole cycle, the stroke of the
output within ``--stroke``) is checked with the kinematics before any dynamic run; the
objective, a measure of the output against its ideal curve or the peak bearing force, is
an ensemble average (`clearance.analysis.design.ensemble`) at the clearances and speeds
given. Everything the command is given is checked before any work: an unknown variable or
output, contradictory bounds, a start outside its bounds, bounds where no design assembles
are refused with one line and exit status 2.

The command writes into ``--out``: ``optimise.md`` (the optimum against the start design,
confirmed by fresh ensembles), ``optimise.json``, ``convergence.png``, and the run outputs of
both designs (``start/``, ``optimum/``: one run each, written as ``clearance run`` writes
them, report and figures included); ``runs/`` keeps every ensemble run, so the same command
run again resumes.
"""

from __future__ import annotations

import argparse
import inspect
import math
import re
import shlex
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from clearance.cli.arg_types import bounded, positive, rpm_option, timestep_option
from clearance.cli.optimise_scenario import ScenarioDesign, read_scenario_design, section_vary
from clearance.cli.options import CONTACT_MODES, DEFAULT_MECHANISM, check_clearance_at, contact_mode_from_args, si
from clearance.cli.parser import CommandParser
from clearance.cli.sweep_common import INTERRUPTED, UsageError, catalogue_entry, check_prepares, usage_error
from clearance.units import UNITS, quantity_of

if TYPE_CHECKING:  # the analysis is imported when the command runs, not when it is parsed
    from clearance.analysis.design.ensemble import EnsembleSettings
    from clearance.analysis.design.optimise import OptimisationResult
    from clearance.analysis.design.optimise_search import SearchSettings
    from clearance.analysis.design.optimise_space import DesignFactory, DesignVariable, StrokeLimits

__all__ = ["main_optimise", "optimise_parser", "parse_variable"]

_OBJECTIVES = ("rms_deviation", "mean_deviation", "peak_deviation", "peak_force")
"""The measures of `clearance.analysis.design.ensemble.MEASURES` (checked equal in the tests)."""

_VARY = re.compile(r"^(?P<key>[A-Za-z_][A-Za-z0-9_]*)(?:\[(?P<index>[0-9]+)\])?=(?P<bounds>.*)$")


def optimise_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance optimise``."""
    p = CommandParser(
        prog="clearance optimise",
        description="Size design variables of a mechanism for the lowest output deviation or bearing force "
        "with clearance, averaged over start-state ensembles; confirm the optimum with fresh runs.",
    )
    p.add_argument(
        "--mechanism", default=None, metavar="NAME", help=f"catalogue mechanism (default {DEFAULT_MECHANISM})"
    )
    p.add_argument(
        "--scenario",
        default=None,
        metavar="TOML",
        help="scenario file naming a catalogue builder, with an [optimise] section of these options (its "
        "[optimise.vary] table: KEY = [LOW, HIGH(, START)]); options given here win over the file's (default: "
        "none, --mechanism and the options given)",
    )
    p.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="KEY=LOW:HIGH[:START]",
        help="a design variable: a builder keyword with its unit in the name, as in scenario files "
        "(rod_length_mm=100:200, slider_mass_kg=0.05:0.4, crank7_pivot_mm[1]=-30:30); repeat for each",
    )
    p.add_argument(
        "--objective",
        default=None,
        metavar="MEASURE",
        help=f"what is minimised, one of {', '.join(_OBJECTIVES)} (default rms_deviation: the fluctuation of "
        "the output about its ideal curve; peak_force: the peak bearing force)",
    )
    p.add_argument("--output", default=None, help="the output measured (default the mechanism's first)")
    p.add_argument(
        "--stroke",
        default=None,
        metavar="LOW:HIGH",
        help="limits of the output's stroke over a cycle, mm for a position output, deg for an angle output "
        "(either side may be left empty; default: no limit)",
    )
    p.add_argument(
        "--clearance-mm",
        type=positive(float, "--clearance-mm"),
        default=None,
        help="radial clearance of every clearance joint [mm] (default the builder's)",
    )
    p.add_argument(
        "--clearance-at", nargs="+", default=None, metavar="JOINT", help="joints with clearance (default the builder's)"
    )
    p.add_argument(
        "--rpm",
        type=rpm_option("--rpm"),
        nargs="+",
        default=None,
        help="drive speeds [rpm] the objective is averaged over (default the builder's)",
    )
    p.add_argument(
        "--runs", type=bounded(int, "--runs", 2), default=None, help="ensemble runs per design and speed (default 20)"
    )
    p.add_argument(
        "--periods",
        type=bounded(int, "--periods", 2),
        default=None,
        help="drive periods per run, the first skipped as start-up (default 2)",
    )
    p.add_argument(
        "--samples",
        type=bounded(int, "--samples", 0),
        default=None,
        help="space-filling designs evaluated with the start design (default 8)",
    )
    p.add_argument(
        "--budget",
        type=bounded(int, "--budget", 2),
        default=None,
        help="most designs simulated by the search, start and samples included (default 30)",
    )
    p.add_argument(
        "--seed",
        type=bounded(int, "--seed", 0),
        default=None,
        help="seed of the search's ensembles and sample (default 0)",
    )
    p.add_argument(
        "--confirm-seed",
        type=bounded(int, "--confirm-seed", 0),
        default=None,
        help="seed of the confirmation ensembles (default seed + 1)",
    )
    p.add_argument(
        "--timestep-us", type=timestep_option(), default=None, help="time step [µs] (default the contact mode's)"
    )
    p.add_argument(
        "--contact-mode",
        default=None,
        metavar="MODE",
        help=f"contact model of every run, one of {', '.join(CONTACT_MODES)} (default exact; see 'clearance run "
        "--help')",
    )
    p.add_argument(
        "--out", default=None, help="output folder (default clearance-optimise-<mechanism>); rerun to resume"
    )
    p.add_argument(
        "--workers", type=positive(int, "--workers"), default=None, help="local worker processes (default CPU count)"
    )
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="Dask scheduler address (default: local processes; needs pip install 'dask[distributed]')",
    )
    p.add_argument("--no-progress", action="store_true", help="no line per design")
    return p


def _builder_key(key: str, params: Sequence[str], mechanism: str) -> tuple[str, float]:
    """(builder keyword, factor to SI) of a --vary key with its unit in the name.

    Raises:
        UsageError: no keyword of the builder matches, or the unit is wrong.
    """
    if key in params and quantity_of(key) is None:
        return key, 1.0
    for p in sorted(params, key=len, reverse=True):
        q = quantity_of(p)
        if q is not None and key.startswith(p + "_") and key[len(p) + 1 :] in UNITS[q]:
            return p, UNITS[q][key[len(p) + 1 :]]
        if q is not None and key == p:
            units = ", ".join(f"{p}_{u}" for u in UNITS[q])
            raise UsageError(f"--vary {key}: give its unit in the name ({units})")
    numbers = [p for p in params if p != "contact"]
    raise UsageError(
        f"--vary {key}: unknown design variable of {mechanism}; its builder's keywords are {', '.join(numbers)}"
    )


def parse_variable(text: str, params: Sequence[str], mechanism: str) -> tuple[str, float, float, float | None]:
    """(variable name, low, high, start or None) in SI of one ``--vary`` value.

    Args:
        text: the option's value, ``KEY=LOW:HIGH[:START]``.
        params: the builder's keyword names.
        mechanism: the catalogue name, for messages.

    Raises:
        UsageError: a malformed value, an unknown keyword or unit, contradictory bounds.
    """
    m = _VARY.match(text.strip())
    if not m:
        raise UsageError(f"--vary {text}: expected KEY=LOW:HIGH[:START], e.g. rod_length_mm=100:200")
    keyword, factor = _builder_key(m.group("key"), params, mechanism)
    name = keyword + (f"[{m.group('index')}]" if m.group("index") is not None else "")
    parts = m.group("bounds").split(":")
    try:
        numbers = [float(v) for v in parts]
    except ValueError:
        numbers = []
    if len(parts) not in (2, 3) or len(numbers) != len(parts) or not all(math.isfinite(v) for v in numbers):
        raise UsageError(f"--vary {text}: expected finite numbers LOW:HIGH or LOW:HIGH:START after '='")
    low, high = numbers[0], numbers[1]
    if not low < high:
        raise UsageError(f"--vary {text}: contradictory bounds, LOW {low:g} must be below HIGH {high:g}")
    start = numbers[2] * factor if len(numbers) == 3 else None
    if len(numbers) == 3 and not low <= numbers[2] <= high:
        raise UsageError(f"--vary {text}: START {numbers[2]:g} lies outside [{low:g}, {high:g}]")
    return name, low * factor, high * factor, start


def _stroke(text: str | None, factor: float) -> tuple[float | None, float | None]:
    if text is None:
        return None, None
    parts = text.split(":")
    try:
        lo, hi = (float(v) * factor if v.strip() else None for v in parts) if len(parts) == 2 else (None, None)
    except ValueError:
        lo = hi = None
    if len(parts) != 2 or (lo is None and hi is None):
        raise UsageError(f"--stroke {text}: expected LOW:HIGH (either may be empty, not both)")
    if lo is not None and hi is not None and not lo < hi:
        raise UsageError(f"--stroke {text}: contradictory limits, LOW must be below HIGH")
    if any(v is not None and (not math.isfinite(v) or v < 0) for v in (lo, hi)):
        raise UsageError(f"--stroke {text}: limits must be finite and >= 0")
    return lo, hi


def main_optimise(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance optimise``; returns the exit status (0 done, 2 refused, 130 interrupted)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = optimise_parser().parse_args(argv)
    except SystemExit as stop:  # --help (0), or a refusal already printed on one line (2)
        return stop.code if isinstance(stop.code, int) else 2
    args.command_line = _command_line(argv)
    try:
        plan = _plan(args)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    try:
        return _optimise(args, plan)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    except KeyboardInterrupt:
        print(f"interrupted; the finished runs are kept in {plan.out / 'runs'}, rerun to resume", file=sys.stderr)
        return INTERRUPTED


@dataclass(frozen=True)
class _Plan:
    """Everything a checked command line asks for, in SI.

    Attributes:
        out: the output folder.
        factory: design point -> mechanism.
        variables: the design variables with their bounds.
        start: the start design (variable -> value).
        conditions: operating conditions (drive speeds) the objective is averaged over.
        output: the output measured.
        angular: the output is an angle.
        stroke: limits of its stroke, or None.
        ensemble: the ensembles' settings.
        search: the search's settings.
    """

    out: Path
    factory: DesignFactory
    variables: tuple[DesignVariable, ...]
    start: dict[str, float]
    conditions: list[dict[str, Any]]
    output: str
    angular: bool
    stroke: StrokeLimits | None
    ensemble: EnsembleSettings
    search: SearchSettings


_SETTINGS: dict[str, tuple[Callable[[str], Any], Any]] = {
    "objective": (str, "rms_deviation"),
    "output": (str, None),
    "runs": (bounded(int, "runs", 2), 20),
    "periods": (bounded(int, "periods", 2), 2),
    "samples": (bounded(int, "samples", 0), 8),
    "budget": (bounded(int, "budget", 2), 30),
    "seed": (bounded(int, "seed", 0), 0),
    "confirm_seed": (bounded(int, "confirm_seed", 0), None),
    "timestep_us": (timestep_option("timestep_us"), None),
    "contact_mode": (str, None),
}
"""Options an ``[optimise]`` section may set: how its value is read, and the default of both."""


def _source(args: argparse.Namespace) -> ScenarioDesign | None:
    """Read ``--scenario`` (None without one) and fill the options not given from its section, or the defaults.

    Raises:
        UsageError: a scenario with --mechanism, --clearance-mm or --clearance-at; a bad value in its section.
    """
    design = None
    section: dict[str, Any] = {}
    if args.scenario is not None:
        given = [
            f
            for f, v in (
                ("--mechanism", args.mechanism),
                ("--clearance-mm", args.clearance_mm),
                ("--clearance-at", args.clearance_at),
            )
            if v is not None
        ]
        if given:
            raise UsageError(
                f"--scenario {args.scenario} cannot be given with {', '.join(given)}: the scenario file names its "
                "mechanism and sets its values; change them in the file"
            )
        design = read_scenario_design(args.scenario)
        section = design.section
        args.mechanism = design.builder_name
        args.vary = section_vary(section, design.path) + list(args.vary)
    args.mechanism = args.mechanism or DEFAULT_MECHANISM
    where = f"--scenario {args.scenario}: [optimise]"
    for key, (read, default) in _SETTINGS.items():
        if getattr(args, key) is not None:
            continue
        if key not in section:
            setattr(args, key, default)
            continue
        try:
            setattr(args, key, read(str(section[key])))
        except (argparse.ArgumentTypeError, ValueError) as err:
            raise UsageError(f"{where} {key}: {err}") from None
    if args.stroke is None and "stroke" in section:
        value = section["stroke"]
        if not (isinstance(value, list) and len(value) == 2):
            raise UsageError(f"{where} stroke must be [LOW, HIGH] (got {value!r})")
        args.stroke = f"{value[0]}:{value[1]}"
    if args.rpm is None and "rpm" in section:
        value = section["rpm"] if isinstance(section["rpm"], list) else [section["rpm"]]
        try:
            args.rpm = [rpm_option(f"{where} rpm")(str(v)) for v in value]
        except argparse.ArgumentTypeError as err:
            raise UsageError(str(err)) from None
    return design


def _plan(args: argparse.Namespace) -> _Plan:
    """Every input checked, before any work: factory, variables, settings (or UsageError)."""
    from clearance.analysis.design.ensemble import EnsembleSettings
    from clearance.analysis.design.optimise_search import SearchSettings
    from clearance.analysis.design.optimise_space import (
        DesignFactory,
        DesignVariable,
        StrokeLimits,
        check_design,
        scan_bounds,
    )
    from clearance.cli.limits import check_mechanism, check_steps
    from clearance.cli.paths import check_folder
    from clearance.cli.sweep_common import check_scheduler
    from clearance.model import OutputKind
    from clearance.options import ModelOptions

    design = _source(args)
    if args.objective not in _OBJECTIVES:
        raise UsageError(
            f"--objective {args.objective}: unknown output measure; choose one of {', '.join(_OBJECTIVES)}"
        )
    if args.contact_mode is not None and args.contact_mode not in CONTACT_MODES:
        raise UsageError(f"--contact-mode {args.contact_mode}: choose one of {', '.join(CONTACT_MODES)}")
    entry = catalogue_entry(design.builder_name if design else args.mechanism)
    check_clearance_at(args.clearance_at, args.mechanism)
    if not args.vary:
        raise UsageError("give at least one design variable with --vary KEY=LOW:HIGH (e.g. rod_length_mm=100:200)")
    params = list(inspect.signature(entry.builder).parameters)
    parsed = [parse_variable(v, params, args.mechanism) for v in args.vary]
    names = [p[0] for p in parsed]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise UsageError(f"--vary names {', '.join(twice)} more than once")
    if args.samples + 2 > args.budget:
        raise UsageError(f"--budget {args.budget}: must be at least --samples + 2 = {args.samples + 2}")
    if args.confirm_seed is not None and args.confirm_seed == args.seed:
        raise UsageError(
            f"--confirm-seed {args.confirm_seed}: must differ from --seed, the confirmation takes fresh runs"
        )
    out = check_folder(args.out or f"clearance-optimise-{args.mechanism}")
    check_scheduler(args.scheduler)
    fixed: dict[str, Any] = dict(design.keywords) if design else {}
    given = f"--mechanism {args.mechanism}"
    if args.clearance_mm is not None:
        fixed["radial_clearance"] = si(args.clearance_mm, "mm")
        given = f"--clearance-mm {args.clearance_mm:g}"
    if args.clearance_at is not None:
        fixed["clearance_at"] = tuple(args.clearance_at)
    if "radial_clearance" in fixed:  # the clearance alone, at the builder's own design, before any variable
        try:
            check_mechanism(entry.builder(**fixed), given)
        except ValueError as err:
            raise UsageError(err if str(err).startswith(given) else f"{given}: {err}") from None
    factory = DesignFactory(entry.builder, fixed, tuple(names))
    variables = tuple(DesignVariable(n, lo, hi) for n, lo, hi, _ in parsed)
    start = {n: s for n, _, _, s in parsed if s is not None}
    conditions = [{}] if args.rpm is None else [{entry.speed_keyword: si(r, "rpm")} for r in args.rpm]
    try:
        x0 = {v.name: start.get(v.name, factory.start_value(v.name)) for v in variables}
    except ValueError as err:
        raise UsageError(f"--vary: {err}") from None
    for v in variables:
        if not v.low <= x0[v.name] <= v.high:
            unit, f = _shown(v.name)
            raise UsageError(
                f"--vary {v.name}: the start design's value {x0[v.name] * f:g} {unit} lies outside its bounds "
                f"[{v.low * f:g}, {v.high * f:g}] {unit}; widen them or give START"
            )
    try:
        probe = factory({**x0, **conditions[0]})
    except (ValueError, ArithmeticError) as err:  # AssemblyError is a ValueError
        scan_bounds(factory, variables)  # refuses bounds where nothing assembles
        raise UsageError(f"--vary: the start design {_design(x0)} cannot be built: {err}") from None
    outputs = {o.name: o.kind for o in probe.outputs}
    output = args.output or next(iter(outputs))
    if output not in outputs:
        raise UsageError(f"--output {output}: unknown output of {args.mechanism}; it has {', '.join(outputs)}")
    angular = outputs[output] is OutputKind.ANGLE
    lo, hi = _stroke(args.stroke, math.pi / 180 if angular else 1e-3)
    stroke = StrokeLimits(lo, hi) if args.stroke else None
    options = ModelOptions(
        timestep=0.0 if args.timestep_us is None else si(args.timestep_us, "us"),
        contact_mode=contact_mode_from_args(args),
    )
    for cond in conditions:
        mech = factory({**x0, **cond})
        check_mechanism(mech, given)
        if mech.drive_period is None:
            raise UsageError(f"--mechanism {args.mechanism}: it has no drive period to run ensembles over")
        check_steps(args.periods * mech.drive_period, options.timestep, f"--periods {args.periods}")
        step = "the default time step" if args.timestep_us is None else f"--timestep-us {args.timestep_us:g}"
        check_prepares(mech, options, f"--mechanism {args.mechanism} at the start design {_design(x0)}", step)
    first = check_design(factory, {**x0, **conditions[0]}, output=output, stroke=stroke)
    if not first.feasible:
        scan_bounds(factory, variables, output=output, stroke=stroke)  # refuses bounds where nothing is feasible
        raise UsageError(f"--vary: the start design {_design(x0)} is infeasible: {first.reason}; give START values")
    return _Plan(
        out,
        factory,
        variables,
        x0,
        conditions,
        output,
        angular,
        stroke,
        EnsembleSettings(runs=args.runs, seed=args.seed, periods=args.periods, output=output, options=options),
        SearchSettings(samples=args.samples, budget=args.budget, seed=args.seed),
    )


def _shown(name: str) -> tuple[str, float]:
    from clearance.analysis.design.optimise_report import display_unit

    unit, f = display_unit(name)
    return unit, f


def _design(point: dict[str, float]) -> str:
    """A design as the command line shows it (``rod_length 120 mm, slider_mass 0.14 kg``)."""
    return ", ".join(
        f"{k} {v * _shown(k)[1]:.5g}{(' ' + _shown(k)[0]) if _shown(k)[0] else ''}" for k, v in point.items()
    )


def _optimise(args: argparse.Namespace, plan: _Plan) -> int:
    """The optimisation of a checked plan, its confirmation and its report; the exit status."""
    from clearance.analysis.design.optimise import optimise_design
    from clearance.analysis.design.optimise_figure import plot_convergence
    from clearance.analysis.sweeps.executor import SchedulerError
    from clearance.cli.paths import folder_lock, staged_outputs

    out: Path = plan.out
    scale, unit = (1e6, "µrad") if plan.angular and args.objective != "peak_force" else (1e6, "µm")
    if args.objective == "peak_force":
        scale, unit = 1.0, "N"
    t0 = time.perf_counter()
    count = [0]
    last = [0.0]  # when the search's last design was done [s after t0]

    def line(point: dict[str, float], check: Any, est: Any) -> None:
        count[0] += 1
        last[0] = time.perf_counter() - t0
        if args.no_progress:
            return
        shown = _design(point)
        what = (
            f"{args.objective} {est.value * scale:.5g} ± {est.se * scale:.2g} {unit}"
            if est is not None
            else f"infeasible: {check.reason[:100]}"
        )
        print(f"  design {count[0]}: {shown}: {what} ({time.perf_counter() - t0:.0f} s)", flush=True)

    print(
        f"optimise {args.mechanism}: {len(plan.variables)} variables, {args.objective}, ensembles of "
        f"{args.runs} runs x {args.periods} periods, at most {args.budget} designs; runs kept in {out / 'runs'}",
        flush=True,
    )
    try:
        with folder_lock(out):
            result = optimise_design(
                plan.factory,
                plan.variables,
                measure=args.objective,
                ensemble=plan.ensemble,
                search=plan.search,
                conditions=plan.conditions,
                stroke=plan.stroke,
                start=plan.start,
                confirm_seed=args.confirm_seed,
                store=out / "runs",
                scheduler_address=args.scheduler,
                max_workers=args.workers,
                on_trial=line,
            )
            search_s = time.perf_counter() - t0
            print(
                f"search: {len(result.search.trials)} designs tried, {result.search.evaluations} simulated, in "
                f"{last[0]:.1f} s; confirmation in {search_s - last[0]:.1f} s",
                flush=True,
            )
            with staged_outputs(out) as stage:  # every report and figure, or none
                reports = _design_runs(plan, result, stage)
                print(f"run reports in {time.perf_counter() - t0 - search_s:.1f} s", flush=True)
                plot_convergence(result, stage / "convergence.png", scale=scale, unit=unit)
                _write_summary(args, plan, result, stage, reports, scale, unit, search_s)
    except SchedulerError as err:
        return usage_error(f"--scheduler {args.scheduler}: {err}")
    c = result.confirmation
    print(
        f"confirmed (seed {c.seed}): start {c.start.value * scale:.5g} ± {c.start.se * scale:.2g} {unit}, optimum "
        f"{c.optimum.value * scale:.5g} ± {c.optimum.se * scale:.2g} {unit}: improvement {c.improvement / c.se:.1f} "
        f"standard errors; {time.perf_counter() - t0:.0f} s; wrote {out / 'optimise.md'}"
    )
    return 0


def _write_summary(
    args: argparse.Namespace,
    plan: _Plan,
    result: OptimisationResult,
    out: Path,
    reports: list[tuple[str, str]],
    scale: float,
    unit: str,
    search_s: float,
) -> None:
    """Write ``optimise.md`` and its JSON into ``out``."""
    from clearance.analysis.design.optimise_report import optimise_markdown, write_optimise_report

    stroke_scale, stroke_unit = (180 / math.pi, "deg") if plan.angular else (1e3, "mm")
    md = optimise_markdown(
        result,
        title=f"Design optimisation of {args.mechanism} with clearance",
        scale=scale,
        unit=unit,
        stroke_scale=stroke_scale,
        stroke_unit=stroke_unit,
        command=args.command_line,
        reports=reports,
        wall_time_s=search_s,
    )
    write_optimise_report(out, result, md)


def _design_runs(plan: _Plan, result: OptimisationResult, out: Path) -> list[tuple[str, str]]:
    """One run of the start design and of the optimum (journals centred, at the first operating condition),
    written into ``start/`` and ``optimum/`` as ``clearance run`` writes a run's outputs; (label, report path)."""
    from clearance.cli.outputs import write_outputs
    from clearance.run.simulation import simulate

    reports = []
    ns = argparse.Namespace(rerun=None)
    settings = plan.ensemble
    for label, point in (("start", result.start), ("optimum", result.optimum)):
        mech = plan.factory({**point, **plan.conditions[0]})
        duration = settings.periods * (mech.drive_period or 0.0)  # every design has one (checked up front)
        run = simulate(mech, duration=duration, options=settings.options)
        ideal = simulate(mech.ideal_twin(), duration=duration, options=settings.options)
        print(f"{label} design, one run with the journals centred:")
        write_outputs(ns, mech, run, ideal, out / label)
        reports.append((f"{label} design", f"{label}/report.md"))
    return reports


def _command_line(argv: Sequence[str]) -> str:
    return "clearance optimise " + shlex.join(argv)
