"""Wall time of the clearance-joint criticality ranking of the Watt six-bar.

    python benchmarks/criticality_speed.py --timestep-us 5 --out /tmp/crit5

Watt six-bar of the catalogue (``watt_six_bar``), clearance at one joint at a time over
every candidate joint (`criticality_candidates`: all revolute joints but the driven
crank's and the output rocker's ground pivots), 3 radial clearances x 3 crank speeds,
ranked by `run_criticality` (the logic of ``clearance rank``) with the local spawn process
pool. Prints the wall time, the per-point times by speed, where the time goes (model
preparation, stepping, ideal twin, analysis; from each point's measured ``timing``), the
machine load, and writes ``ranking.md`` and ``criticality.png`` into the sweep folder.
Delete --out to measure from scratch (a rerun resumes and skips finished points).
``--compare DIR_A DIR_B`` compares two finished sweeps (scores and per-cell deviations).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from clearance.analysis.figures.analysis_figures import plot_criticality
from clearance.analysis.sweeps.criticality import (
    ClearanceAtJoint,
    rank_joints,
    ranking_markdown,
    run_criticality,
)
from clearance.analysis.sweeps.sweep import load_rows
from clearance.builders import rpm, watt_six_bar
from clearance.options import ContactMode, ModelOptions
from clearance.results import atomic_write_text


def breakdown(rows: list[dict], wall: float, workers: int) -> dict:
    """Seconds spent per stage, summed over points, and per-speed point times."""
    t = [r["timing"] for r in rows]
    step = sum(x.get("stepping_s") or 0.0 for x in t)
    prep = sum((x.get("simulate_s") or 0.0) - (x.get("stepping_s") or 0.0) for x in t)
    ideal = sum(x.get("ideal_s") or 0.0 for x in t)
    evaluate = sum(x.get("evaluate_s") or 0.0 for x in t)
    busy = sum(x["wall_time_s"] for x in t)
    per_speed = {}
    for s in sorted({r["point"]["speed"] for r in rows}):
        w = [r["timing"]["wall_time_s"] for r in rows if r["point"]["speed"] == s]
        per_speed[f"{s * 30 / np.pi:.0f} rpm"] = {
            "points": len(w),
            "median_s": round(statistics.median(w), 2),
            "max_s": round(max(w), 2),
            "sum_s": round(sum(w), 1),
        }
    return {
        "worker_seconds": round(busy, 1),
        "preparation_s": round(prep, 1),
        "stepping_s": round(step, 1),
        "ideal_twin_s": round(ideal, 1),
        "ideal_runs": sum(1 for x in t if x.get("ideal_reused") is False),
        "analysis_s": round(evaluate, 1),
        "other_in_points_s": round(busy - prep - step - ideal - evaluate, 1),
        "pool_and_io_s": round(wall * workers - busy, 1),
        "per_speed": per_speed,
    }


def compare(dir_a: str, dir_b: str) -> None:
    """Print the two rankings side by side and the per-cell mean deviations."""
    out = watt_six_bar().outputs[0]  # the rocker angle: scores in rad/m
    ra, rb = (rank_joints(load_rows(d), output=out.name, output_kind=out.kind) for d in (dir_a, dir_b))
    sb = {s.joint: s for s in rb.scores}
    print("| joint | rank A | rank B | score A [rad/m] | 95 % interval A | score B [rad/m] | 95 % interval B | B/A |")
    print("|---|---:|---:|---:|---|---:|---|---:|")
    for a in ra.scores:
        b = sb.get(a.joint)
        if b is None:
            continue
        print(
            f"| {a.joint} | {a.rank} | {b.rank} | {a.score:.3f} | [{a.ci_low:.3f}, {a.ci_high:.3f}] | {b.score:.3f} "
            f"| [{b.ci_low:.3f}, {b.ci_high:.3f}] | {b.score / a.score:.3f} |"
        )
    cb = {(c.joint, c.clearance, c.speed): c for c in rb.cells}
    ratios, within = [], 0
    print(
        "\n| joint | c [mm] | speed [rpm] | mean dev. A [mrad] | s.e. A | mean dev. B [mrad] | s.e. B | B/A | rank A | rank B |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for c in ra.cells:
        d = cb.get((c.joint, c.clearance, c.speed))
        if d is None:
            continue
        ratios.append(d.mean_deviation / c.mean_deviation)
        within += abs(d.mean_deviation - c.mean_deviation) <= 2 * np.hypot(c.sem, d.sem)
        print(
            f"| {c.joint} | {c.clearance * 1e3:g} | {c.speed * 30 / np.pi:.0f} | {c.mean_deviation * 1e3:.4f} "
            f"| {c.sem * 1e3:.2g} | {d.mean_deviation * 1e3:.4f} | {d.sem * 1e3:.2g} | {ratios[-1]:.3f} | {c.rank} "
            f"| {d.rank} |"
        )
    print(
        f"\n{len(ratios)} common cells; mean deviation ratio B/A median {np.median(ratios):.3f}, range "
        f"{min(ratios):.3f}-{max(ratios):.3f}; within 2 combined standard errors at {within}/{len(ratios)} cells"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--timestep-us", type=float, default=5.0)
    p.add_argument("--clearances-mm", type=float, nargs="+", default=[0.02, 0.1, 0.5])
    p.add_argument("--rpm", type=float, nargs="+", default=[100.0, 1000.0, 3000.0])
    p.add_argument("--joints", nargs="*", default=None, help="default: every candidate joint")
    p.add_argument("--periods", type=int, default=6)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument(
        "--contact-mode",
        choices=[m.value for m in ContactMode],
        default="nominal",
        help="contact mode (default nominal, the setting of the committed table)",
    )
    p.add_argument("--out", default="criticality-speed")
    p.add_argument("--compare", nargs=2, metavar=("DIR_A", "DIR_B"), help="compare two finished sweeps and exit")
    args = p.parse_args()
    if args.compare:
        compare(*args.compare)
        return
    load_before = os.getloadavg()
    t0 = time.perf_counter()
    ranking = run_criticality(
        ClearanceAtJoint(watt_six_bar),
        clearances=[c * 1e-3 for c in args.clearances_mm],
        speeds=[rpm(r) for r in args.rpm],
        joints=args.joints,
        out_dir=args.out,
        periods=args.periods,
        options=ModelOptions(timestep=args.timestep_us * 1e-6, contact_mode=ContactMode(args.contact_mode)),
        max_workers=args.workers,
    )
    wall = time.perf_counter() - t0
    load_after = os.getloadavg()
    out = Path(args.out)
    table = ranking_markdown(ranking)
    atomic_write_text(out / "ranking.md", "# Watt six-bar: clearance-joint criticality\n\n" + table)
    plot_criticality(ranking, path=out / "criticality.png")
    rows = load_rows(out)
    print(table)
    print(
        json.dumps(
            {
                "machine": f"{platform.machine()}, {os.cpu_count()} cores, {args.workers} workers",
                "load_average_1_5_15_before": [round(x, 2) for x in load_before],
                "load_average_1_5_15_after": [round(x, 2) for x in load_after],
                "points": len(rows),
                "failed": len(ranking.failed),
                "timestep_us": args.timestep_us,
                "contact_mode": args.contact_mode,
                "periods": args.periods,
                "wall_s": round(wall, 1),
                "per_point_s_median": round(statistics.median(r["timing"]["wall_time_s"] for r in rows), 2),
                **breakdown(rows, wall, args.workers),
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
