"""``clearance bench``: speed against error of MuJoCo settings, against the reference solver.

clearance bench                       full benchmark into clearance-bench/ (hours on 2 cores; resumable)
clearance bench --quick               a small grid and short runs (minutes)
clearance bench --stage report        only rebuild the table and figure from the files
"""

from __future__ import annotations

import argparse
import dataclasses
import fnmatch
import sys
from collections.abc import Sequence

from clearance.bench.scenarios import default_scenarios, write_report
from clearance.bench.speed_error import run_speed_error
from clearance.cli.parser import CommandParser
from clearance.cli.paths import FolderBusyError, check_folder, folder_lock
from clearance.cli.sweep_common import INTERRUPTED

__all__ = ["bench_parser", "main_bench"]


def bench_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance bench``."""
    p = CommandParser(
        prog="clearance bench",
        description="Speed against error of MuJoCo settings (time step, segments, geoms, contact mode) against "
        "the reference solver on four scenarios; a table, the Pareto front and a figure (resumable; --quick: a "
        "small grid in minutes).",
    )
    p.add_argument("--out", default="clearance-bench", help="output folder (default clearance-bench); rerun to resume")
    p.add_argument("--quick", action="store_true", help="small grid and short runs (minutes)")
    p.add_argument("--scenarios", nargs="*", default=None, metavar="NAME", help="scenarios to run (default all)")
    p.add_argument(
        "--stage",
        choices=("all", "accuracy", "timing", "report"),
        default="all",
        help="accuracy runs (parallel), timing runs (one at a time), report, or all (default)",
    )
    p.add_argument(
        "--settings",
        nargs="+",
        default=None,
        metavar="PATTERN",
        help="only the settings whose key matches one of these shell patterns (e.g. 'exact_*' "
        "'calibrated_h2us_Nrule_*'; keys as in the output folder's file names; default: every setting); the "
        "reference always runs",
    )
    p.add_argument("--workers", type=int, default=None, help="processes for the accuracy runs (default: CPU count)")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    return p


def _matches(key: str, patterns: Sequence[str]) -> bool:
    return any(fnmatch.fnmatchcase(key, p) for p in patterns)


def main_bench(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``clearance bench``.

    Exit codes: 0 done, 2 a usage error (or no runs to report), 130 interrupted (Ctrl-C;
    the finished runs are kept).
    """
    args = bench_parser().parse_args(argv)
    if args.workers is not None and args.workers < 1:
        print(f"error: --workers must be >= 1 (got {args.workers})", file=sys.stderr)
        return 2
    try:
        out = check_folder(args.out, "--out")
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    scenarios = default_scenarios(args.quick)
    if args.scenarios:
        known = {s.name for s in scenarios}
        unknown = sorted(set(args.scenarios) - known)
        if unknown:
            print(f"error: unknown scenario(s) {unknown}; choose from {sorted(known)}", file=sys.stderr)
            return 2
        scenarios = [s for s in scenarios if s.name in args.scenarios]
    if args.settings:
        scenarios = [
            dataclasses.replace(s, settings=tuple(st for st in s.settings if _matches(st.key, args.settings)))
            for s in scenarios
        ]
        if not any(s.settings for s in scenarios):
            print(f"error: --settings {' '.join(args.settings)} matches no setting", file=sys.stderr)
            return 2
    stages = {"all": ("accuracy", "timing"), "report": ()}.get(args.stage, (args.stage,))
    try:
        with folder_lock(out):
            run_speed_error(scenarios, out, stages=stages, max_workers=args.workers, progress=not args.no_progress)
            if args.stage in ("all", "report"):
                path = write_report(scenarios, out, command="clearance bench " + " ".join(argv or sys.argv[2:]))
                print(f"wrote {path} and {path.with_suffix('.png')}")
    except FileNotFoundError as err:  # the report of runs that are not there
        print(f"error: {err}", file=sys.stderr)
        return 2
    except FolderBusyError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"interrupted; the finished runs are kept in {out}, rerun to resume", file=sys.stderr)
        return INTERRUPTED
    return 0
