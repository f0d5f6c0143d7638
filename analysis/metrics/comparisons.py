"""Numbers that compare runs: trends over a parameter, agreement of rankings, zig-zag.

Small, pure functions used to test published findings in kind: does a quantity grow with
a parameter (Spearman's rank correlation and the share of rising steps), how close to
linear is it (least squares with R^2), do two rankings agree (Kendall's tau), and how much
does an output's velocity zig-zag compared with the ideal mechanism's (ratio of the total
variation of the two velocity curves).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from clearance.model import Mechanism
from clearance.results import SimulationResult

__all__ = [
    "LinearFit",
    "RankAgreement",
    "Trend",
    "joint_distances",
    "linear_fit",
    "rank_agreement",
    "trend",
    "velocity_zigzag",
]


@dataclass(frozen=True)
class LinearFit:
    """Least-squares line y = slope x + intercept.

    Attributes:
        slope: [y unit / x unit].
        intercept: [y unit].
        r2: coefficient of determination [-].
        n: number of points.
    """

    slope: float
    intercept: float
    r2: float
    n: int


def linear_fit(x: Sequence[float], y: Sequence[float]) -> LinearFit:
    """Fit y = slope x + intercept by least squares (`scipy.stats.linregress`).

    Args:
        x: (n,) abscissae.
        y: (n,) values.

    Raises:
        ValueError: fewer than 3 points, or all x equal.
    """
    xa, ya = np.asarray(x, float), np.asarray(y, float)
    if len(xa) < 3 or len(xa) != len(ya):
        raise ValueError(f"linear_fit needs at least 3 (x, y) pairs of equal length (got {len(xa)}, {len(ya)})")
    if np.ptp(xa) == 0:
        raise ValueError("linear_fit needs at least two different x values")
    from scipy import stats  # here, not at import: scipy.stats takes about 0.4 s to import

    r = stats.linregress(xa, ya)
    return LinearFit(float(r.slope), float(r.intercept), float(r.rvalue**2), len(xa))


@dataclass(frozen=True)
class Trend:
    """How a quantity moves with a parameter.

    Attributes:
        spearman: Spearman rank correlation of y with x [-] (+1: always rising).
        pvalue: its two-sided p-value (NaN for fewer than 3 points).
        rising_steps: share of consecutive steps (x sorted) in which y rises [-].
        ratio: y at the largest x over y at the smallest x [-].
    """

    spearman: float
    pvalue: float
    rising_steps: float
    ratio: float


def trend(x: Sequence[float], y: Sequence[float]) -> Trend:
    """Direction and strength of the change of y with x (see `Trend`).

    Args:
        x: (n,) parameter values.
        y: (n,) quantity values.

    Raises:
        ValueError: fewer than 2 points or lengths differ.
    """
    xa, ya = np.asarray(x, float), np.asarray(y, float)
    if len(xa) < 2 or len(xa) != len(ya):
        raise ValueError(f"trend needs at least 2 (x, y) pairs of equal length (got {len(xa)}, {len(ya)})")
    order = np.argsort(xa, kind="stable")
    ys = ya[order]
    if len(xa) >= 3:
        from scipy import stats  # here, not at import: scipy.stats takes about 0.4 s to import

        rho, p = stats.spearmanr(xa, ya)
    else:
        rho, p = float(np.sign(ys[-1] - ys[0])), float("nan")
    ratio = float(ys[-1] / ys[0]) if ys[0] != 0 else float("inf")
    return Trend(float(rho), float(p), float(np.mean(np.diff(ys) > 0)), ratio)


@dataclass(frozen=True)
class RankAgreement:
    """Agreement of two orderings of the same items.

    Attributes:
        tau: Kendall's tau over the common items [-] (1: same order, -1: reversed).
        pvalue: its p-value.
        common: the common items, in the first ordering.
        same_order: the two orderings of the common items are identical.
        same_first: both put the same item first.
    """

    tau: float
    pvalue: float
    common: tuple[str, ...]
    same_order: bool
    same_first: bool


def rank_agreement(first: Sequence[str], second: Sequence[str]) -> RankAgreement:
    """Kendall's tau between two orderings (most important first), over their common items.

    Args:
        first: items in rank order.
        second: items in rank order.

    Raises:
        ValueError: fewer than 2 common items.
    """
    common = [k for k in first if k in set(second)]
    if len(common) < 2:
        raise ValueError(f"rank_agreement needs at least 2 common items (got {common})")
    in_second = [k for k in second if k in set(common)]
    ra = np.arange(len(common))
    rb = np.array([in_second.index(k) for k in common])
    from scipy import stats  # here, not at import: scipy.stats takes about 0.4 s to import

    tau, p = stats.kendalltau(ra, rb)
    return RankAgreement(float(tau), float(p), tuple(common), common == in_second, common[0] == in_second[0])


def velocity_zigzag(result: SimulationResult, ideal: SimulationResult, output: str, *, skip: float = 0.0) -> float:
    """Zig-zag of an output's velocity: total variation with clearance over the ideal's.

    The total variation sum |v[k+1] - v[k]| of ``<output>_vel`` over t >= t0 + skip, with
    the ideal velocity interpolated on the same times. A smooth velocity gives about 1; a
    velocity that zig-zags about the ideal curve gives more (each zig and zag adds its
    height twice). Use rows at a fixed interval much shorter than the zig-zags.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin.
        output: output name (its ``_vel`` series is used).
        skip: start-up transient skipped [s].

    Raises:
        KeyError: unknown output.
        ValueError: fewer than 3 samples in the window, or an ideal velocity that does not
            vary.
    """
    key = f"{output}_vel"
    t = result.times
    sel = t >= t[0] + skip
    if np.count_nonzero(sel) < 3:
        raise ValueError("velocity_zigzag needs at least 3 samples after skip")
    v = result.outputs[key][sel]
    v0 = np.interp(t[sel], ideal.times, ideal.outputs[key])
    tv0 = float(np.sum(np.abs(np.diff(v0))))
    if tv0 == 0:
        raise ValueError("the ideal velocity does not vary over the window")
    return float(np.sum(np.abs(np.diff(v))) / tv0)


def joint_distances(mechanism: Mechanism, joints: Sequence[str] | None = None) -> Mapping[str, int]:
    """Links between the driven crank and each joint (1: a joint on the crank itself).

    Breadth-first over the link graph (ground excluded, so no path runs through the
    frame): a link's distance is 1 for the first drive's link and one more per joint
    crossed; a joint's distance is the smaller of its two links'.

    Args:
        mechanism: a `Mechanism`.
        joints: joint names (default: all joints).

    Raises:
        KeyError: an unknown joint name.
    """
    ground = mechanism.ground
    drive_joint = mechanism.joint(mechanism.drives[0].joint)
    crank = drive_joint.link_b if drive_joint.link_a == ground else drive_joint.link_a
    dist = {crank: 1}
    frontier = [crank]
    while frontier:
        nxt = []
        for link in frontier:
            for j in mechanism.joints:
                if link in (j.link_a, j.link_b):
                    other = j.link_b if j.link_a == link else j.link_a
                    if other != ground and other not in dist:
                        dist[other] = dist[link] + 1
                        nxt.append(other)
        frontier = nxt
    far = max(dist.values()) + 1
    out = {}
    for name in joints if joints is not None else [j.name for j in mechanism.joints]:
        j = mechanism.joint(name)
        out[name] = min(dist.get(j.link_a, far), dist.get(j.link_b, far))
    return out
