"""The `clearance` command line: the top of the pipeline (may import everything).

    clearance run        simulate a scenario and write arrays, summary, figures, MJCF
    clearance reference  run a scenario with the exact-geometry reference solver
    clearance mjcf       write the MuJoCo model of a scenario
    clearance view       MuJoCo's viewer on a model or a run's folder, at its initial state
    clearance calibrate  fit contact parameters to LN impacts and write a report
    clearance sweep      bifurcation diagram over clearance or drive speed (resumable)
    clearance rank       joint criticality ranking (resumable)
    clearance allocate   cheapest clearance per joint within an output budget (resumable)
    clearance optimise   design variables sized for the behaviour with clearance (resumable)
    clearance bench      speed against error of MuJoCo settings (resumable)
    clearance retrofit   give hinges of any MuJoCo model radial clearance (ring bearings)

One module per command; `clearance.cli.options` holds the options they share and is the one
place units (mm, rpm, µs, ms) are converted to SI. Nothing below this package imports it.
"""

from __future__ import annotations

import argparse
import atexit
import functools
import gc
import importlib
import sys
import warnings
from collections.abc import Callable
from typing import TextIO

from clearance.contact_plugin import PluginUnavailableError
from clearance.kinematics import AssemblyError

__all__ = ["main", "build_parser"]

_OWN_PARSER = {
    "calibrate": (
        "clearance.cli.calibrate",
        "main_calibrate",
        "fit contact parameters to LN impacts; table and force-time plot",
    ),
    "sweep": (
        "clearance.cli.sweep",
        "main_sweep",
        "bifurcation diagram over clearance or drive speed (resumable sweep)",
    ),
    "rank": ("clearance.cli.rank", "main_rank", "joint criticality ranking (resumable sweep)"),
    "allocate": (
        "clearance.cli.allocate",
        "main_allocate",
        "cheapest clearance per joint whose output deviation stays within a budget (resumable)",
    ),
    "optimise": (
        "clearance.cli.optimise",
        "main_optimise",
        "size design variables for the lowest deviation or bearing force with clearance (resumable)",
    ),
    "bench": (
        "clearance.cli.bench",
        "main_bench",
        "speed against error of MuJoCo settings against the reference solver",
    ),
}
"""Commands with a parser of their own: name -> (module, entry point, help)."""

_SUBPARSERS = (
    "clearance.cli.run",
    "clearance.cli.reference",
    "clearance.cli.mjcf",
    "clearance.cli.view",
    "clearance.cli.retrofit",
)
"""Modules whose command is parsed here; each has ``add_parser(sub)`` and ``command(args)``."""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the `clearance` command."""
    from clearance.cli.parser import CommandParser, VersionAction

    p = CommandParser(
        prog="clearance",
        description="Mechanisms with joint clearance in MuJoCo: simulate, sweep, rank, size and retrofit. "
        "Each command's options: clearance COMMAND --help.",
    )
    p.add_argument("--version", action=VersionAction)
    sub = p.add_subparsers(dest="command", required=True)
    for name, (_, _, text) in _OWN_PARSER.items():
        sub.add_parser(name, help=f"{text} (see 'clearance {name} --help')", add_help=False)
    for module in _SUBPARSERS:
        importlib.import_module(module).add_parser(sub)
    return p


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
    *,
    shown: set[str],
) -> None:
    """Warnings as one line on stderr (``warning: ...``), without the source location, each text once
    per command (``shown``: the texts already printed; MuJoCo warns at every compile of a model, e.g.
    of its deprecated ``settotalmass``, and a retrofit compiles the model several times)."""
    text = str(message)
    if text not in shown:
        shown.add(text)
        print(f"warning: {text}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `clearance` console script; returns the process exit status.

    Exit statuses: 0 done, 1 some sweep points failed or a fault during the work (a full disk),
    2 refused (bad input) or stopped by an error, 3 stopped early by --stop-after (resumable),
    130 interrupted with Ctrl-C.
    """
    if argv is None:  # the console script: the process ends with the command
        # at exit, Python's last garbage collections walk every object still alive (0.2 s after a
        # run that drew with matplotlib); frozen, they are skipped, and the memory goes back to
        # the system with the process (atexit handlers, flushing and closing run as before)
        atexit.register(gc.freeze)
    argv = list(sys.argv[1:] if argv is None else argv)
    with warnings.catch_warnings():
        warnings.showwarning = functools.partial(_show_warning, shown=set())
        try:
            return _dispatch(argv)
        except KeyboardInterrupt:
            print("interrupted", file=sys.stderr)
            return 130
        except OSError as err:  # met while writing (bad paths are refused before any work)
            from clearance.cli.messages import FAULT, error
            from clearance.cli.paths import write_fault

            error(f"{write_fault(err)}; no file of this command reads as finished (a resumable one keeps what has run)")
            return FAULT


def _dispatch(argv: list[str]) -> int:
    if argv and argv[0] in _OWN_PARSER:
        module, func, _ = _OWN_PARSER[argv[0]]
        entry: Callable[[list[str]], int] = getattr(importlib.import_module(module), func)
        return entry(argv[1:])
    parser = build_parser()
    args, extra = parser.parse_known_args(argv)
    if extra:  # refused by the command's own parser, so the line names the command
        commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices
        commands[args.command].error(f"unrecognized arguments: {' '.join(extra)}")
    command: Callable[[argparse.Namespace], int] = args.run_command
    try:
        return command(args)
    except (ValueError, AssemblyError, PluginUnavailableError) as err:
        from clearance.cli.messages import error

        return error(err)


if __name__ == "__main__":
    sys.exit(main())
