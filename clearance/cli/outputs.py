"""What ``clearance run`` and ``clearance reference`` write beside the arrays: summary, report, console lines."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import TYPE_CHECKING

from clearance.model import Mechanism, OutputKind
from clearance.results import SimulationResult

if TYPE_CHECKING:
    from clearance.analysis.metrics.reactions import ReactionSummary

__all__ = ["write_outputs", "duration_from_args", "duration_source", "check_output_paths"]


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


def write_outputs(
    args: argparse.Namespace, mech: Mechanism, result: SimulationResult, ideal: SimulationResult, out: Path
) -> None:
    """Write arrays, summary and reactions CSVs, the Markdown report with its figures (and a rerun recording).

    Args:
        args: the command's options (``rerun``: a recording path or None).
        mech: the mechanism that ran.
        result: its run.
        ideal: the ideal twin's run.
        out: output folder (exists).
    """
    from clearance.analysis.figures.report import write_report
    from clearance.analysis.metrics.reactions import summarise_reactions, write_reactions_csv
    from clearance.analysis.metrics.summary import summarise, write_summary_csv

    result.save(out / "result")
    ideal.save(out / "ideal")
    period = mech.drive_period
    # the start-up window (the first drive period) for every statistic, section and figure; the
    # report says when a run is no longer; a mechanism driven by torques alone has none
    skip = period or 0.0
    if getattr(args, "rerun", None):
        from clearance.analysis.figures.report import joint_sections
        from clearance.analysis.recording.rerun_log import record

        # the report's Poincaré sections (t = kT of the drive, after the same transient)
        sections = joint_sections(result, skip=skip)
        rrd = Path(record(result, mech, args.rerun, ideal=ideal, poincare=sections)).resolve()
        print(f"  rerun recording written to {rrd} (open it with: rerun {rrd})")
    rows = summarise(result, ideal, startup=period or 0.0)
    write_summary_csv(rows, out / "summary.csv")
    reactions = summarise_reactions(result, ideal, startup=skip)
    write_reactions_csv(reactions, out / "reactions.csv")
    # the figures in two processes where there are two CPUs (each drawn once, the child waited for)
    write_report(out, result, ideal, skip=skip, processes=2 if (os.cpu_count() or 1) >= 2 else 1, reactions=reactions)
    output = mech.outputs[0].name
    angular = mech.outputs[0].kind is OutputKind.ANGLE
    for r in rows:
        if not r.max_penetration > 0:  # penetration = |e| - c never above 0: the journal never touched
            print(
                f"  {r.joint}: no contact (the journal stayed at least {-r.max_penetration * 1e6:.3g} µm "
                "from the bearing)"
            )
            continue
        print(
            f"  {r.joint}, whole run: peak force {r.peak_force:.4g} N at {r.peak_force_time * 1e3:.3f} ms, "
            f"p95 {r.p95_force:.4g} N, {r.impacts} impacts, in contact {r.contact_fraction:.1%}, "
            f"max penetration {r.max_penetration * 1e6:.3g} µm"
        )
        window = f"the start-up window (the first drive period, {r.startup_window * 1e3:.3g} ms)"
        if r.has_steady_state:
            print(
                f"  {r.joint}, steady state after {window}: peak force {r.steady_peak_force:.4g} N, "
                f"p95 {r.steady_p95_force:.4g} N, {r.steady_impacts} impacts, "
                f"in contact {r.steady_contact_fraction:.1%}, max penetration {r.steady_max_penetration * 1e6:.3g} µm"
            )
        elif r.startup_window > 0:
            print(f"  {r.joint}: no steady state: the run is no longer than its start-up window ({window})")
    joints = [r for r in reactions if r.kind == "joint"]
    if joints:
        loads = ", ".join(f"{r.name} {_peak(r) / 1e3:.3g} kN" for r in joints)
        print(f"  joint reactions, {'steady-state' if joints[0].has_steady_state else 'whole-run'} peaks: {loads}")
    if rows:
        unit, scale = ("rad", 1.0) if angular else ("mm", 1e3)
        print(f"  {output}: RMS deviation from ideal {rows[0].output_rms_deviation * scale:.4g} {unit}")


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
