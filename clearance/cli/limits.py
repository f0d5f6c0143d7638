"""Bounds on what the commands accept, each stated with its reason, checked before any work.

The caps keep a mistyped number from hanging a command or filling the memory: the ring's
segment count, the time steps of a run (every step is kept in memory) and the points of a
sweep. `check_mechanism` refuses what the models do not describe: drives faster than
`clearance.checks.MAX_DRIVE_RPM`, clearances below `MIN_CLEARANCE` and journals thinner than
`MIN_JOURNAL_RATIO` of their bearing. Every refusal is a `ValueError` whose message names the
option or file, the value and the bound.
"""

from __future__ import annotations

import math

from clearance.checks import MAX_DRIVE_RPM, MAX_DRIVE_SPEED
from clearance.model import Clearance, DriveKind, Mechanism

__all__ = [
    "MAX_DRIVE_RPM",
    "MAX_POINTS",
    "MAX_SEGMENTS",
    "MAX_STEPS",
    "MIN_CLEARANCE",
    "MIN_JOURNAL_RATIO",
    "check_clearance",
    "check_mechanism",
    "check_steps",
]

MAX_SEGMENTS = 1024
"""Most bearing segments of a ring (``--segments``).

The ripple rule chooses 144 for the default scenario and the benchmarks go to 512; the
preparation (and the calibration of a new ring) grows with N: 1024 segments take about 15 s
to calibrate, and 100,000 never finish.
"""

MAX_STEPS = 20_000_000
"""Most time steps (or output samples) of one run.

Every step is kept in memory: 20 million steps of the default slider-crank and its ideal
twin take about 5.4 GB (272 bytes a step) and minutes of stepping.
"""

MAX_POINTS = 100_000
"""Most points of one ``clearance sweep`` (the bifurcation benchmark uses 200)."""

MIN_CLEARANCE = 1e-6
"""Smallest radial clearance [m] (1 µm, below the machining tolerance of a pin joint)."""

MIN_JOURNAL_RATIO = 0.5
"""Smallest journal radius as a fraction of its bearing's radius.

The contact laws (Lankarani-Nikravesh and its kin) are those of a journal nearly filling its
bearing; a 10 mm bearing with a 9.99 mm clearance would hold a 10 µm journal.
"""


def check_mechanism(mech: Mechanism, source: str) -> None:
    """Refuse a mechanism outside the bounds above.

    Args:
        mech: the mechanism a command is about to run.
        source: where its numbers came from, for the message (``"--clearance-mm 9.99"``,
            ``"scenario file x.toml"``).

    Raises:
        ValueError: a drive faster than `MAX_DRIVE_RPM`, a clearance below `MIN_CLEARANCE`,
            or a journal below `MIN_JOURNAL_RATIO` of its bearing's radius.
    """
    for d in mech.drives:
        speed = {DriveKind.CONSTANT_SPEED: d.speed, DriveKind.MOTION_LAW: d.motion.speed if d.motion else 0.0}.get(
            d.kind, 0.0
        )
        if abs(speed) > MAX_DRIVE_SPEED:
            raise ValueError(
                f"{source}: drive '{d.name}' turns at {abs(speed) * 60 / (2 * math.pi):.6g} rpm, above "
                f"the {MAX_DRIVE_RPM:,.0f} rpm this package accepts (see clearance.checks.MAX_DRIVE_RPM: faster, "
                "the journals are pressed deeper than their clearance and the runs diverge)"
            )
    for j in mech.clearance_joints:
        check_clearance(f"joint '{j.name}'", j.require_clearance(), source)


def check_clearance(joint: str, c: Clearance, source: str) -> None:
    """Refuse a clearance below `MIN_CLEARANCE` or a journal below `MIN_JOURNAL_RATIO` of its bearing.

    Args:
        joint: the joint, for the message (``"joint 'rod_slider'"``).
        c: its clearance.
        source: where the numbers came from, for the message.

    Raises:
        ValueError: naming the joint, both radii and the bound.
    """
    if c.radial_clearance < MIN_CLEARANCE:
        raise ValueError(
            f"{source}: {joint}: radial clearance {c.radial_clearance * 1e3:.6g} mm is below the "
            f"smallest accepted, {MIN_CLEARANCE * 1e3:g} mm (1 µm)"
        )
    ratio = c.journal_radius / c.bearing_radius
    if ratio < MIN_JOURNAL_RATIO:
        raise ValueError(
            f"{source}: {joint}: a radial clearance of {c.radial_clearance * 1e3:.6g} mm leaves a "
            f"journal of radius {c.journal_radius * 1e3:.6g} mm in a bearing of radius "
            f"{c.bearing_radius * 1e3:.6g} mm ({ratio:.2%} of it); the contact laws are for journals of at "
            f"least {MIN_JOURNAL_RATIO:.0%} of the bearing radius (a radial clearance of at most "
            f"{(1 - MIN_JOURNAL_RATIO) * c.bearing_radius * 1e3:.6g} mm here)"
        )


def check_steps(duration: float, step: float, source: str, *, what: str = "time steps") -> None:
    """Refuse a run of more than `MAX_STEPS` steps (or output samples).

    Args:
        duration: simulated time [s].
        step: time step or output interval [s].
        source: the options that set them, for the message.
        what: what is counted ("time steps", "output samples").

    Raises:
        ValueError: ``duration / step > MAX_STEPS``.
    """
    n = duration / step
    if n > MAX_STEPS:
        raise ValueError(
            f"{source}: {duration:.6g} s at {step:.3g} s is {n:.3g} {what}, above the {MAX_STEPS:,} one run "
            "may take (every step is kept in memory: 20 million steps of the default slider-crank take 5.4 GB); "
            "simulate a shorter time"
        )
