"""Deviation statistics against scipy on known data; lag, peaks and contact modes on runs."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

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
    # identical formulas: agreement to rounding (1e-12 relative)
    assert s.mean_deviation == pytest.approx(np.mean(np.abs(d)), rel=1e-12)
    assert s.rms_deviation == pytest.approx(np.sqrt(np.mean(d**2)), rel=1e-12)
    assert s.band90 == pytest.approx(np.percentile(np.abs(d), 90), rel=1e-12)
    tt = stats.ttest_rel(y, y0)
    assert (s.t_statistic, s.t_pvalue) == pytest.approx((tt.statistic, tt.pvalue), rel=1e-12)
    ks = stats.ks_2samp(y, y0)
    assert (s.ks_statistic, s.ks_pvalue) == pytest.approx((ks.statistic, ks.pvalue), rel=1e-12)
    f = np.var(y, ddof=1) / np.var(y0, ddof=1)
    assert s.f_statistic == pytest.approx(f, rel=1e-12)
    p = 2 * min(stats.f.cdf(f, 1999, 1999), stats.f.sf(f, 1999, 1999))
    assert s.f_pvalue == pytest.approx(p, rel=1e-9)  # cdf vs sf evaluation: 1e-9
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
