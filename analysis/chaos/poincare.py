"""Nonlinear-dynamics tools: phase portraits, Poincaré sections, regime classification.

Poincaré sections sample a series at t = t0 + phase + k T of the constant-speed drive
(linear interpolation between stored samples). A set of section points is classified by
this criterion (`classify_poincare`):

1. Distinct points: the points are grouped greedily (a point joins the first group whose
   first member lies within ``tol`` times ``scale``, by default the set's RMS radius about
   its centroid; pass the RMS radius of the whole trajectory for a robust test). At most
   ``max_period`` groups, each visited at least twice (K >= 2 x groups), means PERIODIC
   with period = number of groups (a set with an RMS radius below ``atol`` is period 1).
2. Otherwise nearest-neighbour divergence of the section map: for every point k with a
   successor, take its nearest other point j (also with a successor) and the log ratio
   ln(|P[k+1] - P[j+1]| / |P[k] - P[j]|). On an invariant closed curve
   (quasi-periodic motion) the map is a rotation and the median ratio is near 0; on a
   strange attractor nearby points separate, and the median is of the order of the largest
   Lyapunov exponent times T. A median above ``divergence_threshold`` means CHAOTIC,
   otherwise QUASI_PERIODIC.
3. Fewer than ``min_points`` (`MIN_SECTION_POINTS`, 20) non-periodic points, or a single
   point, give UNDETERMINED; `section_warning` words the caution for figures and reports.

The Grassberger-Procaccia correlation dimension is reported beside the regime (about 1
for a closed curve, above 1 for the section of a strange attractor) as a diagnostic.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from clearance.results import SimulationResult

__all__ = [
    "MIN_SECTION_POINTS",
    "PhasePortrait",
    "PoincareClassification",
    "Regime",
    "classify_poincare",
    "correlation_dimension",
    "largest_lyapunov",
    "map_divergence",
    "phase_portrait",
    "poincare_from_result",
    "poincare_section",
    "quantity_series",
    "run_section",
    "RunSection",
    "SLIDER_PARTS",
    "section_warning",
]

MIN_SECTION_POINTS = 20
"""Fewest section points from which a regime is told (`classify_poincare`'s ``min_points``):
fewer say too little about recurrence or divergence, and figures and reports say so."""

_JOINT_PARTS = {
    "ex": ("eccentricity", 0),
    "ey": ("eccentricity", 1),
    "vx": ("eccentricity_rate", 0),
    "vy": ("eccentricity_rate", 1),
}

SLIDER_PARTS = ("n", "vn", "tilt", "force")
"""Parts of a slider with play that `quantity_series` samples (``<slider>.<part>``): across the
guide, its rate, the tilt, the net contact-force magnitude."""


class Regime(enum.Enum):
    """Dynamic regime read from a Poincaré section."""

    PERIODIC = "periodic"
    QUASI_PERIODIC = "quasi_periodic"
    CHAOTIC = "chaotic"
    UNDETERMINED = "undetermined"


@dataclass(frozen=True)
class PhasePortrait:
    """A quantity against its rate.

    Attributes:
        times: (n,) [s].
        position: (n,) quantity [m or rad].
        velocity: (n,) its rate [m/s or rad/s].
        name: quantity name.
    """

    times: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    name: str


@dataclass(frozen=True)
class PoincareClassification:
    """Result of `classify_poincare`.

    Attributes:
        regime: the regime.
        n_points: number of section points.
        distinct: number of groups of coinciding points (capped at max_period + 1).
        period: period in drive periods when PERIODIC, else 0.
        divergence: median nearest-neighbour log separation ratio per section step
            (NaN when not computed).
        correlation_dimension: Grassberger-Procaccia estimate (NaN when not computed).
    """

    regime: Regime
    n_points: int
    distinct: int
    period: int
    divergence: float
    correlation_dimension: float


def quantity_series(result: SimulationResult, name: str) -> np.ndarray:
    """A scalar series of a run by name.

    Names: an output (``slider_x``, ``slider_x_vel``, ``slider_x_acc``), or
    ``<joint>.<part>`` for a clearance joint with part ``ex``, ``ey`` (eccentricity in the
    bearing frame [m]), ``vx``, ``vy`` (its rate [m/s]), ``e`` (|eccentricity| [m]),
    ``force`` (contact-force magnitude [N]); or ``<slider>.<part>`` for a slider with play in
    its guide with part ``n`` (its position across the guide [m]), ``vn`` (its rate [m/s]),
    ``tilt`` (its angle to the guide [rad]), ``force`` (net contact-force magnitude [N]).

    Raises:
        KeyError: unknown name.
    """
    if name in result.outputs:
        return result.outputs[name]
    joint, _, part = name.rpartition(".")
    if joint in result.joints:
        jr = result.joints[joint]
        if part in _JOINT_PARTS:
            attr, col = _JOINT_PARTS[part]
            return getattr(jr, attr)[:, col]
        if part == "e":
            return np.hypot(jr.eccentricity[:, 0], jr.eccentricity[:, 1])
        if part == "force":
            return jr.force_magnitude
    if joint in result.sliders and part in SLIDER_PARTS:
        sr = result.sliders[joint]
        if part == "force":
            return np.hypot(sr.contact_force[:, 0], sr.contact_force[:, 1])
        return sr.tilt if part == "tilt" else (sr.position if part == "n" else sr.velocity)[:, 1]
    sliders = (
        f" or '<slider>.<{'|'.join(SLIDER_PARTS)}>' with slider in {list(result.sliders)}" if result.sliders else ""
    )
    raise KeyError(
        f"unknown quantity {name!r}: use an output {sorted(result.outputs)} or "
        f"'<joint>.<ex|ey|vx|vy|e|force>' with joint in {list(result.joints)}{sliders}"
    )


def phase_portrait(result: SimulationResult, name: str) -> PhasePortrait:
    """Phase-portrait data: an output with ``<output>_vel``, or a joint's ``ex``/``ey`` with its rate.

    Raises:
        KeyError: unknown name or no rate for it.
    """
    if name in result.outputs and f"{name}_vel" in result.outputs:
        return PhasePortrait(result.times, result.outputs[name], result.outputs[f"{name}_vel"], name)
    joint, _, part = name.rpartition(".")
    if part in ("ex", "ey"):
        rate = f"{joint}.v{part[1]}"
        return PhasePortrait(result.times, quantity_series(result, name), quantity_series(result, rate), name)
    raise KeyError(f"no phase portrait for {name!r}: give an output with a _vel series or '<joint>.ex|ey'")


def poincare_section(
    times: np.ndarray,
    values: np.ndarray,
    period: float,
    *,
    phase: float = 0.0,
    last: int | None = None,
    skip: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Sample series at t = phase + k T inside the recorded span (linear interpolation).

    Args:
        times: (n,) increasing [s].
        values: (n,) or (n, d) series.
        period: sampling period T [s] (the drive period).
        phase: time offset of the section [s].
        last: keep only the last ``last`` section points (e.g. the last K periods).
        skip: ignore section times before this [s].

    Returns:
        (section times (K,), section values (K, d)).

    Raises:
        ValueError: non-positive period.
    """
    if not (np.isfinite(period) and period > 0):
        raise ValueError(f"period must be > 0 s (got {period!r})")
    times = np.asarray(times, dtype=float)
    vals = np.asarray(values, dtype=float)
    vals = vals[:, None] if vals.ndim == 1 else vals
    start = max(times[0], skip)
    # 1e-9 T slack: a section time that coincides with the first or last sample (up to
    # rounding of k T) is kept
    k0 = int(np.ceil((start - phase) / period - 1e-9))
    k1 = int(np.floor((times[-1] - phase) / period + 1e-9))
    ts = phase + np.arange(k0, k1 + 1) * period
    ts = np.clip(ts, times[0], times[-1])
    if last is not None:
        ts = ts[-last:] if last > 0 else ts[:0]
    out = np.column_stack([np.interp(ts, times, vals[:, i]) for i in range(vals.shape[1])])
    return ts, out.reshape(len(ts), vals.shape[1])


def poincare_from_result(
    result: SimulationResult,
    quantities: str | list[str],
    *,
    period: float | None = None,
    last: int | None = None,
    phase: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Poincaré section of named quantities (see `quantity_series`) once per drive period.

    Args:
        result: a run.
        quantities: one name or a list of names (columns).
        period: drive period [s]; default from the recorded drive speed.
        last: keep the last ``last`` points.
        phase: section phase [s].

    Returns:
        (times (K,), points (K, len(quantities))).
    """
    from clearance.analysis.metrics.statistics import drive_period

    names = [quantities] if isinstance(quantities, str) else list(quantities)
    vals = np.column_stack([quantity_series(result, q) for q in names])
    return poincare_section(result.times, vals, period or drive_period(result), phase=phase, last=last)


@dataclass(frozen=True)
class RunSection:
    """A run's Poincaré section after its start-up transient, classified.

    Attributes:
        quantities: the sampled quantity names (columns).
        times: (K,) section times [s].
        points: (K, d) section points.
        trajectory: (n, d) the quantities from the first section time on.
        scale: RMS radius of that trajectory about its mean [units of the points]: the
            grouping scale `classify_poincare` is given (robust to a slow transient).
        classification: the set's regime; None when there is no section point.
    """

    quantities: tuple[str, ...]
    times: np.ndarray
    points: np.ndarray
    trajectory: np.ndarray
    scale: float
    classification: PoincareClassification | None


def run_section(
    result: SimulationResult,
    quantities: str | list[str],
    *,
    period: float | None = None,
    skip: float = 0.0,
    last: int | None = None,
) -> RunSection:
    """Poincaré section of a run (`poincare_from_result`) after ``skip``, classified.

    Args:
        result: a run.
        quantities: one name or a list of names (`quantity_series`), in comparable units.
        period: drive period [s]; default from the recorded drive speed.
        skip: start-up transient [s] from the run's start; earlier section points are
            dropped.
        last: keep at most the last ``last`` section points.

    Raises:
        KeyError: unknown quantity.
    """
    names = [quantities] if isinstance(quantities, str) else list(quantities)
    ts, pts = poincare_from_result(result, names, period=period, last=last)
    keep = ts >= result.times[0] + skip
    ts, pts = ts[keep], pts[keep]
    sel = result.times >= (ts[0] if len(ts) else np.inf)
    vals = np.column_stack([quantity_series(result, q)[sel] for q in names])
    scale = float(np.sqrt(np.mean(np.sum((vals - vals.mean(axis=0)) ** 2, axis=1)))) if len(vals) else 0.0
    cls = classify_poincare(pts, scale=scale) if len(pts) else None
    return RunSection(tuple(names), ts, pts, vals, scale, cls)


def correlation_dimension(points: np.ndarray, *, r_quantiles: tuple[float, float] = (0.02, 0.2)) -> float:
    """Grassberger-Procaccia correlation dimension of a point set.

    The slope of log C(r) against log r, with C(r) the fraction of point pairs closer than
    r, fitted between the given quantiles of the pair distances (the small-r end is bounded
    by the sample size, the large-r end by the set's size).

    Args:
        points: (K, d).
        r_quantiles: quantiles of the pair-distance distribution bounding the fit.

    Returns:
        The dimension estimate (NaN for fewer than 10 points or coinciding points).
    """
    p = np.asarray(points, dtype=float).reshape(len(points), -1)
    if len(p) < 10:
        return float("nan")
    from scipy.spatial.distance import pdist  # here: a short run's section (< 10 points) never imports scipy.spatial

    d = np.sort(pdist(p))
    d = d[d > 0]
    if len(d) < 10:
        return float("nan")
    r_lo, r_hi = np.quantile(d, r_quantiles)
    r = np.geomspace(r_lo, r_hi, 12)
    c = np.searchsorted(d, r) / len(d)
    ok = c > 0
    if np.count_nonzero(ok) < 3:
        return float("nan")
    return float(np.polyfit(np.log(r[ok]), np.log(c[ok]), 1)[0])


def map_divergence(points: np.ndarray) -> float:
    """Median ln(|P[k+1] - P[j+1]| / |P[k] - P[j]|) over points k and their nearest neighbour j.

    Args:
        points: (K, d) section points in time order.

    Returns:
        The median log ratio per section step (NaN for fewer than 3 points).
    """
    p = np.asarray(points, dtype=float).reshape(len(points), -1)
    if len(p) < 3:
        return float("nan")
    from scipy.spatial import cKDTree  # here: a short run's section (< 3 points) never imports scipy.spatial

    head = p[:-1]
    tree = cKDTree(head)
    dist, idx = tree.query(head, k=min(3, len(head)))
    ratios = []
    for k in range(len(head)):
        for d0, j in zip(np.atleast_1d(dist[k]), np.atleast_1d(idx[k])):
            if j != k and d0 > 0:
                d1 = np.linalg.norm(p[k + 1] - p[j + 1])
                if d1 > 0:
                    ratios.append(np.log(d1 / d0))
                break
    return float(np.median(ratios)) if ratios else float("nan")


def _distinct(points: np.ndarray, radius: float, cap: int) -> int:
    centres: list[np.ndarray] = []
    for q in points:
        if not any(np.linalg.norm(q - c) <= radius for c in centres):
            centres.append(q)
            if len(centres) > cap:
                break
    return len(centres)


def classify_poincare(
    points: np.ndarray,
    *,
    tol: float = 1e-2,
    scale: float | None = None,
    atol: float = 0.0,
    max_period: int = 16,
    divergence_threshold: float = 0.2,
    min_points: int = MIN_SECTION_POINTS,
) -> PoincareClassification:
    """Classify a Poincaré point set as periodic, quasi-periodic or chaotic.

    See the module docstring for the criterion. Give columns in comparable units (the
    grouping radius is isotropic).

    Args:
        points: (K,) or (K, d) section points in time order.
        tol: grouping radius as a fraction of ``scale`` [-].
        scale: size of the motion the tolerance refers to [units of points]; default
            the RMS radius of the set. Give the RMS radius of the whole trajectory when a
            slowly decaying transient may remain (the tail of a converging set is tiny
            and would otherwise look spread out).
        atol: RMS radius below which the set is one point [units of points].
        max_period: largest period reported as PERIODIC.
        divergence_threshold: median log separation ratio per step above which the set is
            CHAOTIC [-] (0.2: neighbours separate by more than 22 % per period).
        min_points: fewest points for the quasi-periodic / chaotic decision.

    Raises:
        ValueError: no points or non-finite points.
    """
    p = np.asarray(points, dtype=float)
    p = p.reshape(len(p), -1)
    if len(p) == 0 or not np.isfinite(p).all():
        raise ValueError("points must be a non-empty array of finite values")
    if len(p) < 2:  # one point says nothing about recurrence
        return PoincareClassification(Regime.UNDETERMINED, len(p), 1, 0, float("nan"), float("nan"))
    rms = float(np.sqrt(np.mean(np.sum((p - p.mean(axis=0)) ** 2, axis=1))))
    if rms <= atol:
        return PoincareClassification(Regime.PERIODIC, len(p), 1, 1, float("nan"), float("nan"))
    groups = _distinct(p, tol * (rms if scale is None else scale), max_period)
    if groups <= max_period and len(p) >= 2 * groups:  # each group revisited at least once
        return PoincareClassification(Regime.PERIODIC, len(p), groups, groups, float("nan"), float("nan"))
    div = map_divergence(p)
    dim = correlation_dimension(p)
    if len(p) < min_points or not np.isfinite(div):
        regime = Regime.UNDETERMINED
    else:
        regime = Regime.CHAOTIC if div > divergence_threshold else Regime.QUASI_PERIODIC
    return PoincareClassification(regime, len(p), groups, 0, div, dim)


def largest_lyapunov(
    times: np.ndarray, a: np.ndarray, b: np.ndarray, *, fit: tuple[float, float] | None = None
) -> float:
    """Largest Lyapunov exponent estimate [1/s] from two runs started close together.

    The slope of ln |a(t) - b(t)| over the fit window. By default the window runs from
    where the separation first exceeds 10 times its initial value to where it first
    exceeds 10 % of the RMS size of ``a`` (the exponential-growth stretch); if it never
    grows that much, the whole run is fitted (a negative slope: the runs converge).

    Args:
        times: (n,) [s].
        a, b: (n,) or (n, d) the same quantity in the two runs.
        fit: (t_start, t_end) window [s] to override the automatic one.
    """
    a = np.asarray(a, float).reshape(len(times), -1)
    b = np.asarray(b, float).reshape(len(times), -1)
    t = np.asarray(times, float)
    sep = np.linalg.norm(a - b, axis=1)
    floor = np.finfo(float).tiny
    if fit is None:
        size = float(np.sqrt(np.mean(np.sum((a - a.mean(axis=0)) ** 2, axis=1))))
        d0 = max(sep[0], floor)
        grow = np.nonzero(sep > 10 * d0)[0]
        sat = np.nonzero(sep > 0.1 * size)[0]
        if len(grow) and len(sat) and sat[0] > grow[0] + 2:
            sel: slice | np.ndarray = slice(grow[0], sat[0])
        else:
            sel = slice(0, len(t))
    else:
        sel = (t >= fit[0]) & (t <= fit[1])
    return float(np.polyfit(t[sel], np.log(np.maximum(sep[sel], floor)), 1)[0])


def section_warning(n_points: int, *, min_points: int = MIN_SECTION_POINTS) -> str | None:
    """The caution for a Poincaré section with too few points, or None when it has enough.

    Args:
        n_points: section points (one per drive period after the start-up window).
        min_points: the threshold (`MIN_SECTION_POINTS`).

    Returns:
        A sentence naming the count, the threshold and the run length that reaches it.
    """
    if n_points >= min_points:
        return None
    count = "no section point" if n_points == 0 else f"only {n_points} section point{'s' if n_points != 1 else ''}"
    return (
        f"{count} (fewer than {min_points}): too few drive periods to tell the regime; a run of "
        f"{min_points + 1} drive periods or more gives {min_points}"
    )
