"""What ``clearance sweep`` and ``clearance rank`` share: look-ups, up-front checks, failures, Ctrl-C.

The mechanisms of a sweep are built from its first and last points before any point is
launched, so an argument its builder rejects, or a point outside `clearance.cli.limits`, is a
usage error (exit 2), not a sweep of error rows; a Dask scheduler without Dask installed is
refused with the install command before any work; a Ctrl-C ends with one line saying how
many points are kept (exit 130).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from clearance.builders.catalogue import CatalogueEntry
from clearance.cli.limits import check_mechanism, check_steps
from clearance.model import Mechanism
from clearance.options import ModelOptions

if TYPE_CHECKING:  # the analysis is imported by the commands that sweep, when they run
    from clearance.analysis.sweeps.sweep import MechanismFactory

__all__ = [
    "INTERRUPTED",
    "STOPPED",
    "UsageError",
    "catalogue_entry",
    "check_prepares",
    "check_scheduler",
    "interrupted",
    "probe",
    "quantities",
    "report_failures",
    "stopped",
    "usage_error",
]

INTERRUPTED = 130
"""Exit status of a command stopped with Ctrl-C (128 + SIGINT, as shells report it)."""

STOPPED = 3
"""Exit status of a command stopped early by ``--stop-after`` (resumable: the same command goes on)."""

_JOINT_PARTS = ("ex", "ey", "vx", "vy", "e", "force")
"""Parts of a clearance joint that `chaos.quantity_series` samples (``<joint>.<part>``)."""


class UsageError(Exception):
    """A command-line argument the mechanism's builder rejects, or one out of bounds."""


def catalogue_entry(name: str) -> CatalogueEntry:
    """The catalogue entry named ``name``.

    Raises:
        UsageError: no such mechanism (the message names the choices).
    """
    from clearance.builders import CATALOGUE

    if name not in CATALOGUE:
        raise UsageError(f"--mechanism: unknown mechanism {name!r}; choose one of {sorted(CATALOGUE)}")
    return CATALOGUE[name]


def usage_error(message: str) -> int:
    """Print ``error: message`` on one line and return the usage-error exit status 2."""
    from clearance.cli.messages import error

    return error(message)


def interrupted(out: Path) -> int:
    """Say how many points of the sweep folder ``out`` are kept after a Ctrl-C; return 130."""
    kept = len(list((out / "points").glob("point_*.json"))) if (out / "points").is_dir() else 0
    print(f"interrupted; {kept} points kept in {out}, rerun to resume", file=sys.stderr)
    return INTERRUPTED


def stopped(limit: int, done: str, kept: Path, skipped: str) -> int:
    """Say that ``--stop-after`` stopped the command, what is kept and what was not written; return 3.

    Args:
        limit: the ``--stop-after`` value.
        done: what has run so far (``12 of 200 points``, ``3 runs``).
        kept: where the finished work is kept.
        skipped: the final outputs not written yet (they would show a part as the whole).
    """
    print(
        f"stopped by --stop-after {limit}: {done} have run, kept in {kept}; {skipped} when every one has run: "
        "run the same command again to resume",
        file=sys.stderr,
    )
    return STOPPED


def check_scheduler(address: str | None) -> None:
    """Refuse ``--scheduler`` when Dask is not installed, naming the install command.

    Raises:
        UsageError: an address was given and ``dask.distributed`` cannot be imported.
    """
    if address is None:
        return
    from clearance.analysis.sweeps.executor import SchedulerError, require_dask

    try:
        require_dask()
    except SchedulerError as err:
        raise UsageError(f"--scheduler {address}: {err}") from None


def probe(
    make: MechanismFactory,
    point: Mapping[str, Any],
    mechanism: str,
    *,
    source: str | None = None,
    periods: float | None = None,
    timestep: float | None = None,
) -> Mechanism:
    """Build the mechanism of one point up front, so a wrong argument is a usage error, not N error rows.

    Args:
        make: the sweep's mechanism factory (point -> `Mechanism`).
        point: the point.
        mechanism: the catalogue name, for the message.
        source: the options that set the point, for a message of `clearance.cli.limits`
            (default: ``--mechanism <name>``).
        periods, timestep: drive periods and time step [s] of each run; with both, a run
            of more than `clearance.cli.limits.MAX_STEPS` steps is refused.

    Returns:
        The point's mechanism.

    Raises:
        UsageError: the builder rejects the point's arguments, or the mechanism or its run
            is outside `clearance.cli.limits`.
    """
    where = source or f"--mechanism {mechanism} at {dict(point)}"
    try:
        mech = make(point)
    except TypeError as err:
        raise UsageError(
            f"--mechanism {mechanism}: its builder does not take the arguments of this command ({err})"
        ) from None
    except ValueError as err:
        raise UsageError(f"{where}: {err}") from None
    try:
        check_mechanism(mech, where)
        if periods is not None and timestep is not None and mech.drive_period is not None:
            check_steps(periods * mech.drive_period, timestep, f"{where} --periods {periods:g}")
    except ValueError as err:
        raise UsageError(str(err)) from None
    return mech


def check_prepares(mech: Mechanism, options: ModelOptions, where: str, timestep: str) -> None:
    """Prepare one run's model up front, so a setting every run shares is refused once, not in each run.

    A time step the contact cannot take (`clearance.run.preparation.TimeStepError`) would fail
    every run of a batch alike; here it is one refusal naming the option.

    Args:
        mech: a mechanism of the batch (its stiffest contact: the smallest clearances).
        options: the runs' `ModelOptions`.
        where: the options that set the mechanism, for other refusals.
        timestep: the option that set the time step (``--timestep-us 1000``, or ``the default time step``).

    Raises:
        UsageError: the model cannot be prepared with these options.
    """
    from clearance.run.preparation import TimeStepError, prepare

    try:
        prepare(mech, options)
    except TimeStepError as err:
        raise UsageError(f"{timestep}: {err}") from None
    except ValueError as err:
        raise UsageError(f"{where}: {err}") from None


def report_failures(failed: int, total: int, first: str, out: Path) -> int:
    """Say how many points failed and where their rows are; return the exit status 1.

    Args:
        failed: failed points.
        total: points run.
        first: the first failure's message.
        out: the sweep folder.
    """
    print(
        f"error: {failed} of {total} points failed (first: {first}); their rows have status 'error' in "
        f"{out / 'sweep.csv'} and {out / 'points'}",
        file=sys.stderr,
    )
    return 1


def quantities(mechanism: Mechanism) -> list[str]:
    """Names `chaos.quantity_series` accepts for a mechanism's runs."""
    from clearance.analysis.chaos.poincare import SLIDER_PARTS

    names = [f"{o.name}{s}" for o in mechanism.outputs for s in ("", "_vel", "_acc")]
    names += [f"{j.name}.{part}" for j in mechanism.clearance_joints for part in _JOINT_PARTS]
    return names + [f"{j.name}.{part}" for j in mechanism.translational_joints for part in SLIDER_PARTS]
