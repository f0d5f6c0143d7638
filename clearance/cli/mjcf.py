"""``clearance mjcf``: write the MuJoCo model (MJCF) of a scenario.

By default it writes the portable ring model (calibrated ring-segment bearings: stock MuJoCo
opens it anywhere); ``--contact-mode exact`` writes the compiled-contact model, which needs
this package installed (its plugin loads with ``import mujoco``).
"""

from __future__ import annotations

import argparse

from clearance.cli.options import (
    add_scenario_args,
    mechanism_from_args,
    options_from_args,
)
from clearance.options import ContactMode

__all__ = ["add_parser", "command"]


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``mjcf`` to the subcommands ``sub`` (argparse's subparsers action)."""
    m = sub.add_parser("mjcf", help="write the MuJoCo model (MJCF) of a scenario")
    add_scenario_args(m)
    m.add_argument("--out", default="model.xml", help="MJCF file to write (default model.xml)")
    m.add_argument("--ideal", action="store_true", help="write the ideal twin instead")
    # the portable ring model unless the compiled-contact one is asked for by name
    m.set_defaults(run_command=command, contact_mode=ContactMode.CALIBRATED.value)
    for action in m._actions:  # the shared help names the run's default (exact): say this command's
        if action.dest == "contact_mode" and action.help:
            action.help = (
                "contact model (default calibrated here: the portable ring of segments, fitted to LN impacts "
                "and cached, which stock MuJoCo opens anywhere; 'clearance run' defaults to exact): exact (the "
                "compiled plugin's exact contact; the model then needs this package installed; 'exact_ln' is the "
                "same), calibrated or nominal (the ring with formula parameters)"
            )


def command(args: argparse.Namespace) -> int:
    """Write the model; returns the exit status."""
    from clearance.cli.paths import check_file
    from clearance.results import atomic_write_text
    from clearance.run.preparation import prepare

    check_file(args.out, "--out", example="model.xml")
    mech = mechanism_from_args(args)
    if args.ideal:
        mech = mech.ideal_twin()
    prepared = prepare(mech, options_from_args(args))
    atomic_write_text(args.out, prepared.to_xml())
    print(f"wrote {args.out}")
    return 0
