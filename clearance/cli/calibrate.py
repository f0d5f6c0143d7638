"""``clearance calibrate``: fit the contact of every clearance joint of a scenario to LN impacts."""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from clearance.cli.messages import error
from clearance.cli.options import (
    add_scenario_args,
    bounded,
    mechanism_from_args,
    options_from_args,
)
from clearance.cli.parser import CommandParser
from clearance.cli.paths import check_folder, folder_lock, staged_outputs
from clearance.model import Mechanism
from clearance.options import ContactMode, ModelOptions

__all__ = ["calibrate_parser", "main_calibrate"]


def calibrate_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance calibrate``."""
    p = CommandParser(
        prog="clearance calibrate",
        description="Fit the MuJoCo contact of every clearance joint of a scenario to LN impacts, at the "
        "sizing 'clearance run' uses (effective mass: median over the ideal cycle, with its "
        "min-max range; fit speeds: impact speed / 50 to impact speed). The calibration file "
        "is what 'clearance run --contact-mode calibrated' then reuses for the same scenario "
        "and numerics.",
    )
    add_scenario_args(p, contact_mode=False)
    p.set_defaults(contact_mode=ContactMode.CALIBRATED.value)  # a calibration is of the ring, whatever the default
    g = p.add_argument_group("fit")
    g.add_argument(
        "--speeds",
        type=bounded(float, "--speeds", hi=100.0, why="a pin joint's impacts are slower than 100 m/s"),
        nargs=2,
        metavar=("LO", "HI"),
        default=None,
        help="fit over LO..HI [m/s] instead of the default range; such a fit is stored on its "
        "own and is not the one 'clearance run --contact-mode calibrated' reuses",
    )
    g.add_argument(
        "--n-speeds",
        type=bounded(int, "--n-speeds", 2, 64, why="each speed is one more impact simulated at every fit step"),
        default=None,
        help="number of log-spaced speeds between LO and HI, 2 to 64 (with --speeds only; default 8)",
    )
    g.add_argument("--no-cache", action="store_true", help="refit even if a calibration file exists")
    p.add_argument("--out", default="clearance-out", help="output folder (default clearance-out)")
    return p


def main_calibrate(argv: Sequence[str] | None = None) -> int:
    """``clearance calibrate``: calibrate every clearance joint of a scenario.

    Takes the scenario and numerics options of ``clearance run`` and sizes each joint as
    `clearance.run.preparation.prepare` does, so that the calibration file written is the one
    a run in ``contact_mode="calibrated"`` reads. Writes ``calibration_<joint>.md`` and
    ``.png`` in ``--out`` and prints the table.

    Returns:
        0 on success, 2 on bad input or an unstable calibration.
    """
    from clearance.contact_calibration.fit import CalibrationStabilityError

    p = calibrate_parser()
    args = p.parse_args(argv)
    if args.speeds is not None and not args.speeds[0] < args.speeds[1]:
        p.error(f"--speeds: LO must be below HI (got {args.speeds[0]:g} {args.speeds[1]:g} m/s)")
    if args.n_speeds is not None and args.speeds is None:
        p.error(
            "--n-speeds needs --speeds LO HI (the default fit uses 8 speeds from impact speed / 50 "
            "to impact speed, the ones a calibrated run reuses)"
        )
    try:
        out = check_folder(args.out, "--out")
        mech = mechanism_from_args(args)
        if not mech.clearance_joints:
            sliders = [j.name for j in mech.translational_joints]
            raise ValueError(
                f"mechanism '{mech.name}' has no clearance joint to calibrate (see --clearance-at)"
                + (
                    f"; a slider's play ({', '.join(sliders)}) is not fitted here: 'clearance run --contact-mode "
                    "calibrated' fits its corners and caches the fit like a ring's"
                    if sliders
                    else ""
                )
            )
        options = options_from_args(args)
        with folder_lock(out):
            _calibrate(args, mech, options)
    except (ValueError, CalibrationStabilityError) as exc:
        return error(exc, prefix="clearance calibrate: error")
    return 0


def _calibrate(args: argparse.Namespace, mech: Mechanism, options: ModelOptions) -> None:
    """Calibrate every clearance joint of ``mech`` and write its report in ``args.out``."""
    from clearance.cli.outputs import calibration_lines
    from clearance.contact_calibration.report import calibration_report
    from clearance.contact_calibration.store import calibrate_joint
    from clearance.run.preparation import prepare

    started = time.time()
    prep = prepare(mech, options)
    speeds = np.geomspace(args.speeds[0], args.speeds[1], args.n_speeds or 8) if args.speeds else None
    for j in mech.clearance_joints:
        ring = prep.built.rings[j.name]
        result, path = calibrate_joint(
            j, ring, prep.sizing[j.name], options, speeds=speeds, use_cache=not args.no_cache
        )
        with staged_outputs(Path(args.out)) as stage:  # the table and its plot together, or neither
            files = calibration_report(
                result,
                j.require_clearance(),
                ring,
                options,
                out_dir=stage,
                stem=f"calibration_{j.name}",
                title=f"Contact calibration: {j.name}",
                source=str(path) if path else None,
            )
            print(files.markdown.read_text())
        print(f"wrote {Path(args.out) / files.markdown.name} and {Path(args.out) / files.plot.name}")
        if path is None:
            where = "not stored (--no-cache)" if args.no_cache else "not stored (the cache folder cannot be written)"
            print(f"{j.name}: contact calibration fitted now, {where}")
        else:
            for line in calibration_lines({j.name: {"source": f"calibrated: {path}"}}, started):
                print(line.strip())
