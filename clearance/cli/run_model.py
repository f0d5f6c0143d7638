"""``clearance run --model DIR``: run what ``clearance retrofit`` wrote, and its unmodified twin.

    clearance run --model DIR [--control CTRL.csv | --sine-amplitude A --sine-frequency-hz F]
                  [--duration-ms T] [--site NAME] [--out OUT] [--rerun RUN.rrd]

Both models run at the retrofit's time step (``DIR/retrofit.json``) from their first
keyframe under the same controls: a control file (a header ``time_s,<actuator>,...`` naming
every actuator once, ``#k`` for an unnamed one; linear interpolation, held beyond its rows)
or the sinusoid the retrofit was sized from (default). The run's arrays go to
``result.npz/json``, the twin's to ``ideal.npz/json``, with ``summary.csv`` (contact
statistics per hinge; for a backlash retrofit ``backlash_summary.csv``: per hinge the angle's
range in the band, the impacts at its ends and the peak stop torque), ``site_deviation.csv``
(of ``--site``, by default the named body deepest below the retrofitted hinges: the end
effector) and ``report.md`` with its
figures (`clearance.analysis.figures.model_report`); ``--rerun`` also records the bodies of
both models moving in 3-D with the orbits beside them (`clearance.analysis.recording.model_rerun`).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from clearance.cli.limits import check_steps
from clearance.cli.options import bounded, positive, si
from clearance.cli.outputs import writing_outputs
from clearance.result_units import result_units
from clearance.units import format_quantity as q

if TYPE_CHECKING:
    from clearance.retrofit.drive import Drive
    from clearance.run.retrofitted import Retrofitted

__all__ = ["add_model_args", "uses_model", "model_command", "SCENARIO_DESTS"]

SCENARIO_DESTS = {
    "mechanism": "--mechanism",
    "scenario": "--scenario",
    "clearance_mm": "--clearance-mm",
    "clearance_at": "--clearance-at",
    "rpm": "--rpm",
    "timestep_us": "--timestep-us",
    "segments": "--segments",
    "journal_geom": "--journal-geom",
    "segment_geom": "--segment-geom",
    "contact_mode": "--contact-mode",
    "revolutions": "--revolutions",
}
"""Options of a mechanism's run that a retrofitted model's run does not take (dest -> flag)."""

_MODEL_ONLY = {"control": "--control", "sine_amplitude": "--sine-amplitude", "sine_frequency_hz": "--sine-frequency-hz"}
_MODEL_ONLY["site"] = "--site"

DEFAULT_DURATION_MS = 1000.0


def add_model_args(r: argparse.ArgumentParser) -> None:
    """Add the options of a retrofitted model's run to ``clearance run``."""
    g = r.add_argument_group(
        "a retrofitted model (what clearance retrofit wrote) in place of a catalogue scenario",
    )
    g.add_argument(
        "--model",
        default=None,
        metavar="DIR",
        help="a folder written by clearance retrofit (or its model.xml): run it and its unmodified twin at the "
        f"retrofit's time step (default duration {DEFAULT_DURATION_MS:g} ms)",
    )
    g.add_argument(
        "--control",
        default=None,
        metavar="CTRL.csv",
        help="controls over time: header time_s and one column per actuator (its name, or #k), linear "
        "interpolation (default: the sinusoid below)",
    )
    g.add_argument(
        "--sine-amplitude",
        type=bounded(float, "--sine-amplitude", 0.0),
        default=None,
        help="sinusoid on every actuator: fraction of its control half-range, at most 1 for an actuator with a "
        "ctrlrange (default 0.5; 0: no motion)",
    )
    g.add_argument(
        "--sine-frequency-hz",
        type=positive(float, "--sine-frequency-hz"),
        default=None,
        help="frequency of that sinusoid [Hz] (default 1)",
    )
    g.add_argument(
        "--site",
        default=None,
        metavar="NAME",
        help="a site (or body) whose deviation from the twin's is reported (an end effector; default the named "
        "body deepest below the retrofitted hinges)",
    )


def uses_model(args: argparse.Namespace) -> bool:
    """True when the options ask for a retrofitted model's run; refuses a mix with the other kind.

    Raises:
        ValueError: scenario options with ``--model``, or model options without it.
    """
    if args.model is None:
        for dest, flag in _MODEL_ONLY.items():
            if getattr(args, dest, None) is not None:
                raise ValueError(f"{flag} is for a retrofitted model's run: give --model DIR too")
        return False
    for dest, flag in SCENARIO_DESTS.items():
        if getattr(args, dest, None) is not None:
            raise ValueError(f"{flag} sets a catalogue scenario; with --model the retrofit's model and time step run")
    if getattr(args, "gravity", False):
        raise ValueError("--gravity sets a catalogue scenario; with --model the model's own gravity applies")
    if args.control is not None and (args.sine_amplitude is not None or args.sine_frequency_hz is not None):
        raise ValueError("--control and --sine-amplitude/--sine-frequency-hz: give one drive, not both")
    return True


def _default_site(loaded: Retrofitted) -> list[str]:
    """The end effector a run reports without ``--site``: the named body deepest below the
    retrofitted hinges (as `clearance rank --model` scores); [] where there is none (a loop
    closure's connect alone, or no named body below)."""
    import mujoco

    from clearance.retrofit import RetrofitError
    from clearance.run.play_candidates import end_effector

    twin, m = loaded.twin, loaded.manifest
    names = [h.name for h in m.hinges] + [b.name for b in m.backlash]
    joints = [n for n in names if mujoco.mj_name2id(twin, mujoco.mjtObj.mjOBJ_JOINT, n) >= 0]
    if not joints:
        return []
    try:
        return [end_effector(twin, joints)]
    except RetrofitError:
        return []


def model_command(args: argparse.Namespace) -> int:
    """Run ``clearance run --model DIR``; returns the exit status (2: refused or stopped by an error)."""
    from clearance.cli.controls import check_sine_amplitude, read_controls
    from clearance.cli.outputs import check_output_paths
    from clearance.cli.paths import folder_lock
    from clearance.retrofit import SineControl
    from clearance.run.retrofitted import load_retrofitted

    out = check_output_paths(args)
    given = Path(args.model)
    if given.is_file() and not (given.parent / "retrofit.json").is_file():
        raise ValueError(
            f"--model {given}: a model file without the retrofit.json that clearance retrofit writes beside its "
            f"model; retrofit it first (clearance retrofit {given} --joint NAME --out DIR), then run --model DIR"
        )
    try:
        loaded = load_retrofitted(given)
    except ValueError as err:  # the message starts with the path it is about
        raise ValueError(f"--model {err}" if str(err).startswith(str(given)) else f"--model {given}: {err}") from None
    drive: Drive
    if args.control is not None:
        drive = read_controls(args.control, loaded.model, "--control")
    else:
        amplitude = 0.5 if args.sine_amplitude is None else args.sine_amplitude
        check_sine_amplitude(amplitude, loaded.model, "--sine-amplitude")
        if amplitude == 0:
            print(
                "warning: --sine-amplitude 0: the actuators get no motion; the run shows the model held at rest",
                file=sys.stderr,
            )
        drive = SineControl(amplitude, 1.0 if args.sine_frequency_hz is None else args.sine_frequency_hz)
    sites = [args.site] if args.site else _default_site(loaded)
    loaded.check_sites(sites)
    duration = si(args.duration_ms if args.duration_ms else DEFAULT_DURATION_MS, "ms")
    source = f"--duration-ms {args.duration_ms:g}" if args.duration_ms else f"the default {DEFAULT_DURATION_MS:g} ms"
    check_steps(duration, loaded.manifest.timestep, source)
    with folder_lock(out):
        return _run(args, loaded, drive, sites, duration, out)


def _run(
    args: argparse.Namespace, loaded: Retrofitted, drive: Drive, sites: list[str], duration: float, out: Path
) -> int:
    from clearance.analysis.figures.model_report import write_model_report
    from clearance.analysis.metrics.backlash_impacts import backlash_summaries, write_backlash_csv
    from clearance.analysis.metrics.site_deviation import site_deviation, write_site_deviation_csv
    from clearance.analysis.metrics.summary import summarise, write_summary_csv
    from clearance.retrofit import SineControl
    from clearance.run.retrofitted import simulate_retrofitted
    from clearance.run.simulation import SimulationError

    m = loaded.manifest
    play = f"radial play at {[h.name for h in m.hinges]}" if m.hinges else ""
    if m.backlash:
        arcmin = ", ".join(f"{b.name} +-{b.half_width * 10800 / math.pi:.4g}'" for b in m.backlash)
        play = f"{play}; " * bool(play) + f"backlash at {arcmin}"
    kind = "" if not m.hinges else ", exact contact" if m.contact_mode == "exact" else f", {m.contact_mode} ring"
    print(
        f"{loaded.folder}: {play}, {q(duration, 's', digits=4)} at h = {q(m.timestep, 's')} (the model's own "
        f"{q(m.original_timestep, 's')}){kind}"
    )
    failed = None
    try:
        result = simulate_retrofitted(loaded, drive, duration, sites=sites)
    except SimulationError as err:
        failed, partial = err, err.partial
        if partial is None:
            print(f"error: {failed}", file=sys.stderr)
            return 2
        result = partial
    try:
        twin = simulate_retrofitted(loaded, drive, duration, twin=True, sites=sites)
    except SimulationError as err:
        print(f"error: the unmodified twin, needed for the deviations: {err}", file=sys.stderr)
        return 2
    for run in (result, twin):  # every array's and number's unit, in the files themselves
        run.metadata["units"] = result_units(run.arrays())
    stopped = None if failed is None else str(failed)
    if stopped is not None:
        result.metadata["stopped"] = stopped
    rows = summarise(result, None)
    backlash = backlash_summaries(result)
    deviation = site_deviation(result, twin, sites[0]) if sites and len(result.times) >= 3 else None
    # contacts longer than 5 % of the sinusoid's period (of the run, under a control file) are continuous
    period = 1.0 / drive.frequency if isinstance(drive, SineControl) else duration
    with writing_outputs(out, args.rerun) as (stage, recording):  # all of them, or none
        result.save(stage / "result")
        twin.save(stage / "ideal")
        write_summary_csv(rows, stage / "summary.csv")
        if backlash:
            write_backlash_csv(backlash, stage / "backlash_summary.csv")
        if deviation is not None:
            write_site_deviation_csv(deviation, stage / "site_deviation.csv")
        write_model_report(stage, result, twin, rows, deviation, continuous_after=0.05 * period, stopped=stopped)
        if recording is not None:
            from clearance.analysis.recording.model_rerun import record_model_run

            record_model_run(result, twin, loaded.model, loaded.twin, recording, deviation=deviation)
    rrd = None if not args.rerun else Path(args.rerun).resolve()
    for r in rows:
        if not r.max_penetration > 0:
            print(f"  {r.joint}: no contact (the journal stayed {q(-r.max_penetration, 'm')} from its ring)")
            continue
        print(
            f"  {r.joint}, whole run: peak force {q(r.peak_force, 'N', digits=4)} at {q(r.peak_force_time, 's')}, "
            f"p95 {q(r.p95_force, 'N', digits=4)}, {r.impacts} impacts, max penetration {q(r.max_penetration, 'm')}"
        )
    for b in backlash:
        print(
            f"  {b.hinge}: backlash angle in [{b.min_angle * 10800 / math.pi:.4g}, {b.max_angle * 10800 / math.pi:.4g}]"
            f"' (band +-{b.half_width * 10800 / math.pi:.4g}'), {b.impacts} impacts at its ends ({b.impacts_upper} at "
            f"+b, {b.impacts_lower} at -b), peak stop torque {q(b.peak_torque, 'N m', digits=4)} at "
            f"{q(b.peak_torque_time, 's')}"
        )
    if deviation is not None:
        axes = ", ".join(f"{k.rsplit('/', 1)[1]} {q(s.rms_deviation, 'm')}" for k, s in deviation.axes.items())
        print(
            f"  {deviation.site}: deviation from the twin up to {q(deviation.max_distance, 'm')} over the whole run; "
            f"RMS {axes}" + ("" if args.site else " (the end effector by default: --site to choose another point)")
        )
    rate = float(f"{result.metadata['steps_per_second']:.3g}")
    print(f"  {rate:,.0f} steps/s; wrote {out}/" + ("" if rrd is None else f" and {rrd}"))
    if failed is not None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    return 0
