"""Time ``clearance run`` takes after the simulation: arrays, summary, reactions, report and figures.

Usage:  python benchmarks/report_time.py [--mechanism seven_bar_press] [--revolutions 3] [--repeats 3]
                                          [--out benchmarks/report_time.md]

The run is made as ``clearance run --mechanism M --revolutions R`` makes it (the command's own
preparation and `simulate_prepared` for the run and its ideal twin, default options); then
the command's `write_outputs` writes everything that follows the simulation into a fresh
folder, ``--repeats`` times, each in a child forked right after the simulation (so each starts
from the state the command is in when its simulation ends, and none profits from another's
warm caches). The stages are timed by wrapping the functions `write_outputs` calls: the
arrays (`SimulationResult.save`, both runs), the summary, the joint reactions' summary and the
report with its figures (`write_report`, the figures drawn by two processes where there are two
CPUs). The goal: the report (summary, reactions, report and figures) in 5 s or less after the
simulation of the seven-bar press at 3 revolutions. The arrays' writing is shown on its own
line: it is disk-bound and the same whatever the figures do.

Timings on a machine shared with other work vary: the load average at the start is written
beside the table, and the CPU time of everything after the simulation (this process and the
figure child, user and system) is given too: it changes far less with the load than the wall time.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import resource
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _tables import write_keeping_reading

GOAL_S = 5.0
"""Summary, reactions and report with figures after the press's simulation, at most [s]."""

STAGES = (
    ("arrays", "clearance.results", "SimulationResult.save", "arrays (result.npz, ideal.npz)"),
    ("summary", "clearance.analysis.metrics.summary", "summarise", "summary numbers"),
    ("reactions", "clearance.analysis.metrics.reactions", "summarise_reactions", "joint reactions' summary"),
    ("report", "clearance.analysis.figures.report", "write_report", "report and figures"),
)
"""(key, module, function or Class.method, what) of each timed stage."""


def _wrap(times: dict[str, float]) -> None:
    """Replace each stage's function by one that adds its wall time to ``times[key]``."""
    import importlib

    for key, module, name, _ in STAGES:
        mod = importlib.import_module(module)
        owner: Any = mod
        attr = name
        if "." in name:
            cls, attr = name.split(".")
            owner = getattr(mod, cls)
        fn = getattr(owner, attr)

        def timed(*a: Any, _fn: Callable[..., Any] = fn, _key: str = key, **k: Any) -> Any:
            t0 = time.perf_counter()
            try:
                return _fn(*a, **k)
            finally:
                times[_key] = times.get(_key, 0.0) + time.perf_counter() - t0

        setattr(owner, attr, timed)


def _after_simulation(mech: Any, result: Any, ideal: Any) -> dict[str, float]:
    """``write_outputs`` into a fresh folder; the stages' and the total wall times [s]."""
    from clearance.cli.outputs import write_outputs

    times: dict[str, float] = {}
    _wrap(times)
    with tempfile.TemporaryDirectory() as tmp:
        t0, c0 = time.perf_counter(), _cpu()
        write_outputs(argparse.Namespace(rerun=None), mech, result, ideal, Path(tmp))
        times["total"] = time.perf_counter() - t0
        times["cpu"] = _cpu() - c0
    return times


def _cpu() -> float:
    """CPU time [s] of this process and its waited-for children (the figure child), user and system."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _in_child(mech: Any, result: Any, ideal: Any) -> dict[str, float]:
    """`_after_simulation` in a forked child (the state right after the simulation); its times."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        status = 1
        try:
            os.close(r)
            sys.stdout = open(os.devnull, "w")  # the command's console lines
            os.write(w, json.dumps(_after_simulation(mech, result, ideal)).encode())
            status = 0
        finally:
            os._exit(status)
    os.close(w)
    chunks = []
    while chunk := os.read(r, 65536):
        chunks.append(chunk)
    os.close(r)
    _, status = os.waitpid(pid, 0)
    if status != 0:
        raise SystemExit("error: the timed child failed")
    return json.loads(b"".join(chunks))


def main(argv: list[str] | None = None) -> int:
    """Simulate once, time what follows ``--repeats`` times, write the table."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--mechanism", default="seven_bar_press")
    p.add_argument("--revolutions", type=float, default=3.0)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--out", default=str(Path(__file__).with_name("report_time.md")))
    args = p.parse_args(argv)
    if not hasattr(os, "fork"):
        sys.exit("error: this benchmark forks a child per repeat (POSIX only)")

    from clearance.builders import CATALOGUE
    from clearance.options import ModelOptions
    from clearance.run.preparation import prepare
    from clearance.run.simulation import default_duration, simulate_prepared

    load = os.getloadavg()[0]
    mech = CATALOGUE[args.mechanism].builder()
    options = ModelOptions()
    duration = default_duration(mech, args.revolutions)
    t0 = time.perf_counter()
    result = simulate_prepared(prepare(mech, options), duration=duration)
    ideal = simulate_prepared(prepare(mech.ideal_twin(), options), duration=duration)
    sim = time.perf_counter() - t0
    print(f"simulated {len(result.times):,} rows per run in {sim:.1f} s", flush=True)
    runs = []
    for k in range(args.repeats):
        runs.append(_in_child(mech, result, ideal))
        print(f"repeat {k + 1}: " + ", ".join(f"{key} {v:.2f} s" for key, v in runs[-1].items()), flush=True)

    def med(key: str) -> float:
        return statistics.median(r.get(key, 0.0) for r in runs)

    def spread(key: str) -> str:
        vals = [r.get(key, 0.0) for r in runs]
        return f"{min(vals):.2f}–{max(vals):.2f}"

    report = med("summary") + med("reactions") + med("report")
    rows = [f"| {what} | {med(key):.2f} | {spread(key)} |" for key, _, _, what in STAGES]
    rows.append(f"| **summary, reactions, report and figures** | **{report:.2f}** | |")
    rows.append(f"| everything after the simulation (arrays included) | {med('total'):.2f} | {spread('total')} |")
    rows.append(
        f"| CPU time of all that, both processes (less sensitive to load) | {med('cpu'):.2f} | {spread('cpu')} |"
    )
    verdict = "met" if report <= GOAL_S else "not met"
    text = "\n".join(
        [
            f"# What `clearance run --mechanism {args.mechanism}` takes after its simulation",
            "",
            f"Generated by `python benchmarks/report_time.py --mechanism {args.mechanism} --revolutions "
            f"{args.revolutions:g} --repeats {args.repeats}` on {datetime.date.today().isoformat()}, "
            f"{platform.machine()}, {os.cpu_count()} CPUs, load average {load:.2f} at the start. "
            f"{args.revolutions:g} revolutions: {len(result.times):,} rows per run, simulated in {sim:.1f} s "
            "(both runs).",
            "",
            f"Median of {args.repeats} repeats, each in a child forked right after the simulation [s]:",
            "",
            "| stage | median | range |",
            "|---|---:|---:|",
            *rows,
            "",
            f"Goal: the report (summary, reactions, report and figures) in {GOAL_S:g} s or less: **{verdict}**.",
            "",
        ]
    )
    write_keeping_reading(args.out, text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
