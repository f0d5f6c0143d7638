"""The oil film of a lubricated joint over a run: how thin it got, how eccentric the journal, how hard it pushed.

Works on any `SimulationResult` (MuJoCo's exact contact or the reference solver) whose joint
carries a film force (`clearance.joint_result.JointResult.film_force`). The minimum film
thickness is h = c − |e| (the gap where it is thinnest; negative where the film ruptured and the
dry law pressed the surfaces into each other), the eccentricity ratio ε = |e|/c.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearance.results import SimulationResult

__all__ = ["FilmSummary", "film_summaries", "film_summary"]


@dataclass(frozen=True)
class FilmSummary:
    """The oil film of one lubricated joint over a window of a run.

    Attributes:
        joint: joint name.
        clearance: radial clearance c [m].
        min_film_thickness: smallest h = c − |e| [m] (negative: dry contact, the surfaces
            overlapping by −h).
        min_film_thickness_time: when [s].
        max_eccentricity_ratio: largest ε = |e|/c [-] (above 1 in dry contact).
        peak_film_force: largest magnitude of the film force [N].
        peak_film_force_time: when [s].
        dry_fraction: share of the samples in dry contact (h < 0) [-]; 0: the film carried the
            load throughout.
        samples: samples in the window.
    """

    joint: str
    clearance: float
    min_film_thickness: float
    min_film_thickness_time: float
    max_eccentricity_ratio: float
    peak_film_force: float
    peak_film_force_time: float
    dry_fraction: float
    samples: int

    @property
    def film_carried_the_load(self) -> bool:
        """Whether the film kept the surfaces apart throughout (no dry contact)."""
        return self.samples > 0 and not self.min_film_thickness < 0


def film_summary(result: SimulationResult, joint: str, *, since: float = 0.0, until: float = np.inf) -> FilmSummary:
    """The `FilmSummary` of one lubricated joint over the samples at times in [since, until).

    Args:
        result: a run.
        joint: a lubricated clearance joint of it.
        since, until: the window [s] (default: the whole run).

    Returns:
        The summary; with no sample in the window its numbers are NaN and ``samples`` 0.

    Raises:
        KeyError: no such clearance joint.
        ValueError: the joint carries no film force (a dry joint, or a result saved before the
            film series existed).
    """
    jr = result.joints[joint]
    film = jr.film_force_magnitude
    if film is None:
        raise ValueError(f"joint {joint!r} carries no film force (a dry joint, or a result saved without it)")
    keep = (result.times >= since) & (result.times < until)
    h, eps, f, t = jr.film_thickness[keep], jr.eccentricity_ratio[keep], film[keep], result.times[keep]
    d = np.hypot(jr.eccentricity[:, 0], jr.eccentricity[:, 1])
    c = float(np.median(d - jr.penetration)) if len(d) else float("nan")
    if not len(h):
        nan = float("nan")
        return FilmSummary(joint, c, nan, nan, nan, nan, nan, nan, 0)
    i, k = int(np.argmin(h)), int(np.argmax(f))
    return FilmSummary(
        joint=joint,
        clearance=c,
        min_film_thickness=float(h[i]),
        min_film_thickness_time=float(t[i]),
        max_eccentricity_ratio=float(eps.max()),
        peak_film_force=float(f[k]),
        peak_film_force_time=float(t[k]),
        dry_fraction=float(np.mean(h < 0)),
        samples=len(h),
    )


def film_summaries(result: SimulationResult, *, since: float = 0.0, until: float = np.inf) -> list[FilmSummary]:
    """One `FilmSummary` per lubricated joint of ``result`` (none for a dry run), in joint order.

    Args:
        result: a run.
        since, until: the window [s] (default: the whole run).
    """
    return [film_summary(result, j, since=since, until=until) for j, jr in result.joints.items() if jr.lubricated]
