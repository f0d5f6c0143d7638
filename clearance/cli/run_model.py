"""``clearance run --model DIR``: run what ``clearance retrofit`` wrote, and its unmodified twin.

    clearance run --model DIR [--control CTRL.csv | --sine-amplitude A --sine-frequency-hz F]
                  [--duration-ms T] [--startup-ms S] [--output-every-us U] [--site NAME] [--out OUT]
                  [--rerun RUN.rrd]

Both models run at the retrofit's time step (``DIR/retrofit.json``) from their first
keyframe under the same controls: a control file (a header ``time_s,<actuator>,...`` naming
every actuator once, ``#k`` for an unnamed one; linear interpolation, held beyond its rows)
or the sinusoid the retrofit was sized from (default). The journals start centred, so their
first drop falls in a start-up window (``--startup-ms``; by default 0.25 s or one period of
the sinusoid, the longer) and the steady-state statistics start after it. The run's arrays go
to ``result.npz/json``, the twin's to ``ideal.npz/json`` (rows thinned beyond `OUTPUT_BUDGET`
bytes per run; ``--output-every-us``), with ``summary.csv`` (contact statistics per hinge from
every step, over the whole run and the steady state; for a backlash retrofit
``backlash_summary.csv``: per hinge the angle's range in the band, the impacts at its ends and
the peak stop torque), ``site_deviation.csv`` (of ``--site``, by default the named body deepest
below the retrofitted hinges: the end effector; also in its floating base's frame where the
model has one) and ``report.md`` with its figures (`clearance.analysis.figures.model_report`),
which also says whether the deviation is the play's or chaos (the twin against itself nudged
by rounding); ``--rerun`` also records the bodies of both models moving in 3-D with the orbits
beside them (`clearance.analysis.recording.model_rerun`). The run itself is
`clearance.cli.run_model_output`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from clearance.cli.limits import check_steps
from clearance.cli.options import bounded, positive, si
from clearance.cli.run_model_output import run_and_write

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
_MODEL_ONLY |= {"site": "--site", "startup_ms": "--startup-ms", "output_every_us": "--output-every-us"}

DEFAULT_DURATION_MS = 1000.0

OUTPUT_BUDGET = 20e6
"""Bytes of arrays a run keeps by default [B]: beyond it its rows are thinned (a run and its twin stay
under 50 MB together, figures included); peaks and contact statistics come from every step anyway."""

DEFAULT_STARTUP_MS = 250.0
"""The start-up window's floor [ms] (as `clearance rank --model` skips); a sinusoid's run skips one of its
periods where that is longer."""


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
        f"retrofit's time step (default duration {DEFAULT_DURATION_MS:g} ms, or twice the start-up window where that "
        "is longer: 2 s under the default 1 Hz sinusoid)",
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
        "--startup-ms",
        type=bounded(float, "--startup-ms", 0.0),
        default=None,
        help=f"start-up window [ms]: the steady-state statistics start after it (default {DEFAULT_STARTUP_MS:g} ms or "
        "one period of the sinusoid, whichever is longer; the journals start centred, so their first drop is in it)",
    )
    g.add_argument(
        "--output-every-us",
        type=bounded(float, "--output-every-us", 0.0),
        default=None,
        help="interval of the rows kept in result.npz and ideal.npz [us] (default: every step up to "
        f"{OUTPUT_BUDGET / 1e6:g} MB of arrays per run, thinned beyond; peaks and contact statistics always from every "
        "step; 0: every step)",
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
    startup = startup_window(args.startup_ms, drive)
    # by default the run leaves a steady state as long as its start-up window
    duration = si(args.duration_ms, "ms") if args.duration_ms else max(si(DEFAULT_DURATION_MS, "ms"), 2 * startup)
    source = f"--duration-ms {args.duration_ms:g}" if args.duration_ms else f"the default {duration * 1e3:g} ms"
    check_steps(duration, loaded.manifest.timestep, source)
    if args.startup_ms is not None and startup >= duration:
        raise ValueError(
            f"--startup-ms {args.startup_ms:g}: the start-up window must be shorter than the run "
            f"({duration * 1e3:g} ms); lower it or give a longer --duration-ms"
        )
    interval = output_interval(args.output_every_us, loaded, duration, sites)
    with folder_lock(out):
        return run_and_write(args, loaded, drive, sites, duration, out, startup=startup, interval=interval)


def startup_window(startup_ms: float | None, drive: Drive) -> float:
    """The start-up window [s]: ``--startup-ms``, else `DEFAULT_STARTUP_MS` or one sinusoid period, the longer."""
    from clearance.retrofit import SineControl

    if startup_ms is not None:
        return si(startup_ms, "ms")
    period = 1.0 / drive.frequency if isinstance(drive, SineControl) else 0.0
    return max(si(DEFAULT_STARTUP_MS, "ms"), period)


def output_interval(every_us: float | None, loaded: Retrofitted, duration: float, sites: list[str]) -> float | None:
    """The rows' interval [s]: ``--output-every-us`` (0: every step), else every step within `OUTPUT_BUDGET`."""
    from clearance.run.retrofit_rows import default_output_interval, row_bytes

    if every_us is not None:
        return None if every_us == 0 else max(si(every_us, "us"), loaded.manifest.timestep)
    m = loaded.manifest
    per_row = row_bytes(loaded.model, len(m.hinges), len(sites), len(m.backlash))
    return default_output_interval(loaded.model, duration, per_row, OUTPUT_BUDGET)
