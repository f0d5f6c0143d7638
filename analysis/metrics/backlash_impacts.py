"""Backlash at a hinge over a run: the angle in the band, the impacts at its ends, the stop's torque.

A run of a backlash retrofit carries, per backlashed hinge, ``backlash/<hinge>/angle``
(q_load - q_motor [rad]) and ``backlash/<hinge>/torque`` (the stop's torque [N m], zero inside
the band; `clearance.run.backlash_readout`), and its metadata ``backlash`` maps each hinge to
its half-width b [rad]. An impact is an onset of the stop's torque (zero on the row before,
non-zero on this one), counted at each end of the band.
"""

from __future__ import annotations

import csv
import io
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from clearance.results import SimulationResult, atomic_write_text

__all__ = ["BacklashSummary", "backlash_summaries", "backlash_summary", "write_backlash_csv"]


@dataclass(frozen=True)
class BacklashSummary:
    """One backlashed hinge over a run.

    Attributes:
        hinge: the hinge (load side).
        half_width: b [rad].
        min_angle, max_angle: extremes of q_load - q_motor [rad] (beyond +-b by the stop's give).
        impacts: onsets of the stop's torque, both ends together.
        impacts_upper, impacts_lower: those at +b and at -b.
        peak_torque: largest stop torque [N m].
        peak_torque_time: its time [s].
        at_stop: fraction of rows with the stop's torque non-zero [-].
    """

    hinge: str
    half_width: float
    min_angle: float
    max_angle: float
    impacts: int
    impacts_upper: int
    impacts_lower: int
    peak_torque: float
    peak_torque_time: float
    at_stop: float


def backlash_summary(result: SimulationResult, hinge: str, half_width: float) -> BacklashSummary:
    """The `BacklashSummary` of ``hinge`` (half-width ``half_width`` [rad]) in ``result``.

    Raises:
        KeyError: the run has no backlash outputs for ``hinge``.
    """
    angle = result.outputs[f"backlash/{hinge}/angle"]
    torque = result.outputs[f"backlash/{hinge}/torque"]
    engaged = torque > 0
    onset = np.concatenate([engaged[:1], engaged[1:] & ~engaged[:-1]])
    upper = int(np.count_nonzero(onset & (angle > 0)))
    total = int(np.count_nonzero(onset))
    k = int(np.argmax(torque)) if len(torque) else 0
    return BacklashSummary(
        hinge=hinge,
        half_width=float(half_width),
        min_angle=float(angle.min()) if len(angle) else float("nan"),
        max_angle=float(angle.max()) if len(angle) else float("nan"),
        impacts=total,
        impacts_upper=upper,
        impacts_lower=total - upper,
        peak_torque=float(torque[k]) if len(torque) else 0.0,
        peak_torque_time=float(result.times[k]) if len(torque) else float("nan"),
        at_stop=float(engaged.mean()) if len(engaged) else 0.0,
    )


def backlash_summaries(result: SimulationResult) -> list[BacklashSummary]:
    """One `BacklashSummary` per hinge of ``result.metadata['backlash']`` (none for a radial run)."""
    return [backlash_summary(result, h, b) for h, b in (result.metadata.get("backlash") or {}).items()]


def write_backlash_csv(rows: list[BacklashSummary], path: str | Path) -> Path:
    """Write the rows as CSV (angles and torques in SI: rad, N m, s), atomically; returns the path."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(BacklashSummary.__dataclass_fields__))
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in asdict(r).items()})
    atomic_write_text(path, buf.getvalue())
    return Path(path)
