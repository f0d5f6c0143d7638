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
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from clearance.analysis.metrics.statistics import DeviationStatistics, deviation_statistics
from clearance.results import SimulationResult, atomic_write_text

__all__ = [
    "MOVING",
    "SiteDeviation",
    "add_frame_outputs",
    "frame_output_names",
    "site_deviation",
    "write_site_deviation_csv",
]

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
        frame: the body whose frame the positions are in (its origin and axes in each run: a
            floating base), None for the world.
    """

    site: str
    axes: dict[str, DeviationStatistics]
    times: np.ndarray
    distance: np.ndarray
    frame: str | None = None

    @property
    def max_distance(self) -> float:
        """Largest distance between the two points [m]."""
        return float(self.distance.max()) if len(self.distance) else float("nan")


def frame_output_names(site: str, frame: str) -> list[str]:
    """Output names of a site's position in a body's frame: ``site/<name>/in <frame>/x``, ``/y``, ``/z``."""
    return [f"site/{site}/in {frame}/{a}" for a in "xyz"]


def add_frame_outputs(run: SimulationResult, site: str, frame: str) -> list[str]:
    """Add ``site``'s position in body ``frame``'s frame (R^T (p - x) from the body's pose in each row) to
    ``run``'s outputs; returns their names (`frame_output_names`).

    Raises:
        KeyError: the site's world outputs or the body are not in the run (``metadata['bodies']``).
    """
    bodies = list(run.metadata.get("bodies", []))
    if frame not in bodies:
        raise KeyError(f"body {frame!r} is not in the run (bodies: {bodies})")
    pose = run.body_poses[:, bodies.index(frame)]
    p = np.column_stack([run.outputs[f"site/{site}/{a}"] for a in "xyz"]) - pose[:, :3]
    w, v = pose[:, 3:4], -pose[:, 4:7]  # the inverse rotation: the conjugate quaternion
    t = 2 * np.cross(v, p)
    local = p + w * t + np.cross(v, t)
    names = frame_output_names(site, frame)
    for k, name in enumerate(names):
        run.outputs[name] = local[:, k].copy()
    return names


def site_deviation(
    result: SimulationResult, twin: SimulationResult, site: str, *, skip: float = 0.0, frame: str | None = None
) -> SiteDeviation:
    """Deviation statistics of ``site`` over the window after ``skip`` [s].

    Args:
        result: the retrofitted model's run, with the site's outputs ``site/<name>/x|y|z``.
        twin: the unmodified twin's run (interpolated to ``result``'s times).
        site: the site (or body) name.
        skip: start of the window after the run's first time [s].
        frame: read the site in this body's frame (outputs `add_frame_outputs` added to both runs);
            None: the world's.

    Returns:
        Per moving coordinate the `DeviationStatistics`, and the distance from the twin's
        position over the window.

    Raises:
        KeyError: the site's outputs are not in both runs.
        ValueError: the window holds fewer than 3 samples.
    """
    names = [f"site/{site}/{a}" for a in "xyz"] if frame is None else frame_output_names(site, frame)
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
    return SiteDeviation(site, axes, t, np.linalg.norm(p - p0, axis=1), frame)


def write_site_deviation_csv(devs: SiteDeviation | Sequence[SiteDeviation], path: str | Path) -> Path:
    """One row per moving coordinate of each deviation (the world's, then a floating base's frame): the
    `DeviationStatistics` fields [m]; written atomically."""
    buf = io.StringIO()
    fields = ["output", *DeviationStatistics.__dataclass_fields__]
    w = csv.DictWriter(buf, fieldnames=fields)
    w.writeheader()
    for dev in [devs] if isinstance(devs, SiteDeviation) else devs:
        for name, s in dev.axes.items():
            w.writerow(
                {"output": name, **{k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in asdict(s).items()}}
            )
    atomic_write_text(path, buf.getvalue())
    return Path(path)
