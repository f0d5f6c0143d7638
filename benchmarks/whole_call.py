"""One whole call on the default slider-crank: `prepare` plus `simulate_prepared` of 3 revolutions.

Usage:  python benchmarks/whole_call.py [--revolutions 3] [--repeat 5] [--cold 3] [--also-us 2]
                                        [--exudyn-step-us 1] [--no-exudyn] [--out benchmarks/whole_call.md | -]

The default slider-crank (`slider_crank()`: c = 0.5 mm at rod_slider, 5000 rpm, the exact contact)
at the default options (`ModelOptions()`, its default step), timed in CPU time
(time.process_time; wall time beside it), best of ``--repeat``:

  * warm process (imports and the plugin's load done, one call made beforehand):
    - `prepare` on a cache miss (an empty cache folder and the process's shapes forgotten), on a
      hit from the folder (`clearance.run.cycle_cache`'s files) and on a hit in the process; the
      same for the press (`seven_bar_press()`, two drives); the sizing's cycle alone, computed,
      cached, and the way `prepare` took it before the cache;
    - `simulate_prepared` of the revolutions (the default outputs: every step read out), and with
      its rows thinned to one every 100 µs (what the readout of every step costs);
    - the same model stepped bare: `mujoco.mj_step` in a Python loop from the model's initial
      keyframe, with its outputs' sensors removed group by group (energy meter, acceleration-stage
      sensors, all but the contact's, all), and `mujoco.rollout` (the loop in C, sensors recorded):
      simulate's overhead per step is against the Python loop of the run's own model;
  * at ``--also-us`` steps (with Exudyn): prepare on a miss and the stepping, for the accuracy rows;
  * cold: a fresh interpreter per run with an empty cache folder: the package's import, then
    the first `prepare` (a miss) and the first `simulate_prepared`;
  * Exudyn 1.13.6 when importable (the ``bench`` extra), as `benchmarks/exudyn_peer.py` sets it up
    (generalized-α at ``--exudyn-step-us``, its Hunt–Crossley sphere-in-sphere contact, which is the
    joint's Lankarani–Nikravesh law exactly): its solve alone and its whole call (items, Assemble,
    SolveDynamic) over the same revolutions; first-impact errors of Exudyn and ours against the
    project's reference (`run_reference`, LSODA at rtol 1e-9, output every 1 µs, one revolution),
    the measure of `analysis.metrics.accuracy.first_impact_errors`.

The machine's load average is recorded before and after: on a shared machine CPU time is the
steadier figure, and every ratio is taken within this one run.
"""

from __future__ import annotations

import argparse
import atexit
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from _clock import clock, since  # benchmarks/_clock.py (scripts run from benchmarks/)

HERE = Path(__file__).resolve().parent

COLD_CHILD = "--cold-child"


def _scratch() -> str:
    """An empty cache folder, removed when the process ends."""
    folder = tempfile.mkdtemp(prefix="whole-call-")
    atexit.register(shutil.rmtree, folder, True)
    return folder


def cold_child(revolutions: float) -> None:
    """Run in a fresh interpreter: import, first prepare (a miss), first simulate; print CPU and wall [s] as JSON."""
    os.environ["CLEARANCE_CACHE_DIR"] = _scratch()
    start = clock()
    from clearance.builders import slider_crank
    from clearance.run.preparation import prepare
    from clearance.run.simulation import simulate_prepared

    imported = since(start)
    mech = slider_crank()
    start = clock()
    prepared = prepare(mech)
    prep = since(start)
    start = clock()
    simulate_prepared(prepared, duration=revolutions * mech.drive_period)
    step = since(start)
    print(json.dumps({"import": imported, "prepare": prep, "simulate": step}))


@dataclass
class Best:
    """Best CPU and wall time [s] over repeats."""

    cpu: float = math.inf
    wall: float = math.inf

    def add(self, t: tuple[float, float]) -> None:
        self.cpu, self.wall = min(self.cpu, t[0]), min(self.wall, t[1])


def _timed(fn: Any, repeat: int, before: Any = None) -> Best:
    best = Best()
    for _ in range(repeat):
        if before is not None:
            before()
        start = clock()
        fn()
        best.add(since(start))
    return best


def _without(prepared: Any, keep: Any) -> Any:
    """The run's portable spec (no energy meter) compiled with only the sensors ``keep(name)`` accepts."""
    spec = prepared.built.spec.copy()
    for sensor in list(spec.sensors):
        if not keep(sensor.name):
            spec.delete(sensor)
    return spec.compile()


def bare_loops(prepared: Any, steps: int, repeat: int) -> dict[str, Best]:
    """The prepared model stepped bare from its initial keyframe: a Python mj_step loop with its outputs
    removed group by group (the sensors a run reads), and mujoco.rollout (the loop in C, sensors recorded)."""
    import mujoco
    import numpy as np
    from _states import keyframe_state  # benchmarks/_states.py (imports mujoco: not before the cold child's clock)
    from mujoco import rollout

    def python_loop(model: Any) -> Best:
        data = mujoco.MjData(model)

        def run() -> None:
            mujoco.mj_resetDataKeyframe(model, data, 0)
            for _ in range(steps):
                mujoco.mj_step(model, data)

        return _timed(run, repeat)

    model = prepared.model
    acc_stage = ("__reaction", "__acc", "__torque")
    out = {
        f"mj_step loop (Python), the run's model ({model.nsensor} sensors)": python_loop(model),
        "mj_step loop, no energy meter": python_loop(_without(prepared, lambda n: True)),
        "mj_step loop, no energy meter, no acceleration-stage sensors (reactions, output acceleration, drive torque)": (
            python_loop(_without(prepared, lambda n: not n.endswith(acc_stage)))
        ),
        "mj_step loop, the contact's sensor only": python_loop(_without(prepared, lambda n: n.endswith("__contact"))),
    }
    flags = model.opt.disableflags
    model.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_SENSOR
    try:
        out["mj_step loop, sensors disabled"] = python_loop(model)
    finally:
        model.opt.disableflags = flags
    state, ctrl = keyframe_state(model)
    data = mujoco.MjData(model)
    control = ctrl.reshape(1, 1, -1)
    states = np.empty((1, steps, state.size))
    sensors = np.empty((1, steps, model.nsensordata))

    def c_loop() -> None:
        rollout.rollout(model, data, state[None], control, nstep=steps, state=states, sensordata=sensors)

    out["mujoco.rollout (C loop) of the run's model, sensors recorded"] = _timed(c_loop, repeat)
    return out


def prepare_miss(mech: Any, options: Any, repeat: int) -> Best:
    """`prepare` on a cache miss: an empty cache folder and the process's shapes forgotten before each call."""
    from clearance.run.cycle_cache import clear_memory
    from clearance.run.preparation import prepare

    def empty_cache() -> None:
        os.environ["CLEARANCE_CACHE_DIR"] = _scratch()
        clear_memory()

    return _timed(lambda: prepare(mech, options), repeat, empty_cache)


def sizing_alone(mech: Any, prepared: Any, repeat: int) -> dict[str, Best]:
    """The sizing's cycle alone: as `prepare` takes it (a miss, a hit in the process) and as it took it
    before the cache (the reactions over 181 times, `joint_reaction_vectors`, and the masses at 36 poses
    on the compiled model, `cycle_effective_mass`, each solving the cycle's kinematics)."""
    import numpy as np

    from clearance.contact_calibration.effective_mass import cycle_effective_mass
    from clearance.loads import joint_reaction_vectors
    from clearance.run.cycle import CYCLE_TIMES, cycle_shape, scale_cycle
    from clearance.run.cycle_cache import ideal_cycle

    times = np.linspace(0.0, mech.drive_period, CYCLE_TIMES)

    def before() -> None:
        joint_reaction_vectors(mech, times)
        cycle_effective_mass(prepared.model, prepared.built, mech)

    return {
        "sizing's cycle before the cache (reactions + masses on the compiled model)": _timed(before, repeat),
        "sizing's cycle, computed (cycle_shape + scale_cycle)": _timed(
            lambda: scale_cycle(cycle_shape(mech), mech), repeat
        ),
        "sizing's cycle, hit in the process (ideal_cycle)": _timed(lambda: ideal_cycle(mech), repeat),
    }


def warm(mech: Any, options: Any, duration: float, repeat: int) -> tuple[dict[str, Best], Any, Any]:
    """Warm-process timings of prepare (miss, file hit, memory hit) and simulate_prepared."""
    from clearance.run.cycle_cache import clear_memory
    from clearance.run.preparation import prepare
    from clearance.run.simulation import simulate_prepared

    prepare(mech, options)  # warm-up: plugin load, first calls
    t: dict[str, Best] = {}
    t["prepare, miss"] = prepare_miss(mech, options, repeat)
    t["prepare, hit from the cache folder"] = _timed(lambda: prepare(mech, options), repeat, clear_memory)
    t["prepare, hit in the process"] = _timed(lambda: prepare(mech, options), repeat)
    from clearance.builders import seven_bar_press

    press = seven_bar_press()  # two drives (a motor and a servo): its cycle is solved at its own speeds
    prepare(press, options)
    t["the press (seven_bar_press()): prepare, miss"] = prepare_miss(press, options, repeat)
    t["the press: prepare, hit in the process"] = _timed(lambda: prepare(press, options), repeat)
    prepared = prepare(mech, options)
    t.update(sizing_alone(mech, prepared, repeat))
    result = simulate_prepared(prepared, duration=duration)
    t["simulate_prepared, every step read out"] = _timed(lambda: simulate_prepared(prepared, duration=duration), repeat)
    t["simulate_prepared, rows every 100 µs"] = _timed(
        lambda: simulate_prepared(prepared, duration=duration, output_interval=1e-4), repeat
    )
    return t, prepared, result


def cold(revolutions: float, runs: int) -> dict[str, Best]:
    """Fresh interpreters, one after another."""
    out = {k: Best() for k in ("import", "prepare", "simulate")}
    for _ in range(runs):
        done = subprocess.run(
            [sys.executable, str(Path(__file__).resolve()), COLD_CHILD, str(revolutions)],
            capture_output=True,
            text=True,
            check=True,
        )
        got = json.loads(done.stdout.strip().splitlines()[-1])
        for k in out:
            out[k].add(tuple(got[k]))
    return out


def exudyn_side(mech: Any, revolutions: float, duration: float, h: float, repeat: int) -> dict[str, Any] | None:
    """Exudyn's timings and first-impact record (exudyn_peer's setup), or None when it is not installed."""
    try:
        import exudyn  # noqa: F401  # only to know whether it is there
    except ImportError:
        return None
    import exudyn_peer as peer

    exu = peer.import_exudyn("fast")
    run = peer.run_exudyn(exu, mech, h=h, duration=duration, repeat=repeat, revolutions=revolutions, newton_rtol=None)
    return {"version": exu.__version__, "run": run, "peer": peer}


def _ms(x: float) -> str:
    return f"{x * 1e3:.2f}"


def _us(x: float) -> str:
    return f"{x * 1e6:.3f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--revolutions", type=float, default=3.0)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--cold", type=int, default=3, help="fresh interpreters for the cold call")
    ap.add_argument("--also-us", type=float, nargs="*", default=[2.0], help="other steps [µs] for the accuracy rows")
    ap.add_argument("--exudyn-step-us", type=float, default=1.0)
    ap.add_argument("--no-exudyn", action="store_true")
    ap.add_argument("--out", default=str(HERE / "whole_call.md"))
    args = ap.parse_args(argv)
    if args.repeat < 1 or args.cold < 0 or args.revolutions <= 0:
        ap.error("--repeat must be >= 1, --cold >= 0 and --revolutions > 0")
    cmd = "python benchmarks/whole_call.py " + " ".join(sys.argv[1:] if argv is None else argv)
    load_before = os.getloadavg()

    from clearance.builders import slider_crank
    from clearance.options import ModelOptions
    from clearance.version import __version__

    mech, options = slider_crank(), ModelOptions()
    h = options.timestep
    revs = args.revolutions
    duration = revs * mech.drive_period
    steps = int(round(duration / h))

    print("warm ...", flush=True)
    t, prepared, result = warm(mech, options, duration, args.repeat)
    print("bare loops ...", flush=True)
    bare = bare_loops(prepared, steps, args.repeat)
    print("cold ...", flush=True)
    cold_t = cold(revs, args.cold) if args.cold else {}
    ex = None if args.no_exudyn else exudyn_side(mech, revs, duration, args.exudyn_step_us * 1e-6, args.repeat)

    accuracy_rows: list[str] = []
    whole_also: dict[float, tuple[Best, Best, Any]] = {}
    if ex is not None:
        print("reference and other steps ...", flush=True)
        from clearance.reference import run_reference
        from clearance.run.preparation import prepare
        from clearance.run.simulation import simulate_prepared

        peer = ex["peer"]
        ref = run_reference(mech, mech.drive_period, output_interval=1e-6, rtol=1e-9)
        for us in args.also_us:
            o = ModelOptions(timestep=us * 1e-6)
            prep_b = prepare_miss(mech, o, args.repeat)
            p = prepare(mech, o)
            res = simulate_prepared(p, duration=duration)
            step_b = _timed(lambda p=p: simulate_prepared(p, duration=duration), args.repeat)
            whole_also[us] = (prep_b, step_b, res)
        accs = {f"ours, {h * 1e6:g} µs (default)": peer.accuracy(result, ref)}
        accs |= {f"ours, {us:g} µs": peer.accuracy(res, ref) for us, (_, _, res) in whole_also.items()}
        accs[f"Exudyn {ex['version']}, {args.exudyn_step_us:g} µs"] = peer.accuracy(ex["run"].result, ref)
        for name, a in accs.items():
            accuracy_rows.append(
                f"| {name} | {a['peak']:.2f} | {a['peak_force']:+.3e} | {a['force']:.2e} |"
                if a
                else f"| {name} | - | - | - |"
            )
    load_after = os.getloadavg()

    miss, hit = t["prepare, miss"], t["prepare, hit in the process"]
    stepping = t["simulate_prepared, every step read out"]
    py_loop = next(iter(bare.values()))  # the run's model in a Python loop
    sim_rev = duration / revs
    lines = [
        "# One whole call: prepare + simulate_prepared of the default slider-crank",
        "",
        f"Command: `{cmd.strip()}`",
        "",
        f"Machine: {platform.machine()}, {os.cpu_count()} cores (shared); Python {platform.python_version()}, "
        f"clearance {__version__}; {datetime.now(UTC):%Y-%m-%d %H:%M} UTC. Load average (1, 5, 15 min) "
        f"{', '.join(f'{x:.1f}' for x in load_before)} before and {', '.join(f'{x:.1f}' for x in load_after)} "
        f"after the run. Times are the best of {args.repeat} (cold: of {args.cold} fresh interpreters), "
        "CPU time (time.process_time) with wall time beside it.",
        "",
        f"Scenario: `slider_crank()` (c = 0.5 mm at rod_slider, 5000 rpm, exact contact), `ModelOptions()` "
        f"(step {h * 1e6:g} µs), {revs:g} revolutions = {duration * 1e3:g} ms simulated, {steps} steps.",
        "",
        "## Warm process (imports excluded)",
        "",
        "| part | CPU [ms] | wall [ms] | CPU per step [µs] | CPU per revolution [ms] |",
        "|---|---|---|---|---|",
    ]
    for name, b in t.items():
        per = name.startswith("simulate")
        lines.append(
            f"| {name} | {_ms(b.cpu)} | {_ms(b.wall)} | {_us(b.cpu / steps) if per else '-'} | "
            f"{_ms(b.cpu / revs) if per else '-'} |"
        )
    for name, b in bare.items():
        lines.append(f"| bare: {name} | {_ms(b.cpu)} | {_ms(b.wall)} | {_us(b.cpu / steps)} | {_ms(b.cpu / revs)} |")
    lines += [
        f"| **whole call, miss** (prepare miss + simulate_prepared) | **{_ms(miss.cpu + stepping.cpu)}** | "
        f"{_ms(miss.wall + stepping.wall)} | - | - |",
        f"| **whole call, hit** (prepare hit + simulate_prepared) | **{_ms(hit.cpu + stepping.cpu)}** | "
        f"{_ms(hit.wall + stepping.wall)} | - | - |",
        "",
        f"- Real time: one revolution is {sim_rev * 1e3:.2f} ms simulated; stepping with readout costs "
        f"{_ms(stepping.cpu / revs)} ms CPU per revolution: **{sim_rev / (stepping.cpu / revs):.2f}x real time** "
        f"(goal >= 2x, <= {sim_rev / 2 * 1e3:.0f} ms per revolution).",
        f"- simulate's overhead per step over the bare Python mj_step loop of the same model: "
        f"**{(stepping.cpu / py_loop.cpu - 1) * 100:+.1f} %** (goal <= 15 %); rows thinned to 100 µs: "
        f"{(t['simulate_prepared, rows every 100 µs'].cpu / py_loop.cpu - 1) * 100:+.1f} %.",
        f"- prepare: miss {_ms(miss.cpu)} ms (goal <= 10 ms in a fresh process), hit {_ms(hit.cpu)} ms (goal <= 2 ms); "
        f"the press on a miss {_ms(t['the press (seven_bar_press()): prepare, miss'].cpu)} ms (goal <= 30 ms).",
    ]
    if cold_t:
        total = sum(b.cpu for b in cold_t.values())
        lines += [
            "",
            "## Cold (a fresh interpreter, empty cache folder)",
            "",
            "| part | CPU [ms] | wall [ms] |",
            "|---|---|---|",
            *[f"| {k} | {_ms(b.cpu)} | {_ms(b.wall)} |" for k, b in cold_t.items()],
            f"| total | {_ms(total)} | {_ms(sum(b.wall for b in cold_t.values()))} |",
        ]
    if ex is not None:
        run = ex["run"]
        ours_whole = miss.cpu + stepping.cpu
        lines += [
            "",
            f"## Against Exudyn {ex['version']} (exudyn_peer's setup, step {args.exudyn_step_us:g} µs)",
            "",
            "| run | step [µs] | solve CPU [ms] | whole call CPU [ms] | solve / ours | whole call / ours (miss) |",
            "|---|---|---|---|---|---|",
            f"| Exudyn, generalized-α | {args.exudyn_step_us:g} | {_ms(run.solve.cpu)} | {_ms(run.whole.cpu)} | "
            f"{run.solve.cpu / stepping.cpu:.1f}x | {run.whole.cpu / ours_whole:.1f}x |",
            f"| ours (default) | {h * 1e6:g} | {_ms(stepping.cpu)} | {_ms(ours_whole)} | 1 | 1 |",
        ]
        for us, (prep_b, step_b, _) in whole_also.items():
            lines.append(
                f"| ours | {us:g} | {_ms(step_b.cpu)} | {_ms(prep_b.cpu + step_b.cpu)} | "
                f"Exudyn {run.solve.cpu / step_b.cpu:.1f}x | Exudyn {run.whole.cpu / (prep_b.cpu + step_b.cpu):.1f}x |"
            )
        lines += [
            "",
            "First impact against the reference (LSODA, rtol 1e-9, output 1 µs), `first_impact_errors`:",
            "",
            "| run | first-impact peak [N] | peak error | force error over the first impact |",
            "|---|---|---|---|",
            *accuracy_rows,
        ]
    else:
        lines += ["", "Exudyn: not installed (the bench extra); its rows are left out."]
    text = "\n".join(lines) + "\n"
    if args.out == "-":
        print(text)
    else:
        from _tables import write_keeping_reading  # benchmarks/_tables.py

        write_keeping_reading(args.out, text)
        print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == COLD_CHILD:
        cold_child(float(sys.argv[2]))
    else:
        sys.exit(main())
