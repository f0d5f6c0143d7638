"""The deviation statistics' tests, computed without scipy, give scipy.stats' results."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from scipy import special, stats

from clearance.analysis.metrics.significance import (
    ks_equal_size_pvalue,
    ks_two_sample,
    paired_t_test,
    regularized_beta,
    variance_ratio_cdf,
)

RTOL = 1e-9
"""Against scipy, n <= 5000: the t and F p-values take ln Gamma of n / 2 (rounding ~1e-16 n ln n,
measured 3e-11 at n = 8000); the KS p-value multiplies up to h rounded factors (~1e-13 here)."""


def pairs():
    """(y, y_ideal) pairs from nearly equal to clearly apart, n from 3 to 5000."""
    rng = np.random.default_rng(7)
    for n in (3, 10, 57, 400, 5000):
        for spread, shift in ((0.0, 0.0), (0.05, 0.001), (0.3, 0.05), (1.0, 0.5)):
            y = rng.normal(size=n)
            yield n, y, 0.97 * y + spread * rng.normal(size=n) + shift


@pytest.mark.parametrize(("n", "y", "y_ideal"), list(pairs()))
def test_the_three_tests_match_scipy_stats(n, y, y_ideal):
    t, p = paired_t_test(y, y_ideal)
    ref = stats.ttest_rel(y, y_ideal)
    assert t == pytest.approx(ref.statistic, rel=RTOL)
    assert p == pytest.approx(ref.pvalue, rel=RTOL, abs=1e-300)
    ratio = float(np.var(y, ddof=1) / np.var(y_ideal, ddof=1))
    assert variance_ratio_cdf(ratio, n - 1, n - 1) == pytest.approx(stats.f.cdf(ratio, n - 1, n - 1), rel=RTOL)
    d, p_ks = ks_two_sample(y, y_ideal)
    ks = stats.ks_2samp(y, y_ideal)  # exact method for n <= 10,000
    assert d == pytest.approx(ks.statistic, rel=RTOL)
    assert p_ks == pytest.approx(ks.pvalue, rel=RTOL, abs=1e-300)


def exact_tail(n: int, h: int) -> float:
    """P(D_{n,n} >= h / n) in rational arithmetic: 2 sum_k (-1)^(k+1) C(2n, n - k h) / C(2n, n)."""
    total = sum(Fraction((-1) ** (k + 1) * math.comb(2 * n, n - k * h)) for k in range(1, n // h + 1))
    return float(min(Fraction(1), 2 * total / math.comb(2 * n, n)))


@pytest.mark.parametrize(
    ("n", "h"),
    # small h at large n: the sum is cut short (k h >= 9 sqrt(n)); h near n: one or two terms
    [(1, 1), (2, 1), (7, 3), (400, 1), (400, 5), (400, 60), (1500, 2), (1500, 40), (1500, 1400)],
)
def test_ks_pvalue_equals_the_exact_sum(n, h):
    # against the rational sum: rounding of h factors (h <= 1400: < 1e-12 relative)
    assert ks_equal_size_pvalue(n, h) == pytest.approx(exact_tail(n, h), rel=1e-12, abs=1e-300)


def test_ks_pvalue_beyond_scipys_exact_range_is_scipys_exact_value():
    # above n = 10,000 scipy's default is asymptotic; its exact method is the reference here
    rng = np.random.default_rng(3)
    y = rng.normal(size=20_000)
    y_ideal = y + 0.02 * rng.normal(size=20_000) + 0.01
    d, p = ks_two_sample(y, y_ideal)
    ref = stats.ks_2samp(y, y_ideal, method="exact")
    assert d == pytest.approx(ref.statistic, rel=RTOL)
    assert p == pytest.approx(ref.pvalue, rel=RTOL)


def test_identical_samples_and_bad_input():
    y = np.linspace(0.0, 1.0, 50)
    assert ks_two_sample(y, y) == (0.0, 1.0)
    with pytest.raises(ValueError, match="equal size"):
        ks_two_sample(y, y[:-1])
    with pytest.raises(ValueError, match="0 <= h <= n"):
        ks_equal_size_pvalue(5, 6)


X = np.concatenate([np.geomspace(1e-12, 0.5, 40), 1 - np.geomspace(1e-12, 0.5, 40)])
"""Arguments from 1e-12 to 1 - 1e-12 (1 - x is exact for x >= 0.5)."""


@pytest.mark.parametrize(
    ("a", "b", "closed_form"),
    [
        # the arcsine law, each side from its own end (asin is ill-conditioned near 1)
        (
            0.5,
            0.5,
            lambda x, y: np.where(
                x <= 0.5, np.arcsin(np.sqrt(x)) / (np.pi / 2), 1 - np.arcsin(np.sqrt(y)) / (np.pi / 2)
            ),
        ),
        (3.7, 1.0, lambda x, y: x**3.7),
        (1.0, 250.0, lambda x, y: -np.expm1(250 * np.log1p(-x))),
    ],
)
def test_regularized_beta_closed_forms(a, b, closed_form):
    ours = np.array([regularized_beta(a, b, x, 1 - x) for x in X])
    exact = closed_form(X, 1 - X)
    keep = exact > 1e-290
    # the fraction stops at 1e-16; lgamma and exp of small arguments: a few roundings
    assert ours[keep] == pytest.approx(exact[keep], rel=1e-13)


@pytest.mark.parametrize("a", [0.5, 1.0, 2.5, 10.0, 200.0, 4000.0, 500_000.0])
@pytest.mark.parametrize("b", [0.5, 3.0, "a"])
def test_regularized_beta_matches_scipy(a, b):
    b = a if b == "a" else b  # the t test's (a, 1/2) and the variance ratio's (a, a) among them
    ours = np.array([regularized_beta(a, b, x, 1 - x) for x in X])
    ref = special.betainc(a, b, X)
    keep = ref > 1e-290  # scipy's own values underflow below
    # ln Gamma(a + b) - ln Gamma(a) - ln Gamma(b) rounds to ~1e-16 (a + b) ln(a + b) in the
    # prefactor (measured 4e-9 at a = b = 5e5); scipy itself is 3.5e-11 off the arcsine law at
    # a = b = 1/2, x = 1 - 1e-12 (the closed forms above hold ours to 1e-13)
    assert ours[keep] == pytest.approx(ref[keep], rel=1e-10 + 1e-15 * (a + b) * math.log(a + b + 2))
    assert np.all((ours >= 0) & (ours <= 1))
