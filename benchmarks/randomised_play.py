"""Randomised backlash for training: 64 worlds of the pusher x 10 s at 2 ms, timed (issue 34's goal: < 30 s on 2 cores).

Runs `examples/randomised_backlash.py`'s batch (backlash at the pusher's seven actuated hinges,
each world's bands and stops drawn; one `mujoco.rollout` call) at 1 and 2 threads, and the
unmodified pusher's 64 copies under the same drive at the same step as the baseline. Each
configuration runs ``REPEATS`` times; the table gives the fastest and the slowest, and the load
average the machine had (other work shares its 2 cores).

Writes ``benchmarks/randomised_play.md`` (the text from ``## Reading`` on is kept).

    python benchmarks/randomised_play.py
"""

from __future__ import annotations

import datetime
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np

from clearance.retrofit import SineControl
from clearance.retrofit.motion import control_signal
from clearance.run.world_batch import step_worlds

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "examples"))
from _tables import write_keeping_reading
from randomised_backlash import STEP, Outcome, pusher_path, run

OUT = Path(__file__).with_suffix(".md")
COMMAND = "python benchmarks/randomised_play.py"
WORLDS = 64
SECONDS = 10.0
REPEATS = 3
GOAL_S = 30.0


def _unmodified(threads: int) -> float:
    """Rollout wall time [s] of the unmodified pusher's WORLDS copies under the same drive."""
    spec = mujoco.MjSpec.from_file(str(pusher_path()))
    spec.option.timestep = STEP
    model = spec.compile()
    control = control_signal(model, SineControl(), np.arange(int(round(SECONDS / STEP))) * STEP)[None]
    return step_worlds([model] * WORLDS, control=control, nthread=threads).wall_time


def _timed(fn: Callable[[], float]) -> tuple[float, float, float]:
    """(fastest, slowest rollout [s], slowest whole call [s]) over REPEATS calls of ``fn`` (which returns its rollout time)."""
    rollouts, totals = [], []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        rollouts.append(fn())
        totals.append(time.perf_counter() - t0)
    return min(rollouts), max(rollouts), max(totals)


def main() -> None:
    """Time every configuration and write the table."""
    load0 = os.getloadavg()
    rows = []
    spread = 0.0
    for threads in (2, 1):
        base = _timed(lambda threads=threads: _unmodified(threads))
        rows.append(("unmodified pusher", threads, *base))
        outcomes: list[Outcome] = []

        def backlash(threads: int = threads, seen: list[Outcome] = outcomes) -> float:
            out = run(WORLDS, SECONDS, threads)
            seen.append(out)
            return out.batch.wall_time

        timed = _timed(backlash)
        spread = outcomes[-1].tip_spread
        rows.append(("backlash at 7 hinges, randomised per world (recipe stop)", threads, *timed))
    load1 = os.getloadavg()
    lines = [
        "# Randomised backlash for training: 64 pusher worlds at the robot's step",
        "",
        "```",
        COMMAND,
        "```",
        "",
        f"{datetime.date.today().isoformat()}; MuJoCo {mujoco.__version__}; {os.cpu_count()} CPUs; load average "
        f"{load0[0]:.2f} at the start, {load1[0]:.2f} at the end (other work shared the machine: timings are "
        "indicative, the fastest of the repeats the closest to an idle machine).",
        "",
        f"{WORLDS} worlds x {SECONDS:g} s at {STEP * 1e3:g} ms ({int(round(SECONDS / STEP))} steps each) under "
        "`SineControl()`, one `mujoco.rollout` call per batch (`clearance.run.world_batch.step_worlds`). Backlash: "
        "examples/randomised_backlash.py (each world's band b drawn in 1'..10' and its stop's stiffness and damping in "
        f"0.5..2 x the model's own, per hinge). {REPEATS} repeats per row. Goal: the backlash batch in < "
        f"{GOAL_S:g} s on 2 cores.",
        "",
        "| worlds | threads | rollout fastest [s] | rollout slowest [s] | whole call slowest [s] | simulated s per wall s "
        "(fastest) | goal |",
        "|---|---:|---:|---:|---:|---:|---|",
    ]
    for name, threads, fast, slow, whole in rows:
        goal = ("met" if whole < GOAL_S else "missed") if "backlash" in name else ""
        lines.append(
            f"| {name} | {threads} | {fast:.2f} | {slow:.2f} | {whole:.2f} | {WORLDS * SECONDS / fast:.0f} | {goal} |"
        )
    lines += [
        "",
        f"The tool tip's spread across the worlds (RMS distance from their mean over the run): {spread * 1e3:.3f} mm.",
        "",
    ]
    write_keeping_reading(OUT, "\n".join(lines))
    print(OUT.read_text())


if __name__ == "__main__":
    main()
