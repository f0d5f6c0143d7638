"""Poincaré sections and the regime classifier on a forced Duffing oscillator (scipy)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from clearance.analysis.chaos.poincare import (
    Regime,
    classify_poincare,
    correlation_dimension,
    largest_lyapunov,
    map_divergence,
    poincare_section,
)

W = 1.2  # forcing frequency of the double-well Duffing oscillator (Guckenheimer & Holmes)
T = 2 * np.pi / W


def _duffing(delta, alpha, beta, forces, *, x0=(1.0, 0.0), periods=120, period=T, n_per=40):
    """x'' + delta x' + alpha x + beta x^3 = sum g cos(w t), sampled n_per times a period."""

    def f(t, y):
        x, v = y
        return [v, -delta * v - alpha * x - beta * x**3 + sum(g * np.cos(w * t) for g, w in forces)]

    te = np.linspace(0.0, periods * period, periods * n_per + 1)
    # rtol 1e-9: the section points of the periodic regimes then agree to far better than
    # the classifier's 1 % grouping radius
    s = solve_ivp(f, (0.0, te[-1]), x0, t_eval=te, rtol=1e-9, atol=1e-11, method="DOP853")
    return s.t, s.y.T


def _rms_radius(y):
    return float(np.sqrt(np.mean(np.sum((y - y.mean(axis=0)) ** 2, axis=1))))


def _section(t, y, period, skip_periods=40):
    keep = t >= skip_periods * period
    _, p = poincare_section(t, y, period, skip=skip_periods * period)
    return p, _rms_radius(y[keep])


def test_poincare_section_samples_at_multiples_of_the_period():
    t = np.linspace(0.0, 10.0, 1001)
    ts, p = poincare_section(t, np.column_stack([t, 2 * t]), 2.5, last=3)
    np.testing.assert_allclose(ts, [5.0, 7.5, 10.0])  # the last 3 of k T in [0, 10]
    # linear series: interpolation is exact up to rounding (1e-12)
    np.testing.assert_allclose(p, np.column_stack([ts, 2 * ts]), atol=1e-12)


def test_periodic_regimes():
    # gamma = 0.2: period-1 orbit in one well; gamma = 0.28: period 2 (period-doubling
    # cascade of this oscillator, Guckenheimer & Holmes section 2.2)
    t, y = _duffing(0.3, -1.0, 1.0, [(0.2, W)])
    p, scale = _section(t, y, T)
    c = classify_poincare(p, scale=scale)
    assert c.regime is Regime.PERIODIC and c.period == 1
    t, y = _duffing(0.3, -1.0, 1.0, [(0.28, W)])
    p, scale = _section(t, y, T)
    c = classify_poincare(p, scale=scale)
    assert c.regime is Regime.PERIODIC and c.period == 2


def test_quasi_periodic_regime():
    # hardening Duffing forced at two incommensurate frequencies (ratio = golden mean),
    # sampled once per period of the first: an invariant closed curve
    w2 = (np.sqrt(5) - 1) / 2
    period = 2 * np.pi
    t, y = _duffing(0.2, 1.0, 0.1, [(0.3, 1.0), (0.3, w2)], x0=(0.1, 0.0), period=period)
    p, scale = _section(t, y, period)
    c = classify_poincare(p, scale=scale)
    assert c.regime is Regime.QUASI_PERIODIC
    # a closed curve: near-zero divergence (below the 0.2 threshold with margin) and a
    # correlation dimension near 1 (0.3 allows the small-sample bias of 80 points)
    assert abs(c.divergence) < 0.1
    assert abs(c.correlation_dimension - 1.0) < 0.3


def test_chaotic_regime_and_lyapunov():
    # gamma = 0.5: the chaotic double-well attractor (largest Lyapunov exponent ~0.15 1/s)
    t, y = _duffing(0.3, -1.0, 1.0, [(0.5, W)], periods=200)
    p, scale = _section(t, y, T)
    c = classify_poincare(p, scale=scale)
    assert c.regime is Regime.CHAOTIC
    assert c.divergence > 0.4  # twice the threshold: the decision is not marginal
    t2, y2 = _duffing(0.3, -1.0, 1.0, [(0.5, W)], x0=(1.0 + 1e-9, 0.0), periods=60)
    lam = largest_lyapunov(t2, y[: len(t2)], y2)
    # published values for this attractor are about 0.1-0.2 1/s; a two-run estimate from
    # one trajectory pair scatters, so accept a factor of about 2 either way
    assert 0.05 < lam < 0.4
    # a periodic run: nearby starts converge (negative exponent)
    ta, ya = _duffing(0.3, -1.0, 1.0, [(0.2, W)], periods=30)
    _, yb = _duffing(0.3, -1.0, 1.0, [(0.2, W)], x0=(1.0 + 1e-6, 0.0), periods=30)
    assert largest_lyapunov(ta, ya, yb) < 0


def test_correlation_dimension_of_a_circle_and_a_square():
    rng = np.random.default_rng(0)
    th = rng.uniform(0, 2 * np.pi, 600)
    # 600 points: the Grassberger-Procaccia fit is within 0.15 of the true 1 for a curve
    # without ends; a square's edges lower the estimate (pairs near the boundary lose
    # neighbours), measured 1.85 here, so 0.25 for the square
    assert abs(correlation_dimension(np.column_stack([np.cos(th), np.sin(th)])) - 1.0) < 0.15
    assert abs(correlation_dimension(rng.uniform(size=(600, 2))) - 2.0) < 0.25
    # rotation on a circle is an isometry: zero divergence up to rounding
    k = np.arange(200) * 2 * np.pi * (np.sqrt(5) - 1) / 2
    assert abs(map_divergence(np.column_stack([np.cos(k), np.sin(k)]))) < 1e-9


def test_classify_small_sets():
    # one point: no recurrence seen; two equal points: period 1; 2 distinct points: each
    # group must be seen twice before a period is claimed
    assert classify_poincare(np.array([[1.0, 2.0]])).regime is Regime.UNDETERMINED
    assert classify_poincare(np.array([[1.0], [1.0]])).period == 1
    assert classify_poincare(np.array([[1.0], [2.0]])).regime is Regime.UNDETERMINED


def test_classify_rejects_bad_input():
    with pytest.raises(ValueError, match="finite"):
        classify_poincare(np.array([[np.nan, 1.0]]))
