"""The `clearance` command line: the top of the pipeline (may import everything).

    clearance run        simulate a scenario and write arrays, summary, figures, MJCF
    clearance reference  run a scenario with the exact-geometry reference solver
    clearance mjcf       write the MuJoCo model of a scenario
    clearance calibrate  fit contact parameters to LN impacts and write a report
    clearance sweep      bifurcation diagram over clearance or drive speed (resumable)
    clearance rank       joint criticality ranking (resumable)
    clearance bench      speed against error of MuJoCo settings (resumable)

Units on the command line are the ones people use (mm, rpm, µs); they are converted to SI
here, once.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["main", "build_parser"]


from clearance.cli_options import add_scenario_args as _add_scenario_args
from clearance.cli_options import mechanism_from_args as _mechanism
from clearance.cli_options import numerics_given as _numerics_given
from clearance.cli_options import options_from_args as _options
from clearance.cli_options import positive as _positive


_FORWARDED = {
    "calibrate": ("clearance.contact_calibration.report", "main_calibrate",
                  "fit contact parameters to LN impacts; table and force-time plot"),
    "sweep": ("clearance.analysis.cli_commands", "main_sweep",
              "bifurcation diagram over clearance or drive speed (resumable sweep)"),
    "rank": ("clearance.analysis.cli_commands", "main_rank", "joint criticality ranking (resumable sweep)"),
    "bench": ("clearance.bench", "main_bench", "speed against error of MuJoCo settings against the reference solver"),
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the `clearance` command."""
    p = argparse.ArgumentParser(prog="clearance", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    for name, (_, _, text) in _FORWARDED.items():
        sub.add_parser(name, help=f"{text} (see 'clearance {name} --help')", add_help=False)
    r = sub.add_parser("run", help="simulate a scenario and write results, figures and the model")
    _add_scenario_args(r)
    r.add_argument("--revolutions", type=_positive(float, "--revolutions"), default=None,
                   help="revolutions of the slowest speed-driven crank to simulate (default 3)")
    r.add_argument("--duration-ms", type=_positive(float, "--duration-ms"), default=None,
                   help="simulated time [ms] (overrides --revolutions)")
    r.add_argument("--out", default="clearance-out", help="output folder (default clearance-out)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument("--rerun", default=None, metavar="PATH",
                   help="also write a rerun recording (.rrd) of the run and its ideal twin to PATH")
    f = sub.add_parser("reference", help="run a scenario with the exact-geometry reference solver (slow)")
    _add_scenario_args(f, numerics=False)  # MuJoCo numerics are refused (see _cmd_reference)
    f.add_argument("--revolutions", type=_positive(float, "--revolutions"), default=None,
                   help="revolutions of the slowest speed-driven crank to simulate (default 1)")
    f.add_argument("--duration-ms", type=_positive(float, "--duration-ms"), default=None,
                   help="simulated time [ms] (overrides --revolutions)")
    f.add_argument("--rtol", type=_positive(float, "--rtol"), default=1e-9, help="relative tolerance (default 1e-9)")
    f.add_argument("--output-us", type=_positive(float, "--output-us"), default=10.0,
                   help="output interval [µs] (default 10)")
    f.add_argument("--out", default="clearance-reference-out", help="output folder (default clearance-reference-out)")
    f.add_argument("--rerun", default=None, metavar="PATH", help="also write a rerun recording (.rrd) to PATH")
    f.add_argument("--no-progress", action="store_true", help="no progress bar")
    m = sub.add_parser("mjcf", help="write the MuJoCo model (MJCF) of a scenario")
    _add_scenario_args(m)
    m.add_argument("--out", default="model.xml", help="MJCF file to write (default model.xml)")
    m.add_argument("--ideal", action="store_true", help="write the ideal twin instead")
    return p


def _cmd_mjcf(args) -> int:
    from clearance.preparation import prepare
    from clearance.results import atomic_write_text

    mech = _mechanism(args)
    if args.ideal:
        mech = mech.ideal_twin()
    prepared = prepare(mech, _options(args))
    atomic_write_text(args.out, prepared.to_xml())
    print(f"wrote {args.out}")
    return 0


def _write_outputs(args, mech, result, ideal, out: Path) -> None:
    """Arrays, summary CSV, the Markdown report with its figures (and a rerun recording)."""
    from clearance.analysis.report import write_report
    from clearance.analysis.summary import summarise, write_summary_csv

    result.save(out / "result")
    ideal.save(out / "ideal")
    periods = [d.period for d in mech.drives if d.kind.value != "torque"]
    # statistics skip the first drive period as start-up transient when the run is long enough;
    # a mechanism driven by torques alone has no period: nothing is skipped
    skip = min(periods) if periods and result.times[-1] > 2 * min(periods) else 0.0
    if getattr(args, "rerun", None):
        from clearance.analysis.rerun_log import record
        from clearance.analysis.report import joint_sections

        # the report's Poincaré sections (t = kT of the drive, after the same transient)
        sections = joint_sections(result, skip=skip)
        print(f"  wrote {record(result, mech, args.rerun, ideal=ideal, poincare=sections)}")
    rows = summarise(result, ideal)
    write_summary_csv(rows, out / "summary.csv")
    write_report(out, result, ideal, skip=skip)
    output = mech.outputs[0].name
    angular = mech.outputs[0].kind.value == "angle"
    for r in rows:
        if not r.max_penetration > 0:  # penetration = |e| - c never above 0: the journal never touched
            print(f"  {r.joint}: no contact (the journal stayed at least {-r.max_penetration * 1e6:.3g} µm "
                  "from the bearing)")
            continue
        print(f"  {r.joint}: peak force {r.peak_force:.4g} N at {r.peak_force_time * 1e3:.3f} ms, "
              f"p95 {r.p95_force:.4g} N, {r.impacts} impacts, in contact {r.contact_fraction:.1%}, "
              f"max penetration {r.max_penetration * 1e6:.3g} µm")
    if rows:
        unit, scale = ("rad", 1.0) if angular else ("mm", 1e3)
        print(f"  {output}: RMS deviation from ideal {rows[0].output_rms_deviation * scale:.4g} {unit}")


def _duration(args, mech, default_revolutions: float) -> float:
    """Simulated time [s]: --duration-ms, else --revolutions of the slowest speed-driven crank.

    Raises:
        ValueError: --revolutions for a mechanism driven by torques alone (it has no period).
    """
    from clearance.simulation import default_duration

    if args.duration_ms:
        return args.duration_ms * 1e-3
    if all(d.kind.value == "torque" for d in mech.drives):
        if args.revolutions is not None:
            raise ValueError(f"--revolutions {args.revolutions:g}: mechanism '{mech.name}' is driven by torques "
                             "alone and has no drive period; give the simulated time with --duration-ms")
        duration = default_duration(mech)
        print(f"{mech.name} is driven by torques alone: simulating {duration:g} s (set it with --duration-ms)")
        return duration
    return default_duration(mech, default_revolutions if args.revolutions is None else args.revolutions)


def _cmd_run(args) -> int:
    from clearance.preparation import prepare
    from clearance.results import atomic_write_text
    from clearance.simulation import SimulationError, simulate_prepared

    mech = _mechanism(args)
    options = _options(args)
    duration = _duration(args, mech, 3.0)
    out = Path(args.out)
    prepared = prepare(mech, options)
    ideal_prepared = prepare(mech.ideal_twin(), options)
    out.mkdir(parents=True, exist_ok=True)  # only once the models are built: a refused run leaves no folder
    atomic_write_text(out / "model.xml", prepared.to_xml())
    atomic_write_text(out / "ideal_model.xml", ideal_prepared.to_xml())
    print(f"{mech.name}: clearance at {[j.name for j in mech.clearance_joints]}, "
          f"{duration * 1e3:.3g} ms at h = {options.timestep:g} s, segments {prepared.metadata['segments']}")
    progress = not args.no_progress
    failed = None
    try:
        result = simulate_prepared(prepared, duration=duration, progress=progress)
    except SimulationError as err:
        failed, result = err, err.partial
    if result is None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    ideal = simulate_prepared(ideal_prepared, duration=duration, progress=progress)
    _write_outputs(args, mech, result, ideal, out)
    print(f"  {result.metadata['steps_per_second']:.3g} steps/s; wrote {out}/")
    if failed is not None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    return 0


def _cmd_reference(args) -> int:
    from clearance.reference import ReferenceSolverError, run_reference

    given = _numerics_given(args)
    if given:
        raise ValueError(
            f"clearance reference does not take {', '.join(given)}: those are MuJoCo options, and the "
            "reference solver has exact circle-in-circle geometry (no segments or geoms), applies each "
            "joint's contact law exactly (no contact mode) and takes adaptive steps (no time step); "
            "set its accuracy with --rtol and its output interval with --output-us"
        )
    mech = _mechanism(args)
    duration = _duration(args, mech, 1.0)
    out = Path(args.out)
    print(f"{mech.name} (reference solver): clearance at {[j.name for j in mech.clearance_joints]}, "
          f"{duration * 1e3:.3g} ms, rtol {args.rtol:g}")
    progress = not args.no_progress
    failed = None
    try:
        result = run_reference(mech, duration, output_interval=args.output_us * 1e-6, rtol=args.rtol, progress=progress)
    except ReferenceSolverError as err:
        failed, result = err, getattr(err, "partial", None)
    if result is None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    print(f"  ideal twin (no clearance), {duration * 1e3:.3g} ms, for the deviations")
    ideal = run_reference(mech.ideal_twin(), duration, output_interval=args.output_us * 1e-6, rtol=args.rtol,
                          progress=progress)
    out.mkdir(parents=True, exist_ok=True)
    _write_outputs(args, mech, result, ideal, out)
    print(f"  wall time {result.metadata.get('wall_time_s', float('nan')):.3g} s; wrote {out}/")
    if failed is not None:
        print(f"error: {failed}", file=sys.stderr)
        return 2
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `clearance` console script."""
    import importlib

    from clearance.kinematics import AssemblyError

    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in _FORWARDED:
        module, func, _ = _FORWARDED[argv[0]]
        return getattr(importlib.import_module(module), func)(argv[1:])
    args = build_parser().parse_args(argv)
    try:
        if args.command == "run":
            return _cmd_run(args)
        if args.command == "mjcf":
            return _cmd_mjcf(args)
        if args.command == "reference":
            return _cmd_reference(args)
    except (ValueError, AssemblyError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    return 1


if __name__ == "__main__":
    sys.exit(main())
