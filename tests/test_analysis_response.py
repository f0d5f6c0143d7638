"""Deviation statistics against scipy on known data; lags, peaks and contact modes on runs."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from clearance.analysis.metrics.lag import joint_lag
from clearance.analysis.metrics.response import (
    ContactMode,
    LagMethod,
    compare_response,
    contact_events,
    contact_modes,
    output_lag,
)
from clearance.analysis.metrics.statistics import (
    deviation_statistics,
    deviation_statistics_from_arrays,
    per_cycle_mean_deviation,
)
from clearance.results import JointResult, SimulationResult

OMEGA = 2 * np.pi * 10.0  # 10 Hz drive of the synthetic results


def _synthetic(y: np.ndarray, t: np.ndarray, pen: np.ndarray | None = None) -> SimulationResult:
    n = len(t)
    pen = np.full(n, -1e-6) if pen is None else pen
    force = np.column_stack([np.where(pen > 0, 1e9 * np.maximum(pen, 0), 0.0), np.zeros(n)])
    return SimulationResult(
        times=t,
        outputs={"x": y, "x_vel": np.gradient(y, t), "x_acc": np.gradient(np.gradient(y, t), t)},
        joints={"j": JointResult(np.zeros((n, 2)), np.zeros((n, 2)), pen, force)},
        drive_angle=(OMEGA * t)[:, None],
        drive_speed=np.full((n, 1), OMEGA),
        drive_torque=np.zeros((n, 1)),
        link_poses=np.zeros((n, 1, 3)),
        closure_violation=np.zeros(n),
    )


def test_statistics_match_scipy_and_numpy():
    rng = np.random.default_rng(1)
    y0 = np.sin(np.linspace(0, 20, 2000))
    y = y0 + 0.01 + 0.02 * rng.standard_normal(2000)
    s = deviation_statistics_from_arrays(y, y0)
    d = y - y0
    # the statistics: the same NumPy formulas as scipy's or these (measured equal); 1e-12 relative
    # leaves room for a reordered sum (a few ulps)
    assert s.mean_deviation == pytest.approx(np.mean(np.abs(d)), rel=1e-12)
    assert s.rms_deviation == pytest.approx(np.sqrt(np.mean(d**2)), rel=1e-12)
    assert s.band90 == pytest.approx(np.percentile(np.abs(d), 90), rel=1e-12)
    tt = stats.ttest_rel(y, y0)
    assert s.t_statistic == pytest.approx(tt.statistic, rel=1e-12)
    # the p-value (2.8e-93) is the project's regularized beta against scipy's: its ln Gamma terms
    # (~1e4 at n = 2000) round to ~1e-16 n ln n in ln p (tests/test_significance.py); measured
    # 8.9e-13 relative, so 1e-10 (100x); abs=0, as approx's default 1e-12 would accept any p here
    assert s.t_pvalue == pytest.approx(tt.pvalue, rel=1e-10, abs=0.0)
    ks = stats.ks_2samp(y, y0)
    assert (s.ks_statistic, s.ks_pvalue) == pytest.approx((ks.statistic, ks.pvalue), rel=1e-12)
    f = np.var(y, ddof=1) / np.var(y0, ddof=1)
    assert s.f_statistic == pytest.approx(f, rel=1e-12)
    p = 2 * min(stats.f.cdf(f, 1999, 1999), stats.f.sf(f, 1999, 1999))
    # cdf vs sf evaluation: measured 1.4e-12; 1e-9, tests/test_significance.py's bound for n <= 5000
    assert s.f_pvalue == pytest.approx(p, rel=1e-9)
    # a known shift: |d| = 0.5 everywhere, zero-variance t-test handled, band = 0.5
    s2 = deviation_statistics_from_arrays(y0 + 0.5, y0)
    assert s2.mean_deviation == pytest.approx(0.5, rel=1e-12)
    assert s2.band90 == pytest.approx(0.5, rel=1e-12)
    assert s2.t_pvalue == 0.0 and s2.f_statistic == pytest.approx(1.0, rel=1e-12)


def test_window_skips_first_period_and_per_cycle_values():
    t = np.arange(0, 0.5, 1e-4)  # 5 drive periods of 0.1 s
    y0 = np.sin(OMEGA * t)
    dev = np.where(t < 0.1, 1.0, 0.01)  # large deviation only in the first period
    res, ideal = _synthetic(y0 + dev, t), _synthetic(y0, t)
    s = deviation_statistics(res, ideal, "x")
    assert s.window_start == pytest.approx(0.1, abs=1e-4)  # one period, one sample
    assert s.mean_deviation == pytest.approx(0.01, rel=1e-9)
    cyc = per_cycle_mean_deviation(res, ideal, "x")
    assert len(cyc) == 4  # 4 whole periods after the first
    np.testing.assert_allclose(cyc, 0.01, rtol=1e-9)


@pytest.mark.parametrize("method", list(LagMethod))
def test_lag_of_a_shifted_sine(method):
    t = np.arange(0, 0.5, 1e-4)
    lag = 3.3e-3  # 33 samples
    res, ideal = _synthetic(np.sin(OMEGA * (t - lag)), t), _synthetic(np.sin(OMEGA * t), t)
    # parabolic refinement of the correlation peak: well below one sample (1e-4 s); the
    # phase method is exact for a pure sine up to rounding
    assert output_lag(res, ideal, "x", method=method) == pytest.approx(lag, abs=2e-5)
    cmp = compare_response(res, ideal, "x", method=method)
    assert cmp.lag_angle == pytest.approx(OMEGA * lag, abs=OMEGA * 2e-5)
    assert cmp.peak_ratio == pytest.approx(1.0, abs=1e-6)  # same amplitude; sampled peaks
    assert len(cmp.peaks.cycle_max) == 5


def test_contact_events_and_modes():
    t = np.arange(0, 0.2, 1e-4)  # 2 periods of 0.1 s; continuous threshold 5 ms
    pen = np.full(len(t), -1e-6)
    pen[100:110] = 1e-6  # 1 ms: impact
    pen[500:700] = 1e-6  # 20 ms: continuous
    ev = contact_events(t, pen, np.where(pen > 0, 10.0, 0.0), continuous_after=5e-3)
    assert [e.mode for e in ev] == [ContactMode.IMPACT, ContactMode.CONTINUOUS]
    assert ev[0].duration == pytest.approx(1e-3, rel=1e-9)
    assert ev[0].impulse == pytest.approx(10.0 * 1e-3, rel=1e-9)  # F * duration
    m = contact_modes(_synthetic(np.sin(OMEGA * t), t, pen), "j")
    assert m.continuous_after == pytest.approx(5e-3, rel=1e-9)
    assert m.fractions[ContactMode.CONTINUOUS] == pytest.approx(0.1, rel=1e-9)
    assert m.fractions[ContactMode.IMPACT] == pytest.approx(0.005, rel=1e-9)
    assert m.dominant is ContactMode.FREE_FLIGHT
    assert m.summary.impacts == 2


def test_on_a_simulated_slider_crank(slow_pair):
    res, ideal = slow_pair
    s = deviation_statistics(res, ideal, "slider_x")
    # the slider can move at most by the radial clearance c = 0.5 mm relative to the
    # ideal mechanism (pin offset) plus penetration (< 0.05 mm here)
    assert 0 < s.mean_deviation < 0.55e-3
    cmp = compare_response(res, ideal, "slider_x")
    assert abs(cmp.lag) < 0.25 * 0.06  # searched range: a quarter period
    m = contact_modes(res, "rod_slider")
    assert sum(m.fractions.values()) == pytest.approx(1.0, abs=1e-12)
    assert m.impulse > 0


@pytest.fixture(scope="module")
def slow_pair():
    """Slider-crank at 1000 rpm (T = 60 ms), 3 revolutions, 5 us step, 36 segments."""
    from clearance import ModelOptions, simulate
    from clearance.builders import rpm, slider_crank

    m = slider_crank(crank_speed=rpm(1000.0))
    o = ModelOptions(timestep=5e-6, segments=36)
    return simulate(m, options=o), simulate(m.ideal_twin(), options=o)


def _shifted(tau: float, periods: int, seed: int = 0) -> tuple[SimulationResult, SimulationResult]:
    """A run whose output is the ideal output delayed by ``tau``, as a clearance run looks.

    Displacement: offset by 0.2 mm (the pin's offset in its bearing) with a small ripple;
    velocity: with white noise; acceleration: with 40 impact spike pairs 10-50 times the
    ideal's peak. Output x = 0.05 sin(W t) + 0.01 sin(2 W t + 0.7), W the 10 Hz drive.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0, periods * 0.1, 1e-4)

    def sig(s):
        return (
            0.05 * np.sin(OMEGA * s) + 0.01 * np.sin(2 * OMEGA * s + 0.7),
            0.05 * OMEGA * np.cos(OMEGA * s) + 0.02 * OMEGA * np.cos(2 * OMEGA * s + 0.7),
            -0.05 * OMEGA**2 * np.sin(OMEGA * s) - 0.04 * OMEGA**2 * np.sin(2 * OMEGA * s + 0.7),
        )

    y0, v0, a0 = sig(t)
    y, v, a = sig(t - tau)
    k = rng.choice(len(t) - 1, 40, replace=False)
    amp = 50 * np.abs(a0).max() * rng.uniform(0.2, 1, 40)
    a[k] += amp
    a[k + 1] -= amp
    res, ideal = _synthetic(y0, t), _synthetic(y0, t)
    res.outputs.update(
        x=y + 2e-4 + 1e-5 * np.sin(37 * OMEGA * t), x_vel=v + 0.002 * rng.standard_normal(len(t)), x_acc=a
    )
    ideal.outputs.update(x=y0, x_vel=v0, x_acc=a0)
    return res, ideal


@pytest.mark.parametrize("tau", [2.5e-4, -2.5e-4, 1.3e-3])
@pytest.mark.parametrize("periods", [2, 3])
def test_joint_lag_agrees_in_sign_and_size_on_a_shifted_signal(tau, periods):
    res, ideal = _shifted(tau, periods)
    lag = joint_lag(res, ideal, "x", startup=0.1)
    # measured error of the joint estimate on these signals: below 3e-7 s (0.3 % of a
    # sample, from the velocity noise and the spikes); 2e-6 s leaves a margin of 6
    assert lag.lag == pytest.approx(tau, abs=2e-6)
    assert lag.periods == periods - 1 and lag.resolution == pytest.approx(1e-4, rel=1e-9)  # sample grid
    assert {np.sign(v) for v in lag.per_signal.values()} == {np.sign(tau)}
    assert lag.resolved, lag.note
    if periods == 3:
        assert 0 < lag.uncertainty < 1e-6  # two periods: a standard error, well below the lag
    # the single-signal estimate on one steady period searched a window cut by its range
    # and gave displacement, velocity and acceleration lags of different signs (about
    # -7.7, +8.1, -5.7 ms for tau = +0.25 ms): the failure the joint estimate replaces
    if periods == 2:
        old = [output_lag(res, ideal, k, skip=0.1) for k in ("x", "x_vel", "x_acc")]
        assert len({np.sign(v) for v in old}) > 1


def test_joint_lag_of_no_shift_and_of_a_run_without_steady_state():
    res, ideal = _shifted(0.0, 3)
    lag = joint_lag(res, ideal, "x", startup=0.1)
    assert abs(lag.lag) < 1e-6  # the noise's share, as above
    assert not lag.resolved
    short = joint_lag(*_shifted(1e-3, 1), "x", startup=0.1)
    assert np.isnan(short.lag) and short.periods == 0 and "no whole drive period" in short.note
    with pytest.raises(ValueError, match="bound_fraction"):
        joint_lag(res, ideal, "x", startup=0.1, bound_fraction=0.5)


def test_joint_lag_agrees_in_sign_on_the_press():
    """The seven-bar press, two revolutions at 40 us and at 20 us (one steady period each)."""
    from clearance import ModelOptions, simulate
    from clearance.builders import seven_bar_press

    m = seven_bar_press()
    period = m.drive_period
    lags = []
    for h in (40e-6, 20e-6):
        options = ModelOptions(timestep=h)
        res = simulate(m, options=options, duration=2 * period)
        ideal = simulate(m.ideal_twin(), options=options, duration=2 * period)
        lag = joint_lag(res, ideal, "slider_y", startup=period)
        # displacement and velocity agree in sign with the joint estimate; the acceleration's own
        # estimate follows the journals' contact-force ripple and is not asked to (its lag read
        # +0.79 / -0.42 / +0.064 ms at 40 / 20 / 5 us, around a joint lag of -0.0217 ms)
        assert np.sign(lag.per_signal["slider_y"]) == np.sign(lag.per_signal["slider_y_vel"]) == np.sign(lag.lag)
        assert abs(lag.lag) < lag.bound
        lags.append(lag.lag)
    # the joint lag is the mechanism's, not the step's: measured -0.02165 / -0.02156 ms at 40 / 20
    # us (-0.02177 ms at 5 us): within 1 % of each other; 5 % still catches a lag that moves with the step
    assert lags[0] == pytest.approx(lags[1], rel=0.05)


def test_contact_modes_classify_an_event_over_its_whole_duration():
    t = np.arange(0, 0.2, 1e-4)  # 2 periods of 0.1 s; continuous threshold 5 ms
    pen = np.full(len(t), -1e-6)
    pen[450:550] = 1e-6  # 10 ms of contact across t = 52 ms
    res = _synthetic(np.sin(OMEGA * t), t, pen)
    late = contact_modes(res, "j", skip=0.052)
    # the 3 ms after the window's start belong to a 10 ms event: continuous contact, not an
    # impact; the event starts before the window, so the window counts none (exact counts)
    assert late.fractions[ContactMode.CONTINUOUS] == pytest.approx(30 / 1480, rel=1e-12)
    assert late.fractions[ContactMode.IMPACT] == 0.0 and late.events == ()
    early = contact_modes(res, "j", end=0.052)
    assert early.fractions[ContactMode.CONTINUOUS] == pytest.approx(70 / 520, rel=1e-12)
    assert len(early.events) == 1 and early.impulse == pytest.approx(70 * 1e-4 * 1e3, rel=1e-9)  # 1e9 N/m * 1 um


def test_the_lag_s_fft_length_is_the_smallest_5_smooth_one():
    """The misfit's FFT length: scipy's next_fast_len for real input, without importing scipy.fft."""
    from scipy.fft import next_fast_len

    from clearance.analysis.metrics.lag import _fast_length

    rng = np.random.default_rng(3)
    for n in [*range(1, 2000), *rng.integers(2000, 10**7, 300).tolist()]:
        assert _fast_length(n) == next_fast_len(n, real=True)
