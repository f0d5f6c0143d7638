"""What ``clearance sweep`` and ``clearance rank`` share: catalogue look-up, the up-front probe, failures.

The mechanism of a sweep is built once from the first point before any point is launched, so
an argument its builder rejects is a usage error (exit 2), not a sweep of error rows.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from clearance.builders.catalogue import CatalogueEntry
from clearance.model import Mechanism

if TYPE_CHECKING:  # the analysis is imported by the commands that sweep, when they run
    from clearance.analysis.sweeps.sweep import MechanismFactory

__all__ = ["UsageError", "catalogue_entry", "probe", "quantities", "report_failures", "usage_error"]

_JOINT_PARTS = ("ex", "ey", "vx", "vy", "e", "force")
"""Parts of a clearance joint that `chaos.quantity_series` samples (``<joint>.<part>``)."""


def catalogue_entry(name: str) -> CatalogueEntry:
    """The catalogue entry named ``name``; exits with a usage message naming the choices otherwise."""
    from clearance.builders import CATALOGUE

    if name not in CATALOGUE:
        raise SystemExit(f"error: unknown mechanism {name!r}; choose one of {sorted(CATALOGUE)}")
    return CATALOGUE[name]


def usage_error(message: str) -> int:
    """Print ``error: message`` and return the usage-error exit status 2."""
    print(f"error: {message}", file=sys.stderr)
    return 2


class UsageError(Exception):
    """A command-line argument the mechanism's builder rejects."""


def probe(make: MechanismFactory, point: Mapping[str, Any], mechanism: str) -> Mechanism:
    """Build the mechanism of one point up front, so a wrong argument is a usage error, not N error rows.

    Args:
        make: the sweep's mechanism factory (point -> `Mechanism`).
        point: the first point.
        mechanism: the catalogue name, for the message.

    Returns:
        The point's mechanism.

    Raises:
        UsageError: the builder rejects the point's arguments.
    """
    try:
        return make(point)
    except TypeError as err:
        raise UsageError(
            f"--mechanism {mechanism}: its builder does not take the arguments of this command ({err})"
        ) from None
    except ValueError as err:
        raise UsageError(f"--mechanism {mechanism} at {point}: {err}") from None


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
    names = [f"{o.name}{s}" for o in mechanism.outputs for s in ("", "_vel", "_acc")]
    return names + [f"{j.name}.{part}" for j in mechanism.clearance_joints for part in _JOINT_PARTS]
