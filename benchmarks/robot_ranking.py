"""Benchmark: gymnasium's seven-joint pusher ranked by what radial play and backlash at each hinge cost its tool tip.

    python benchmarks/robot_ranking.py [--workers 2]

Runs ``clearance rank --model pusher.xml`` with its defaults (every actuated hinge, radial play
c = 0.1 mm steel with the compiled exact contact and backlash b = 5', amplitudes 0.25 and 0.5,
2 and 4 Hz, 1.25 s per run, score after 0.25 s) on 2 local workers into a fresh folder, and
writes ``benchmarks/robot_ranking.md``: the command, the wall time, the load average and the
ranking the command wrote.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def pusher() -> Path:
    """gymnasium's pusher.xml (gymnasium's wheel ships it)."""
    spec = importlib.util.find_spec("gymnasium")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("gymnasium is not installed: pip install gymnasium")
    return Path(next(iter(spec.submodule_search_locations))) / "envs" / "mujoco" / "assets" / "pusher.xml"


def main() -> int:
    """Run the ranking and write the table; returns the command's exit status."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--workers", type=int, default=2)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "rank"
        cmd = ["clearance", "rank", "--model", str(pusher()), "--workers", str(args.workers), "--no-progress"]
        cmd += ["--out", str(out)]
        load = os.getloadavg()
        t0 = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        load_after = os.getloadavg()
        if done.returncode != 0:
            print(done.stdout, done.stderr, file=sys.stderr)
        rows = [json.loads(f.read_text()) for f in sorted((out / "points").glob("point_*.json"))]
        summed = sum(r["timing"]["wall_time_s"] for r in rows)
        ranking = (out / "ranking.md").read_text() if (out / "ranking.md").is_file() else "(no ranking written)\n"
        ranking = ranking.split("\n", 2)[2] if ranking.startswith("# ") else ranking
        ranking = ranking.replace("![ranking](ranking.png)", "")
        ranking = "\n".join(ln for ln in ranking.splitlines() if not ln.startswith("`clearance rank"))  # shown above
        if (out / "ranking.png").is_file():
            (HERE / "robot_ranking.png").write_bytes((out / "ranking.png").read_bytes())
    shown = shlex.join(["clearance", *cmd[1:3], "gymnasium/envs/mujoco/assets/pusher.xml", *cmd[4:-2]])
    lines = [
        "# gymnasium's pusher: which hinge's play costs the tool tip most",
        "",
        "```",
        "python benchmarks/robot_ranking.py",
        f"{shown}   # what it runs, into a fresh folder",
        "```",
        "",
        f"{time.strftime('%Y-%m-%d', time.gmtime())}; {os.cpu_count()} CPUs, {args.workers} workers; load average "
        f"{load[0]:.2f} before, {load_after[0]:.2f} after (others' work on the machine counts in the wall time). "
        f"Exit status {done.returncode}.",
        "",
        f"**Wall time: {wall:.1f} s** (goal: at most 600 s on 2 cores). {len(rows)} runs, each against its twin; "
        f"their times summed: {summed:.0f} s (what one core would spend; on a quiet machine the wall time is about "
        f"half of it plus the workers' start).",
        "",
        ranking.strip(),
        "",
        "![ranking](robot_ranking.png)",
        "",
    ]
    (HERE / "robot_ranking.md").write_text("\n".join(lines))
    print(f"{wall:.1f} s, exit {done.returncode}; wrote {HERE / 'robot_ranking.md'}")
    return done.returncode


if __name__ == "__main__":
    sys.exit(main())
