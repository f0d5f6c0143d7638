"""Design optimisation with clearance, as a user runs it: the slider-crank and the seven-bar press.

    python benchmarks/optimise_designs.py --out /tmp/optimise-bench

Runs ``clearance optimise`` (in a subprocess, 2 local workers) on two problems, from an
empty folder each (delete --out to measure from scratch; a rerun resumes from the stored
runs and takes seconds):

- slider-crank, clearance 0.1 mm at the rod-slider joint, 2000 rpm: rod length, slider mass
  and crank length, the stroke held within 95-105 mm; objective the RMS deviation of the
  slider from its ideal curve (the fluctuation about it);
- seven-bar press (the hybrid seven-bar press paper, Shock and Vibration 2020: docs/references.md), clearances 0.1 mm at A and C, crank 2 at
  90 rpm (3 pi rad/s, the press paper's upper speed), time step 20 µs: the plate's point C (both
  coordinates) and the length of rod 5, the slider's stroke within 125-145 mm; objective the
  RMS deviation of the slider (the press paper's fluctuation of the slider's output).

Writes ``benchmarks/optimise_designs.md``: per problem the wall time (goal: at most 15
minutes on 2 cores), the designs tried and simulated, the wall time and worker time per
evaluated design (one ensemble of 20 runs), the confirmation by fresh ensembles (another
seed) at the start design and at the optimum with standard errors, and whether the optimum
is lower by more than three standard errors of the difference; the machine's load average
before and after each.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _tables import write_keeping_reading

from clearance.results import atomic_write_bytes

PROBLEMS = {
    "slider_crank": [
        "--mechanism",
        "slider_crank",
        "--clearance-mm",
        "0.1",
        "--rpm",
        "2000",
        "--vary",
        "rod_length_mm=100:200",
        "--vary",
        "slider_mass_kg=0.05:0.4",
        "--vary",
        "crank_length_mm=45:60",
        "--stroke",
        "95:105",
        "--runs",
        "20",
        "--periods",
        "3",
        "--samples",
        "8",
        "--budget",
        "30",
    ],
    "seven_bar_press": [
        "--mechanism",
        "seven_bar_press",
        "--clearance-mm",
        "0.1",
        "--rpm",
        "90",
        "--timestep-us",
        "20",
        "--vary",
        "plate4_point_mm[0]=40:120",
        "--vary",
        "plate4_point_mm[1]=-200:-80",
        "--vary",
        "rod5_length_mm=200:320",
        "--stroke",
        "125:145",
        "--runs",
        "20",
        "--periods",
        "2",
        "--samples",
        "8",
        "--budget",
        "30",
    ],
}
"""Problem -> the options of ``clearance optimise`` (besides --out, --workers)."""

GOAL_S = 15 * 60
"""The goal: each optimisation within 15 minutes on 2 cores."""


def run(name: str, out: Path, workers: int) -> dict:
    """Run one problem; its numbers."""
    folder = out / name
    argv = ["clearance", "optimise", *PROBLEMS[name], "--workers", str(workers), "--out", str(folder)]
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    load1 = os.getloadavg()[0]
    sys.stdout.write(proc.stdout)
    sys.stderr.write(proc.stderr)
    if proc.returncode != 0:
        raise SystemExit(f"{name}: clearance optimise exited {proc.returncode}")
    data = json.loads((folder / "optimise.json").read_text())
    m = re.search(r"simulated, in ([0-9.]+) s; confirmation in ([0-9.]+) s", proc.stdout)
    r = re.search(r"run reports in ([0-9.]+) s", proc.stdout)
    search_s, confirm_s = (float(m.group(1)), float(m.group(2))) if m else (float("nan"), float("nan"))
    trials = data["search"]["trials"]
    simulated = [t for t in trials if t["feasible"]]
    worker = [t["run_seconds"] for t in simulated if t["run_seconds"] is not None]
    return {
        "name": name,
        "command": " ".join(argv[:2] + [f"'{a}'" if "[" in a else a for a in argv[2:]]),
        "wall_s": wall,
        "search_s": search_s,
        "confirm_s": confirm_s,
        "reports_s": float(r.group(1)) if r else float("nan"),
        "tried": len(trials),
        "simulated": len(simulated),
        "per_design_s": search_s / max(1, len(simulated)),
        "worker_per_design_s": sum(worker) / max(1, len(worker)),
        "worker_per_run_s": sum(worker) / max(1, sum(t["runs"] for t in simulated)),
        "data": data,
        "load": (load0, load1),
    }


def _variables(d: dict) -> str:
    def show(name: str, v: float) -> str:
        return f"{v:.4g} kg" if name.endswith("mass") else f"{v * 1e3:.4g} mm"

    return "; ".join(
        f"{v['name']} {show(v['name'], d['start'][v['name']])} -> {show(v['name'], d['optimum'][v['name']])}"
        for v in d["variables"]
    )


def markdown(results: list[dict], workers: int, out: Path) -> str:
    lines = [
        "# Design optimisation with clearance: slider-crank and seven-bar press",
        "",
        f"Command: `python benchmarks/optimise_designs.py --out {out}` (each problem from an empty "
        f"folder, {workers} local workers).",
        f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, measured "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.",
        "",
        "| problem | wall time (goal <= 15 min) | designs tried / simulated | search | per design (wall) "
        "| per design (worker s) | per run (worker s) | confirmation | run reports | load avg before / after |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        lines.append(
            f"| {r['name']} | **{r['wall_s']:.0f} s** ({'met' if r['wall_s'] <= GOAL_S else 'MISSED'}) "
            f"| {r['tried']} / {r['simulated']} | {r['search_s']:.0f} s | {r['per_design_s']:.1f} s "
            f"| {r['worker_per_design_s']:.1f} | {r['worker_per_run_s']:.2f} | {r['confirm_s']:.0f} s "
            f"| {r['reports_s']:.0f} s | {r['load'][0]:.2f} / {r['load'][1]:.2f} |"
        )
    lines += [
        "",
        "Confirmation: fresh ensembles of 20 runs (seed 1; the search used seed 0) at the start design and at the "
        "optimum; objective RMS deviation of the slider from its ideal curve, ± standard error; the goal is an "
        "improvement above three standard errors of the difference.",
        "",
        "| problem | start [µm] | optimum [µm] | improvement [µm] | in s.e. of the difference | goal (> 3 s.e.) "
        "| design: start -> optimum |",
        "|---|---:|---:|---:|---:|---|---|",
    ]
    for r in results:
        c = r["data"]["confirmation"]
        lines.append(
            f"| {r['name']} | {c['start']['value'] * 1e6:.2f} ± {c['start']['se'] * 1e6:.2f} "
            f"| {c['optimum']['value'] * 1e6:.2f} ± {c['optimum']['se'] * 1e6:.2f} | {c['improvement'] * 1e6:.2f} "
            f"| {c['improvement'] / c['se']:.1f} | {'met' if c['significant'] else 'MISSED'} | {_variables(r['data'])} |"
        )
    lines += ["", "Commands as run:", ""]
    lines += [f"- {r['name']}: `{r['command']}`" for r in results]
    lines += [""]
    lines += [f"![{r['name']} convergence](optimise_{r['name']}.png)\n" for r in results]
    return "\n".join(lines) + "\n"


def main() -> None:
    p = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    p.add_argument("--out", default="/tmp/optimise-bench", help="folder of the optimisations")
    p.add_argument("--workers", type=int, default=2, help="local worker processes (default 2)")
    p.add_argument("--only", choices=sorted(PROBLEMS), default=None, help="run one problem only")
    args = p.parse_args()
    names = [args.only] if args.only else list(PROBLEMS)
    results = [run(n, Path(args.out), args.workers) for n in names]
    text = markdown(results, args.workers, Path(args.out))
    if args.only is None:
        here = Path(__file__).parent
        for n in names:  # the convergence figures beside the table
            atomic_write_bytes(here / f"optimise_{n}.png", (Path(args.out) / n / "convergence.png").read_bytes())
        write_keeping_reading(Path(__file__).with_suffix(".md"), text)
    print(text)


if __name__ == "__main__":
    main()
