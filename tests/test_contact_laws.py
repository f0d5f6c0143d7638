"""Contact force laws against hand-computed values (docs/references.md: contact laws and friction).

Hand values use K = 1e10 N/m^1.5 and δ = 4e-6 m, so K δ^1.5 = 1e10 · 8e-9 = 80 N exactly;
every expected number below is worked out by hand in plain floats. Tolerance for those:
rel 1e-12, i.e. a few ulps of rounding in the handful of operations each law performs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearance.contact_calibration import laws
from clearance.contact_calibration.laws import (
    ambrosio_friction,
    bearing_stiffness,
    bearing_stiffness_from,
    flores,
    gonthier,
    hertz,
    hu_guo,
    hunt_crossley,
    hysteresis_factor,
    impact_law,
    lankarani_nikravesh,
    normal_force,
)
from clearance.model import STEEL, Clearance, ContactLaw, Material

ULPS = 1e-12  # rel. tolerance: rounding of a few floating-point operations (measured 4.1e-16 at most)
K = 1e10
D = 4e-6  # K * D**1.5 == 80 N
DISSIPATIVE = {
    ContactLaw.LANKARANI_NIKRAVESH: lankarani_nikravesh,
    ContactLaw.HUNT_CROSSLEY: hunt_crossley,
    ContactLaw.FLORES: flores,
    ContactLaw.GONTHIER: gonthier,
    ContactLaw.HU_GUO: hu_guo,
}


@pytest.mark.parametrize(
    ("c", "expected"),
    [(0.5e-3, "6.61e+10"), (0.25e-3, "9.47e+10"), (0.1e-3, "1.51e+11"), (0.02e-3, "3.39e+11")],
)
def test_bearing_stiffness_matches_reference_values(c: float, expected: str) -> None:
    # docs/references.md quotes these derived values to 3 significant figures.
    k = bearing_stiffness(Clearance(radial_clearance=c, bearing_radius=0.010))
    assert f"{k:.2e}" == expected


def test_bearing_stiffness_by_hand() -> None:
    # Two materials, R_B = 10 mm, R_J = 9 mm: sqrt(10e-3 * 9e-3 / 1e-3) = 0.3 m^0.5.
    soft = Material(youngs_modulus=100e9, poisson_ratio=0.0)
    sigma = (1 - 0.09) / 207e9 + 1.0 / 100e9
    expected = 4.0 / (3.0 * sigma) * 0.3
    k = bearing_stiffness_from(0.010, 0.009, STEEL, soft)
    assert k == pytest.approx(expected, rel=ULPS)  # rounding only


def test_hertz_by_hand() -> None:
    assert hertz(D, stiffness=K) == pytest.approx(80.0, rel=ULPS)  # 1e10 * 8e-9
    assert hertz(D, stiffness=K, exponent=1.0) == pytest.approx(4.0e4, rel=ULPS)  # 1e10 * 4e-6
    assert hertz(-D, stiffness=K) == 0.0 and hertz(0.0, stiffness=K) == 0.0  # exact zero
    out = hertz(np.array([-1.0, 0.0, D]), stiffness=K)
    assert isinstance(out, np.ndarray) and out.shape == (3,)
    np.testing.assert_allclose(out, [0.0, 0.0, 80.0], rtol=ULPS, atol=0)  # rounding only


# Compression point: δ̇ = 0.5, δ̇⁻ = 2 (ratio 0.25); restitution point: δ̇ = -1 (ratio -0.5);
# cₑ = 0.8. Factors χ: LN 3(1-0.64)/4 = 0.27; HC 1.5*0.2 = 0.3; Flores 1.6/4 = 0.4;
# Gonthier 0.36/0.8 = 0.45; Hu-Guo 0.6/1.6 = 0.375.
HAND = {
    ContactLaw.LANKARANI_NIKRAVESH: (0.27, 80 * 1.0675, 80 * 0.865),
    ContactLaw.HUNT_CROSSLEY: (0.3, 80 * 1.075, 80 * 0.85),
    ContactLaw.FLORES: (0.4, 80 * 1.1, 80 * 0.8),
    ContactLaw.GONTHIER: (0.45, 80 * 1.1125, 80 * 0.775),
    ContactLaw.HU_GUO: (0.375, 80 * 1.09375, 80 * 0.8125),
}


@pytest.mark.parametrize("law", list(DISSIPATIVE))
@pytest.mark.filterwarnings("ignore::clearance.contact_calibration.laws.UnverifiedLawWarning")  # tested below
def test_dissipative_laws_by_hand(law: ContactLaw) -> None:
    chi, f_in, f_out = HAND[law]
    fn = DISSIPATIVE[law]
    assert hysteresis_factor(law, 0.8) == pytest.approx(chi, rel=ULPS)  # rounding only
    assert fn(D, 0.5, 2.0, stiffness=K, restitution=0.8) == pytest.approx(f_in, rel=ULPS)
    assert fn(D, -1.0, 2.0, stiffness=K, restitution=0.8) == pytest.approx(f_out, rel=ULPS)
    # The enum dispatch is the same computation: bitwise equal.
    assert normal_force(law, D, -1.0, 2.0, stiffness=K, restitution=0.8) == fn(
        D, -1.0, 2.0, stiffness=K, restitution=0.8
    )
    # No force outside contact, whatever the rate (exact zero).
    assert fn(-D, 5.0, 2.0, stiffness=K, restitution=0.8) == 0.0
    assert fn(0.0, 5.0, 2.0, stiffness=K, restitution=0.8) == 0.0


@pytest.mark.parametrize("law", list(DISSIPATIVE))
def test_dissipative_laws_clip_at_zero(law: ContactLaw) -> None:
    # cₑ = 0.5 and δ̇/δ̇⁻ = -10: every bracket 1 + χ·(-10) is negative (χ >= 0.5625 for all
    # five laws at cₑ = 0.5), so the force is clipped to exactly 0 (no adhesion).
    assert DISSIPATIVE[law](D, -10.0, 1.0, stiffness=K, restitution=0.5) == 0.0


def test_restitution_one_is_hertz() -> None:
    # χ(1) = 0 for every law: the dissipative laws reduce to Hertz, to rounding.
    for fn in DISSIPATIVE.values():
        assert fn(D, 3.0, 1.0, stiffness=K, restitution=1.0) == pytest.approx(80.0, rel=ULPS)
    assert hysteresis_factor(ContactLaw.HERTZ, 0.3) == 0.0  # exact by definition


def test_vectorised_broadcast() -> None:
    delta = np.array([[-D], [D]])  # (2, 1)
    rate = np.array([0.5, -1.0])  # (2,)
    out = lankarani_nikravesh(delta, rate, np.array([2.0, 2.0]), stiffness=K, restitution=0.8)
    assert out.shape == (2, 2)
    expected = [[0.0, 0.0], [80 * 1.0675, 80 * 0.865]]  # hand values above
    np.testing.assert_allclose(out, expected, rtol=ULPS, atol=0)  # rounding only


def test_impact_law_by_hand() -> None:
    # d_max = 1e-5, δ = 4e-6: z = 0.4, STEP = 0.16 * (3 - 0.8) = 0.352;
    # c_max = 1e5, δ̇ = 0.5: damping 1e5 * 0.352 * 0.5 = 17600 N; total 80 + 17600.
    kw = dict(stiffness=K, c_max=1e5, d_max=1e-5)
    assert impact_law(D, 0.5, **kw) == pytest.approx(17680.0, rel=ULPS)  # rounding only
    # Beyond d_max full damping: δ = 1.6e-5 gives K δ^1.5 = 1e10 * 6.4e-8 = 640 N;
    # δ̇ = -1e-3: 640 - 1e5 * 1e-3 = 540 N.
    assert impact_law(1.6e-5, -1e-3, **kw) == pytest.approx(540.0, rel=ULPS)
    assert impact_law(1.6e-5, -1.0, **kw) == 0.0  # 640 - 1e5 < 0: clipped (exact)
    assert impact_law(-D, 5.0, **kw) == 0.0  # outside contact (exact)
    assert normal_force(ContactLaw.IMPACT, D, 0.5, None, restitution=0.9, **kw) == impact_law(D, 0.5, **kw)


def test_ambrosio_friction_by_hand() -> None:
    # F_N = 100 N, μ = 0.2, v0 = 1e-4, v1 = 1e-3: full μF_N = 20 N above v1; at
    # |v| = 5.5e-4 the ramp is (4.5e-4)/(9e-4) = 0.5, i.e. 10 N; none below v0.
    v = np.array([1.0, -1.0, 5.5e-4, -5.5e-4, 5e-5, 0.0])
    out = ambrosio_friction(100.0, v, friction=0.2)
    np.testing.assert_allclose(out, [-20, 20, -10, 10, 0, 0], rtol=ULPS, atol=1e-12)  # rounding
    assert ambrosio_friction(100.0, 1.0, friction=0.0) == 0.0  # no friction (exact)
    # Other thresholds: v0 = 1e-3, v1 = 5e-2, v = 2.55e-2 is half-way: 10 N.
    f = ambrosio_friction(100.0, 2.55e-2, friction=0.2, v0=1e-3, v1=5e-2)
    assert f == pytest.approx(-10.0, rel=1e-12)  # rounding only


@pytest.mark.parametrize("speed", [0.0, -1.0, float("nan"), np.array([1.0, 0.0])])
def test_bad_approach_speed_is_named(speed: object) -> None:
    with pytest.raises(ValueError, match="approach_speed"):
        lankarani_nikravesh(D, 1.0, speed, stiffness=K, restitution=0.9)


def test_bad_arguments_are_named() -> None:
    with pytest.raises(ValueError, match="stiffness"):
        flores(D, 1.0, 1.0, stiffness=-1.0, restitution=0.9)
    with pytest.raises(ValueError, match="exponent"):
        hertz(D, stiffness=K, exponent=0.0)
    with pytest.raises(ValueError, match="restitution"):
        gonthier(D, 1.0, 1.0, stiffness=K, restitution=1.5)
    with pytest.raises(ValueError, match="restitution"):
        flores(D, 1.0, 1.0, stiffness=K, restitution=0.0)  # Flores divides by cₑ
    assert lankarani_nikravesh(D, 0.0, 1.0, stiffness=K, restitution=0.0) == pytest.approx(
        80.0, rel=ULPS
    )  # LN is defined at cₑ = 0; δ̇ = 0 leaves the elastic term (rounding only)
    with pytest.raises(ValueError, match="c_max"):
        normal_force(ContactLaw.IMPACT, D, 1.0, 1.0, stiffness=K, restitution=0.9)
    with pytest.raises(ValueError, match="d_max"):
        impact_law(D, 1.0, stiffness=K, c_max=1.0, d_max=0.0)
    with pytest.raises(ValueError, match="IMPACT"):
        hysteresis_factor(ContactLaw.IMPACT, 0.9)
    with pytest.raises(ValueError, match="law"):
        bad_law: ContactLaw = "lankarani_nikravesh"  # type: ignore[assignment]
        normal_force(bad_law, D, 1.0, 1.0, stiffness=K, restitution=0.9)
    with pytest.raises(ValueError, match="friction"):
        ambrosio_friction(1.0, 1.0, friction=-0.1)
    with pytest.raises(ValueError, match="v0"):
        ambrosio_friction(1.0, 1.0, friction=0.1, v0=1e-3, v1=1e-4)
    with pytest.raises(ValueError, match="journal_radius"):
        bearing_stiffness_from(0.01, 0.01, STEEL, STEEL)


def test_public_arguments_are_documented() -> None:
    import inspect

    for name in laws.__all__:
        obj = getattr(laws, name)
        if not callable(obj) or (isinstance(obj, type) and issubclass(obj, Warning)):
            continue  # constants, and warning classes (no arguments of their own)
        doc = inspect.getdoc(obj) or ""
        for arg in inspect.signature(obj).parameters:
            assert f"{arg}:" in doc, f"{name}: argument {arg} is not documented"


def test_hu_guo_warns_once_that_its_factor_is_unverified(monkeypatch) -> None:
    import warnings

    monkeypatch.setattr(laws, "_warned_unverified", set())  # as in a fresh process
    with pytest.warns(laws.UnverifiedLawWarning, match="Hu and Guo 2015.*half this factor"):
        hysteresis_factor(ContactLaw.HU_GUO, 0.8)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        hu_guo(D, 0.5, 2.0, stiffness=K, restitution=0.8)  # once per process, not per call
        for law in DISSIPATIVE:
            if law is not ContactLaw.HU_GUO:
                hysteresis_factor(law, 0.8)  # the checked laws never warn


def test_reference_and_exact_ln_share_the_approach_speed_floor() -> None:
    from clearance.builders import slider_crank
    from clearance.reference import ReferenceSystem

    # one constant: a grazing onset (or a contact present at t = 0) gets the same damping
    # in the reference solver and in exact-LN mode
    assert laws.MIN_APPROACH_SPEED == 1e-3  # exact: the floor the reference solver was validated with
    assert ReferenceSystem(slider_crank()).min_approach_speed == laws.MIN_APPROACH_SPEED


def test_exact_ln_onset_speed_is_the_crossing_speed():
    """At constant acceleration the crossing speed is exact: delta(t) = d0 + v0 t + a t^2 / 2."""
    from clearance.contact_calibration.exact_ln import crossing_speed

    h, d0, v0, a = 1e-6, -5e-9, 0.005, 22_000.0  # a grazing onset under a 2 kN load on 0.09 kg
    v1 = v0 + a * h
    tau = (-v0 + math.sqrt(v0**2 - 2 * a * d0)) / a  # the root of d0 + v0 t + a t^2 / 2 in [0, h]
    assert 0 < tau < h
    # exact for this motion: 1e-12 relative is float round-off of the square root
    assert crossing_speed(d0, v0, v1, h) == pytest.approx(v0 + a * tau, rel=1e-12)
    assert crossing_speed(d0, v0, v1, h) < 0.7 * v1  # the speed one step later over-states it by > 40 %
    # free flight (no acceleration): the speed itself
    assert crossing_speed(-3e-9, 0.1, 0.1, h) == 0.1
