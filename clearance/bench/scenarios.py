"""The scenarios and settings of ``clearance bench`` (speed against error), and its report.

The scenarios of the benchmark (the default slider-crank, the same at c = 0.1 mm, the same
at 200 rpm with gravity, and the seven-bar press with clearances A and C) and the grid of
settings (time step x segment count x ring contact mode, two more geom pairs, the compiled exact
contact at several steps) are
defined here; the machinery is in `clearance.bench.speed_error` and
`clearance.bench.speed_error_report`. Like the CLI, this module is the top of the
pipeline: it names builders and hands them to the analysis as picklable factories.

    clearance bench                       full benchmark into clearance-bench/ (hours on 2 cores; resumable)
    clearance bench --quick               a small grid and short runs (minutes)
    clearance bench --stage report        only rebuild the table and figure from the files
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from pathlib import Path

from clearance.bench.speed_error import Scenario, Setting

__all__ = ["FIXED_PER_REV", "default_scenarios", "settings_grid", "write_report"]

FIXED_PER_REV = {"slider_crank": 1.5}
"""Fixed wall time per revolution [s] of an exact minimal-coordinate solution of the default
scenario on the benchmark machine (docs/references.md, "The default scenario, measured"), a second baseline."""


def settings_grid(
    timesteps: Sequence[float],
    *,
    segments: Sequence[int | None] = (36, 72, None),
    modes: Sequence[str] = ("nominal", "calibrated"),
    pair_timestep: float | None = None,
    exact_timesteps: Sequence[float] = (),
) -> tuple[Setting, ...]:
    """Time step x segment count x ring contact mode (sphere/sphere), plus other pairs and exact contact.

    Args:
        timesteps: time steps [s].
        segments: segment counts (None: the ripple rule).
        modes: contact modes of the grid.
        pair_timestep: time step of the capsule/capsule and sphere/box settings (calibrated,
            ripple-rule N); None leaves them out.
        exact_timesteps: time steps of the compiled exact contact (no ring: N does not apply).
    """
    out = [Setting(h, n, contact_mode=m) for m in modes for h in timesteps for n in segments]
    if pair_timestep is not None:
        out += [
            Setting(pair_timestep, None, j, s, "calibrated") for j, s in (("capsule", "capsule"), ("sphere", "box"))
        ]
    out += [Setting(h, None, contact_mode="exact") for h in exact_timesteps]
    return tuple(out)


def default_scenarios(quick: bool = False) -> list[Scenario]:
    """The benchmark's scenarios (``quick``: a small grid and short runs, for a first look)."""
    from clearance.builders import rpm, seven_bar_press, slider_crank

    us = 1e-6
    if quick:
        grid = settings_grid([1 * us, 5 * us], segments=(72, None), exact_timesteps=[2 * us])
        return [
            Scenario(
                "slider_crank",
                functools.partial(slider_crank),
                12,
                2,
                grid,
                blocks=4,
                description="Default slider-crank (c = 0.5 mm at rod_slider, 5000 rpm), quick grid.",
            )
        ]
    fast_grid = settings_grid(  # the two 5000 rpm scenarios share one grid
        [0.5 * us, 1 * us, 2 * us, 5 * us, 10 * us],
        pair_timestep=2 * us,
        exact_timesteps=[0.5 * us, 1 * us, 2 * us, 3 * us, 5 * us, 10 * us],
    )
    return [
        Scenario(
            "slider_crank",
            functools.partial(slider_crank),
            200,
            3,
            fast_grid,
            blocks=10,
            description="Default slider-crank: c = 0.5 mm at rod_slider, 5000 rpm, no gravity.",
        ),
        Scenario(
            "slider_crank_c0.1mm",
            functools.partial(slider_crank, radial_clearance=0.1e-3),
            200,
            3,
            fast_grid,
            blocks=10,
            description="Slider-crank, c = 0.1 mm at rod_slider, 5000 rpm, no gravity.",
        ),
        Scenario(
            "slider_crank_200rpm",
            functools.partial(slider_crank, crank_speed=rpm(200), gravity=9.81),
            40,
            1,
            settings_grid(
                [1 * us, 2 * us, 5 * us, 10 * us, 20 * us],
                segments=(36, 72, 144, None),
                pair_timestep=5 * us,
                exact_timesteps=[2 * us, 5 * us, 10 * us, 20 * us],
            ),
            blocks=6,
            output_interval=5 * us,
            description="Slider-crank, c = 0.5 mm at rod_slider, 200 rpm, gravity 9.81 m/s².",
        ),
        Scenario(
            "seven_bar_press",
            functools.partial(seven_bar_press),
            6,
            0.25,
            settings_grid(
                [2 * us, 5 * us, 10 * us, 20 * us, 40 * us],
                segments=(36, 72, 144, None),
                pair_timestep=10 * us,
                exact_timesteps=[5 * us, 10 * us, 20 * us, 40 * us],
            ),
            blocks=5,
            output_interval=10 * us,
            description="Hybrid-driven seven-bar press (project dimensions), clearances A and C at 0.1 mm, "
            "both cranks at π rad/s, gravity.",
        ),
    ]


def write_report(scenarios: Sequence[Scenario], out_dir: str | Path, *, command: str = "clearance bench") -> Path:
    """Write ``speed_error.md`` and ``speed_error.png`` into ``out_dir`` from its files.

    Returns:
        The Markdown path.
    """
    import json
    import os
    import platform
    import time

    from clearance.bench.speed_error import REFERENCE
    from clearance.bench.speed_error_plot import plot_speed_error
    from clearance.bench.speed_error_report import (
        compare_scenario,
        reference_scatter,
        speed_error_markdown,
    )
    from clearance.results import atomic_write_text

    out = Path(out_dir)
    rows, parts = {}, []
    for sc in scenarios:
        fixed = FIXED_PER_REV.get(sc.name)
        rows[sc.name] = compare_scenario(sc, out, fixed_per_rev=fixed)
        ref_t = json.loads((out / "timing" / sc.name / f"{REFERENCE}.json").read_text())
        parts.append(
            speed_error_markdown(
                sc,
                rows[sc.name],
                reference_per_rev=ref_t.get("cpu_per_rev_s", ref_t["wall_per_rev_s"]),
                fixed_per_rev=fixed,
                ref_scatter=reference_scatter(sc, out),
            )
        )
    plot_speed_error(rows, path=out / "speed_error.png")
    loads = [json.loads(f.read_text()).get("load_average") for f in (out / "timing").rglob("*.json")]
    loads = [x for x in loads if x is not None]
    load_text = (
        f"1-minute load average during the timing runs {min(loads):.1f}–{max(loads):.1f} on {os.cpu_count()} CPUs"
        if loads
        else "load not recorded"
    )
    head = [
        "# Speed against error",
        "",
        f"Command: `{command}`. Machine: {platform.machine()}, Python {platform.python_version()}, "
        f"{load_text}; written {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.",
        "",
        "Columns: CPU and wall time per drive revolution (MuJoCo stepping and readout, one thread; model "
        "preparation apart; the speed-ups use the CPU time, which is the steadier on a shared machine and "
        "equals the wall time on a quiet one), speed-up against the reference solver timed in the same call "
        "(× ref) and against a fixed 1.5 s per revolution (× fixed, default scenario only); first impact: "
        "relative errors of peak contact force, maximum penetration and impulse of each joint's first impact "
        "(deterministic); the time "
        "the run separates from the reference (journal centres 10 % of the clearance apart); statistics: "
        "relative error against the reference with ± the combined standard error of both runs (batch means), "
        "worst joint shown.",
        "",
        "![speed against error](speed_error.png)",
        "",
    ]
    path = out / "speed_error.md"
    atomic_write_text(path, "\n".join(head) + "\n" + "\n".join(parts))
    return path
