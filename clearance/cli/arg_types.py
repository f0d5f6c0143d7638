"""Argparse ``type`` functions for numbers: finite, in range, the message naming the option.

Every numeric option of the commands is read by one of these, so a bad number reads the same
everywhere: ``--clearance-mm must be a finite number (got nan)``, ``--segments must be at most
1,024 (got 100000); <why>``.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import TypeVar

from clearance.cli.limits import MAX_DRIVE_RPM, MAX_SEGMENTS

__all__ = ["bounded", "positive", "rpm_option", "segments_option", "timestep_option"]

_N = TypeVar("_N", int, float)


def positive(kind: type[_N], name: str) -> Callable[[str], _N]:
    """An argparse ``type`` accepting finite numbers > 0 of ``kind`` (int or float)."""
    return bounded(kind, name)


def bounded(
    kind: type[_N], name: str, lo: float | None = None, hi: float | None = None, why: str = ""
) -> Callable[[str], _N]:
    """An argparse ``type`` accepting finite numbers of ``kind`` in [lo, hi] (lo None: > 0).

    Args:
        kind: int or float.
        name: the option, for the message.
        lo: smallest accepted value; None accepts any value above 0.
        hi: largest accepted value (None: no bound).
        why: the reason for ``hi``, appended to the message when it is exceeded.
    """

    def conv(text: str) -> _N:
        try:
            v = kind(text)
        except ValueError:
            what = "a whole number" if kind is int else "a number"
            raise argparse.ArgumentTypeError(f"{name} must be {what} (got {text!r})") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{name} must be a finite number (got {text})")
        if lo is None and not v > 0:
            raise argparse.ArgumentTypeError(f"{name} must be > 0 (got {text})")
        if lo is not None and v < lo:
            raise argparse.ArgumentTypeError(f"{name} must be at least {lo:g} (got {text})")
        if hi is not None and v > hi:
            raise argparse.ArgumentTypeError(f"{name} must be at most {hi:,g} (got {text}){'; ' + why if why else ''}")
        return v

    return conv


def rpm_option(name: str) -> Callable[[str], float]:
    """The argparse ``type`` of a drive speed in rpm: > 0 and at most `MAX_DRIVE_RPM`."""
    return bounded(
        float,
        name,
        hi=MAX_DRIVE_RPM,
        why="faster, the journals are pressed deeper than their clearance and runs diverge "
        "(clearance.checks.MAX_DRIVE_RPM)",
    )


def timestep_option(name: str = "--timestep-us") -> Callable[[str], float]:
    """The argparse ``type`` of a time step in µs: > 0 and at most 10,000 (ModelOptions' 0.01 s)."""
    return bounded(float, name, hi=1e4, why="a step of 10 ms (0.01 s) is the longest MuJoCo is given here")


def segments_option(name: str = "--segments") -> Callable[[str], int]:
    """The argparse ``type`` of a ring's segment count: 8 to `MAX_SEGMENTS`."""
    return bounded(
        int,
        name,
        8,
        MAX_SEGMENTS,
        why="the ripple rule picks 144 for the default scenario, and preparing a ring takes longer the more "
        "segments it has (100,000 never finish)",
    )
