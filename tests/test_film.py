"""The hydrodynamic film force against closed forms and against Reynolds' equation.

The closed forms below are written out here from the texts (load capacity and attitude angle
of the steady short and long bearing; the squeeze film), not taken from the module; the
general states (squeeze, whirl and spin together) are checked against the pressure of
Reynolds' equation integrated by quadrature over the pi film, a derivation that shares no
arithmetic with the module's closed forms.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from clearance.contact_calibration.film import (
    film_force,
    film_parts,
    film_ratio,
    film_terms,
    film_torques,
    minimum_film_thickness,
)
from clearance.lubrication import FilmModel, Lubrication
from clearance.model import Clearance

MU, R, L, C = 0.03, 0.0095, 0.012, 50e-6
HT = 1e-6
PARAMS = dict(viscosity=MU, journal_radius=R, bearing_length=L, clearance=C, transition_thickness=HT)
RATIOS = (0.2, 0.5, 0.8)


def _state(ratio: float, angle: float) -> np.ndarray:
    return C * ratio * np.array([math.cos(angle), math.sin(angle)])


def _nt(angle: float) -> tuple[np.ndarray, np.ndarray]:
    n = np.array([math.cos(angle), math.sin(angle)])
    return n, np.array([-n[1], n[0]])


def _steady(film: FilmModel, ratio: float, omega: float) -> tuple[float, float]:
    """(load capacity W [N], attitude angle [rad]) of the model, steady, at a slanted e."""
    angle = 0.7
    f = film_force(film, _state(ratio, angle), np.zeros(2), omega, **PARAMS)
    n, t = _nt(angle)
    return float(np.hypot(*f)), math.atan2(float(f @ t), -float(f @ n))


@pytest.mark.parametrize("ratio", RATIOS)
def test_short_bearing_steady_load_and_attitude(ratio: float) -> None:
    omega = 300.0
    load, attitude = _steady(FilmModel.SHORT, ratio, omega)
    s = 1.0 - ratio**2
    # Ocvirk's short bearing, half-Sommerfeld (the textbook closed forms)
    expected = MU * omega * R * L**3 * ratio * math.sqrt(16 * ratio**2 + math.pi**2 * s) / (4 * C**2 * s**2)
    expected_attitude = math.atan(math.pi * math.sqrt(s) / (4 * ratio))
    # 1e-6: the goal of the issue; both sides are closed forms, equal to rounding
    assert load == pytest.approx(expected, rel=1e-6)
    assert attitude == pytest.approx(expected_attitude, rel=1e-6)


@pytest.mark.parametrize("ratio", RATIOS)
def test_long_bearing_steady_load_and_attitude(ratio: float) -> None:
    omega = 300.0
    load, attitude = _steady(FilmModel.LONG, ratio, omega)
    s = 1.0 - ratio**2
    # Sommerfeld's long bearing, half-Sommerfeld (the textbook closed forms)
    expected = (
        6 * MU * omega * R**3 * L * ratio * math.sqrt(math.pi**2 * s + 4 * ratio**2) / (C**2 * (2 + ratio**2) * s)
    )
    expected_attitude = math.atan(math.pi * math.sqrt(s) / (2 * ratio))
    # 1e-6: the goal of the issue; both sides are closed forms, equal to rounding
    assert load == pytest.approx(expected, rel=1e-6)
    assert attitude == pytest.approx(expected_attitude, rel=1e-6)


@pytest.mark.parametrize("ratio", RATIOS)
def test_short_bearing_pure_squeeze(ratio: float) -> None:
    """Closing at ε̇ without spin or whirl: half of the full film's squeeze force, radially."""
    angle, rate = -1.1, 0.02  # m/s along n
    n, t = _nt(angle)
    f = film_force(FilmModel.SHORT, _state(ratio, angle), rate * n, 0.0, **PARAMS)
    s = 1.0 - ratio**2
    eps_dot = rate / C
    # full 2 pi film: W = pi mu R L^3 eps_dot (1 + 2 eps^2) / (c^2 s^(5/2)); the pi film holds half
    full = math.pi * MU * R * L**3 * eps_dot * (1 + 2 * ratio**2) / (C**2 * s**2.5)
    # the pi film's tangential part: mu R L^3 / (2 c^2) * 4 eps eps_dot / s^2 (Pinkus & Sternlicht)
    tangential = MU * R * L**3 / (2 * C**2) * 4 * ratio * eps_dot / s**2
    # 1e-6: closed forms on both sides, equal to rounding
    assert float(f @ n) == pytest.approx(-full / 2, rel=1e-6)
    assert float(f @ t) == pytest.approx(tangential, rel=1e-6)


def _reynolds_pi_film(film: FilmModel, ratio: float, w: float, eps_dot: float) -> tuple[float, float]:
    """(F_n, F_t) by quadrature of Reynolds' equation over the pi film θ in (−π, 0).

    h = c (1 − ε cos θ), θ from n in the sense of the spin; right-hand side 6 μ c G(θ) with
    G = ε w sin θ − 2 ε̇ cos θ (wedge, whirl and squeeze); force on the journal
    −∫ p (cos θ, sin θ) R dθ over the film.
    """

    def h(th: float) -> float:
        return C * (1.0 - ratio * math.cos(th))

    def g(th: float) -> float:
        return ratio * w * math.sin(th) - 2.0 * eps_dot * math.cos(th)

    opts = dict(epsabs=0.0, epsrel=1e-10, limit=200)
    if film is FilmModel.SHORT:  # p integrated over z: −μ c L³ G / (2 h³)

        def pbar(th: float) -> float:
            return -MU * C * L**3 * g(th) / (2.0 * h(th) ** 3)

    else:  # d/dθ(h³ p') = 6 μ R² c G, p(−π) = p(0) = 0; force per length times L

        def q(th: float) -> float:  # 6 μ R² c ∫G
            return 6.0 * MU * R**2 * C * (-ratio * w * math.cos(th) - 2.0 * eps_dot * math.sin(th))

        i1 = integrate.quad(lambda s: q(s) / h(s) ** 3, -math.pi, 0.0, **opts)[0]
        i0 = integrate.quad(lambda s: 1.0 / h(s) ** 3, -math.pi, 0.0, **opts)[0]

        def pbar(th: float) -> float:
            return L * integrate.quad(lambda s: (q(s) - i1 / i0) / h(s) ** 3, -math.pi, th, **opts)[0]

    fn = -R * integrate.quad(lambda th: pbar(th) * math.cos(th), -math.pi, 0.0, **opts)[0]
    ft = -R * integrate.quad(lambda th: pbar(th) * math.sin(th), -math.pi, 0.0, **opts)[0]
    return fn, ft


@pytest.mark.parametrize("film", list(FilmModel))
def test_film_force_is_reynolds_pressure_integrated(film: FilmModel) -> None:
    rng = np.random.default_rng(35)
    for _ in range(3):
        ratio, angle = rng.uniform(0.05, 0.9), rng.uniform(-math.pi, math.pi)
        omega, vn, vt = rng.uniform(-400, 400), rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02)
        n, t = _nt(angle)
        f = film_force(film, _state(ratio, angle), vn * n + vt * t, omega, **PARAMS)
        w = omega - 2.0 * vt / (C * ratio)
        fn, ft = _reynolds_pi_film(film, ratio, w, vn / C)
        scale = math.hypot(fn, ft)
        # 1e-7 of the force: nested adaptive quadrature at rtol 1e-10 (measured agreement below 1e-10)
        assert float(f @ n) == pytest.approx(fn, abs=1e-7 * scale)
        assert float(f @ t) == pytest.approx(ft, abs=1e-7 * scale)


@pytest.mark.parametrize("film", list(FilmModel))
def test_damping_is_symmetric_positive_definite_and_exact(film: FilmModel) -> None:
    ratios = np.linspace(0.0, 0.98, 50)
    e = np.stack([C * ratios * math.cos(2.0), C * ratios * math.sin(2.0)], axis=-1)
    held, damping = film_parts(film, e, 100.0, **PARAMS)
    assert np.array_equal(damping, np.swapaxes(damping, -1, -2))  # built symmetric, bit for bit
    assert np.all(np.linalg.eigvalsh(damping) > 0)
    # the force is affine in the rate: F(v) = F_0 - D v for any v (to rounding, 1e-12 of |F|)
    v = np.array([0.013, -0.007])
    f = film_force(film, e, np.broadcast_to(v, e.shape), 100.0, **PARAMS)
    expected = held - damping @ v
    assert np.allclose(f, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


def test_centred_short_film_is_isotropic_damping() -> None:
    _, damping = film_parts(FilmModel.SHORT, np.zeros(2), 0.0, **PARAMS)
    scale = MU * R * L**3 / C**3
    # at ε = 0: b_r = g_t = π/2, b_t = 0 (exact arithmetic); the scale is rounded in another order
    # on each side, through libm's pow in L**3 and C**3: measured equal; a last-bit change of any of
    # those pows puts the sides 4.4e-16 apart at most (tried), so 1e-15
    assert damping == pytest.approx(scale * math.pi / 2 * np.eye(2), rel=1e-15, abs=0.0)


@pytest.mark.parametrize("film", list(FilmModel))
def test_transition_is_continuous_and_bounded(film: FilmModel) -> None:
    angle = 0.3
    n, t = _nt(angle)
    v = 0.01 * n - 0.004 * t
    h_values = np.array([HT * (1 + 1e-9), HT, HT * (1 - 1e-9), 0.5 * HT, 0.0, -2e-6])
    e = (C - h_values)[:, None] * n
    f = film_force(film, e, np.broadcast_to(v, e.shape), 250.0, **PARAMS)
    # across h_t the force changes by its slope times the 1e-15 m step: 1e-6 relative covers
    # the steepest slope (short film, (1 - ε²)^(-7/2) near ε_t = 0.98)
    assert np.allclose(f[0], f[1], rtol=1e-6) and np.allclose(f[2], f[1], rtol=1e-6)
    # below h_t the coefficients are held at ε_t: the same force for the same direction and rate
    # (to the rounding of n = e/|e| at different |e|, a few 1e-16: 1e-14 relative)
    assert np.allclose(f[3:], np.broadcast_to(f[2], f[3:].shape), rtol=1e-14, atol=0.0)
    assert film_ratio(C - 0.5 * HT, clearance=C, transition_thickness=HT) == 1.0 - HT / C


def test_torques_balance_the_forces() -> None:
    rng = np.random.default_rng(7)
    e = rng.uniform(-0.6 * C, 0.6 * C, (20, 2))
    v = rng.uniform(-0.02, 0.02, (20, 2))
    w = rng.uniform(-500, 500, 20)
    f = film_force(FilmModel.SHORT, e, v, w, **PARAMS)
    tj, tb = film_torques(FilmModel.SHORT, e, f, w, **PARAMS)
    moment = e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0]
    # F at the journal centre, -F at the bearing centre, T_J, T_B: no net moment (to rounding)
    assert np.allclose(tj + tb + moment, 0.0, atol=1e-12 * np.abs(tj).max())


@pytest.mark.parametrize("ratio", RATIOS)
def test_steady_short_friction_torque(ratio: float) -> None:
    """The journal's friction torque: Couette over 2 π plus half the load's moment (textbook)."""
    omega = 300.0
    e = _state(ratio, 0.0)
    f = film_force(FilmModel.SHORT, e, np.zeros(2), omega, **PARAMS)
    tj, _ = film_torques(FilmModel.SHORT, e, f, omega, **PARAMS)
    s = 1.0 - ratio**2
    # shear force on the journal (short bearing, PDSim's form): 2π/√s ((L/R)² ε²/(16 s) + 1) μ ω R L R/c
    shear = 2 * math.pi / math.sqrt(s) * ((L / R) ** 2 * ratio**2 / (16 * s) + 1) * MU * omega * R * L * R / C
    # 1e-12: closed forms on both sides
    assert tj == pytest.approx(-shear * R, rel=1e-12)


def test_minimum_film_thickness() -> None:
    h = minimum_film_thickness(np.array([[3e-6, 4e-6], [0.0, 0.0]]), clearance=C)
    assert np.allclose(h, [C - 5e-6, C], rtol=0, atol=1e-18)  # 3-4-5 triangle: exact to rounding


def test_film_terms_arithmetic_is_shared_by_floats_and_arrays() -> None:
    for film in FilmModel:
        arr = film_terms(film, np.array([0.3, 0.6]))
        for i, r in enumerate((0.3, 0.6)):
            scalar = film_terms(film, r)
            # same operations but one: an array's ** 0.5 is NumPy's sqrt, a float's libm's pow, which differ in
            # the last bit for ~0.1 % of arguments (measured 2.8e-16 relative at most over 20,000 ratios, equal
            # at these two): 2e-15 (9 ulps) still fails any formula that differs between the paths
            assert all(
                math.isclose(float(a[i]), b, rel_tol=2e-15, abs_tol=0.0) for a, b in zip(arr, scalar, strict=True)
            )


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: Lubrication(0.0), "viscosity must be > 0"),
        (lambda: Lubrication(0.03, film="short"), "film must be a FilmModel"),  # type: ignore[arg-type]
        (lambda: Lubrication(0.03, transition_thickness=-1e-6), "transition_thickness must be > 0"),
        (lambda: Clearance(C, lubrication=Lubrication(0.03)), "needs bearing_length"),
        (lambda: Clearance(C, bearing_length=0.0), "bearing_length must be > 0"),
        (
            lambda: Clearance(C, bearing_length=L, lubrication=Lubrication(0.03, transition_thickness=C)),
            "transition_thickness must be < radial_clearance",
        ),
    ],
)
def test_bad_lubrication_is_refused_in_one_line(make, match: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match=match) as info:
        make()
    assert "\n" not in str(info.value)
