"""Speed against error of MuJoCo settings against the reference solver (``clearance bench``).

    python benchmarks/speed_error.py                      # everything (resumable; hours on 2 cores)
    python benchmarks/speed_error.py --stage accuracy     # only the long accuracy runs (parallel)
    python benchmarks/speed_error.py --stage timing       # only the timing runs (one at a time)

Runs ``clearance bench`` into build/bench (resumable: a rerun skips finished runs), then
copies the generated table and figure to benchmarks/speed_error_table.md and
benchmarks/speed_error.png. The reading of the results (benchmarks/speed_error.md) is
written by hand from that table.

The accuracy stage needs no quiet machine (it measures errors, not time) and can run on
any number of cores; the timing stage runs one run at a time and should run on the
machine whose speed is reported, with nothing else running.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from clearance.cli.bench import main_bench

HERE = Path(__file__).resolve().parent


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--out", default="build/bench", help="bench folder (default build/bench, run from the repository root)"
    )
    ap.add_argument("--stage", choices=("all", "accuracy", "timing", "report"), default="all")
    ap.add_argument("--workers", type=int, default=None)
    args = ap.parse_args()
    argv = ["--out", args.out, "--stage", args.stage] + (["--workers", str(args.workers)] if args.workers else [])
    rc = main_bench(argv)
    if rc == 0 and args.stage in ("all", "report"):
        out = Path(args.out)
        shutil.copyfile(out / "speed_error.md", HERE / "speed_error_table.md")
        shutil.copyfile(out / "speed_error.png", HERE / "speed_error.png")
        print(f"copied to {HERE / 'speed_error_table.md'} and {HERE / 'speed_error.png'}")
    return rc


if __name__ == "__main__":
    sys.exit(main())
