"""``clearance run --model DIR``, once its options are checked: the two runs, the files and the console.

The retrofitted model and its twin run at the retrofit's step with their rows thinned beyond a size
(``--output-every-us``); each hinge's contact statistics come from every step (`summary_of_series`),
over the whole run and over the steady state after the start-up window. The end effector's
deviation from the twin is taken over the steady state, also in the floating base's frame where
the model has one (its world position then carries where the base went), and the twin is run once
more from a start nudged by rounding (`clearance.run.sensitivity`): a deviation that the nudged twin
nearly matches is chaos, not play, and the console and the report say so.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from clearance.cli.outputs import run_with_twin, writing_outputs
from clearance.result_units import result_units
from clearance.units import format_quantity as q

if TYPE_CHECKING:
    from clearance.analysis.metrics.site_deviation import SiteDeviation
    from clearance.analysis.metrics.summary import JointSummary
    from clearance.results import SimulationResult
    from clearance.retrofit.drive import Drive
    from clearance.run.retrofitted import Retrofitted
    from clearance.run.sensitivity import Sensitivity

__all__ = ["EveryStep", "run_and_write"]


@dataclass
class EveryStep:
    """Collects each hinge's penetration and contact-force magnitude at every step of a run (float32)."""

    times: list[np.ndarray] = field(default_factory=list)
    series: dict[str, list[tuple[np.ndarray, np.ndarray]]] = field(default_factory=dict)

    def __call__(self, times: np.ndarray, hinges: dict[str, tuple[np.ndarray, np.ndarray]]) -> None:
        self.times.append(np.asarray(times, dtype=float))
        for name, (pen, force) in hinges.items():
            self.series.setdefault(name, []).append((pen.astype(np.float32), force.astype(np.float32)))

    def summaries(self, startup: float) -> list[JointSummary]:
        """Each hinge's statistics over every step (`summary_of_series`)."""
        from clearance.analysis.metrics.summary import summary_of_series

        t = np.concatenate(self.times) if self.times else np.zeros(0)
        out = []
        for name, parts in self.series.items():
            pen = np.concatenate([p for p, _ in parts]).astype(float)
            force = np.concatenate([f for _, f in parts]).astype(float)
            out.append(summary_of_series(name, t, pen, force, startup=startup))
        return out


def run_and_write(
    args: argparse.Namespace,
    loaded: Retrofitted,
    drive: Drive,
    sites: list[str],
    duration: float,
    out: Path,
    *,
    startup: float,
    interval: float | None,
) -> int:
    """Run the retrofit and its twin, write every file into ``out`` and report in the console.

    Args:
        args: the command's options (``--rerun``, ``--site``).
        loaded: the retrofit. drive: its controls. sites: the point reported ([] for none).
        duration: simulated time [s]. out: the output folder.
        startup: the start-up window [s]. interval: the rows' interval [s] (None: every step).

    Returns:
        The exit status (2: the run stopped early or the twin failed).
    """
    from clearance.analysis.figures.model_report import write_model_report
    from clearance.analysis.metrics.backlash_impacts import backlash_summaries, write_backlash_csv
    from clearance.analysis.metrics.site_deviation import write_site_deviation_csv
    from clearance.analysis.metrics.summary import write_summary_csv
    from clearance.retrofit import SineControl
    from clearance.run.retrofitted import simulate_retrofitted

    _header(loaded, duration, startup, interval)
    every = EveryStep()
    runs = run_with_twin(
        lambda: simulate_retrofitted(loaded, drive, duration, sites=sites, output_interval=interval, every_step=every),
        lambda: simulate_retrofitted(loaded, drive, duration, twin=True, sites=sites, output_interval=interval),
        twin_name="the unmodified twin",
    )
    if runs is None:
        return 2
    result, twin, failed = runs
    stopped = None if failed is None else str(failed)
    if stopped is not None:
        result.metadata["stopped"] = stopped
    rows = every.summaries(startup)
    backlash = backlash_summaries(result)
    deviations, sensitivity = _deviations(loaded, drive, result, twin, sites, startup, interval)
    for run in (result, twin):  # every array's and number's unit, in the files themselves
        run.metadata["units"] = result_units(run.arrays())
        run.metadata["startup_window"] = startup
        run.metadata["rows"] = "every step" if interval is None else f"every {interval:.6g} s (thinned)"
    # contacts longer than 5 % of the sinusoid's period (of the run, under a control file) are continuous
    period = 1.0 / drive.frequency if isinstance(drive, SineControl) else duration
    with writing_outputs(out, args.rerun) as (stage, recording):  # all of them, or none
        result.save(stage / "result")
        twin.save(stage / "ideal")
        write_summary_csv(rows, stage / "summary.csv")
        if backlash:
            write_backlash_csv(backlash, stage / "backlash_summary.csv")
        if deviations:
            write_site_deviation_csv(deviations, stage / "site_deviation.csv")
        write_model_report(
            stage,
            result,
            twin,
            rows,
            deviations[0] if deviations else None,
            continuous_after=0.05 * period,
            startup=startup,
            stopped=stopped,
            frame_deviation=deviations[1] if len(deviations) > 1 else None,
            sensitivity=sensitivity,
        )
        if recording is not None:
            from clearance.analysis.recording.model_rerun import record_model_run

            record_model_run(
                result, twin, loaded.model, loaded.twin, recording, deviation=deviations[0] if deviations else None
            )
    _console(args, rows, backlash, deviations, sensitivity, startup)
    for line in _outside_region(loaded, rows):
        print(line)
    rate = float(f"{result.metadata['steps_per_second']:.3g}")
    rrd = None if not args.rerun else Path(args.rerun).resolve()
    print(f"  {rate:,.0f} steps/s; wrote {out}/" + ("" if rrd is None else f" and {rrd}"))
    if failed is not None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    return 0


def _outside_region(loaded: Retrofitted, rows: list[JointSummary]) -> list[str]:
    """A warning per robot-step radial stop that sank beyond the share of c its region allows
    (`clearance.retrofit.step_stop.MAX_PENETRATION`): the run's control closed it faster than the sizing motion."""
    from clearance.retrofit.manifest import ROBOT_STEP_MODE
    from clearance.retrofit.step_stop import MAX_PENETRATION

    m = loaded.manifest
    if m.contact_mode != ROBOT_STEP_MODE:
        return []
    c = {h.name: h.radial_clearance for h in m.hinges}
    return [
        f"  warning: {r.joint}'s stop sank {r.max_penetration / c[r.joint]:.0%} of c (its region allows "
        f"{MAX_PENETRATION:.0%}): this run closes it faster than the sizing motion did, so the robot-step stop is "
        "outside where it was fitted; retrofit with a larger clearance or a smaller --robot-step"
        for r in rows
        if r.joint in c and r.max_penetration > MAX_PENETRATION * c[r.joint]
    ]


def _header(loaded: Retrofitted, duration: float, startup: float, interval: float | None) -> None:
    from clearance.retrofit.manifest import ROBOT_STEP_MODE

    m = loaded.manifest
    play = f"radial play at {[h.name for h in m.hinges]}" if m.hinges else ""
    if m.backlash:
        arcmin = ", ".join(f"{b.name} +-{b.half_width * 10800 / math.pi:.4g}'" for b in m.backlash)
        play = f"{play}; " * bool(play) + f"backlash at {arcmin}"
    kind = (
        ""
        if not m.hinges
        else ", exact contact"
        if m.contact_mode == "exact"
        else ", tendon-limit stops at the robot's step"
        if m.contact_mode == ROBOT_STEP_MODE
        else f", {m.contact_mode} ring"
    )
    print(
        f"{loaded.folder}: {play}, {q(duration, 's', digits=4)} at h = {q(m.timestep, 's')} (the model's own "
        f"{q(m.original_timestep, 's')}){kind}"
    )
    rows = "every step" if interval is None else f"rows every {q(interval, 's')} (thinned; statistics from every step)"
    steady = (
        f"steady state after the first {q(startup, 's')}"
        if startup < duration
        else f"no steady state: the run is shorter than its start-up window {q(startup, 's')}"
    )
    print(f"  {steady}; {rows}")


def _deviations(
    loaded: Retrofitted,
    drive: Drive,
    result: SimulationResult,
    twin: SimulationResult,
    sites: list[str],
    startup: float,
    interval: float | None,
) -> tuple[list[SiteDeviation], Sensitivity | None]:
    """The site's deviation over the steady state (whole run where there is none), in the world and, for a
    floating base, in the base's frame; and the twin's sensitivity to a rounding-size nudge."""
    from clearance.analysis.metrics.site_deviation import add_frame_outputs, site_deviation
    from clearance.run.play_candidates import floating_base
    from clearance.run.sensitivity import twin_sensitivity
    from clearance.run.simulation import SimulationError

    if not sites or len(result.times) < 3:
        return [], None
    site = sites[0]
    skip = startup if result.times[-1] - result.times[0] > startup + 2 * (result.times[1] - result.times[0]) else 0.0
    out = [site_deviation(result, twin, site, skip=skip)]
    base = floating_base(loaded.twin, site)
    if base is not None and base != site:
        for run in (result, twin):
            add_frame_outputs(run, site, base)
        out.append(site_deviation(result, twin, site, skip=skip, frame=base))
    try:
        sensitivity = twin_sensitivity(loaded, drive, twin, site, output_interval=interval)
    except SimulationError:
        sensitivity = None
    return out, sensitivity


def _console(
    args: argparse.Namespace,
    rows: list[JointSummary],
    backlash: list,
    deviations: list[SiteDeviation],
    sensitivity: Sensitivity | None,
    startup: float,
) -> None:
    from clearance.run.sensitivity import is_chaos

    for r in rows:
        if not r.max_penetration > 0:
            print(f"  {r.joint}: no contact (the journal stayed {q(-r.max_penetration, 'm')} from its ring)")
            continue
        print(
            f"  {r.joint}, whole run: peak force {q(r.peak_force, 'N', digits=4)} at {q(r.peak_force_time, 's')}, "
            f"p95 {q(r.p95_force, 'N', digits=4)}, {r.impacts} impacts, max penetration {q(r.max_penetration, 'm')}"
        )
        if r.has_steady_state:
            print(
                f"  {r.joint}, after {q(startup, 's')}: peak force {q(r.steady_peak_force, 'N', digits=4)}, p95 "
                f"{q(r.steady_p95_force, 'N', digits=4)}, {r.steady_impacts} impacts, max penetration "
                f"{q(r.steady_max_penetration, 'm')}"
            )
    for b in backlash:
        print(
            f"  {b.hinge}: backlash angle in [{b.min_angle * 10800 / math.pi:.4g}, {b.max_angle * 10800 / math.pi:.4g}]"
            f"' (band +-{b.half_width * 10800 / math.pi:.4g}'), {b.impacts} impacts at its ends ({b.impacts_upper} at "
            f"+b, {b.impacts_lower} at -b), peak stop torque {q(b.peak_torque, 'N m', digits=4)} at "
            f"{q(b.peak_torque_time, 's')}"
        )
    for dev in deviations:
        where = "" if dev.frame is None else f" in the frame of its floating base {dev.frame}"
        window = "the steady state" if dev.times[0] > 0 else "the whole run"
        axes = ", ".join(f"{k.rsplit('/', 1)[1]} {q(s.rms_deviation, 'm')}" for k, s in dev.axes.items())
        print(
            f"  {dev.site}{where}: deviation from the twin up to {q(dev.max_distance, 'm')} over {window}; RMS {axes}"
            + ("" if args.site or dev.frame else " (the end effector by default: --site to choose another point)")
        )
    if deviations and deviations[0].frame is None and len(deviations) > 1:
        print(f"  (the world position carries where the floating base {deviations[1].frame} went; read the base frame)")
    if sensitivity is not None and deviations:
        worst = max(d.max_distance for d in deviations)
        verdict = (
            "chaos rather than play: the twin itself moves that far under rounding"
            if is_chaos(sensitivity, worst)
            else "the play's: the twin under rounding stays far below it"
        )
        print(
            f"  sensitivity: the twin started {sensitivity.perturbation:g} rad or m off moves {sensitivity.site} by "
            f"{q(sensitivity.max_distance, 'm')}; the deviation is {verdict}"
        )
