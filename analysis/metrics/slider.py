"""A slider in its guide: contact phases, the time in each contact case, the slider's excursions.

The reference solver records, per prismatic joint with play, the contact case of every
sample (`clearance.translational.SliderContact`: free flight, one corner, two corners on one
side, two diagonal corners). `contact_phases` cuts the run into phases of one case and one
set of touched lines; `slider_summary` gives the numbers the report and the benchmark print.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from clearance.translational import SliderContact, SliderResult

__all__ = ["Lines", "ContactPhase", "SliderSummary", "contact_phases", "touched_lines", "slider_summary"]


class Lines(enum.IntEnum):
    """Which guide lines a sample's touching corners press on (the codes of `touched_lines`)."""

    NONE = 0
    UPPER = 1
    """The +n line (corners 0 and 1 of `clearance.translational.CORNERS`)."""
    LOWER = 2
    """The -n line (corners 2 and 3)."""
    BOTH = 3

    @property
    def label(self) -> str:
        """'none', '+n line', '-n line' or 'both lines'."""
        return ("none", "+n line", "-n line", "both lines")[self.value]


def touched_lines(corner_penetration: np.ndarray) -> np.ndarray:
    """(n,) `Lines` codes: which guide lines the corners in contact (penetration > 0) touch.

    Args:
        corner_penetration: (n, 4) penetration of corners 0-3 [m].
    """
    on = np.asarray(corner_penetration) > 0.0
    upper, lower = (on[:, 0] | on[:, 1]).astype(np.int8), (on[:, 2] | on[:, 3]).astype(np.int8)
    return upper * Lines.UPPER.value + lower * Lines.LOWER.value


@dataclass(frozen=True)
class ContactPhase:
    """A stretch of samples in one contact case on one set of guide lines.

    Attributes:
        case: the contact case.
        lines: the lines touched.
        start, end: time of the phase's first sample and of the next phase's first sample
            (the run's last time for the last phase) [s].
    """

    case: SliderContact
    lines: Lines
    start: float
    end: float

    @property
    def duration(self) -> float:
        """end - start [s]."""
        return self.end - self.start

    def label(self) -> str:
        """'free', or the case and its lines ('one side on +n line')."""
        if self.case is SliderContact.FREE:
            return "free"
        return f"{self.case.name.lower().replace('_', ' ')} on {self.lines.label}"


def contact_phases(times: np.ndarray, cases: np.ndarray, lines: np.ndarray) -> list[ContactPhase]:
    """Cut a run into phases of constant contact case and touched lines.

    Args:
        times: (n,) sample times [s], increasing.
        cases: (n,) `SliderContact` codes.
        lines: (n,) `Lines` codes.

    Returns:
        The phases in time order (empty for an empty run).

    Raises:
        ValueError: the arrays differ in length.
    """
    t, c, ln = np.asarray(times, dtype=float), np.asarray(cases), np.asarray(lines)
    if not (len(t) == len(c) == len(ln)):
        raise ValueError(f"times, cases and lines must have one length (got {len(t)}, {len(c)}, {len(ln)})")
    if len(t) == 0:
        return []
    key = c.astype(np.int64) * 4 + ln
    starts = np.concatenate([[0], np.flatnonzero(key[1:] != key[:-1]) + 1])
    ends = np.concatenate([starts[1:], [len(t) - 1]])
    members = list(SliderContact)
    return [ContactPhase(members[int(c[a])], Lines(int(ln[a])), float(t[a]), float(t[b])) for a, b in zip(starts, ends)]


@dataclass(frozen=True)
class SliderSummary:
    """The numbers of one slider's run.

    Attributes:
        shares: contact case -> share of the run's time in it [-] (sums to 1).
        phase_counts: contact case -> number of phases in it.
        switches: number of changes of case or lines.
        max_across: largest |position across the guide| [m].
        max_tilt: largest |tilt| [rad].
        max_penetration: deepest corner penetration [m] (0 if no corner touched).
        peak_corner_force: largest normal force at any corner [N].
    """

    shares: dict[SliderContact, float]
    phase_counts: dict[SliderContact, int]
    switches: int
    max_across: float
    max_tilt: float
    max_penetration: float
    peak_corner_force: float


def slider_summary(times: np.ndarray, slider: SliderResult, *, start: float = -np.inf) -> SliderSummary:
    """Summarise a slider's run from ``start`` on.

    Args:
        times: (n,) the run's times [s].
        slider: its `SliderResult`.
        start: first time included [s] (default: the whole run).

    Returns:
        The summary. Shares weight each sample by the time to the next one.

    Raises:
        ValueError: fewer than 2 samples from ``start`` on.
    """
    keep = np.asarray(times) >= start
    if keep.sum() < 2:
        raise ValueError(f"fewer than 2 samples from t = {start:g} s on")
    t = np.asarray(times)[keep]
    sl = slider.sliced(keep)
    phases = contact_phases(t, sl.contact_case, touched_lines(sl.corner_penetration))
    span = t[-1] - t[0]
    shares = {case: 0.0 for case in SliderContact}
    counts = {case: 0 for case in SliderContact}
    for p in phases:
        shares[p.case] += p.duration / span
        counts[p.case] += 1
    return SliderSummary(
        shares=shares,
        phase_counts=counts,
        switches=len(phases) - 1,
        max_across=float(np.max(np.abs(sl.position[:, 1]))),
        max_tilt=float(np.max(np.abs(sl.tilt))),
        max_penetration=float(max(np.max(sl.corner_penetration), 0.0)),
        peak_corner_force=float(np.max(sl.corner_force)),
    )
