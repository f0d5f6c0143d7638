"""``clearance sweep``: bifurcation diagram over clearance or drive speed (resumable).

It looks builders up by name in `clearance.builders` and hands them to the sweeps as
picklable factories; each catalogue entry names its builder's drive-speed keyword and the
speed range swept by default.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from clearance.cli.options import add_clearance_mm, add_sweep_args, positive, si, sweep_options, sweep_out
from clearance.cli.sweep_common import (
    UsageError,
    catalogue_entry,
    probe,
    quantities,
    report_failures,
    usage_error,
)

__all__ = ["main_sweep", "sweep_parser"]


def sweep_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance sweep``."""
    p = argparse.ArgumentParser(
        prog="clearance sweep", description="Bifurcation diagram over clearance or crank speed."
    )
    p.add_argument("--parameter", choices=["clearance", "speed"], default="clearance", help="swept parameter")
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
    p.add_argument("--points", type=int, default=200, help="number of values (default 200)")
    p.add_argument("--log", action="store_true", help="logarithmic spacing")
    add_clearance_mm(p, what="when sweeping speed")
    p.add_argument(
        "--rpm",
        type=positive(float, "--rpm"),
        default=None,
        help="drive speed when sweeping clearance [rpm] (default the catalogue's high speed)",
    )
    p.add_argument("--quantity", default=None, help="sampled quantity (default <first clearance joint>.ex)")
    p.add_argument("--periods", type=int, default=60, help="drive periods per point (default 60)")
    p.add_argument("--sampled", type=int, default=40, help="last periods sampled (default 40)")
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
    usage error, 3 stopped before the last point (rerun to resume).
    """
    import numpy as np

    from clearance.analysis.figures.analysis_figures import plot_bifurcation
    from clearance.analysis.sweeps.bifurcation import run_bifurcation
    from clearance.analysis.sweeps.sweep import KeywordFactory

    args = sweep_parser().parse_args(argv)
    entry = catalogue_entry(args.mechanism)
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
    if args.points < 1:
        return usage_error(f"--points must be at least 1 (got {args.points})")
    values = (np.geomspace if args.log else np.linspace)(lo, hi, args.points)
    make = KeywordFactory(entry.builder, fixed=fixed)
    try:
        probed = probe(make, {key: float(values[0])}, args.mechanism)
    except UsageError as err:
        return usage_error(str(err))
    valid = quantities(probed)
    quantity = args.quantity
    if quantity is None:
        if not probed.clearance_joints:
            return usage_error("the mechanism has no clearance joint; give --clearance-at or --quantity")
        quantity = f"{probed.clearance_joints[0].name}.ex"
    elif quantity not in valid:
        return usage_error(f"--quantity {quantity!r} is not a quantity of {args.mechanism}; choose one of {valid}")
    out = sweep_out(args, "sweep")
    try:
        diagram = run_bifurcation(
            values,
            make,
            out_dir=out,
            parameter=key,
            quantity=quantity,
            periods=args.periods,
            sampled=args.sampled,
            options=sweep_options(args),
            scheduler_address=args.scheduler,
            progress=not args.no_progress,
            stop_after=args.stop_after,
            max_workers=args.workers,
        )
    except ValueError as err:
        return usage_error(str(err))
    png = out / "bifurcation.png"
    plot_bifurcation(diagram, path=png)
    counts = {r: diagram.regimes.count(r) for r in dict.fromkeys(diagram.regimes)}
    print(f"{len(diagram.values)}/{args.points} points in {out}; regimes {counts}; figure {png}")
    errors = [e for r, e in zip(diagram.regimes, diagram.errors) if r == "error"]
    if errors:
        return report_failures(len(errors), len(diagram.values), errors[0], out)
    return 0 if len(diagram.values) == args.points else 3
