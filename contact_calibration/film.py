"""Hydrodynamic film force of a lubricated journal bearing (pure NumPy, no MuJoCo).

The journal (radius R, length L) turns at ``spin`` ω relative to the bearing inside a gap of
radial clearance c full of oil of viscosity μ. In a frame fixed to the bearing, e is the
journal centre minus the bearing centre, ė its rate, ε = |e|/c, n = e/|e| (towards the
thinnest film; the bearing's x axis when e = 0), t = z × n, and

  ε̇ = n·ė / c   (> 0 closing the film),   φ̇ = t·ė / |e|   (whirl of the line of centres).

The force on the journal is F = F_n n + F_t t with, writing w = ω − 2φ̇,

  F_n = −S (a_r(ε) w + b_r(ε) ε̇),   F_t = S (a_t(ε) w + b_t(ε) ε̇)

(Flores, Ambrósio, Claro & Lankarani 2009, after Pinkus & Sternlicht): the pressure of
Reynolds' equation integrated over the half of the film that converges under pure rotation,
the other half cavitated (the π film). Per `FilmModel`:

  SHORT (Ocvirk), S = μ R L³ / c²:  a_r = ε²/s²,  b_r = π(1 + 2ε²)/(2 s^(5/2)),
      a_t = πε/(4 s^(3/2)),  b_t = 2ε/s²,                 s = 1 − ε²
  LONG (Sommerfeld), S = 12 μ R³ L / c²:  a_r = ε²/(q s),  b_r = (π/2 − 8/(π q))/s^(3/2),
      a_t = πε/(2 q s^(1/2)),  b_t = 2ε/(q s),            q = 2 + ε²

Steady (ε̇ = φ̇ = 0) these are the textbook load capacity and attitude angle
tan ψ = a_t/a_r (π sqrt(1 − ε²)/(4ε) short, π sqrt(1 − ε²)/(2ε) long); [checked] against two
implementations we did not write (docs/references.md) and, squeeze and whirl included,
[derived] again in the tests by quadrature of Reynolds' equation.

Since b_t = 2 a_r/ε, the force is affine in ė with a symmetric damping matrix:
F = F_0 − D ė, F_0 = S ω (−a_r n + a_t t) (held over a step) and, in (n, t),

  D = (S/c) [[b_r, −b_t], [−b_t, g_t]],   g_t = 2 a_t/ε  (π/(2 s^(3/2)) short, π/(q s^(1/2)) long)

D is positive definite for 0 <= ε < 1 (tested on a grid): the ė-dependent part only
dissipates. `film_parts` returns F_0 and D for an in-step treatment of the damping.

Transition to dry contact. Below the film thickness h_t the film ruptures: ε is clamped at
ε_t = 1 − h_t/c in a, b and g (n and ė stay the true ones), so the film force is continuous
(no jump at h = h_t: the clamp is the identity there) and bounded; the joint's dry contact
law acts, as without oil, on δ = |e| − c > 0, where it starts from 0. The joint's force is
the sum of the two.

Torques (the fluid is massless: forces and moments on it balance). F acts on the journal
through its centre and −F on the bearing through the bearing's centre; the film's shear adds
T_J = −T_c − (e × F)/2 on the journal and T_B = T_c − (e × F)/2 on the bearing, with the
Couette torque T_c = 2π μ ω R³ L / (c sqrt(1 − ε²)) over the whole circumference, so that
T_J + T_B + e × F = 0.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearance.checks import positive
from clearance.lubrication import FilmModel, Lubrication

__all__ = [
    "FilmTerms",
    "film_terms",
    "film_scale",
    "film_ratio",
    "film_parts",
    "film_force",
    "film_torques",
    "minimum_film_thickness",
    "FilmParameters",
    "film_parameters",
    "film_scalar",
]

_PI = math.pi


class FilmTerms(NamedTuple):
    """Dimensionless film coefficients at an eccentricity ratio (floats or arrays).

    Attributes:
        a_r, b_r: radial coefficients of w = ω − 2φ̇ and of ε̇.
        a_t, b_t: tangential coefficients of w and of ε̇.
        g_t: 2 a_t / ε, the whirl damping coefficient (finite at ε = 0).
    """

    a_r: Any
    b_r: Any
    a_t: Any
    b_t: Any
    g_t: Any


def film_terms(film: FilmModel, ratio: Any) -> FilmTerms:
    """The coefficients a_r, b_r, a_t, b_t, g_t of the module docstring at ε = ``ratio``.

    The same arithmetic serves floats (the reference solver) and arrays; no validation.

    Args:
        film: the approximation.
        ratio: ε [-], 0 <= ε < 1 (float or array).

    Returns:
        `FilmTerms`.
    """
    e2 = ratio * ratio
    s = 1.0 - e2
    if film is FilmModel.SHORT:
        rs = s**0.5
        return FilmTerms(
            a_r=e2 / (s * s),
            b_r=_PI * (1.0 + 2.0 * e2) / (2.0 * s * s * rs),
            a_t=_PI * ratio / (4.0 * s * rs),
            b_t=2.0 * ratio / (s * s),
            g_t=_PI / (2.0 * s * rs),
        )
    q = 2.0 + e2
    rs = s**0.5
    return FilmTerms(
        a_r=e2 / (q * s),
        b_r=(_PI / 2.0 - 8.0 / (_PI * q)) / (s * rs),
        a_t=_PI * ratio / (2.0 * q * rs),
        b_t=2.0 * ratio / (q * s),
        g_t=_PI / (q * rs),
    )


def film_scale(
    film: FilmModel, *, viscosity: float, journal_radius: float, bearing_length: float, clearance: float
) -> float:
    """The film's force scale S [N s]: μ R L³/c² (SHORT) or 12 μ R³ L/c² (LONG).

    Args:
        film: the approximation.
        viscosity: μ [Pa s] > 0.
        journal_radius: R [m] > 0.
        bearing_length: L [m] > 0.
        clearance: c [m] > 0.

    Returns:
        S [N s].

    Raises:
        ValueError: a value not positive and finite, or ``film`` not a `FilmModel`.
    """
    mu = positive("viscosity", viscosity, "Pa s")
    r = positive("journal_radius", journal_radius, "m")
    length = positive("bearing_length", bearing_length, "m")
    c = positive("clearance", clearance, "m")
    if film is FilmModel.SHORT:
        return mu * r * length**3 / (c * c)
    if film is FilmModel.LONG:
        return 12.0 * mu * r**3 * length / (c * c)
    raise ValueError(f"film must be a FilmModel (got {film!r})")


def film_ratio(distance: ArrayLike, *, clearance: float, transition_thickness: float) -> Any:
    """ε that enters the film coefficients: |e|/c, clamped at ε_t = 1 − h_t/c.

    Args:
        distance: |e| [m] >= 0, any shape.
        clearance: c [m] > 0.
        transition_thickness: h_t [m], 0 < h_t < c.

    Returns:
        min(|e|/c, 1 − h_t/c) (float for a scalar).

    Raises:
        ValueError: h_t not in (0, c).
    """
    c = positive("clearance", clearance, "m")
    ht = positive("transition_thickness", transition_thickness, "m")
    if ht >= c:
        raise ValueError(f"transition_thickness must be < clearance = {c} m (got {transition_thickness!r} m)")
    r = np.minimum(np.asarray(distance, dtype=float) / c, 1.0 - ht / c)
    return float(r) if r.ndim == 0 else r


def minimum_film_thickness(eccentricity: ArrayLike, *, clearance: float) -> Any:
    """h = c − |e| [m] (negative: the surfaces overlap by −h), for (..., 2) eccentricities."""
    e = np.asarray(eccentricity, dtype=float)
    h = clearance - np.hypot(e[..., 0], e[..., 1])
    return float(h) if h.ndim == 0 else h


def _frame(eccentricity: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(e (..., 2), |e| (...), n (..., 2)); n is the x axis where e = 0."""
    e = np.asarray(eccentricity, dtype=float)
    if e.shape[-1:] != (2,):
        raise ValueError(f"eccentricity must have shape (..., 2) (got {e.shape})")
    d = np.hypot(e[..., 0], e[..., 1])
    safe = np.where(d > 0, d, 1.0)
    n = np.where((d > 0)[..., None], e / safe[..., None], np.array([1.0, 0.0]))
    return e, d, n


class _Film(NamedTuple):
    scale: float
    c: float
    ht: float


def _film(
    film: FilmModel, viscosity: float, journal_radius: float, bearing_length: float, clearance: float, ht: float
) -> _Film:
    s = film_scale(
        film, viscosity=viscosity, journal_radius=journal_radius, bearing_length=bearing_length, clearance=clearance
    )
    return _Film(s, float(clearance), positive("transition_thickness", ht, "m"))


def film_parts(
    film: FilmModel,
    eccentricity: ArrayLike,
    spin: ArrayLike,
    *,
    viscosity: float,
    journal_radius: float,
    bearing_length: float,
    clearance: float,
    transition_thickness: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The film force split as F = F_0 − D ė (module docstring), with the transition clamp.

    Args:
        film: the approximation.
        eccentricity: e [m], (..., 2), in a frame fixed to the bearing.
        spin: ω [rad/s], the journal's angular velocity relative to the bearing, (...).
        viscosity: μ [Pa s] > 0.
        journal_radius: R [m] > 0.
        bearing_length: L [m] > 0.
        clearance: c [m] > 0.
        transition_thickness: h_t [m], 0 < h_t < c.

    Returns:
        (F_0 (..., 2) [N], D (..., 2, 2) [N s/m]) in the frame of ``eccentricity``.

    Raises:
        ValueError: a parameter out of range or a bad shape.
    """
    f = _film(film, viscosity, journal_radius, bearing_length, clearance, transition_thickness)
    e, d, n = _frame(eccentricity)
    k = film_terms(film, film_ratio(d, clearance=f.c, transition_thickness=f.ht))
    t = np.stack([-n[..., 1], n[..., 0]], axis=-1)
    w = np.asarray(spin, dtype=float)
    held = f.scale * w[..., None] * (-np.asarray(k.a_r)[..., None] * n + np.asarray(k.a_t)[..., None] * t)
    g = f.scale / f.c
    nn = n[..., :, None] * n[..., None, :]
    tt = t[..., :, None] * t[..., None, :]
    nt = n[..., :, None] * t[..., None, :]
    damping = g * (
        np.asarray(k.b_r)[..., None, None] * nn
        - np.asarray(k.b_t)[..., None, None] * (nt + np.swapaxes(nt, -1, -2))
        + np.asarray(k.g_t)[..., None, None] * tt
    )
    return held, damping


def film_force(
    film: FilmModel,
    eccentricity: ArrayLike,
    eccentricity_rate: ArrayLike,
    spin: ArrayLike,
    *,
    viscosity: float,
    journal_radius: float,
    bearing_length: float,
    clearance: float,
    transition_thickness: float,
) -> NDArray[np.float64]:
    """Film force on the journal [N], (..., 2), in the bearing frame (module docstring).

    Args:
        film: the approximation.
        eccentricity: e [m], (..., 2), in a frame fixed to the bearing.
        eccentricity_rate: ė [m/s], (..., 2): e's rate seen from the bearing.
        spin: ω [rad/s], the journal's angular velocity relative to the bearing, (...).
        viscosity, journal_radius, bearing_length, clearance, transition_thickness: as in
            `film_parts`.

    Returns:
        F (..., 2) [N]: F_0 − D ė.

    Raises:
        ValueError: a parameter out of range or a bad shape.
    """
    held, damping = film_parts(
        film,
        eccentricity,
        spin,
        viscosity=viscosity,
        journal_radius=journal_radius,
        bearing_length=bearing_length,
        clearance=clearance,
        transition_thickness=transition_thickness,
    )
    v = np.asarray(eccentricity_rate, dtype=float)
    return held - np.einsum("...ij,...j->...i", damping, v)


def film_torques(
    film: FilmModel,
    eccentricity: ArrayLike,
    force: ArrayLike,
    spin: ArrayLike,
    *,
    viscosity: float,
    journal_radius: float,
    bearing_length: float,
    clearance: float,
    transition_thickness: float,
) -> tuple[Any, Any]:
    """Shear torques of the film on journal and bearing [N m] about their centres.

    T_J = −T_c − (e × F)/2, T_B = T_c − (e × F)/2, T_c = 2π μ ω R³ L/(c sqrt(1 − ε²)) with ε
    clamped as for the force (module docstring); e × F with the true e, so that the film's
    forces and torques on the two bodies sum to zero force and zero moment.

    Args:
        film: the approximation (the Couette torque is the same for both; it is validated).
        eccentricity: e [m], (..., 2).
        force: the film force F on the journal [N], (..., 2), from `film_force`.
        spin: ω [rad/s] relative to the bearing, (...).
        viscosity, journal_radius, bearing_length, clearance, transition_thickness: as in
            `film_parts`.

    Returns:
        (T_J, T_B) [N m], each of shape (...) (floats for scalars).

    Raises:
        ValueError: a parameter out of range.
    """
    f = _film(film, viscosity, journal_radius, bearing_length, clearance, transition_thickness)
    e, d, _ = _frame(eccentricity)
    r = film_ratio(d, clearance=f.c, transition_thickness=f.ht)
    fv = np.asarray(force, dtype=float)
    couette = 2.0 * _PI * viscosity * np.asarray(spin, dtype=float) * journal_radius**3 * bearing_length
    couette = couette / (f.c * np.sqrt(1.0 - np.asarray(r) ** 2))
    moment = e[..., 0] * fv[..., 1] - e[..., 1] * fv[..., 0]
    tj, tb = -couette - 0.5 * moment, couette - 0.5 * moment
    if np.ndim(tj) == 0:
        return float(tj), float(tb)
    return tj, tb


class FilmParameters(NamedTuple):
    """A lubricated joint's film, prepared for `film_scalar` (SI).

    Attributes:
        film: the approximation.
        scale: S [N s] (`film_scale`).
        clearance: c [m].
        ratio_max: ε_t = 1 − h_t/c, the clamp of the transition.
        couette: 2π μ R³ L / c [N m s], the Couette torque per unit spin before 1/sqrt(1 − ε²).
    """

    film: FilmModel
    scale: float
    clearance: float
    ratio_max: float
    couette: float


def film_parameters(
    lubrication: Lubrication, *, journal_radius: float, bearing_length: float, clearance: float
) -> FilmParameters:
    """`FilmParameters` of a lubricated joint.

    Args:
        lubrication: the joint's oil film.
        journal_radius: R [m] > 0.
        bearing_length: L [m] > 0.
        clearance: c [m] > 0, above the transition thickness.

    Raises:
        ValueError: a value out of range.
    """
    s = film_scale(
        lubrication.film,
        viscosity=lubrication.viscosity,
        journal_radius=journal_radius,
        bearing_length=bearing_length,
        clearance=clearance,
    )
    c = float(clearance)
    ratio_max = float(film_ratio(c, clearance=c, transition_thickness=lubrication.transition_thickness))
    couette = 2.0 * _PI * lubrication.viscosity * journal_radius**3 * bearing_length / c
    return FilmParameters(lubrication.film, s, c, ratio_max, couette)


def film_scalar(
    p: FilmParameters, ex: float, ey: float, vx: float, vy: float, spin: float
) -> tuple[float, float, float, float]:
    """Film force and torques at one state in plain floats (the operation order of a port).

    The same quantities as `film_force` and `film_torques`, for one joint; the reference
    solver evaluates it at every right-hand side.

    Args:
        p: the joint's `FilmParameters`.
        ex, ey: e [m] in a frame fixed to the bearing (or any frame, with vx, vy alike).
        vx, vy: ė [m/s], e's rate seen from the bearing, in the same axes.
        spin: ω [rad/s], the journal's angular velocity relative to the bearing.

    Returns:
        (F_x, F_y, T_J, T_B): the force on the journal [N] in the axes of e, and the shear
        torques on journal and bearing [N m].
    """
    d = math.hypot(ex, ey)
    nx, ny = (ex / d, ey / d) if d > 0.0 else (1.0, 0.0)
    tx, ty = -ny, nx
    vn, vt = nx * vx + ny * vy, tx * vx + ty * vy
    ratio = min(d / p.clearance, p.ratio_max)
    k = film_terms(p.film, ratio)
    c = p.clearance
    fn = -p.scale * (k.a_r * spin + (k.b_r * vn - k.b_t * vt) / c)
    ft = p.scale * (k.a_t * spin + (k.b_t * vn - k.g_t * vt) / c)
    fx, fy = fn * nx + ft * tx, fn * ny + ft * ty
    couette = p.couette * spin / math.sqrt(1.0 - ratio * ratio)
    moment = ex * fy - ey * fx
    return fx, fy, -couette - 0.5 * moment, couette - 0.5 * moment
