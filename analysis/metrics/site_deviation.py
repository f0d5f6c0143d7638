"""Deviation of a point of a 3-D model (an end effector) from its unmodified twin's.

A retrofitted model's run carries the world position of a chosen site as three outputs
``site/<name>/x``, ``/y``, ``/z`` (`clearance.run.retrofitted`); its twin's run the same.
Each coordinate that moves in the twin's run gets the deviation statistics the criticality
study uses (`deviation_statistics`: mean, RMS, max, 90 % band, t, F and KS tests); the
distance between the two points gets its own series.
"""

from __future__ import annotations

import csv
import io
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from clearance.analysis.metrics.statistics import DeviationStatistics, deviation_statistics
from clearance.results import SimulationResult, atomic_write_text

__all__ = ["MOVING", "SiteDeviation", "site_deviation", "write_site_deviation_csv"]

MOVING = 1e-9
"""A coordinate moves when its range over the twin's run exceeds this [m]."""


@dataclass(frozen=True)
class SiteDeviation:
    """A site's deviation from the twin's.

    Attributes:
        site: the site (or body) name.
        axes: output name (``site/<name>/x`` ...) -> its statistics, for each coordinate that moves.
        times: (m,) the window's times [s].
        distance: (m,) |p - p_twin| over the window [m].
    """

    site: str
    axes: dict[str, DeviationStatistics]
    times: np.ndarray
    distance: np.ndarray

    @property
    def max_distance(self) -> float:
        """Largest distance between the two points [m]."""
        return float(self.distance.max()) if len(self.distance) else float("nan")


def site_deviation(result: SimulationResult, twin: SimulationResult, site: str, *, skip: float = 0.0) -> SiteDeviation:
    """Deviation statistics of ``site`` over the window after ``skip`` [s].

    Args:
        result: the retrofitted model's run, with the site's outputs ``site/<name>/x|y|z``.
        twin: the unmodified twin's run (interpolated to ``result``'s times).
        site: the site (or body) name.
        skip: start of the window after the run's first time [s].

    Returns:
        Per moving coordinate the `DeviationStatistics`, and the distance from the twin's
        position over the window.

    Raises:
        KeyError: the site's outputs are not in both runs.
        ValueError: the window holds fewer than 3 samples.
    """
    names = [f"site/{site}/{a}" for a in "xyz"]
    for n in names:
        if n not in result.outputs or n not in twin.outputs:
            raise KeyError(f"site {site!r} is not an output of both runs (outputs: {sorted(result.outputs)})")
    axes = {
        n: deviation_statistics(result, twin, n, skip=skip) for n in names if float(np.ptp(twin.outputs[n])) > MOVING
    }
    keep = result.times >= result.times[0] + skip
    t = result.times[keep]
    p = np.column_stack([result.outputs[n][keep] for n in names])
    p0 = np.column_stack([np.interp(t, twin.times, twin.outputs[n]) for n in names])
    return SiteDeviation(site, axes, t, np.linalg.norm(p - p0, axis=1))


def write_site_deviation_csv(dev: SiteDeviation, path: str | Path) -> Path:
    """One row per moving coordinate: the `DeviationStatistics` fields [m]; written atomically."""
    buf = io.StringIO()
    fields = ["output", *DeviationStatistics.__dataclass_fields__]
    w = csv.DictWriter(buf, fieldnames=fields)
    w.writeheader()
    for name, s in dev.axes.items():
        w.writerow({"output": name, **{k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in asdict(s).items()}})
    atomic_write_text(path, buf.getvalue())
    return Path(path)
