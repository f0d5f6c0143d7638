"""``clearance sweep``: bifurcation diagram over clearance or drive speed (resumable).

It looks builders up by name in `clearance.builders` and hands them to the sweeps as
picklable factories; each catalogue entry names its builder's drive-speed keyword and the
speed range swept by default.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from clearance.cli.limits import MAX_POINTS
from clearance.cli.options import (
    add_clearance_mm,
    add_sweep_args,
    bounded,
    check_clearance_at,
    positive,
    rpm_option,
    si,
    sweep_options,
    sweep_out,
)
from clearance.cli.parser import CommandParser
from clearance.cli.paths import check_folder, folder_lock, staged_outputs
from clearance.cli.sweep_common import (
    UsageError,
    catalogue_entry,
    check_scheduler,
    interrupted,
    probe,
    quantities,
    report_failures,
    stopped,
    usage_error,
)

__all__ = ["main_sweep", "sweep_parser"]


def sweep_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance sweep``."""
    p = CommandParser(prog="clearance sweep", description="Bifurcation diagram over clearance or crank speed.")
    p.add_argument(
        "--parameter",
        choices=["clearance", "speed"],
        default="clearance",
        help="swept parameter: the radial clearance of every clearance joint, or the drive speed (default clearance)",
    )
    p.add_argument(
        "--start",
        type=positive(float, "--start"),
        default=None,
        help="first value [mm or rpm] (default 0.01 mm / the catalogue's low speed: 1000 rpm, press 30 rpm)",
    )
    p.add_argument(
        "--stop",
        type=positive(float, "--stop"),
        default=None,
        help="last value [mm or rpm] (default 1 mm / the catalogue's high speed: 5000 rpm, press 90 rpm)",
    )
    p.add_argument(
        "--points",
        type=bounded(int, "--points", 1, MAX_POINTS, why="a sweep's points are all listed in its manifest"),
        default=200,
        help=f"number of values, 1 to {MAX_POINTS:,} (default 200)",
    )
    p.add_argument("--log", action="store_true", help="logarithmic spacing")
    add_clearance_mm(p, what="when sweeping speed")
    p.add_argument(
        "--rpm",
        type=rpm_option("--rpm"),
        default=None,
        help="drive speed when sweeping clearance [rpm] (default the catalogue's high speed)",
    )
    p.add_argument(
        "--quantity",
        default=None,
        help="sampled quantity (default <first clearance joint>.ex, or <slider>.n: a slider's place across its guide)",
    )
    p.add_argument(
        "--periods", type=bounded(int, "--periods", 2), default=60, help="drive periods per point (default 60)"
    )
    p.add_argument(
        "--sampled",
        type=positive(int, "--sampled"),
        default=40,
        help="last periods sampled, fewer than --periods (default 40)",
    )
    p.add_argument(
        "--clearance-at",
        nargs="*",
        default=None,
        metavar="JOINT",
        help="joints with clearance (default: the builder's default)",
    )
    add_sweep_args(p, "sweep")
    return p


def main_sweep(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance sweep``; writes the sweep folder, ``bifurcation.png``; returns the exit code.

    Exit codes: 0 every point ran, 1 a point failed (its row has status ``error``), 2 a
    usage error, 3 stopped before the last point (rerun to resume), 130 interrupted (Ctrl-C;
    the finished points are kept).
    """
    p = sweep_parser()
    args = p.parse_args(argv)
    if not args.sampled < args.periods:
        p.error(f"--sampled {args.sampled} must be below --periods {args.periods} (the first periods are transient)")
    if args.start is not None and args.stop is not None and args.points > 1 and not args.start < args.stop:
        p.error(
            f"--start {args.start:g} must be below --stop {args.stop:g} (each point is run on its own, so the "
            "order does not matter: swap them)"
        )
    if args.parameter == "clearance" and args.clearance_mm is not None:
        p.error("--clearance-mm sets the clearance of a sweep over speed (--parameter speed); this sweep varies it")
    if args.parameter == "speed" and args.rpm is not None:
        p.error("--rpm sets the speed of a sweep over clearance; this sweep varies it (--start, --stop)")
    try:
        out = check_folder(sweep_out(args, "sweep"))
        check_scheduler(args.scheduler)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    try:
        return _sweep(args, out)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    except KeyboardInterrupt:
        return interrupted(out)


def _sweep(args: argparse.Namespace, out: Path) -> int:
    """The sweep of checked arguments into the checked folder ``out``; returns the exit code."""
    import numpy as np

    from clearance.analysis.sweeps.executor import SchedulerError
    from clearance.analysis.sweeps.sweep import KeywordFactory

    entry = catalogue_entry(args.mechanism)
    check_clearance_at(args.clearance_at, args.mechanism, sliders=True)
    fixed: dict[str, object] = {} if args.clearance_at is None else {"clearance_at": tuple(args.clearance_at)}
    if args.parameter == "clearance":
        lo, hi, key = si(args.start or 0.01, "mm"), si(args.stop or 1.0, "mm"), "radial_clearance"
        fixed[entry.speed_keyword] = entry.speed_range[1] if args.rpm is None else si(args.rpm, "rpm")
    else:
        key = entry.speed_keyword
        lo = entry.speed_range[0] if args.start is None else si(args.start, "rpm")
        hi = entry.speed_range[1] if args.stop is None else si(args.stop, "rpm")
        if args.clearance_mm is not None:
            fixed["radial_clearance"] = si(args.clearance_mm, "mm")
    unit = "mm" if args.parameter == "clearance" else "rpm"
    if args.points > 1 and not lo < hi:  # a default start or stop against one given
        raise UsageError(
            f"--start must be below --stop: the {args.parameter} sweep would run from {lo / si(1, unit):g} to "
            f"{hi / si(1, unit):g} {unit} (give both, or swap them)"
        )
    values = (np.geomspace if args.log else np.linspace)(lo, hi, args.points)
    make = KeywordFactory(entry.builder, fixed=fixed)
    options = sweep_options(args)
    # the two ends of the range: each bound of `clearance.cli.limits` is met first at one of them
    probed, _ = (
        probe(
            make,
            {key: float(v)},
            args.mechanism,
            source=f"--mechanism {args.mechanism} --parameter {args.parameter} {flag} {v / si(1, unit):g}",
            periods=args.periods,
            timestep=options.timestep,
        )
        for flag, v in (("--start", values[0]), ("--stop", values[-1]))
    )
    valid = quantities(probed)
    quantity = args.quantity
    if quantity is None:
        if probed.clearance_joints:
            quantity = f"{probed.clearance_joints[0].name}.ex"
        elif probed.translational_joints:  # a slider's play: its position across the guide
            quantity = f"{probed.translational_joints[0].name}.n"
        else:
            return usage_error("the mechanism has no clearance joint; give --clearance-at or --quantity")
    elif quantity not in valid:
        return usage_error(f"--quantity {quantity!r} is not a quantity of {args.mechanism}; choose one of {valid}")
    from clearance.analysis.figures.analysis_figures import plot_bifurcation
    from clearance.analysis.sweeps.bifurcation import run_bifurcation

    try:
        with folder_lock(out):
            diagram = run_bifurcation(
                values,
                make,
                out_dir=out,
                parameter=key,
                quantity=quantity,
                periods=args.periods,
                sampled=args.sampled,
                options=options,
                scheduler_address=args.scheduler,
                progress=not args.no_progress,
                stop_after=args.stop_after,
                max_workers=args.workers,
            )
            if len(diagram.values) < args.points:  # stopped by --stop-after: no figure of a part
                return stopped(
                    args.stop_after, f"{len(diagram.values)} of {args.points} points", out / "points",
                    "bifurcation.png is drawn",
                )  # fmt: skip
            png = out / "bifurcation.png"
            with staged_outputs(out) as stage:  # a whole figure or none
                plot_bifurcation(diagram, path=stage / png.name)
    except SchedulerError as err:
        return usage_error(f"--scheduler {args.scheduler}: {err}")
    counts = {r: diagram.regimes.count(r) for r in dict.fromkeys(diagram.regimes)}
    print(f"{len(diagram.values)}/{args.points} points in {out}; regimes {counts}; figure {png}")
    errors = [e for r, e in zip(diagram.regimes, diagram.errors) if r == "error"]
    if errors:
        return report_failures(len(errors), len(diagram.values), errors[0], out)
    return 0
