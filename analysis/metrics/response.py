"""Response of a run with clearance against the ideal mechanism: lag, peaks, contact modes.

Lag of one signal: the time shift that best aligns the output with the ideal output (peak
of their cross-correlation, refined by a parabola through the three samples around it), or
the phase of the drive-frequency Fourier component. The report uses the one lag of
displacement, velocity and acceleration together (`clearance.analysis.metrics.lag`)
instead: one signal's lag can disagree in sign with its derivatives'. Peaks: largest and
smallest values and their times, overall, per drive period (`output_peaks`) and per window
(`window_peaks`: the start-up apart from the steady state).

Contact modes (the criterion, per contact event = a maximal run of samples with
penetration > 0):

* free flight: samples with penetration <= 0;
* impact: samples in a contact event shorter than ``continuous_after``;
* continuous contact: samples in a contact event lasting ``continuous_after`` or longer.

The default ``continuous_after`` is 5 % of the drive period (an 18 degree crank arc): a
Hertz impact of the benchmark lasts of order 0.1 ms, about 1 % of the 12 ms period at
5000 rpm (Flores and Ambrósio 2004, docs/references.md), while a journal that follows the bearing wall stays in
contact for a sizeable part of the cycle. A joint's dominant mode is the mode with the
largest share of the time in the window asked for (the whole run, the start-up window or
the steady state).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from clearance.analysis.metrics.statistics import drive_period
from clearance.analysis.metrics.summary import JointSummary, contact_series, joint_summary
from clearance.results import SimulationResult

__all__ = [
    "CONTINUOUS_SHARE",
    "ContactMode",
    "ContactEvent",
    "JointContactModes",
    "LagMethod",
    "OutputPeaks",
    "ResponseComparison",
    "WindowPeaks",
    "compare_response",
    "contact_events",
    "contact_modes",
    "output_lag",
    "output_peaks",
    "window_peaks",
]


CONTINUOUS_SHARE = 0.05
"""A contact event lasting this share of the drive period or longer is continuous contact (`contact_modes`)."""


class LagMethod(enum.Enum):
    """How the output lag is measured."""

    CROSS_CORRELATION = "cross_correlation"
    PHASE = "phase"


class ContactMode(enum.Enum):
    """Contact mode of a clearance joint (see the module docstring for the criterion)."""

    FREE_FLIGHT = "free_flight"
    IMPACT = "impact"
    CONTINUOUS = "continuous_contact"


@dataclass(frozen=True)
class OutputPeaks:
    """Extremes of one output.

    Attributes:
        max_value, max_time: largest value [output unit] and its time [s].
        min_value, min_time: smallest value and its time.
        cycle_max, cycle_max_time: (K,) largest value in each drive period and its time.
        cycle_min, cycle_min_time: (K,) smallest value in each drive period and its time.
    """

    max_value: float
    max_time: float
    min_value: float
    min_time: float
    cycle_max: np.ndarray
    cycle_max_time: np.ndarray
    cycle_min: np.ndarray
    cycle_min_time: np.ndarray


@dataclass(frozen=True)
class ResponseComparison:
    """An output against the ideal output.

    Attributes:
        output: output name.
        lag: time by which the output lags the ideal one [s] (positive: later).
        lag_angle: the lag as a drive angle, lag * 2 pi / T [rad].
        peaks: extremes of the output with clearance.
        ideal_peaks: extremes of the ideal output.
        peak_ratio: max |y| / max |y_ideal| [-].
    """

    output: str
    lag: float
    lag_angle: float
    peaks: OutputPeaks
    ideal_peaks: OutputPeaks
    peak_ratio: float


@dataclass(frozen=True)
class WindowPeaks:
    """Extremes of an output and of the ideal output over one window of a run (`window_peaks`).

    Attributes:
        window: (start, end) of the window [s].
        max_value, max_time: largest value [output unit] and its time [s].
        min_value, min_time: smallest value and its time.
        ideal_max, ideal_min: the ideal output's extremes over the same window.
        peak_ratio: max |y| / max |y_ideal| over the window [-] (inf when the ideal is 0).
    """

    window: tuple[float, float]
    max_value: float
    max_time: float
    min_value: float
    min_time: float
    ideal_max: float
    ideal_min: float
    peak_ratio: float


@dataclass(frozen=True)
class ContactEvent:
    """One contact event (penetration > 0 without a break).

    Attributes:
        start, end: times of its first and last sample [s].
        duration: end - start + one sample interval [s].
        peak_force: largest force magnitude [N].
        impulse: integral of the force magnitude over the event [N s].
        mode: IMPACT or CONTINUOUS.
    """

    start: float
    end: float
    duration: float
    peak_force: float
    impulse: float
    mode: ContactMode


@dataclass(frozen=True)
class JointContactModes:
    """Contact-mode classification of one clearance joint.

    Attributes:
        joint: joint name.
        dominant: mode with the largest time share in the window.
        fractions: mode -> share of the window's samples [-].
        events: contact events starting in the window (classified over their whole duration).
        impulse: total contact impulse in the window [N s].
        continuous_after: the duration threshold used [s].
        summary: the joint's contact statistics over the whole run (`JointSummary`).
    """

    joint: str
    dominant: ContactMode
    fractions: dict[ContactMode, float]
    events: tuple[ContactEvent, ...]
    impulse: float
    continuous_after: float
    summary: JointSummary


def _sample_interval(times: np.ndarray) -> float:
    return float(np.median(np.diff(times))) if len(times) > 1 else 0.0


def _correlate_valid(b: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Valid-mode cross-correlation c[k] = sum_t a[t] b[t + k], k = 0 .. len(b) - len(a), by FFT.

    numpy's FFT gives what ``scipy.signal.correlate(b, a, mode="valid", method="fft")`` gives,
    without importing scipy.signal (about 0.5 s).
    """
    size = len(b) + len(a) - 1
    nfft = 1 << (size - 1).bit_length()
    c = np.fft.irfft(np.fft.rfft(b, nfft) * np.conj(np.fft.rfft(a, nfft)), nfft)
    return c[: len(b) - len(a) + 1]


def output_peaks(result: SimulationResult, output: str, *, period: float | None = None) -> OutputPeaks:
    """Largest and smallest values of an output, overall and per drive period.

    Args:
        result: a run.
        output: output name (``slider_x_acc``, ...).
        period: drive period T [s]; default from the recorded drive speed.

    Raises:
        KeyError: unknown output.
    """
    y, t = result.outputs[output], result.times
    if period is None:
        period = drive_period(result)
    k = np.floor((t - t[0]) / period + 1e-9).astype(int)
    cmx, cmxt, cmn, cmnt = [], [], [], []
    for i in np.unique(k):
        idx = np.nonzero(k == i)[0]
        a, b = idx[np.argmax(y[idx])], idx[np.argmin(y[idx])]
        cmx.append(y[a])
        cmxt.append(t[a])
        cmn.append(y[b])
        cmnt.append(t[b])
    a, b = int(np.argmax(y)), int(np.argmin(y))
    return OutputPeaks(
        float(y[a]),
        float(t[a]),
        float(y[b]),
        float(t[b]),
        np.array(cmx),
        np.array(cmxt),
        np.array(cmn),
        np.array(cmnt),
    )


def output_lag(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    *,
    method: LagMethod = LagMethod.CROSS_CORRELATION,
    skip: float | None = None,
    max_lag: float | None = None,
) -> float:
    """Time by which ``output`` lags the ideal output [s] (positive: the output is later).

    Cross-correlation: the shift s maximising sum y(t) y_ideal(t - s) over the window
    (means removed), searched within +-max_lag, refined to sub-sample precision by a
    parabola. Phase: -(phase(y) - phase(y_ideal)) / omega of the Fourier component at the
    drive frequency omega = 2 pi / T.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin.
        output: output name.
        method: `LagMethod`.
        skip: start-up transient skipped [s]; default one drive period.
        max_lag: largest lag searched [s]; default a quarter of the drive period.

    Raises:
        KeyError: unknown output.
        ValueError: too short a window.
    """
    from clearance.analysis.metrics.statistics import deviation_series

    period = drive_period(result)
    t, y, y0 = deviation_series(result, ideal, output, skip=skip)
    if method is LagMethod.PHASE:
        w = 2 * np.pi / period
        # whole periods only, so the component is not smeared by a partial cycle
        n_per = max(1, int(np.floor((t[-1] - t[0]) / period + 0.01)))
        sel = t <= t[0] + n_per * period
        basis = np.exp(-1j * w * t[sel])
        ph = np.angle(np.sum(y[sel] * basis)) - np.angle(np.sum(y0[sel] * basis))
        ph = (ph + np.pi) % (2 * np.pi) - np.pi
        return float(-ph / w)
    h = _sample_interval(t)
    if max_lag is None:
        max_lag = period / 4
    m = max(1, int(round(max_lag / h)))
    # the output stays in a fixed window; the ideal output (known over the whole run) is
    # shifted under it, so every shift averages over the same samples
    times = result.times
    b = np.interp(times, ideal.times, ideal.outputs[output])
    i0 = int(np.searchsorted(times, t[0]))
    i0m = max(i0, m)
    i1 = min(i0 + len(t), len(times) - m)
    per = int(round(period / h))
    if i1 - i0m >= per:  # whole periods: a partial cycle biases the peak of a periodic signal
        i1 = i0m + (i1 - i0m) // per * per
    if i1 - i0m < 3:
        raise ValueError("the run is too short for the lag search: use a longer run or a smaller max_lag")
    a = result.outputs[output][i0m:i1]
    a = a - a.mean()
    # c[k] = sum_t a[t] b[i0m - m + t + k]; shift s = m - k (the output is b delayed by s)
    c = _correlate_valid(b[i0m - m : i1 + m], a)
    lags = m - np.arange(len(c))
    i = int(np.argmax(c))
    frac = 0.0
    if 0 < i < len(c) - 1:
        den = c[i - 1] - 2 * c[i] + c[i + 1]
        if den < 0:
            frac = 0.5 * (c[i - 1] - c[i + 1]) / den
    return float((lags[i] - frac) * h)  # lags fall by one per index


def compare_response(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    *,
    method: LagMethod = LagMethod.CROSS_CORRELATION,
    skip: float | None = None,
) -> ResponseComparison:
    """Lag and peaks of ``output`` against the ideal run (see `output_lag`, `output_peaks`).

    Args:
        result: run with clearance.
        ideal: run of the ideal twin.
        output: output name.
        method: `LagMethod` of the lag.
        skip: start-up transient skipped by the lag [s]; default one drive period.

    The lag is NaN when the run is too short to search for it.

    Raises:
        KeyError: unknown output.
    """
    period = drive_period(result)
    try:
        lag = output_lag(result, ideal, output, method=method, skip=skip)
    except ValueError:
        lag = float("nan")  # run too short for a lag search: peaks are still meaningful
    pk, pk0 = output_peaks(result, output, period=period), output_peaks(ideal, output, period=period)
    big0 = max(abs(pk0.max_value), abs(pk0.min_value))
    big = max(abs(pk.max_value), abs(pk.min_value))
    return ResponseComparison(
        output=output,
        lag=lag,
        lag_angle=float(lag * 2 * np.pi / period),
        peaks=pk,
        ideal_peaks=pk0,
        peak_ratio=float(big / big0) if big0 > 0 else float("inf"),
    )


def window_peaks(
    result: SimulationResult, ideal: SimulationResult, output: str, *, start: float, end: float = float("inf")
) -> WindowPeaks | None:
    """Extremes of ``output`` and the ideal output over the samples with start <= t < end.

    Use it to keep the start-up window's peaks apart from the steady state's: a journal
    released from the bearing centre makes its largest impacts in the first drive period.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin (interpolated on the result's times).
        output: output name.
        start, end: the window [s] (times of the run).

    Returns:
        The `WindowPeaks`, or None when no sample lies in the window.

    Raises:
        KeyError: unknown output.
    """
    t = result.times
    sel = (t >= start) & (t < end)
    if not sel.any():
        return None
    tt, y = t[sel], result.outputs[output][sel]
    y0 = np.interp(tt, ideal.times, ideal.outputs[output])
    a, b = int(np.argmax(y)), int(np.argmin(y))
    big0 = float(np.max(np.abs(y0)))
    return WindowPeaks(
        window=(float(tt[0]), float(tt[-1])),
        max_value=float(y[a]),
        max_time=float(tt[a]),
        min_value=float(y[b]),
        min_time=float(tt[b]),
        ideal_max=float(y0.max()),
        ideal_min=float(y0.min()),
        peak_ratio=float(np.max(np.abs(y)) / big0) if big0 > 0 else float("inf"),
    )


def _event_bounds(penetration: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and last sample index of each contact event (maximal run of penetration > 0)."""
    contact = np.asarray(penetration) > 0
    edges = np.diff(np.concatenate([[0], contact.astype(np.int8), [0]]))
    return np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0] - 1


def contact_events(
    times: np.ndarray, penetration: np.ndarray, force: np.ndarray, *, continuous_after: float
) -> list[ContactEvent]:
    """Contact events of one joint from its penetration and force-magnitude series.

    Args:
        times: (n,) [s].
        penetration: (n,) [m]; > 0 in contact.
        force: (n,) contact-force magnitude [N].
        continuous_after: events at least this long are CONTINUOUS [s].
    """
    h = _sample_interval(times)
    out = []
    for a, b in zip(*_event_bounds(penetration)):
        seg_f = force[a : b + 1]
        dur = float(times[b] - times[a] + h)
        # rectangle rule: each sample holds its force for one sample interval, so a
        # one-sample event still carries impulse
        imp = float(np.sum(seg_f) * h)
        mode = ContactMode.CONTINUOUS if dur >= continuous_after else ContactMode.IMPACT
        out.append(ContactEvent(float(times[a]), float(times[b]), dur, float(seg_f.max()), imp, mode))
    return out


def contact_modes(
    result: SimulationResult,
    joint: str,
    *,
    continuous_after: float | None = None,
    skip: float | None = None,
    end: float | None = None,
) -> JointContactModes:
    """Classify a clearance joint's (or a slider's) contact as free flight, impacts or continuous contact.

    Events are found and classified over the whole run (an event that crosses the window's
    edge keeps the mode of its whole duration); the fractions, events and impulse are those
    of the window from ``skip`` to ``end`` after the run's start.

    Args:
        result: a run.
        joint: clearance joint name, or a slider with play (`summary.contact_series`).
        continuous_after: duration threshold [s]; default 5 % of the drive period.
        skip: start of the window after the run's start [s]; default 0 (the first impact
            is part of the behaviour).
        end: end of the window after the run's start [s] (samples before it); default
            the run's end.

    Raises:
        KeyError: unknown joint.
    """
    penetration, force = contact_series(result, joint)
    if continuous_after is None:
        continuous_after = CONTINUOUS_SHARE * drive_period(result)
    t = result.times
    h = _sample_interval(t)
    keep = t >= t[0] + (skip or 0.0)
    if end is not None:
        keep &= t < t[0] + end
    code = {ContactMode.FREE_FLIGHT: 0, ContactMode.IMPACT: 1, ContactMode.CONTINUOUS: 2}
    label = np.zeros(len(t), dtype=np.int8)  # each sample's mode (code), from its whole event
    events = []
    for e, a, b in zip(
        contact_events(t, penetration, force, continuous_after=continuous_after),
        *_event_bounds(penetration),
    ):
        label[a : b + 1] = code[e.mode]
        if keep[a]:
            events.append(e)
    n = int(np.count_nonzero(keep))
    counts = {m: int(np.count_nonzero(label[keep] == i)) for m, i in code.items()}
    fractions = {m: (c / n if n else 0.0) for m, c in counts.items()}
    dominant = max(fractions, key=lambda m: fractions[m])
    in_contact = keep & (label > 0)
    return JointContactModes(
        joint=joint,
        dominant=dominant,
        fractions=fractions,
        events=tuple(events),
        impulse=float(np.sum(force[in_contact]) * h),
        continuous_after=float(continuous_after),
        summary=joint_summary(result, joint),
    )
