"""``clearance rank``: joint criticality ranking over a clearance x speed grid (resumable).

It looks builders up by name in `clearance.builders` and hands them to the sweeps as
picklable factories; each catalogue entry names its builder's drive-speed keyword and the
speed range swept by default.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from clearance.cli.options import add_sweep_args, positive, si, sweep_options, sweep_out
from clearance.cli.sweep_common import (
    UsageError,
    catalogue_entry,
    probe,
    report_failures,
    usage_error,
)

__all__ = ["main_rank", "rank_parser"]


def rank_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance rank``."""
    p = argparse.ArgumentParser(prog="clearance rank", description="Rank clearance joints by output deviation.")
    p.add_argument(
        "--clearances-mm",
        type=positive(float, "--clearances-mm"),
        nargs="+",
        default=[0.1, 0.5],
        help="clearances [mm]",
    )
    p.add_argument(
        "--rpm",
        type=positive(float, "--rpm"),
        nargs="+",
        default=None,
        help="drive speeds [rpm] (default the catalogue's low speed and the middle of its range: "
        "1000 and 3000 rpm, press 30 and 60 rpm)",
    )
    p.add_argument("--joints", nargs="*", default=None, help="joints (default: all but driven/output ground pivots)")
    p.add_argument("--periods", type=int, default=6, help="drive periods per run (default 6; the first is skipped)")
    add_sweep_args(p, "rank")
    return p


def main_rank(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance rank``; writes ``ranking.md`` and ``criticality.png``; returns the exit code.

    Exit codes: 0 every point ran, 1 a point failed (the ranking, if any, uses the others),
    2 a usage error.
    """
    from clearance.analysis.figures.analysis_figures import plot_criticality
    from clearance.analysis.sweeps.criticality import (
        ClearanceAtJoint,
        NothingToRankError,
        ranking_markdown,
        run_criticality,
    )
    from clearance.results import atomic_write_text

    args = rank_parser().parse_args(argv)
    entry = catalogue_entry(args.mechanism)
    clearable = entry.info.clearable
    if args.joints is not None:
        unknown = [j for j in args.joints if j not in clearable]
        if unknown or not args.joints:
            return usage_error(
                f"--joints {args.joints} must name joints of {args.mechanism} that can carry a clearance: "
                f"{list(clearable)}"
            )
    lo, hi = entry.speed_range
    speeds = [lo, 0.5 * (lo + hi)] if args.rpm is None else [si(r, "rpm") for r in args.rpm]
    clearances = [si(c, "mm") for c in args.clearances_mm]
    make = ClearanceAtJoint(entry.builder, speed_key=entry.speed_keyword)
    try:
        probe(
            make,
            {"joint": args.joints[0] if args.joints else None, "clearance": clearances[0], "speed": speeds[0]},
            args.mechanism,
        )
    except UsageError as err:
        return usage_error(str(err))
    out = sweep_out(args, "rank")
    try:
        ranking = run_criticality(
            make,
            clearances=clearances,
            speeds=speeds,
            joints=args.joints,
            out_dir=out,
            periods=args.periods,
            options=sweep_options(args),
            scheduler_address=args.scheduler,
            progress=not args.no_progress,
            stop_after=args.stop_after,
            max_workers=args.workers,
        )
    except NothingToRankError as err:
        return report_failures(len(err.failed), len(err.failed), err.failed[0][1] if err.failed else "", out)
    except ValueError as err:
        return usage_error(str(err))
    table = ranking_markdown(ranking)
    atomic_write_text(out / "ranking.md", "# Clearance-joint criticality\n\n" + table)
    plot_criticality(ranking, path=out / "criticality.png")
    print(table)
    if ranking.failed:
        total = len(ranking.failed) + len(ranking.cells)
        return report_failures(len(ranking.failed), total, ranking.failed[0][1], out)
    return 0
