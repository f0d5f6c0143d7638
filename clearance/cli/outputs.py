"""What ``clearance run`` and ``clearance reference`` write beside the arrays: summary, report, console lines."""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from clearance.model import Mechanism, OutputKind
from clearance.result_units import result_units
from clearance.results import SimulationResult
from clearance.units import format_quantity

if TYPE_CHECKING:
    from clearance.analysis.metrics.film import FilmSummary
    from clearance.analysis.metrics.reactions import ReactionSummary
    from clearance.analysis.metrics.summary import JointSummary
    from clearance.run.simulation import SimulationError

__all__ = [
    "write_outputs",
    "writing_outputs",
    "note_stop",
    "console_lines",
    "slider_lines",
    "calibration_lines",
    "duration_from_args",
    "duration_source",
    "check_output_paths",
    "run_with_twin",
]


def check_output_paths(args: argparse.Namespace) -> Path:
    """Check ``--out`` (a folder) and ``--rerun`` (a file) before any work; the folder.

    Raises:
        ValueError: either cannot be written (`clearance.cli.paths`), with the path and why.
    """
    from clearance.cli.paths import check_file, check_folder

    out = check_folder(args.out, "--out")
    if getattr(args, "rerun", None) is not None:
        check_file(args.rerun, "--rerun", example="run.rrd")
    return out


def run_with_twin(
    run: Callable[[], SimulationResult], twin: Callable[[], SimulationResult], *, twin_name: str
) -> tuple[SimulationResult, SimulationResult, SimulationError | None] | None:
    """Run a model, then its twin, as the run commands do; None (after printing why) when there is
    nothing to write.

    A run that stops (`clearance.run.simulation.SimulationError`) keeps what it computed: its
    partial result is returned with the error, for the outputs and the closing error line. A stop
    with no rows, or a twin that stops, is printed as one error line.

    Args:
        run: simulates the model.
        twin: simulates its twin (the deviations need all of it).
        twin_name: what the twin is, for its error line ("the ideal twin (no clearance)").

    Returns:
        (result, twin's result, the run's stop or None), or None.
    """
    import sys

    from clearance.run.simulation import SimulationError

    failed = None
    try:
        result = run()
    except SimulationError as err:
        failed, partial = err, err.partial
        if partial is None:
            print(f"error: {failed}", file=sys.stderr)
            return None
        result = partial
    try:
        other = twin()
    except SimulationError as err:
        print(f"error: {twin_name}, needed for the deviations: {err}", file=sys.stderr)
        return None
    return result, other, failed


@contextmanager
def writing_outputs(out: Path, rerun: str | None) -> Iterator[tuple[Path, Path | None]]:
    """Where a run writes its files: a private folder and a hidden recording path, published together.

    The files go into a private folder beside ``out`` (`clearance.cli.paths.staged_outputs`) and
    the recording, if asked for, to a hidden name beside ``rerun``; when the block ends without
    an error the files move into ``out`` and the recording takes its name. A block that fails
    (a full disk, a fault) leaves neither: no file that looks like a finished run.

    Args:
        out: the output folder (exists; locked).
        rerun: the recording's path (``--rerun``), or None.

    Yields:
        (the folder to write the files in, the path to write the recording to or None).
    """
    from clearance.cli.paths import staged_outputs

    final = None if not rerun else Path(rerun).resolve()
    tmp = None if final is None else final.with_name(f".partial-{os.getpid()}-{final.name}")
    try:
        with staged_outputs(out) as stage:
            yield stage, tmp
        if final is not None and tmp is not None and tmp.exists():
            os.replace(tmp, final)
            print(f"  rerun recording written to {final} (open it with: rerun {final})")
    finally:
        if tmp is not None:
            tmp.unlink(missing_ok=True)


def note_stop(report: Path, stopped: str) -> None:
    """Put a run's stop at the head of its report, so the files of a stopped run never read as finished."""
    text = report.read_text(encoding="utf-8") if report.exists() else ""
    head = f"**This run stopped before its end: {stopped}. Every file here holds the run up to that time.**\n\n"
    report.write_text(head + text, encoding="utf-8")


def write_outputs(
    args: argparse.Namespace,
    mech: Mechanism,
    result: SimulationResult,
    ideal: SimulationResult,
    out: Path,
    *,
    recording: Path | None = None,
    stopped: str | None = None,
) -> None:
    """Write arrays, summary and reactions CSVs, the Markdown report with its figures (and a rerun recording).

    Args:
        args: the command's options.
        mech: the mechanism that ran.
        result: its run.
        ideal: the ideal twin's run.
        out: output folder (exists; `writing_outputs`' private folder).
        recording: where to write the rerun recording, or None for none.
        stopped: why the run stopped before its end (its result is the part before), or None;
            said in ``result.json`` (``stopped``) and at the head of ``report.md``.
    """
    from clearance.analysis.figures.report import write_report
    from clearance.analysis.metrics.reactions import summarise_reactions, write_reactions_csv
    from clearance.analysis.metrics.summary import summarise, write_summary_csv

    angular = [o.name for o in mech.outputs if o.kind is OutputKind.ANGLE]
    for run in (result, ideal):  # every array's and number's unit, in the files themselves
        run.metadata["units"] = result_units(run.arrays(), angular)
    if stopped is not None:
        result.metadata["stopped"] = stopped
    result.save(out / "result")
    ideal.save(out / "ideal")
    period = mech.drive_period
    # the start-up window (the first drive period) for every statistic, section and figure; the
    # report says when a run is no longer; a mechanism driven by torques alone has none
    skip = period or 0.0
    if recording is not None:
        from clearance.analysis.figures.report import joint_sections
        from clearance.analysis.recording.rerun_log import record

        # the report's Poincaré sections (t = kT of the drive, after the same transient)
        sections = joint_sections(result, skip=skip)
        record(result, mech, recording, ideal=ideal, poincare=sections)
    rows = summarise(result, ideal, startup=period or 0.0)
    write_summary_csv(rows, out / "summary.csv")
    reactions = summarise_reactions(result, ideal, startup=skip)
    write_reactions_csv(reactions, out / "reactions.csv")
    # the figures in two processes where there are two CPUs (each drawn once, the child waited for)
    write_report(out, result, ideal, skip=skip, processes=2 if (os.cpu_count() or 1) >= 2 else 1, reactions=reactions)
    if stopped is not None:
        note_stop(out / "report.md", stopped)
    from clearance.analysis.metrics.film import film_summaries

    for line in console_lines(mech, rows, reactions, films=film_summaries(result)):
        print(line)
    for line in slider_lines(result):
        print(line)


def console_lines(
    mech: Mechanism,
    rows: list[JointSummary],
    reactions: list[ReactionSummary],
    *,
    films: Sequence[FilmSummary] = (),
) -> list[str]:
    """The run's numbers for the console: contact per joint, reaction peaks, the output's deviation.

    Every number is in the unit its size calls for (`clearance.units.format_quantity`: 45.9 kN,
    252 µs), and every statistic says whether it is over the whole run or the steady state. A
    lubricated joint says whether its oil film carried the load (its minimum film thickness,
    largest eccentricity ratio and peak film force) or ruptured into dry contact.

    Args:
        mech: the mechanism that ran (its first output is the one measured).
        rows: `summarise`'s rows, one per clearance joint.
        reactions: `summarise_reactions`' rows.
        films: `film_summaries`' rows over the whole run, one per lubricated joint.
    """
    q = format_quantity
    lines = []
    oiled = {f.joint: f for f in films}
    for r in rows:
        film = oiled.get(r.joint)
        if film is not None and film.film_carried_the_load:
            lines.append(
                f"  {r.joint}: no dry contact: the oil film carried the load (minimum film thickness "
                f"{q(film.min_film_thickness, 'm')}, largest eccentricity ratio {film.max_eccentricity_ratio:.3g}, "
                f"peak film force {q(film.peak_film_force, 'N')} at {q(film.peak_film_force_time, 's')})"
            )
            continue
        if not r.max_penetration > 0:  # penetration = |e| - c never above 0: the journal never touched
            what = "the slider's corners" if r.joint in {j.name for j in mech.translational_joints} else "the journal"
            where = "guide" if what != "the journal" else "bearing"
            lines.append(
                f"  {r.joint}: no contact ({what} stayed at least {q(-r.max_penetration, 'm')} from the {where})"
            )
            continue
        if film is not None:
            lines.append(
                f"  {r.joint}: the oil film ruptured: dry contact in {film.dry_fraction:.1%} of the run "
                f"(largest eccentricity ratio {film.max_eccentricity_ratio:.3g}; peak film force "
                f"{q(film.peak_film_force, 'N')}); the force below is film and dry contact together"
            )
        lines.append(
            f"  {r.joint}, whole run: peak force {q(r.peak_force, 'N', digits=4)} at {q(r.peak_force_time, 's')}, "
            f"p95 {q(r.p95_force, 'N', digits=4)}, {r.impacts} impacts, in contact {r.contact_fraction:.1%}, "
            f"max penetration {q(r.max_penetration, 'm')}"
        )
        window = f"the start-up window (the first drive period, {q(r.startup_window, 's')})"
        if r.has_steady_state:
            lines.append(
                f"  {r.joint}, steady state after {window}: peak force {q(r.steady_peak_force, 'N', digits=4)}, "
                f"p95 {q(r.steady_p95_force, 'N', digits=4)}, {r.steady_impacts} impacts, "
                f"in contact {r.steady_contact_fraction:.1%}, max penetration {q(r.steady_max_penetration, 'm')}"
            )
        elif r.startup_window > 0:
            lines.append(f"  {r.joint}: no steady state: the run is no longer than {window}")
    joints = [r for r in reactions if r.kind == "joint"]
    if joints:
        loads = ", ".join(f"{r.name} {q(_peak(r), 'N')}" for r in joints)
        lines.append(
            f"  joint reactions, {'steady-state' if joints[0].has_steady_state else 'whole-run'} peaks: {loads}"
        )
    if rows:
        output = mech.outputs[0].name
        unit = "rad" if mech.outputs[0].kind is OutputKind.ANGLE else "m"
        r = rows[0]
        text = f"  {output}: RMS deviation from ideal {q(r.output_rms_deviation, unit, digits=4)} over the whole run"
        if r.has_steady_state and math.isfinite(r.steady_output_rms_deviation):
            text += (
                f", {q(r.steady_output_rms_deviation, unit, digits=4)} in the steady state (after "
                f"{q(r.startup_window, 's')}, as the report gives it)"
            )
        lines.append(text)
    return lines


def slider_lines(result: SimulationResult) -> list[str]:
    """One console line per slider with play: time in each contact case, largest tilt and force."""
    from clearance.analysis.metrics.slider import slider_summary

    q = format_quantity
    lines = []
    for joint, sr in result.sliders.items():
        s = slider_summary(result.times, sr)
        shares = ", ".join(f"{c.name.lower().replace('_', ' ')} {v:.1%}" for c, v in s.shares.items())
        lines.append(
            f"  {joint}, whole run: {shares} ({s.switches} switches); largest tilt {q(s.max_tilt, 'rad')}, "
            f"peak corner force {q(s.peak_corner_force, 'N')}, max penetration {q(s.max_penetration, 'm')}"
        )
    return lines


def calibration_lines(contact: dict[str, dict[str, object]], started: float) -> list[str]:
    """Whether each ring's calibration was fitted by this command or reused from the cache, and where.

    Args:
        contact: the prepared model's per-joint contact metadata (``source``: ``calibrated:
            <file>`` for a calibrated ring, ``calibrated: not cached`` where the cache folder
            could not be written).
        started: when the command began preparing its models (`time.time`): a file written
            since was fitted now.

    Returns:
        One line per calibrated joint (none for the exact contact or the nominal ring).
    """
    import datetime

    lines = []
    for joint, meta in contact.items():
        source = str(meta.get("source", ""))
        if not source.startswith("calibrated: "):
            continue
        where = source.removeprefix("calibrated: ")
        if where == "not cached":
            lines.append(f"  {joint}: contact calibration fitted now, not stored (the cache folder cannot be written)")
            continue
        try:
            fitted = os.stat(where).st_mtime
        except OSError:
            fitted = started
        if fitted >= started - 1.0:  # written by this command (1 s: file systems' time resolution)
            lines.append(f"  {joint}: contact calibration fitted now and stored in {where} (later runs reuse it)")
        else:
            when = datetime.datetime.fromtimestamp(fitted).strftime("%Y-%m-%d %H:%M")
            lines.append(f"  {joint}: contact calibration reused from {where} (fitted {when})")
    return lines


def _peak(r: ReactionSummary) -> float:
    """A reaction's steady-state peak where the run has a steady state, else its whole-run peak."""
    return r.steady_peak if r.has_steady_state else r.peak


def duration_source(args: argparse.Namespace, default_revolutions: float) -> str:
    """The options that set the simulated time, for a message (``--duration-ms 5``)."""
    if args.duration_ms:
        return f"--duration-ms {args.duration_ms:g}"
    if args.revolutions is not None:
        return f"--revolutions {args.revolutions:g}"
    return f"the default {default_revolutions:g} revolutions"


def duration_from_args(args: argparse.Namespace, mech: Mechanism, default_revolutions: float) -> float:
    """Simulated time [s]: --duration-ms, else --revolutions of the slowest speed-driven crank.

    Args:
        args: the command's options (``duration_ms``, ``revolutions``).
        mech: the mechanism to run.
        default_revolutions: revolutions when neither option is given.

    Returns:
        The duration [s].

    Raises:
        ValueError: --revolutions for a mechanism driven by torques alone (it has no period).
    """
    from clearance.cli.options import si
    from clearance.run.simulation import default_duration

    if args.duration_ms:
        return si(args.duration_ms, "ms")
    if mech.drive_period is None:
        if args.revolutions is not None:
            raise ValueError(
                f"--revolutions {args.revolutions:g}: mechanism '{mech.name}' is driven by torques "
                "alone and has no drive period; give the simulated time with --duration-ms"
            )
        duration = default_duration(mech)
        print(f"{mech.name} is driven by torques alone: simulating {duration:g} s (set it with --duration-ms)")
        return duration
    return default_duration(mech, default_revolutions if args.revolutions is None else args.revolutions)
