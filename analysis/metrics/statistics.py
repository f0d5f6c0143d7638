"""Deviation statistics of an output against the ideal mechanism's output.

The measures of the clearance-criticality literature (Alok, Chaudhary and Guha 2020; docs/references.md): mean
deviation, RMS deviation, 90 % tolerance band, and three two-sample tests (t-test on the
deviation, F-test on the variances, Kolmogorov-Smirnov on the distributions: the results of
`scipy.stats`, computed by `clearance.analysis.metrics.significance`). All are taken over a
steady-state window that skips the start-up transient (by default the first drive period).

The samples of a simulated output are strongly autocorrelated, so the tests' p-values are
not probabilities of independent samples; use the statistics to compare runs with each
other (as the literature does), not as absolute significance levels.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from clearance.analysis.metrics.significance import ks_two_sample, paired_t_test, variance_ratio_cdf
from clearance.results import SimulationResult

__all__ = [
    "DeviationStatistics",
    "drive_period",
    "deviation_series",
    "deviation_statistics",
    "deviation_statistics_from_arrays",
    "per_cycle_mean_deviation",
]


@dataclass(frozen=True)
class DeviationStatistics:
    """Statistics of d = y - y_ideal over a window.

    Attributes:
        n: number of samples used.
        window_start: first time of the window [s].
        window_end: last time of the window [s].
        mean_deviation: mean of |d| [output unit] (the literature's "mean deviation").
        mean_signed_deviation: mean of d [output unit].
        rms_deviation: sqrt(mean(d^2)) [output unit].
        max_deviation: max |d| [output unit].
        band90: 90th percentile of |d| [output unit]: 90 % of the samples lie within
            +-band90 of the ideal curve (the 90 % tolerance band half-width).
        band90_low, band90_high: 5th and 95th percentiles of d [output unit].
        t_statistic, t_pvalue: paired t-test of y against y_ideal (one-sample t-test of
            d against 0, `scipy.stats.ttest_rel`).
        f_statistic, f_pvalue: F = var(y) / var(y_ideal) with (n - 1, n - 1) degrees of
            freedom, two-sided p-value.
        ks_statistic, ks_pvalue: two-sample Kolmogorov-Smirnov test of y against y_ideal
            (`scipy.stats.ks_2samp`; its p-value exact at every n, where scipy's is asymptotic
            above n = 10,000).
    """

    n: int
    window_start: float
    window_end: float
    mean_deviation: float
    mean_signed_deviation: float
    rms_deviation: float
    max_deviation: float
    band90: float
    band90_low: float
    band90_high: float
    t_statistic: float
    t_pvalue: float
    f_statistic: float
    f_pvalue: float
    ks_statistic: float
    ks_pvalue: float

    def as_dict(self) -> dict[str, float]:
        """The statistics as a flat dict (JSON-serialisable)."""
        return asdict(self)


def drive_period(result: SimulationResult, drive: int = 0) -> float:
    """Period of a drive [s] from its mean recorded speed: 2 pi / mean |speed|.

    Args:
        result: a run.
        drive: drive index (column of ``result.drive_speed``).

    Raises:
        ValueError: the drive does not turn (mean speed 0) or does not exist.
    """
    if result.drive_speed.ndim != 2 or not 0 <= drive < result.drive_speed.shape[1]:
        raise ValueError(f"drive index {drive} out of range (result has {result.drive_speed.shape[-1]} drives)")
    w = float(np.mean(np.abs(result.drive_speed[:, drive])))
    if not (np.isfinite(w) and w > 0):
        raise ValueError(f"drive {drive} has mean speed {w!r} rad/s: no drive period")
    return 2 * np.pi / w


def deviation_series(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    *,
    skip: float | None = None,
    end: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times, output and ideal output (interpolated on the result's times) in a window.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin (any time grid covering the result's).
        output: output name (``slider_x``, ``slider_x_vel``, ...).
        skip: start-up transient skipped [s]; default one drive period.
        end: end of the window [s]; default the end of the run.

    Returns:
        (t, y, y_ideal), each (m,).

    Raises:
        KeyError: unknown output.
        ValueError: the window holds fewer than 3 samples.
    """
    if output not in result.outputs or output not in ideal.outputs:
        raise KeyError(f"output {output!r} not in both results (have {sorted(result.outputs)})")
    if skip is None:
        skip = drive_period(result)
    t = result.times
    keep = t >= t[0] + skip if len(t) else np.zeros(0, bool)
    if end is not None:
        keep &= t <= end
    if np.count_nonzero(keep) < 3:
        raise ValueError(
            f"the window [{skip:g} s, {end if end is not None else 'end'}] holds fewer than 3 samples "
            f"(run is {t[-1] - t[0] if len(t) else 0:g} s long): use a longer run or a smaller skip"
        )
    y = result.outputs[output][keep]
    y_ideal = np.interp(t[keep], ideal.times, ideal.outputs[output])
    return t[keep], y, y_ideal


def deviation_statistics_from_arrays(
    y: np.ndarray, y_ideal: np.ndarray, *, window: tuple[float, float] = (np.nan, np.nan)
) -> DeviationStatistics:
    """`DeviationStatistics` of two equally long sample arrays.

    Args:
        y: (m,) output with clearance.
        y_ideal: (m,) ideal output at the same times.
        window: (start, end) times recorded in the result [s].

    Raises:
        ValueError: shapes differ or fewer than 3 samples.
    """
    y = np.asarray(y, dtype=float)
    y_ideal = np.asarray(y_ideal, dtype=float)
    if y.shape != y_ideal.shape or y.ndim != 1:
        raise ValueError(f"y and y_ideal must be 1-D of equal length (got {y.shape} and {y_ideal.shape})")
    if len(y) < 3:
        raise ValueError(f"need at least 3 samples (got {len(y)})")
    d = y - y_ideal
    ad = np.abs(d)
    n = len(d)
    # ttest_rel is undefined for a constant deviation (zero variance up to rounding)
    if np.ptp(d) <= 1e-12 * max(float(np.max(np.abs(d))), np.finfo(float).tiny):
        t_stat, t_p = (0.0, 1.0) if d[0] == 0 else (float(np.sign(d[0]) * np.inf), 0.0)
    else:
        t_stat, t_p = paired_t_test(y, y_ideal)
    v1, v0 = np.var(y, ddof=1), np.var(y_ideal, ddof=1)
    if v0 > 0:
        f_stat = float(v1 / v0)
        cdf = variance_ratio_cdf(f_stat, n - 1, n - 1)
        f_p = float(min(1.0, 2 * min(cdf, 1 - cdf)))
    else:
        f_stat, f_p = (float("nan"), float("nan"))
    ks_stat, ks_p = ks_two_sample(y, y_ideal)
    lo, hi = np.percentile(d, [5, 95])
    return DeviationStatistics(
        n=n,
        window_start=float(window[0]),
        window_end=float(window[1]),
        mean_deviation=float(ad.mean()),
        mean_signed_deviation=float(d.mean()),
        rms_deviation=float(np.sqrt(np.mean(d**2))),
        max_deviation=float(ad.max()),
        band90=float(np.percentile(ad, 90)),
        band90_low=float(lo),
        band90_high=float(hi),
        t_statistic=t_stat,
        t_pvalue=t_p,
        f_statistic=f_stat,
        f_pvalue=f_p,
        ks_statistic=ks_stat,
        ks_pvalue=ks_p,
    )


def deviation_statistics(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    *,
    skip: float | None = None,
    end: float | None = None,
) -> DeviationStatistics:
    """Deviation statistics of ``output`` against the ideal run over a steady-state window.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin.
        output: output name.
        skip: start-up transient skipped [s]; default one drive period.
        end: end of the window [s]; default the end of the run.

    Raises:
        KeyError: unknown output.
        ValueError: the window holds fewer than 3 samples.
    """
    t, y, y0 = deviation_series(result, ideal, output, skip=skip, end=end)
    return deviation_statistics_from_arrays(y, y0, window=(float(t[0]), float(t[-1])))


def per_cycle_mean_deviation(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    *,
    period: float | None = None,
    skip: float | None = None,
) -> np.ndarray:
    """Mean |y - y_ideal| over each whole drive period after the transient.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin.
        output: output name.
        period: drive period T [s]; default from the recorded drive speed.
        skip: transient skipped [s]; default one period.

    Returns:
        (K,) one mean deviation per whole period in the window [output unit].
    """
    if period is None:
        period = drive_period(result)
    if skip is None:
        skip = period
    t, y, y0 = deviation_series(result, ideal, output, skip=skip)
    k = np.floor((t - t[0]) / period + 1e-9).astype(int)
    # a period counts when the window covers at least 99 % of it (the run ends one step
    # short of its nominal duration, so the last period is one sample short)
    full = int(np.floor((t[-1] - t[0]) / period + 0.01))
    ad = np.abs(y - y0)
    return np.array([ad[k == i].mean() for i in range(full) if np.any(k == i)])
