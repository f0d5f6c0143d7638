"""``clearance rank``: joint criticality ranking over a clearance x speed grid (resumable).

It looks builders up by name in `clearance.builders` and hands them to the sweeps as
picklable factories; each catalogue entry names its builder's drive-speed keyword and the
speed range swept by default.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from clearance.cli.options import add_sweep_args, bounded, positive, rpm_option, si, sweep_options, sweep_out
from clearance.cli.parser import CommandParser
from clearance.cli.paths import check_folder, folder_lock, staged_outputs
from clearance.cli.sweep_common import (
    UsageError,
    catalogue_entry,
    check_scheduler,
    interrupted,
    probe,
    report_failures,
    stopped,
    usage_error,
)

__all__ = ["main_rank", "rank_parser"]


def rank_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance rank``."""
    p = CommandParser(prog="clearance rank", description="Rank clearance joints by output deviation.")
    p.add_argument(
        "--clearances-mm",
        type=positive(float, "--clearances-mm"),
        nargs="+",
        default=[0.1, 0.5],
        help="clearances [mm] (default 0.1 0.5)",
    )
    p.add_argument(
        "--rpm",
        type=rpm_option("--rpm"),
        nargs="+",
        default=None,
        help="drive speeds [rpm] (default the catalogue's low speed and the middle of its range: "
        "1000 and 3000 rpm, press 30 and 60 rpm)",
    )
    p.add_argument(
        "--joints",
        nargs="*",
        default=None,
        help="joints, a slider's prismatic joint among them (its play in its guide at the same c) "
        "(default: the revolute joints but the driven and output ground pivots, and every slider)",
    )
    p.add_argument(
        "--periods",
        type=bounded(int, "--periods", 3, why=""),
        default=6,
        help="drive periods per run, at least 3 (default 6; the first is skipped)",
    )
    p.add_argument(
        "--model",
        metavar="MODEL.xml",
        default=None,
        help="rank the hinges of a MuJoCo model (a robot) by what radial play or backlash at each costs its end "
        "effector, instead of a catalogue mechanism's joints (default: none, the catalogue's --mechanism; see "
        "clearance rank --model M --help)",
    )
    add_sweep_args(p, "rank")
    return p


def main_rank(argv: Sequence[str] | None = None) -> int:
    """Run ``clearance rank``; writes ``ranking.md`` and ``criticality.png``; returns the exit code.

    Exit codes: 0 every point ran, 1 a point failed (the ranking, if any, uses the others),
    2 a usage error, 3 stopped by --stop-after (rerun to resume), 130 interrupted (Ctrl-C; the
    finished points are kept).
    """
    if argv is not None and any(a == "--model" or a.startswith("--model=") for a in argv):
        from clearance.cli.rank_model import main_rank_model

        return main_rank_model(argv)
    args = rank_parser().parse_args(argv)
    try:
        out = check_folder(sweep_out(args, "rank"))
        check_scheduler(args.scheduler)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    try:
        return _rank(args, out)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    except KeyboardInterrupt:
        return interrupted(out)


def _rank(args: argparse.Namespace, out: Path) -> int:
    """The ranking of checked arguments into the checked folder ``out``; returns the exit code."""
    from clearance.analysis.figures.analysis_figures import plot_criticality
    from clearance.analysis.sweeps.criticality import (
        ClearanceAtJoint,
        NothingToRankError,
        ranking_markdown,
        run_criticality,
    )
    from clearance.analysis.sweeps.executor import SchedulerError
    from clearance.results import atomic_write_text

    entry = catalogue_entry(args.mechanism)
    clearable = (*entry.info.clearable, *entry.info.sliders)  # a slider's play in its guide ranks like a hinge's
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
    options = sweep_options(args)
    joint = (args.joints or entry.info.criticality or clearable)[0]
    # every clearance and speed on its own (the bounds of clearance.cli.limits are per value)
    for c, c_mm in zip(clearances, args.clearances_mm):
        probe(
            make,
            {"joint": joint, "clearance": c, "speed": speeds[0]},
            args.mechanism,
            source=f"--mechanism {args.mechanism} --clearances-mm {c_mm:g}",
        )
    for sp in speeds:
        rpm = sp / si(1, "rpm")
        probe(
            make,
            {"joint": joint, "clearance": clearances[0], "speed": sp},
            args.mechanism,
            source=f"--mechanism {args.mechanism} --rpm {rpm:g}",
            periods=args.periods,
            timestep=options.timestep,
        )
    try:
        with folder_lock(out):
            ranking = run_criticality(
                make,
                clearances=clearances,
                speeds=speeds,
                joints=args.joints,
                sliders=True,  # a slider's play in its guide is a candidate like a hinge's
                out_dir=out,
                periods=args.periods,
                options=options,
                scheduler_address=args.scheduler,
                progress=not args.no_progress,
                stop_after=args.stop_after,
                max_workers=args.workers,
            )
            if not ranking.complete:  # stopped by --stop-after: no ranking of a part
                done = len(list((out / "points").glob("point_*.json")))
                return stopped(
                    args.stop_after, f"{done} points", out / "points", "ranking.md and criticality.png are written"
                )
            table = ranking_markdown(ranking)
            with staged_outputs(out) as stage:  # both files, or neither
                atomic_write_text(stage / "ranking.md", "# Clearance-joint criticality\n\n" + table)
                plot_criticality(ranking, path=stage / "criticality.png")
    except NothingToRankError as err:
        return report_failures(len(err.failed), len(err.failed), err.failed[0][1] if err.failed else "", out)
    except SchedulerError as err:
        return usage_error(f"--scheduler {args.scheduler}: {err}")
    print(table)
    if ranking.failed:
        total = len(ranking.failed) + len(ranking.cells)
        return report_failures(len(ranking.failed), total, ranking.failed[0][1], out)
    return 0
