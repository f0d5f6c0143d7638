"""Does the robot-step model run in MuJoCo Warp? Load and step it on the CPU, and record what it took.

The model: gymnasium's pusher with radial play c = 0.7 mm at its two shoulder hinges at the
robot's step of 2 ms (`RetrofitOptions(robot_step=...)`: each journal held by a spatial-tendon
limit, stock MJCF), written by `write_retrofit` and read back from its file. It is put on a
Warp device (``warp-lang`` runs its kernels on the CPU: no GPU needed), stepped for 1 s in
`N_WORLDS` worlds, and compared with MuJoCo's C engine over the same second (Warp computes in
float32). The exact contact (the compiled plugin) is tried too, to record what Warp refuses.

Needs ``mujoco-warp`` and ``warp-lang`` (``pip install -e '.[warp]'``; not in the test extra:
Warp compiles its kernels on first use, minutes on a CPU). Run
``python benchmarks/warp_portability.py``; writes ``benchmarks/warp_portability.md``.
"""

from __future__ import annotations

import importlib.metadata
import os
import sys
import tempfile
import time
import traceback
from pathlib import Path

import mujoco
import numpy as np
from _gym import gym_model
from _tables import write_keeping_reading

from clearance.options import ContactMode
from clearance.retrofit import RadialPlay, RetrofitOptions, SineControl, retrofit, write_retrofit
from clearance.retrofit.motion import control_signal

HINGES = ("r_shoulder_pan_joint", "r_shoulder_lift_joint")
"""The pusher's hinges given radial play."""

CLEARANCE, STEP = 0.7e-3, 2e-3
"""Radial clearance [m] (the smallest both shoulders represent at 2 ms, benchmarks/robot_step_radial.md) and step [s]."""

N_WORLDS, DURATION = 8, 1.0
"""Worlds stepped together, and how long [s]."""

CONTROL = SineControl(0.5, 1.0)
"""The sizing sinusoid, the same in every world."""

TIP = "tips_arm"
"""The pusher's tool tip (a body)."""

OUT = Path(__file__).with_suffix(".md")


def written(mode: str, folder: Path) -> mujoco.MjModel:
    """The retrofitted pusher (``mode`` 'robot step' or 'exact'), written to ``folder`` and read back."""
    plays = {h: RadialPlay.make(CLEARANCE) for h in HINGES}
    if mode == "robot step":
        options = RetrofitOptions(robot_step=STEP, measure_speed=False)
    else:
        options = RetrofitOptions(contact_mode=ContactMode.EXACT, measure_speed=False)
    paths = write_retrofit(
        retrofit(mujoco.MjSpec.from_file(str(gym_model("pusher"))), plays, options), folder / mode.replace(" ", "_")
    )
    return mujoco.MjModel.from_xml_path(str(paths["model"]))


def c_engine(model: mujoco.MjModel, u: np.ndarray) -> tuple[np.ndarray, float]:
    """(tip position after the run [m], wall time [s]) in MuJoCo's C engine."""
    data = mujoco.MjData(model)
    t0 = time.perf_counter()
    for row in u:
        data.ctrl[:] = row
        mujoco.mj_step(model, data)
    wall = time.perf_counter() - t0
    mujoco.mj_kinematics(model, data)
    return data.xpos[model.body(TIP).id].copy(), wall


def in_warp(model: mujoco.MjModel, u: np.ndarray, cache: Path) -> dict[str, object]:
    """Put ``model`` on Warp's CPU device and step it; what it took and where its tip ended.

    ``cache``: Warp's kernel cache folder, empty at the first call, so the first step compiles every kernel.
    """
    import mujoco_warp as mjw
    import warp as wp

    wp.config.kernel_cache_dir = str(cache)
    wp.init()
    out: dict[str, object] = {}
    with wp.ScopedDevice("cpu"):
        t0 = time.perf_counter()
        m = mjw.put_model(model)
        d = mjw.make_data(model, nworld=N_WORLDS)
        out["put"] = time.perf_counter() - t0
        ctrl = np.repeat(u[:, None, :], N_WORLDS, axis=1).astype(np.float32)
        t0 = time.perf_counter()
        d.ctrl.assign(ctrl[0])
        mjw.step(m, d)  # the first step compiles (or loads from Warp's kernel cache) every kernel it calls
        wp.synchronize()
        out["first step"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        for row in ctrl[1:]:
            d.ctrl.assign(row)
            mjw.step(m, d)
        wp.synchronize()
        out["steps"] = time.perf_counter() - t0
        host = mujoco.MjData(model)
        tips = []
        for w in range(N_WORLDS):
            mjw.get_data_into(host, model, d, world_id=w)
            mujoco.mj_kinematics(model, host)
            tips.append(host.xpos[model.body(TIP).id].copy())
        out["tips"] = np.array(tips)
        out["finite"] = bool(np.isfinite(d.qpos.numpy()).all())
    return out


def main() -> None:
    """Run both models and write the record."""
    load = os.getloadavg()[0]
    versions = {p: importlib.metadata.version(p) for p in ("mujoco", "mujoco-warp", "warp-lang")}
    lines = [
        "# The robot-step model in MuJoCo Warp (CPU)",
        "",
        f"`python benchmarks/warp_portability.py`; Python {sys.version.split()[0]}, "
        + ", ".join(f"{p} {v}" for p, v in versions.items())
        + f"; 2 cores, load {load:.1f} at the start; Warp's kernel cache an empty folder at the start (every "
        "kernel compiled; a later run loads them from the cache).",
        "",
        f"Gymnasium's pusher with radial play c = {CLEARANCE * 1e3:g} mm at {' and '.join(HINGES)}, written as MJCF "
        f"and read back; {N_WORLDS} worlds, {DURATION:g} s of the sizing sinusoid (amplitude {CONTROL.amplitude:g}, "
        f"{CONTROL.frequency:g} Hz) from qpos0, the same controls in every world.",
        "",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for mode in ("robot step", "exact"):
            lines += [f"## {mode}", ""]
            try:
                model = written(mode, Path(tmp))
            except Exception as err:  # the exact mode without its plugin: record it
                lines += [f"Not built: {type(err).__name__}: {err}", ""]
                continue
            n = int(round(DURATION / model.opt.timestep)) if mode == "robot step" else 10
            u = control_signal(model, CONTROL, np.arange(n) * model.opt.timestep)
            lines.append(
                f"Model: step {model.opt.timestep:g} s, nq {model.nq}, ntendon {model.ntendon}, nplugin "
                f"{model.nplugin}, integrator {mujoco.mjtIntegrator(model.opt.integrator).name}; {n} steps."
            )
            try:
                got = in_warp(model, u, Path(tmp) / "warp_cache")
            except Exception as err:
                last = traceback.extract_tb(err.__traceback__)[-1]
                lines += [
                    "",
                    f"**Refused by mujoco_warp**: {type(err).__name__}: {err} (raised in "
                    f"{Path(last.filename).name}:{last.lineno}, `{last.name}`).",
                    "",
                    "Read in mujoco_warp's io.py, not run: put_model keeps only geom plugins ('filter plugins for "
                    "only geom plugins, drop the rest'), so without its plugin sensors the exact contact (instance "
                    "plugins computing passive forces) would be dropped without a word, the journals free in "
                    "their bearings. Warp's route for a compiled law is its passive-force callback (a Warp kernel "
                    "writing qfrc_passive), not the C plugin.",
                    "",
                ]
                continue
            tip, wall_c = c_engine(model, u)
            tips = got["tips"]
            assert isinstance(tips, np.ndarray)
            off = float(np.abs(tips - tip[None, :]).max())
            spread = float(np.abs(tips - tips[0]).max())
            steps = float(got["steps"])  # type: ignore[arg-type]
            lines += [
                "",
                "Loads and steps: yes" + ("" if got["finite"] else " (but the state went non-finite)") + ".",
                "",
                "| phase | wall [s] |",
                "|---|---|",
                f"| put_model + make_data | {got['put']:.2f} |",
                f"| first step (kernel compile or cache load) | {got['first step']:.1f} |",
                f"| {n - 1} further steps x {N_WORLDS} worlds | {steps:.2f} ({steps / (n - 1) * 1e3:.2f} ms per "
                f"step of all worlds) |",
                f"| MuJoCo C, the same {n} steps, 1 world | {wall_c:.3f} |",
                "",
                f"Tool tip after {n * model.opt.timestep:g} s: Warp (float32) against MuJoCo C (float64) differs by "
                f"{off * 1e6:.3g} µm at most over the worlds; the worlds differ among themselves by "
                f"{spread * 1e6:.3g} µm.",
                "",
            ]
    lines += [
        "## What a GPU run needs",
        "",
        "The same script with `wp.ScopedDevice('cuda:0')`: an NVIDIA GPU with a CUDA driver warp-lang supports "
        "(CUDA 12.4 or later for graph capture with conditional nodes: mujoco_warp warns otherwise), the kernels "
        "compiled again for that device on first use (cached in Warp's kernel cache), and thousands of worlds "
        "per call to pay for the launches (a CPU runs them one after another). The play parameters a policy "
        "randomises (tendon_range, tendon_solref_lim) are model fields Warp can batch per world "
        "(`put_model(..., batch_sizes=...)`); not measured here: this machine has no GPU.",
        "",
    ]
    print(write_keeping_reading(OUT, "\n".join(lines)))


if __name__ == "__main__":
    main()
