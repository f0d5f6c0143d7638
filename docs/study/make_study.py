"""Reproduce in kind the published clearance-joint findings (docs/references.md: the press paper
of Shock and Vibration 2020 and Alok, Chaudhary and Guha 2020).

Usage (from the repository root, in the project's environment)::

    python docs/study/make_study.py [--cache build/study-cache] [--workers 2]

Runs the study's simulations and sweeps (`plan.py`), each resumable in the cache folder
(an interrupted study resumes where it stopped; a finished one only redraws), then writes
docs/study/study.md and its PNG figures (`study_report.py`). About 25 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

# the segment-count rule falls back (with a RuntimeWarning) at light joint loads; the
# study reports this once instead of once per run (workers inherit the filter)
os.environ.setdefault("PYTHONWARNINGS", "ignore:no segment count up to:RuntimeWarning")

import plan  # noqa: E402
import study_report  # noqa: E402


def _timed(stages: dict, name: str, fn, *args):
    t0 = time.perf_counter()
    print(f"[study] {name} ...", flush=True)
    out = fn(*args)
    dt = time.perf_counter() - t0
    if dt > 5.0:  # a stage that computed something (a cached one takes a second or two)
        stages.setdefault(name, []).append(round(dt, 1))
    print(f"[study] {name}: {dt:.0f} s", flush=True)
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cache", default="build/study-cache", help="folder of the resumable runs and sweeps")
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    args = p.parse_args()
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    log = cache / "timings.json"
    stages = json.loads(log.read_text()) if log.exists() else {}
    load = os.getloadavg()
    n_before = {k: len(v) for k, v in stages.items() if isinstance(v, list)}
    store = _timed(stages, "press runs", plan.run_press, cache, args.workers)
    diagrams = _timed(stages, "press bifurcation diagrams", plan.run_press_bifurcations, cache, args.workers)
    crit = _timed(stages, "criticality sweeps", plan.run_criticalities, cache, args.workers)
    if any(isinstance(v, list) and len(v) > n_before.get(n, 0) for n, v in stages.items()):  # this call computed
        stages["_machine"] = (
            f"{platform.machine()}, {os.cpu_count()} cores, {args.workers} workers; load average "
            f"{load[0]:.1f} when the computation started"
        )
    log.write_text(json.dumps(stages, indent=1))
    machine = stages.pop("_machine", f"{platform.machine()}, {os.cpu_count()} cores")
    t0 = time.perf_counter()
    study_report.write_study(HERE, store, diagrams, crit, stages=stages, machine=machine)
    print(f"[study] figures and study.md: {time.perf_counter() - t0:.0f} s -> {HERE / 'study.md'}")


if __name__ == "__main__":
    main()
