"""``clearance reference``: a scenario with the exact-geometry reference solver (slow, exact)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from clearance.cli.limits import check_steps
from clearance.cli.options import (
    add_scenario_args,
    bounded,
    mechanism_from_args,
    numerics_given,
    positive,
    si,
)
from clearance.cli.outputs import (
    check_output_paths,
    duration_from_args,
    duration_source,
    write_outputs,
    writing_outputs,
)
from clearance.cli.paths import folder_lock
from clearance.model import Mechanism
from clearance.units import format_quantity

__all__ = ["add_parser", "command"]


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``reference`` to the subcommands ``sub`` (argparse's subparsers action)."""
    f = sub.add_parser("reference", help="run a scenario with the exact-geometry reference solver (slow)")
    add_scenario_args(f, numerics=False)  # MuJoCo numerics are refused (see command)
    f.add_argument(
        "--revolutions",
        type=positive(float, "--revolutions"),
        default=None,
        help="revolutions of the slowest speed-driven crank to simulate (default 1)",
    )
    f.add_argument(
        "--duration-ms",
        type=positive(float, "--duration-ms"),
        default=None,
        help="simulated time [ms] (overrides --revolutions; default: one revolution's time)",
    )
    f.add_argument(
        "--rtol",
        type=bounded(float, "--rtol", 1e-13, 1e-3, why="looser, the contact events are not resolved"),
        default=1e-9,
        help="relative tolerance, 1e-13 to 1e-3 (default 1e-9)",
    )
    f.add_argument(
        "--output-us", type=positive(float, "--output-us"), default=10.0, help="output interval [µs] (default 10)"
    )
    f.add_argument("--out", default="clearance-reference-out", help="output folder (default clearance-reference-out)")
    f.add_argument(
        "--rerun", default=None, metavar="PATH", help="also write a rerun recording (.rrd) to PATH (default: none)"
    )
    f.add_argument("--no-progress", action="store_true", help="no progress bar")
    f.set_defaults(run_command=command)


def command(args: argparse.Namespace) -> int:
    """Run ``clearance reference``; returns the exit status (2: refused or stopped by an error)."""
    given = numerics_given(args)
    if given:
        raise ValueError(
            f"clearance reference does not take {', '.join(given)}: those are MuJoCo options, and the "
            "reference solver has exact circle-in-circle geometry (no segments or geoms), applies each "
            "joint's contact law exactly (no contact mode) and takes adaptive steps (no time step); "
            "set its accuracy with --rtol and its output interval with --output-us"
        )
    out = check_output_paths(args)
    mech = mechanism_from_args(args)
    duration = duration_from_args(args, mech, 1.0)
    interval = si(args.output_us, "us")
    if interval > duration:
        raise ValueError(
            f"--output-us {args.output_us:g}: the output interval is longer than the run "
            f"({duration * 1e6:.6g} µs, {duration_source(args, 1.0)})"
        )
    check_steps(
        duration, interval, f"{duration_source(args, 1.0)} --output-us {args.output_us:g}", what="output samples"
    )
    with folder_lock(out):
        return _reference(args, mech, duration, interval, out)


def _reference(args: argparse.Namespace, mech: Mechanism, duration: float, interval: float, out: Path) -> int:
    from clearance.reference import ReferenceSolverError, run_reference

    print(
        f"{mech.name} (reference solver): clearance at {[j.name for j in mech.joints if j.has_play]}, "
        f"{format_quantity(duration, 's')}, rtol {args.rtol:g}"
    )
    progress = not args.no_progress
    failed = None
    try:
        result = run_reference(mech, duration, output_interval=interval, rtol=args.rtol, progress=progress)
    except ReferenceSolverError as err:
        failed, partial = err, getattr(err, "partial", None)
        if partial is None:
            print(f"error: {failed}", file=sys.stderr)
            return 2
        result = partial
    print(f"  ideal twin (no clearance), {format_quantity(duration, 's')}, for the deviations")
    try:
        ideal = run_reference(mech.ideal_twin(), duration, output_interval=interval, rtol=args.rtol, progress=progress)
    except ReferenceSolverError as err:
        print(f"error: the ideal twin (no clearance), needed for the deviations: {err}", file=sys.stderr)
        return 2
    with writing_outputs(out, args.rerun) as (stage, recording):
        stopped = None if failed is None else str(failed)
        write_outputs(args, mech, result, ideal, stage, recording=recording, stopped=stopped)
    rrd = None if not args.rerun else Path(args.rerun).resolve()
    wall = format_quantity(result.metadata.get("wall_time_s", float("nan")), "s")
    print(f"  wall time {wall}; wrote {out}/" + ("" if rrd is None else f" and {rrd}"))
    if failed is not None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    return 0
