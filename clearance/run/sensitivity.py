"""Chaos or play: the unmodified twin against itself, nudged by a rounding-size perturbation.

A retrofitted model's deviation from its twin is the play's only where the twin is predictable:
a walker whose foot lands differently after a 1e-12 rad change of its start moves as far under
rounding as under play. `twin_sensitivity` runs the twin again from its first keyframe with every
hinge and slide coordinate (and each free joint's position) moved by `ROUNDING` and measures how
far a point drifts from the unperturbed twin; `is_chaos` calls a deviation chaos where that drift
reaches `CHAOS_SHARE` of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearance.results import SimulationResult
from clearance.retrofit.drive import Drive
from clearance.run.retrofitted import Retrofitted, simulate_retrofitted, site_output_names

__all__ = ["CHAOS_SHARE", "ROUNDING", "Sensitivity", "is_chaos", "point_distance", "twin_sensitivity"]

ROUNDING = 1e-12
"""The nudge [rad or m]: about 1e4 ulps of a unit angle, far below any play (1 µm, 0.1')."""

CHAOS_SHARE = 0.1
"""A deviation is chaos rather than play where the nudged twin drifts this share of it [-]."""


@dataclass(frozen=True)
class Sensitivity:
    """How far a point of the twin drifts when its start is nudged.

    Attributes:
        site: the point (a site, or a body's origin).
        perturbation: the nudge [rad or m].
        times: (n,) the rows [s].
        distance: (n,) |p_twin - p_nudged| [m].
    """

    site: str
    perturbation: float
    times: np.ndarray
    distance: np.ndarray

    @property
    def max_distance(self) -> float:
        """Largest drift over the run [m] (0 for no rows)."""
        return float(self.distance.max()) if len(self.distance) else 0.0


def point_distance(a: SimulationResult, b: SimulationResult, site: str) -> np.ndarray:
    """(n,) distance between ``site`` in two runs over their common rows [m]."""
    names = site_output_names(site)
    n = min(len(a.times), len(b.times))
    pa = np.column_stack([a.outputs[k][:n] for k in names])
    pb = np.column_stack([b.outputs[k][:n] for k in names])
    return np.linalg.norm(pa - pb, axis=1)


def twin_sensitivity(
    loaded: Retrofitted,
    drive: Drive,
    twin_run: SimulationResult,
    site: str,
    *,
    output_interval: float | None = None,
    perturbation: float = ROUNDING,
) -> Sensitivity:
    """Run the twin nudged by ``perturbation`` over ``twin_run``'s span; ``site``'s drift from ``twin_run``.

    Args:
        loaded: the retrofit (its twin runs).
        drive: the controls ``twin_run`` was run under.
        twin_run: the unperturbed twin's run, with ``site`` among its outputs.
        site: the point compared.
        output_interval: rows kept [s] (``twin_run``'s: the drift is read on common rows).
        perturbation: the nudge [rad or m].

    Raises:
        SimulationError: the nudged twin diverged.
    """
    duration = float(twin_run.times[-1] - twin_run.times[0]) + float(twin_run.metadata.get("timestep", 0.0))
    nudged = simulate_retrofitted(
        loaded,
        drive,
        duration,
        twin=True,
        sites=[site],
        output_interval=output_interval,
        perturbation=perturbation,
    )
    distance = point_distance(twin_run, nudged, site)
    return Sensitivity(site, perturbation, twin_run.times[: len(distance)].copy(), distance)


def is_chaos(sensitivity: Sensitivity, deviation: float) -> bool:
    """Whether a deviation [m] is chaos rather than play: the nudged twin drifts `CHAOS_SHARE` of it or more."""
    return sensitivity.max_distance >= CHAOS_SHARE * deviation
