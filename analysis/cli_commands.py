"""Command-line entry points of the sweeps, for wiring as ``clearance sweep`` and ``clearance rank``.

    clearance sweep   bifurcation diagram over clearance or crank speed (resumable)
    clearance rank    clearance-joint criticality ranking over a clearance x speed grid

This module is CLI glue (the top of the pipeline): it looks builders up by name in
`clearance.builders` and hands them to the sweeps as picklable factories; each catalogue
entry names its builder's drive-speed keyword and the speed range swept by default. Units
on the command line are mm and rpm; they are converted to SI here, once. The mechanism
is built once from the first point before any point is launched, so an argument its
builder rejects is a usage error (exit 2), not a sweep of error rows.
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

_JOINT_PARTS = ("ex", "ey", "vx", "vy", "e", "force")
"""Parts of a clearance joint that `chaos.quantity_series` samples (``<joint>.<part>``)."""


def _entry(name: str):
    from clearance.builders import CATALOGUE

    if name not in CATALOGUE:
        raise SystemExit(f"error: unknown mechanism {name!r}; choose one of {sorted(CATALOGUE)}")
    return CATALOGUE[name]


def _usage(message: str) -> int:
    print(f"error: {message}", file=sys.stderr)
    return 2


class _UsageError(Exception):
    """A command-line argument the mechanism's builder rejects."""


def _probe(make, point: dict, mechanism: str):
    """Build the mechanism of one point up front, so a wrong argument is a usage error, not N error rows."""
    try:
        return make(point)
    except TypeError as err:
        raise _UsageError(f"--mechanism {mechanism}: its builder does not take the arguments of this command "
                          f"({err})") from None
    except ValueError as err:
        raise _UsageError(f"--mechanism {mechanism} at {point}: {err}") from None


def _common(p: argparse.ArgumentParser, command: str) -> None:
    p.add_argument("--mechanism", default="slider_crank", help="catalogue mechanism (default slider_crank)")
    p.add_argument("--timestep-us", type=positive(float, "--timestep-us"), default=5.0, help="time step [µs] (default 5)")
    p.add_argument("--segments", type=int, default=None, help="bearing segments N (default: ripple rule)")
    p.add_argument("--out", default=None,
                   help=f"output folder (default clearance-{command}-<mechanism>); rerun to resume")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="Dask scheduler address (default: local processes)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: CPU count)")
    p.add_argument("--stop-after", type=int, default=None, help="stop after this many points (resume later)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def _out(args, command: str) -> Path:
    return Path(args.out or f"clearance-{command}-{args.mechanism}")


def _options(args):
    from clearance.options import ModelOptions

    return ModelOptions(timestep=args.timestep_us * 1e-6, segments=args.segments)


def _failures(failed: int, total: int, first: str, out: Path) -> int:
    print(f"error: {failed} of {total} points failed (first: {first}); their rows have status 'error' in "
          f"{out / 'sweep.csv'} and {out / 'points'}", file=sys.stderr)
    return 1


def _quantities(mechanism) -> list[str]:
    """Names `chaos.quantity_series` accepts for a mechanism's runs."""
    names = [f"{o.name}{s}" for o in mechanism.outputs for s in ("", "_vel", "_acc")]
    return names + [f"{j.name}.{part}" for j in mechanism.clearance_joints for part in _JOINT_PARTS]


def sweep_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance sweep``."""
    p = argparse.ArgumentParser(prog="clearance sweep", description="Bifurcation diagram over clearance or crank speed.")
    p.add_argument("--parameter", choices=["clearance", "speed"], default="clearance", help="swept parameter")
    p.add_argument("--start", type=positive(float, "--start"), default=None,
                   help="first value [mm or rpm] (default 0.01 mm / the catalogue's low speed: 1000 rpm, press 30 rpm)")
    p.add_argument("--stop", type=positive(float, "--stop"), default=None,
                   help="last value [mm or rpm] (default 1 mm / the catalogue's high speed: 5000 rpm, press 90 rpm)")
    p.add_argument("--points", type=int, default=200, help="number of values (default 200)")
    p.add_argument("--log", action="store_true", help="logarithmic spacing")
    p.add_argument("--clearance-mm", type=positive(float, "--clearance-mm"), default=0.5, help="clearance when sweeping speed [mm]")
    p.add_argument("--rpm", type=positive(float, "--rpm"), default=None,
                   help="drive speed when sweeping clearance [rpm] (default the catalogue's high speed)")
    p.add_argument("--quantity", default=None, help="sampled quantity (default <first clearance joint>.ex)")
    p.add_argument("--periods", type=int, default=60, help="drive periods per point (default 60)")
    p.add_argument("--sampled", type=int, default=40, help="last periods sampled (default 40)")
    p.add_argument("--clearance-at", nargs="*", default=None, metavar="JOINT",
                   help="joints with clearance (default: the builder's default)")
    _common(p, "sweep")
    return p


def main_sweep(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance sweep``; writes the sweep folder, ``bifurcation.png``; returns the exit code.

    Exit codes: 0 every point ran, 1 a point failed (its row has status ``error``), 2 a
    usage error, 3 stopped before the last point (rerun to resume).
    """
    import numpy as np

    from clearance.analysis.bifurcation import run_bifurcation
    from clearance.analysis.figures import plot_bifurcation
    from clearance.analysis.sweep import KeywordFactory

    args = sweep_parser().parse_args(argv)
    entry = _entry(args.mechanism)
    fixed = {} if args.clearance_at is None else {"clearance_at": tuple(args.clearance_at)}
    if args.parameter == "clearance":
        lo, hi, key = (args.start or 0.01) * 1e-3, (args.stop or 1.0) * 1e-3, "radial_clearance"
        fixed[entry.speed_keyword] = entry.speed_range[1] if args.rpm is None else args.rpm * _RPM
    else:
        key = entry.speed_keyword
        lo = entry.speed_range[0] if args.start is None else args.start * _RPM
        hi = entry.speed_range[1] if args.stop is None else args.stop * _RPM
        fixed["radial_clearance"] = args.clearance_mm * 1e-3
    if args.points < 1:
        return _usage(f"--points must be at least 1 (got {args.points})")
    values = (np.geomspace if args.log else np.linspace)(lo, hi, args.points)
    make = KeywordFactory(entry.builder, fixed=fixed)
    try:
        probe = _probe(make, {key: float(values[0])}, args.mechanism)
    except _UsageError as err:
        return _usage(str(err))
    valid = _quantities(probe)
    quantity = args.quantity
    if quantity is None:
        if not probe.clearance_joints:
            return _usage("the mechanism has no clearance joint; give --clearance-at or --quantity")
        quantity = f"{probe.clearance_joints[0].name}.ex"
    elif quantity not in valid:
        return _usage(f"--quantity {quantity!r} is not a quantity of {args.mechanism}; choose one of {valid}")
    out = _out(args, "sweep")
    try:
        diagram = run_bifurcation(
            values, make, out_dir=out, parameter=key, quantity=quantity, periods=args.periods,
            sampled=args.sampled, options=_options(args), scheduler_address=args.scheduler,
            progress=not args.no_progress, stop_after=args.stop_after, max_workers=args.workers,
        )
    except ValueError as err:
        return _usage(str(err))
    png = out / "bifurcation.png"
    plot_bifurcation(diagram, path=png)
    counts = {r: diagram.regimes.count(r) for r in dict.fromkeys(diagram.regimes)}
    print(f"{len(diagram.values)}/{args.points} points in {out}; regimes {counts}; figure {png}")
    errors = [e for r, e in zip(diagram.regimes, diagram.errors) if r == "error"]
    if errors:
        return _failures(len(errors), len(diagram.values), errors[0], out)
    return 0 if len(diagram.values) == args.points else 3


def rank_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance rank``."""
    p = argparse.ArgumentParser(prog="clearance rank", description="Rank clearance joints by output deviation.")
    p.add_argument("--clearances-mm", type=positive(float, "--clearances-mm"), nargs="+", default=[0.1, 0.5], help="clearances [mm]")
    p.add_argument("--rpm", type=positive(float, "--rpm"), nargs="+", default=None,
                   help="drive speeds [rpm] (default the catalogue's low speed and the middle of its range: "
                   "1000 and 3000 rpm, press 30 and 60 rpm)")
    p.add_argument("--joints", nargs="*", default=None, help="joints (default: all but driven/output ground pivots)")
    p.add_argument("--periods", type=int, default=6, help="drive periods per run (default 6; the first is skipped)")
    _common(p, "rank")
    return p


def main_rank(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance rank``; writes ``ranking.md`` and ``criticality.png``; returns the exit code.

    Exit codes: 0 every point ran, 1 a point failed (the ranking, if any, uses the others),
    2 a usage error.
    """
    from clearance.analysis.criticality import (
        ClearanceAtJoint,
        NothingToRankError,
        ranking_markdown,
        run_criticality,
    )
    from clearance.analysis.figures import plot_criticality
    from clearance.results import atomic_write_text

    args = rank_parser().parse_args(argv)
    entry = _entry(args.mechanism)
    clearable = entry.info.clearable
    if args.joints is not None:
        unknown = [j for j in args.joints if j not in clearable]
        if unknown or not args.joints:
            return _usage(f"--joints {args.joints} must name joints of {args.mechanism} that can carry a clearance: "
                          f"{list(clearable)}")
    lo, hi = entry.speed_range
    speeds = [lo, 0.5 * (lo + hi)] if args.rpm is None else [r * _RPM for r in args.rpm]
    clearances = [c * 1e-3 for c in args.clearances_mm]
    make = ClearanceAtJoint(entry.builder, speed_key=entry.speed_keyword)
    try:
        _probe(make, {"joint": args.joints[0] if args.joints else None, "clearance": clearances[0],
                      "speed": speeds[0]}, args.mechanism)
    except _UsageError as err:
        return _usage(str(err))
    out = _out(args, "rank")
    try:
        ranking = run_criticality(
            make, clearances=clearances, speeds=speeds, joints=args.joints, out_dir=out, periods=args.periods,
            options=_options(args), scheduler_address=args.scheduler, progress=not args.no_progress,
            stop_after=args.stop_after, max_workers=args.workers,
        )
    except NothingToRankError as err:
        return _failures(len(err.failed), len(err.failed), err.failed[0][1] if err.failed else "", out)
    except ValueError as err:
        return _usage(str(err))
    table = ranking_markdown(ranking)
    atomic_write_text(out / "ranking.md", "# Clearance-joint criticality\n\n" + table)
    plot_criticality(ranking, path=out / "criticality.png")
    print(table)
    if ranking.failed:
        total = len(ranking.failed) + len(ranking.cells)
        return _failures(len(ranking.failed), total, ranking.failed[0][1], out)
    return 0
