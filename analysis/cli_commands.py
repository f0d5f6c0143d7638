"""Command-line entry points of the sweeps, for wiring as ``clearance sweep`` and ``clearance rank``.

    clearance sweep   bifurcation diagram over clearance or crank speed (resumable)
    clearance rank    clearance-joint criticality ranking over a clearance x speed grid

This module is CLI glue (the top of the pipeline): it looks builders up by name in
`clearance.builders` and hands them to the sweeps as picklable factories. Units on the
command line are mm and rpm; they are converted to SI here, once.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path

from clearance.cli_options import positive

__all__ = ["main_rank", "main_sweep", "rank_parser", "sweep_parser"]

_RPM = 2 * math.pi / 60


def _builder(name: str):
    from clearance.builders import CATALOGUE

    if name not in CATALOGUE:
        raise SystemExit(f"error: unknown mechanism {name!r}; choose one of {sorted(CATALOGUE)}")
    return CATALOGUE[name].builder


def _common(p: argparse.ArgumentParser, out: str) -> None:
    p.add_argument("--mechanism", default="slider_crank", help="catalogue mechanism (default slider_crank)")
    p.add_argument("--timestep-us", type=positive(float, "--timestep-us"), default=5.0, help="time step [µs] (default 5)")
    p.add_argument("--segments", type=int, default=None, help="bearing segments N (default: ripple rule)")
    p.add_argument("--out", default=out, help=f"output folder (default {out}); rerun to resume")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="Dask scheduler address (default: local processes)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: CPU count)")
    p.add_argument("--stop-after", type=int, default=None, help="stop after this many points (resume later)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def _options(args):
    from clearance.options import ModelOptions

    return ModelOptions(timestep=args.timestep_us * 1e-6, segments=args.segments)


def sweep_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance sweep``."""
    p = argparse.ArgumentParser(prog="clearance sweep", description="Bifurcation diagram over clearance or crank speed.")
    p.add_argument("--parameter", choices=["clearance", "speed"], default="clearance", help="swept parameter")
    p.add_argument("--start", type=positive(float, "--start"), default=None, help="first value [mm or rpm] (default 0.01 mm / 1000 rpm)")
    p.add_argument("--stop", type=positive(float, "--stop"), default=None, help="last value [mm or rpm] (default 1 mm / 5000 rpm)")
    p.add_argument("--points", type=int, default=200, help="number of values (default 200)")
    p.add_argument("--log", action="store_true", help="logarithmic spacing")
    p.add_argument("--clearance-mm", type=positive(float, "--clearance-mm"), default=0.5, help="clearance when sweeping speed [mm]")
    p.add_argument("--rpm", type=positive(float, "--rpm"), default=5000.0, help="crank speed when sweeping clearance [rpm]")
    p.add_argument("--quantity", default=None, help="sampled quantity (default <first clearance joint>.ex)")
    p.add_argument("--periods", type=int, default=60, help="drive periods per point (default 60)")
    p.add_argument("--sampled", type=int, default=40, help="last periods sampled (default 40)")
    p.add_argument("--clearance-at", nargs="*", default=None, metavar="JOINT",
                   help="joints with clearance (default: the builder's default)")
    _common(p, "clearance-sweep")
    return p


def main_sweep(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance sweep``; writes the sweep folder, ``bifurcation.png``; returns the exit code."""
    import numpy as np

    from clearance.analysis.bifurcation import run_bifurcation
    from clearance.analysis.figures import plot_bifurcation
    from clearance.analysis.sweep import KeywordFactory

    args = sweep_parser().parse_args(argv)
    builder = _builder(args.mechanism)
    fixed = {} if args.clearance_at is None else {"clearance_at": tuple(args.clearance_at)}
    if args.parameter == "clearance":
        lo, hi, scale, key = args.start or 0.01, args.stop or 1.0, 1e-3, "radial_clearance"
        fixed["crank_speed"] = args.rpm * _RPM
    else:
        lo, hi, scale, key = args.start or 1000.0, args.stop or 5000.0, _RPM, "crank_speed"
        fixed["radial_clearance"] = args.clearance_mm * 1e-3
    values = (np.geomspace if args.log else np.linspace)(lo, hi, args.points) * scale
    make = KeywordFactory(builder, fixed=fixed)
    quantity = args.quantity
    if quantity is None:
        probe = make({key: float(values[0])})
        if not probe.clearance_joints:
            raise SystemExit("error: the mechanism has no clearance joint; give --clearance-at or --quantity")
        quantity = f"{probe.clearance_joints[0].name}.ex"
    try:
        diagram = run_bifurcation(
            values, make, out_dir=args.out, parameter=key, quantity=quantity, periods=args.periods,
            sampled=args.sampled, options=_options(args), scheduler_address=args.scheduler,
            progress=not args.no_progress, stop_after=args.stop_after, max_workers=args.workers,
        )
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    png = Path(args.out) / "bifurcation.png"
    plot_bifurcation(diagram, path=png)
    counts = {r: diagram.regimes.count(r) for r in dict.fromkeys(diagram.regimes)}
    print(f"{len(diagram.values)}/{args.points} points in {args.out}; regimes {counts}; figure {png}")
    return 0 if len(diagram.values) == args.points else 3


def rank_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance rank``."""
    p = argparse.ArgumentParser(prog="clearance rank", description="Rank clearance joints by output deviation.")
    p.add_argument("--clearances-mm", type=positive(float, "--clearances-mm"), nargs="+", default=[0.1, 0.5], help="clearances [mm]")
    p.add_argument("--rpm", type=positive(float, "--rpm"), nargs="+", default=[1000.0, 3000.0], help="crank speeds [rpm]")
    p.add_argument("--joints", nargs="*", default=None, help="joints (default: all but driven/output ground pivots)")
    p.add_argument("--periods", type=int, default=6, help="drive periods per run (default 6; the first is skipped)")
    _common(p, "clearance-rank")
    return p


def main_rank(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance rank``; writes ``ranking.md`` and ``criticality.png``; returns the exit code."""
    from clearance.analysis.criticality import ClearanceAtJoint, ranking_markdown, run_criticality
    from clearance.analysis.figures import plot_criticality
    from clearance.results import atomic_write_text

    args = rank_parser().parse_args(argv)
    make = ClearanceAtJoint(_builder(args.mechanism))
    try:
        ranking = run_criticality(
            make, clearances=[c * 1e-3 for c in args.clearances_mm], speeds=[r * _RPM for r in args.rpm],
            joints=args.joints, out_dir=args.out, periods=args.periods, options=_options(args),
            scheduler_address=args.scheduler, progress=not args.no_progress, stop_after=args.stop_after,
            max_workers=args.workers,
        )
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    out = Path(args.out)
    table = ranking_markdown(ranking)
    atomic_write_text(out / "ranking.md", "# Clearance-joint criticality\n\n" + table)
    plot_criticality(ranking, path=out / "criticality.png")
    print(table)
    return 0
