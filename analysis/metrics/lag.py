"""Lag of a run's output behind the ideal mechanism's, one estimate from its displacement,
velocity and acceleration together, over the steady state.

A lag tau says the output is the ideal output delayed: y(t) ~ y_ideal(t - tau). Then its
velocity and acceleration are delayed by the same tau, so one number serves all three. The
estimate (`joint_lag`):

1. Window: the whole drive periods after the start-up window (the first period of the
   slowest drive in a report). A partial period biases the correlation of a periodic signal;
   a run with no whole period after the start-up gets no estimate.
2. For each signal s (displacement, velocity, acceleration) and each shift tau on the sample
   grid within +-``bound`` (an eighth of the drive period by default): the squared misfit
   M_s(tau) of the output over the window against the ideal output delayed by tau, means
   removed (the ideal run extended periodically past its ends, so every shift uses the
   same samples of the output).
3. The lag minimises sum_s M_s(tau) / min M_s: each signal's misfit relative to its own
   best fit, i.e. a least-squares fit with each signal weighted by the inverse of its
   residual. A signal the delay model fits badly (an acceleration with impact spikes) has
   a large residual and weighs little; refined by a parabola through the three grid values
   around the minimum.
4. Uncertainty: the standard error of the same estimate over each whole period alone (two
   periods or more); resolution: the sample interval before refinement.
5. Each signal's own lag (the minimum of its M_s) is kept beside, to show whether the three
   agree. The lag is ``resolved`` when it lies inside the bound, the three signals agree in
   sign with it, it is at least `RESOLUTION_FLOOR` of the sample interval and (with two
   periods or more) more than twice its uncertainty.

The earlier per-signal cross-correlation (`response.output_lag`) searched a window cut by
the search range and disagreed in sign between the three signals of one run (the press at
one revolution: +108, -273, +82 ms); this estimate replaces it in the report.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from clearance.analysis.metrics.statistics import drive_period
from clearance.results import SimulationResult

__all__ = ["DEFAULT_BOUND_FRACTION", "RESOLUTION_FLOOR", "OutputLag", "joint_lag"]

DEFAULT_BOUND_FRACTION = 0.125
"""Lags searched up to this fraction of the drive period either way (45 degrees of the drive)."""

RESOLUTION_FLOOR = 0.01
"""A lag smaller than this fraction of the sample interval is no lag: the parabolic refinement
finds a whole-sample shift of a smooth signal to about 0.2 % of the interval (tests), so a
hundredth leaves a margin of five."""


@dataclass(frozen=True)
class OutputLag:
    """The lag of an output behind the ideal output (see the module docstring).

    Attributes:
        output: output name (position; its ``_vel`` and ``_acc`` are used with it).
        lag: joint estimate [s] (positive: the output is later); NaN when not estimated.
        uncertainty: standard error over the whole periods, each alone [s]; NaN with fewer
            than two periods.
        resolution: sample interval of the search grid [s].
        bound: largest |lag| searched [s].
        periods: whole drive periods in the window.
        window: (start, end) of the window [s].
        per_signal: signal name -> its own lag [s] (NaN where not estimated).
        resolved: the lag is inside the bound, the signals agree in sign with it, it is at
            least `RESOLUTION_FLOOR` of the sample interval and more than twice its
            uncertainty (when there is one).
        note: why there is no estimate or why it is not resolved ("" when resolved).
    """

    output: str
    lag: float
    uncertainty: float
    resolution: float
    bound: float
    periods: int
    window: tuple[float, float]
    per_signal: dict[str, float] = field(default_factory=dict)
    resolved: bool = False
    note: str = ""


def _periodic(times: np.ndarray, values: np.ndarray, period: float, at: np.ndarray) -> np.ndarray:
    """``values`` at times ``at``, the series extended periodically past its ends."""
    t0, t1 = float(times[0]), float(times[-1])
    at = np.where(at > t1, at - period * np.ceil((at - t1) / period), at)
    at = np.where(at < t0, at + period * np.ceil((t0 - at) / period), at)
    return np.interp(at, times, values)


def _fast_length(n: int) -> int:
    """The smallest 2^i 3^j 5^k >= n: a length the FFT takes fast (scipy's next_fast_len, without its import)."""
    best = 1 << (n - 1).bit_length()
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            q = -(-n // p35)  # the power of two that brings p35 to n or more
            best = min(best, p35 * (1 << (q - 1).bit_length()))
            p35 *= 3
        p5 *= 5
    return best


def _misfits(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Squared misfit of ``a`` (n,) against each length-n slice b[k : k + n], means removed.

    sum_t ((a_t - mean a) - (b_{k+t} - mean of the slice))^2 for k = 0 .. len(b) - n, by FFT
    cross-correlation and running sums.
    """
    n, nb = len(a), len(b)
    a = a - a.mean()
    # circular correlation of length >= nb wraps no shift k <= nb - n (k + t < nb for t < n);
    # a 5-smooth length is fast for the FFT
    size = _fast_length(nb)
    cross = np.fft.irfft(np.fft.rfft(b, size) * np.conj(np.fft.rfft(a, size)), size)[: nb - n + 1]
    c1 = np.concatenate([[0.0], np.cumsum(b)])
    c2 = np.concatenate([[0.0], np.cumsum(b * b)])
    s1, s2 = c1[n:] - c1[:-n], c2[n:] - c2[:-n]
    return np.maximum(float(np.sum(a * a)) - 2 * cross + (s2 - s1 * s1 / n), 0.0)


def _lowest(curve: np.ndarray) -> tuple[float, bool]:
    """(index of the minimum refined by a parabola, whether it is at an end of the grid)."""
    i = int(np.argmin(curve))
    if not 0 < i < len(curve) - 1:
        return float(i), True
    den = curve[i - 1] - 2 * curve[i] + curve[i + 1]
    frac = 0.5 * (curve[i - 1] - curve[i + 1]) / den if den > 0 else 0.0
    return i + frac, False


def _curves(
    result: SimulationResult, ideal: SimulationResult, signals: list[str], i0: int, i1: int, m: int, period: float
) -> list[np.ndarray]:
    """Misfit of each signal on rows i0:i1 over the shifts k = 0 .. 2m (shift tau = (m - k) h)."""
    t = result.times
    h = float(np.median(np.diff(t)))
    at = t[0] + (np.arange(i0 - m, i1 + m) * h)  # the result's grid, continued past its ends
    out = []
    for s in signals:
        b = _periodic(ideal.times, ideal.outputs[s], period, at)
        out.append(_misfits(result.outputs[s][i0:i1], b))
    return out


def _estimate(curves: list[np.ndarray], m: int, h: float) -> tuple[float, bool]:
    """(lag [s], at the bound) minimising the sum of each signal's misfit over its own least misfit."""
    total = np.zeros_like(curves[0])
    for c in curves:
        floor = max(float(c.min()), 1e-12 * float(c.max()), np.finfo(float).tiny)
        total += c / floor
    k, edge = _lowest(total)
    return (m - k) * h, edge


def joint_lag(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    *,
    startup: float,
    bound_fraction: float = DEFAULT_BOUND_FRACTION,
) -> OutputLag:
    """One lag of ``output`` behind the ideal output from its displacement, velocity and acceleration.

    See the module docstring for the estimate.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin (same drive).
        output: position output name; its ``_vel`` and ``_acc`` series join it where present.
        startup: start-up window after the run's start [s]; the estimate uses the whole drive
            periods after it.
        bound_fraction: largest |lag| searched, as a fraction of the drive period (0 < f < 0.5).

    Returns:
        The `OutputLag` (``lag`` NaN and a ``note`` when the run has no whole period after
        the start-up window).

    Raises:
        KeyError: unknown output.
        ValueError: ``bound_fraction`` outside (0, 0.5).
    """
    if not 0 < bound_fraction < 0.5:
        raise ValueError(f"bound_fraction must be in (0, 0.5) (got {bound_fraction!r})")
    if output not in result.outputs or output not in ideal.outputs:
        raise KeyError(f"output {output!r} not in both results (have {sorted(result.outputs)})")
    signals = [s for s in (output, f"{output}_vel", f"{output}_acc") if s in result.outputs and s in ideal.outputs]
    period = drive_period(result)
    t = result.times
    h = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    bound = bound_fraction * period
    start = float(t[0]) + startup
    periods = int(np.floor((float(t[-1]) + h - start) / period + 1e-6)) if h > 0 else 0
    nan = float("nan")
    blank = {s: nan for s in signals}
    if periods < 1:
        return OutputLag(
            output,
            nan,
            nan,
            h,
            bound,
            0,
            (start, float(t[-1])),
            blank,
            note="the run has no whole drive period after its start-up window",
        )
    per = int(round(period / h))
    i0 = int(np.searchsorted(t, start - 0.5 * h))
    i1 = min(i0 + periods * per, len(t))
    m = max(1, int(round(bound / h)))
    curves = _curves(result, ideal, signals, i0, i1, m, period)
    lag, edge = _estimate(curves, m, h)
    per_signal = {}
    for s, c in zip(signals, curves):
        k, _ = _lowest(c)
        per_signal[s] = (m - k) * h
    uncertainty = nan
    if periods >= 2:
        each = [
            _estimate(_curves(result, ideal, signals, i0 + k * per, i0 + (k + 1) * per, m, period), m, h)[0]
            for k in range(periods)
        ]
        uncertainty = float(np.std(each, ddof=1) / np.sqrt(periods))
    window = (float(t[i0]), float(t[i1 - 1]))
    notes = []
    if edge:
        notes.append(f"the best fit lies at the search bound (±{bound * 1e3:.4g} ms)")
    signs = {np.sign(v) for v in per_signal.values()}
    if len(signs) > 1 or (signs and np.sign(lag) not in signs):
        notes.append("the signals disagree in sign")
    if np.isfinite(uncertainty) and not abs(lag) > 2 * uncertainty:
        notes.append("the lag is within twice its uncertainty of zero")
    if not abs(lag) >= RESOLUTION_FLOOR * h:
        notes.append(f"the lag is below {RESOLUTION_FLOOR:.0%} of the sample interval: no lag")
    return OutputLag(
        output,
        float(lag),
        uncertainty,
        h,
        bound,
        periods,
        window,
        per_signal,
        resolved=not notes,
        note="; ".join(notes),
    )
