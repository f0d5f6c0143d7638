"""Wall time of a bifurcation diagram over clearance for the default slider-crank.

    python benchmarks/bifurcation_speed.py --points 200 --timestep-us 5 [--contact-mode calibrated] --out /tmp/bif

Default slider-crank (clearance at rod_slider, 5000 rpm; contact mode the package default
unless given), radial clearance 0.01-1 mm
(linear spacing), 60 drive periods per point, Poincaré section of the journal eccentricity
x (bearing frame) over the last 40 periods. Runs through `run_bifurcation` with the local
spawn process pool; prints the wall time, the per-point times with the worker seconds of
each stage (preparation including any calibration fit, stepping, ideal twin, evaluation)
and the regime counts, and writes the diagram PNG into the sweep folder. Delete --out to measure from
scratch (a rerun resumes and skips finished points).
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from clearance.analysis.figures.analysis_figures import plot_bifurcation
from clearance.analysis.sweeps.bifurcation import run_bifurcation
from clearance.analysis.sweeps.sweep import KeywordFactory
from clearance.builders import slider_crank
from clearance.options import ModelOptions


def compare(dir_a: str, dir_b: str) -> None:
    """Print, per clearance present in both sweeps, regimes, peak force and section statistics."""
    from clearance.analysis.sweeps.sweep import load_rows

    rows_b = {round(r["point"]["radial_clearance"], 12): r for r in load_rows(dir_b)}
    print(
        "| c [mm] | regime A | regime B | peak force A [kN] | peak force B [kN] | mean ex A [µm] | mean ex B [µm] "
        "| std ex A [µm] | std ex B [µm] |"
    )
    print("|---:|---|---|---:|---:|---:|---:|---:|---:|")
    agree, ratios = 0, []
    for ra in load_rows(dir_a):
        c = round(ra["point"]["radial_clearance"], 12)
        rb = rows_b.get(c)
        if rb is None or ra["status"] != "ok" or rb["status"] != "ok":
            continue
        fa, fb = ra["summary"]["rod_slider"]["peak_force"], rb["summary"]["rod_slider"]["peak_force"]
        xa, xb = (np.asarray(r["poincare"]["points"])[:, 0] * 1e6 for r in (ra, rb))
        ga, gb = ra["poincare"]["regime"], rb["poincare"]["regime"]
        agree += ga == gb
        ratios.append(fa / fb)
        print(
            f"| {c * 1e3:.3f} | {ga} | {gb} | {fa / 1e3:.2f} | {fb / 1e3:.2f} | {xa.mean():.1f} | {xb.mean():.1f} "
            f"| {xa.std():.1f} | {xb.std():.1f} |"
        )
    print(
        f"regimes agree at {agree}/{len(ratios)} points; peak force ratio A/B median {np.median(ratios):.3f}, "
        f"range {min(ratios):.3f}-{max(ratios):.3f}"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--points", type=int, default=200)
    p.add_argument("--timestep-us", type=float, default=5.0)
    p.add_argument("--segments", type=int, default=None)
    p.add_argument(
        "--contact-mode", default=ModelOptions().contact_mode.value, choices=("nominal", "calibrated", "exact")
    )
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--periods", type=int, default=60)
    p.add_argument("--sampled", type=int, default=40)
    p.add_argument("--every", type=int, default=1, help="run every k-th value of the grid (accuracy checks)")
    p.add_argument("--out", default="bifurcation-speed")
    p.add_argument("--compare", nargs=2, metavar=("DIR_A", "DIR_B"), help="compare two finished sweeps and exit")
    args = p.parse_args()
    if args.compare:
        compare(*args.compare)
        return
    values = np.linspace(0.01e-3, 1e-3, args.points)[:: args.every]
    opts = ModelOptions(timestep=args.timestep_us * 1e-6, segments=args.segments, contact_mode=args.contact_mode)
    t0 = time.perf_counter()
    d = run_bifurcation(
        values,
        KeywordFactory(slider_crank),
        out_dir=args.out,
        quantity="rod_slider.ex",
        periods=args.periods,
        sampled=args.sampled,
        options=opts,
        max_workers=args.workers,
    )
    wall = time.perf_counter() - t0
    plot_bifurcation(d, path=Path(args.out) / "bifurcation.png")
    rows = [json.loads(f.read_text()) for f in sorted((Path(args.out) / "points").glob("*.json"))]
    per = [r["timing"]["wall_time_s"] for r in rows]
    counts = {r: d.regimes.count(r) for r in dict.fromkeys(d.regimes)}

    def total(key: str) -> float:
        return round(sum(r["timing"].get(key) or 0.0 for r in rows), 1)

    stepping = total("stepping_s")
    print(
        json.dumps(
            {
                "machine": f"{platform.machine()}, {args.workers} workers",
                "points": len(d.values),
                "timestep_us": args.timestep_us,
                "segments": args.segments or "ripple rule",
                "contact_mode": args.contact_mode,
                "wall_s": round(wall, 1),
                "per_point_s_median": round(statistics.median(per), 2),
                "per_point_s_max": round(max(per), 2),
                "regimes": counts,
                "worker_s": {
                    "points": total("wall_time_s"),
                    "stepping": stepping,
                    "preparation": round(total("simulate_s") - stepping, 1),
                    "ideal": total("ideal_s"),
                    "evaluation": total("evaluate_s"),
                },
                "errors": sorted({e.split(":")[0] for e in d.errors if e}),
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
