"""``clearance run``: simulate a scenario in MuJoCo and write arrays, summary, report, figures, models."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from clearance.cli.limits import check_steps
from clearance.cli.options import (
    add_scenario_args,
    mechanism_from_args,
    options_from_args,
    positive,
)
from clearance.cli.outputs import (
    calibration_lines,
    check_output_paths,
    duration_from_args,
    duration_source,
    run_with_twin,
    write_outputs,
    writing_outputs,
)
from clearance.cli.paths import folder_lock
from clearance.cli.run_model import add_model_args, model_command, uses_model
from clearance.model import Mechanism
from clearance.options import ModelOptions
from clearance.units import format_quantity

__all__ = ["add_parser", "command"]


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``run`` to the subcommands ``sub`` (argparse's subparsers action)."""
    r = sub.add_parser("run", help="simulate a scenario and write results, figures and the model")
    add_scenario_args(r)
    r.add_argument(
        "--revolutions",
        type=positive(float, "--revolutions"),
        default=None,
        help="revolutions of the slowest speed-driven crank to simulate (default 3)",
    )
    r.add_argument(
        "--duration-ms",
        type=positive(float, "--duration-ms"),
        default=None,
        help="simulated time [ms] (overrides --revolutions; default: 3 revolutions' time)",
    )
    r.add_argument(
        "--out",
        default="clearance-out",
        help="output folder (default clearance-out); the files a run writes are replaced, others are left alone, "
        "and a second command writing there at the same time is refused",
    )
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument(
        "--rerun",
        default=None,
        metavar="PATH",
        help="also write a rerun recording (.rrd) of the run and its ideal twin to PATH (default: none)",
    )
    add_model_args(r)
    r.set_defaults(run_command=command)


def command(args: argparse.Namespace) -> int:
    """Run ``clearance run``; returns the exit status (2: refused or stopped by an error).

    Every option, the output folder and the recording's path are checked before any work;
    the folder is locked (`clearance.cli.paths.folder_lock`) from the preparation of the
    models to the last file written, and a run refused while preparing leaves no folder.
    """
    if uses_model(args):
        return model_command(args)
    out = check_output_paths(args)
    mech = mechanism_from_args(args)
    options = options_from_args(args)
    duration = duration_from_args(args, mech, 3.0)
    check_steps(duration, options.timestep, duration_source(args, 3.0))
    with folder_lock(out):
        return _run(args, mech, options, duration, out)


def _segments(segments: dict[str, int]) -> str:
    """A ring's segment counts for the console: ``144 segments at rod_slider``."""
    return ", ".join(f"{n} segments at {joint}" for joint, n in segments.items())


def _run(args: argparse.Namespace, mech: Mechanism, options: ModelOptions, duration: float, out: Path) -> int:
    from clearance.results import atomic_write_text
    from clearance.run.preparation import prepare
    from clearance.run.simulation import simulate_prepared

    started = time.time()
    prepared = prepare(mech, options)
    ideal_prepared = prepare(mech.ideal_twin(), options)
    print(
        f"{mech.name}: clearance at {[j.name for j in mech.joints if j.has_play]}, "
        f"{format_quantity(duration, 's')} at h = {format_quantity(options.timestep, 's')}, "
        f"{options.contact_mode.value} contact"
        + (
            ""
            if prepared.built.exact_contact or not prepared.built.rings
            else ", " + _segments(prepared.metadata["segments"])
        )
    )
    for line in calibration_lines(prepared.metadata.get("contact", {}), started):
        print(line)
    progress = not args.no_progress
    runs = run_with_twin(
        lambda: simulate_prepared(prepared, duration=duration, progress=progress),
        lambda: simulate_prepared(ideal_prepared, duration=duration, progress=progress),
        twin_name="the ideal twin (no clearance)",
    )
    if runs is None:
        return 2
    result, ideal, failed = runs
    with writing_outputs(out, args.rerun) as (stage, recording):
        atomic_write_text(stage / "model.xml", prepared.to_xml())
        atomic_write_text(stage / "ideal_model.xml", ideal_prepared.to_xml())
        stopped = None if failed is None else str(failed)
        write_outputs(args, mech, result, ideal, stage, recording=recording, stopped=stopped)
    rate = float(f"{result.metadata['steps_per_second']:.3g}")
    rrd = "" if not args.rerun else f" and {Path(args.rerun).resolve()}"
    print(f"  {rate:,.0f} steps/s; wrote {out}/{rrd}")
    if failed is not None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    return 0
