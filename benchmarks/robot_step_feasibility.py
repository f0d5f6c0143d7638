"""Where backlash can be represented at a robot's own time step: the smallest band against the step.

The step-limited stop (`clearance.retrofit.step_stop`: MuJoCo's soft limit with its spring time
constant two steps, damping fitted to the compiled exact stop's rebound and impulse per impact)
penetrates p h v at closing speed v and step h, with one number p per integrator (the fitted
stop is one dimensionless system in units of the step). A band b is represented where that is
at most 0.2 b at the fastest closing under the sizing motion (`SineControl()`, 1 s), which the
retrofitted model runs at h (`clearance.retrofit.robot_step`):

- analytic: b >= p h v / 0.2 for a given closing speed (the dashed lines of the figure);
- per arm (the flywheel of benchmarks/backlash_recipe.py, gymnasium's reacher and pusher, and robosuite's
  Panda and UR5e with the armature robosuite gives their joints; every actuated hinge given the same band): for steps 0.5, 1, 2, 5 and 10 ms, bands 1'-60', the
  fastest closing and the deepest penetration measured in the sizing run, against p h v; and
  the smallest band on the ladder 1'..600' (10 degrees) represented at every hinge
  (`robot_step.smallest_common_band`), the arm's curve in the figure;
- a check of the closing speeds: the fine-step exact model (the law in the compiled plugin) under
  the same motion at 60', its fastest closing per band against the step-limited model's.

Writes ``benchmarks/robot_step_feasibility.md`` and ``.png`` (the text from ``## Reading`` on is kept).

    python benchmarks/robot_step_feasibility.py
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import mujoco
import numpy as np

from clearance.contact_calibration.torsional_stop import MeshLaw
from clearance.retrofit import Backlash, SineControl
from clearance.retrofit.backlash import add_backlash
from clearance.retrofit.robot_step import add_robot_step_backlash, sizing_closings, smallest_common_band
from clearance.retrofit.step_stop import MAX_PENETRATION, fit_step_stop, smallest_band

sys.path.insert(0, str(Path(__file__).parent))
from _gym import gym_model
from _tables import write_keeping_reading
from backlash_recipe import FLYWHEEL, _stop_sensors
from robot_step_play import actuated
from robot_step_play import arms as robosuite_arms

OUT = Path(__file__).with_suffix(".md")
FIGURE = Path(__file__).with_suffix(".png")
COMMAND = "python benchmarks/robot_step_feasibility.py"
STEPS_MS = (0.5, 1.0, 2.0, 5.0, 10.0)
BANDS_ARCMIN = (1.0, 2.0, 3.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0)
CHECK_ARCMIN = 60.0
SPEED_LINES = (0.3, 1.0, 3.0)


def arms() -> list[tuple[str, mujoco.MjSpec, list[str]]]:
    """(name, spec, actuated hinges) of the flywheel, the reacher, the pusher, and robosuite's Panda and UR5e as
    robosuite runs them (`robot_step_play.as_robosuite_runs_it`), where robosuite is installed."""
    out = []
    for name, spec in (
        ("flywheel", mujoco.MjSpec.from_string(FLYWHEEL)),
        ("reacher", mujoco.MjSpec.from_file(str(gym_model("reacher")))),
        ("pusher", mujoco.MjSpec.from_file(str(gym_model("pusher")))),
    ):
        m = spec.copy().compile()
        out.append((name, spec, [m.joint(int(m.actuator_trnid[k, 0])).name for k in range(m.nu)]))
    for name, spec in robosuite_arms():
        if name.endswith("as robosuite runs it"):
            out.append((name.replace(" as robosuite runs it", " (robosuite's armature)"), spec, actuated(spec)))
    return out


def _arcmin(rad: float) -> float:
    return math.degrees(rad) * 60


def exact_closings(spec: mujoco.MjSpec, hinges: list[str], arcmin: float) -> tuple[np.ndarray, float, float]:
    """Fastest closing per band [rad/s] of the fine-step exact model under `SineControl()` for 1 s; its step and
    wall time [s]."""
    out = add_backlash(spec, {h: Backlash.from_arcmin(arcmin, stop="exact") for h in hinges})
    m = out.model
    sensors = _stop_sensors(m, hinges)
    tendons = [int(m.tendon(x.tendon).id) for x in out.hinges.values()]
    n = int(round(1.0 / m.opt.timestep))
    from clearance.retrofit.motion import control_signal, initial_data

    u = control_signal(m, SineControl(), np.arange(n) * m.opt.timestep)
    d = initial_data(m)
    fastest = np.zeros(len(hinges))
    touching = np.zeros(len(hinges), dtype=bool)
    t0 = time.perf_counter()
    for i in range(n):
        d.ctrl[:] = u[i]
        mujoco.mj_step(m, d)
        for k, adr in enumerate(sensors):
            now = d.sensordata[adr + 2] > 0
            if now and not touching[k]:
                fastest[k] = max(fastest[k], abs(float(d.ten_velocity[tendons[k]])))
            touching[k] = now
    return fastest, float(m.opt.timestep), time.perf_counter() - t0


def measure() -> tuple[list[str], dict[str, dict[float, float | None]], dict[int, float]]:
    """The tables' lines, each arm's smallest common band per step [arcmin] (None: none up to 600'), and p per
    integrator."""
    lines: list[str] = []
    curves: dict[str, dict[float, float | None]] = {}
    pvals: dict[int, float] = {}
    grid = [
        "## Per arm, step and band: the sizing motion at the step",
        "",
        "Every actuated hinge given the same band; the sizing motion (`SineControl()`: half of each control range at "
        "1 Hz, phases spread; 1 s) run on the retrofitted model at the step. v: the fastest closing over the bands "
        "(rad/s); depth: the deepest penetration over b, measured; p h v / b: the same predicted from the fitted "
        "stop at v (each band's own v; the largest over the bands); a band is represented where p h v <= "
        f"{MAX_PENETRATION:g} b at every hinge (yes/no).",
        "",
        "| arm | step [ms] | " + " | ".join(f"{b:g}'" for b in BANDS_ARCMIN) + " | smallest band on the ladder |",
        "|---|---:|" + "---|" * len(BANDS_ARCMIN) + "---:|",
    ]
    for name, spec, hinges in arms():
        curves[name] = {}
        for step_ms in STEPS_MS:
            t0 = time.perf_counter()
            r = add_robot_step_backlash(
                spec,
                {h: Backlash.from_arcmin(BANDS_ARCMIN[0]) for h in hinges},
                robot_step=step_ms * 1e-3,
                refuse=False,
            )
            pvals[int(r.retrofit.model.opt.integrator)] = r.stop.penetration / r.stop.timestep
            run, cells = r.sizing, []
            saved = run.model.tendon_range.copy()
            for b_arc in BANDS_ARCMIN:
                b = math.radians(b_arc / 60)
                run.model.tendon_range[run.tendons] = (-b, b)
                fastest, deepest, _ = sizing_closings(run.model, run.tendons, run.control, run.duration)
                v = np.where(fastest > 0, fastest, run.estimates)
                predicted = max(smallest_band(r.stop, float(s)) for s in v) * MAX_PENETRATION / b
                ok = predicted <= MAX_PENETRATION
                cells.append(
                    f"v {v.max():.2g}, depth {deepest.max() / b:.2g}, pred {predicted:.2g} {'yes' if ok else 'no'}"
                )
            run.model.tendon_range[:] = saved
            least = smallest_common_band(run, r.stop)
            curves[name][step_ms] = least
            grid.append(
                f"| {name} | {step_ms:g} | "
                + " | ".join(cells)
                + f" | {'none up to 600' if least is None else f'{least:g}'}' |"
            )
            print(grid[-1], f"({time.perf_counter() - t0:.1f} s)", flush=True)
    lines += grid
    return lines, curves, pvals


def check_section() -> list[str]:
    """The fine-step exact model's fastest closings at `CHECK_ARCMIN` against the step-limited model's at 0.5 and 1 ms."""
    lines = [
        "",
        f"## Check: closing speeds of the fine-step exact model at {CHECK_ARCMIN:g}'",
        "",
        "The fastest closing per band under the same sizing motion: the exact stop (the law in the compiled plugin, "
        "at its own fine step) against the step-limited stop at 0.5 and 1 ms. The region is drawn with the "
        "step-limited model's closings (what `clearance retrofit --robot-step` measures); this says how far they "
        "are from the exact model's.",
        "",
        "| arm | exact step [s] | exact run [s] | exact fastest closing per band [rad/s] | 0.5 ms | 1 ms |",
        "|---|---:|---:|---|---|---|",
    ]
    for name, spec, hinges in arms():
        fast, step, wall = exact_closings(spec, hinges, CHECK_ARCMIN)
        coarse = []
        for step_ms in (0.5, 1.0):
            r = add_robot_step_backlash(
                spec, {h: Backlash.from_arcmin(CHECK_ARCMIN) for h in hinges}, robot_step=step_ms * 1e-3, refuse=False
            )
            coarse.append(", ".join(f"{b.closing_speed:.3g}" for b in r.bands.values()))
        lines.append(
            f"| {name} | {step:.3g} | {wall:.1f} | {', '.join(f'{v:.3g}' for v in fast)} | {coarse[0]} | {coarse[1]} |"
        )
        print(lines[-1], flush=True)
    return lines


def figure(curves: dict[str, dict[float, float | None]], pvals: dict[int, float]) -> None:
    """Smallest band against step, one curve per arm; the analytic lines b = p h v / 0.2."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.5, 5))
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    h = np.geomspace(0.4, 12, 50)
    p = max(pvals.values())
    for v in SPEED_LINES:
        ax.loglog(h, _arcmin(1) * p * h * 1e-3 * v / MAX_PENETRATION, "k:", lw=0.8)
        ax.text(
            11, _arcmin(1) * p * 11e-3 * v / MAX_PENETRATION, f"v = {v:g} rad/s", fontsize=7, ha="right", va="bottom"
        )
    for (name, curve), marker in zip(curves.items(), ("o", "s", "^", "D", "v")):
        xs = [s for s, b in curve.items() if b is not None]
        ax.loglog(xs, [curve[s] for s in xs], marker + "-", label=name)
        none = [s for s, b in curve.items() if b is None]
        if none:
            ax.loglog(none, [600] * len(none), marker, mfc="none", color=ax.lines[-1].get_color())
    ax.axhspan(1, 60, color="tab:green", alpha=0.08, label="1'-60' (the bands asked about)")
    ax.axhline(600, color="grey", lw=0.8)
    ax.text(0.42, 640, "10 degrees (MAX_BACKLASH): open markers, nothing represented up to here", fontsize=7)
    ax.set(
        xlabel="robot time step h [ms]",
        ylabel="smallest band represented, b [arcmin]",
        title="Backlash at the robot's step: penetration <= 0.2 b at the fastest closing of the sizing motion",
        ylim=(0.8, 2000),
    )
    ax.title.set_fontsize(9)
    ax.set_xticks([0.5, 1, 2, 5, 10], ["0.5", "1", "2", "5", "10"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    tmp = FIGURE.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, FIGURE)


def main() -> None:
    """Measure and write the table and the figure."""
    load = os.getloadavg()
    t0 = time.perf_counter()
    law = MeshLaw(1e4, 0.8)
    fits = {
        integ: fit_step_stop(law, timestep=1e-3, integrator=int(integ), inertia=1.43e-3, speed=1.0)
        for integ in (mujoco.mjtIntegrator.mjINT_EULER, mujoco.mjtIntegrator.mjINT_RK4)
    }
    head = [
        "# Backlash at the robot's step: where it can be represented",
        "",
        "```",
        COMMAND,
        "```",
        "",
        f"{time.strftime('%Y-%m-%d')}; MuJoCo {mujoco.__version__}; load average at the start {load[0]:.2f} "
        f"{load[1]:.2f} {load[2]:.2f} (2 cores shared). Mesh law K = 1e4 N m/rad, e = 0.8 (the defaults).",
        "",
        "## The step-limited stop (analytic part)",
        "",
        "Spring time constant 2 h (omega h = 0.5), impedance 0.99 (pose-independent), damping ratio fitted to the exact "
        "stop's rebound and impulse per impact over four onset phases; one dimensionless stop, so the penetration "
        "per closing speed is p h and the smallest band b = p h v / 0.2:",
        "",
        "| integrator | damping ratio | exact rebound | rebound error (worst phase) | impulse error | p = depth/(h v) "
        "(worst phase) | b at 1 ms, 1 rad/s [arcmin] |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for integ, s in fits.items():
        p = s.penetration / s.timestep
        head.append(
            f"| {integ.name.removeprefix('mjINT_')} | {s.dampratio:.4f} | {s.exact.rebound:.4f} | {100 * s.rebound_error:+.2f} % | "
            f"{100 * s.impulse_error:+.2f} % | {p:.3f} | {_arcmin(p * 1e-3 / MAX_PENETRATION):.3g} |"
        )
    body, curves, pvals = measure()
    figure(curves, pvals)
    summary = [
        "",
        "## The region: smallest band represented at every hinge",
        "",
        "| arm | " + " | ".join(f"{s:g} ms" for s in STEPS_MS) + " |",
        "|---|" + "---:|" * len(STEPS_MS),
    ]
    for name, curve in curves.items():
        summary.append(
            f"| {name} | " + " | ".join("none <= 600'" if b is None else f"{b:g}'" for b in curve.values()) + " |"
        )
    summary += ["", f"![smallest band against step]({FIGURE.name})", ""]
    check = check_section()
    tail = ["", f"Whole run {time.perf_counter() - t0:.0f} s."]
    write_keeping_reading(OUT, "\n".join(head + summary + body + check + tail) + "\n")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
