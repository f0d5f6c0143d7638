"""Contact laws of a pin in a hole: the cylindrical (conformal) laws of the clearance-joint literature.

A journal of radius R_J touches its bearing of radius R_B = R_J + c along a line of the
bearing's length L, not at a point: these laws give the force of that line contact. Notation
(SI): c = R_B − R_J, σ_k = (1 − ν_k²)/E_k, E* = 1/(σ_B + σ_J) (the convention of
`laws.bearing_stiffness`), R = R_B R_J / c, F the total normal force [N], δ the penetration [m].

Logarithmic laws give the penetration as a function of the force,

    δ(F) = k F [β + ln(F₀/F)],   k = 1/(π E* L),

    JOHNSON                 β = −1    F₀ = 4π E* c L
    RADZIMOVSKY             β = 2/3   F₀ = 6.25 E* c L   (ln(4R_B/b) + ln(4R_J/b), b = 1.6 sqrt(F R/(E* L)))
    GOLDSMITH               β = 1     F₀ = π E* L³/R
    DUBOWSKY_FREUDENSTEIN   β = 1     F₀ = π E* L³ c/(R_B R_J)
    ESDU_78035              β = 1     F₀ = 4π E* c L

and are solved for F by `solve_logarithmic` (Newton's method to rounding). δ(F) rises to
δ* = k F₀ e^(β−1) at F* = F₀ e^(β−1) and falls beyond: no force gives a deeper penetration,
so the law refuses one (`elastic` raises; the integrators' kernel `elastic_force` returns
+inf, a wall that rejects a trial step; the reference solver's divergence limit is at most δ*).

Explicit laws:

    LIU       F = (π/2) E* L δ sqrt(δ/(2(c + δ)))
    PEREIRA   F = K δⁿ, K = (a c' + b) L' E*'/c' · 1000ⁿ with c', L' in mm and E*' in MPa
              (the fit's units), a = 0.965, b = 0.0965 (internal contact), n = Y c'^−0.005,
              Y = 1.51 (ln 1000c')^−0.151 for c' <= 0.34954 mm, 0.0151 c' + 1.151 above;
              fitted for 0.005 mm <= c <= 10 mm and refused outside
    PERSSON   F = π E* c L s(1 + s)/(2 − ln(1 + s) − 2s²), s = tan²(ε/2) = δ/(2c + δ), where
              cos ε = c/(c + δ); the denominator vanishes at s = s* (δ* = 2c s*/(1 − s*),
              about 10 c): the force grows without bound there, and deeper is refused.

Damping: every law here takes Lankarani–Nikravesh's hysteresis, as Pereira et al. write their
law: F = F_el(δ) [1 + 3(1 − cₑ²)/4 · δ̇/δ̇⁻], clipped at 0 (`laws.hysteresis_factor`).

Provenance (docs/references.md). None of these papers was read here. JOHNSON, RADZIMOVSKY, LIU
and PEREIRA are [checked]: the force at δ = 0.1, 1 and 10 µm (c = 0.1 mm, L = 20 mm, steel)
equals that of ladisk/DyS's ``contact_model_cylinder.py``, run by hand, within 1e-12. The
others are [recalled] and warn (`laws.UnverifiedLawWarning`) on their first use:
DUBOWSKY_FREUDENSTEIN and ESDU_78035 are taken with the line-contact compliance 1/(π E* L)
that Johnson's and Radzimovsky's share (σ = (1 − ν²)/(πE) in their papers' notation, as
recalled), where DyS writes σ = (1 − ν²)/E, giving π (ESDU: π²) times less force; GOLDSMITH
with the L³ that makes its logarithm dimensionless (DyS writes L), which makes it the same law
as Dubowsky–Freudenstein's for a pin in a hole; PERSSON is the expression DyS carries but marks
not implemented.
"""

from __future__ import annotations

import enum
import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from clearance.checks import positive
from clearance.contact_calibration.laws import UnverifiedLawWarning, hysteresis_factor
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw, Material

__all__ = [
    "CylinderLaw",
    "bearing_length",
    "cylinder_law",
    "cylinder_law_from",
    "solve_logarithmic",
    "elastic_force",
    "damped_force",
    "elastic",
    "cylindrical_force",
    "penetration",
    "elastic_energy",
    "PEREIRA_CLEARANCE_RANGE",
    "NEWTON_MAX_ITERATIONS",
]

Force = Any  # float for scalar inputs, np.ndarray otherwise

PEREIRA_CLEARANCE_RANGE = (0.005e-3, 10e-3)
"""Clearances [m] Pereira et al.'s exponent was fitted for (0.005–10 mm); refused outside."""

NEWTON_MAX_ITERATIONS = 100
"""Cap on `solve_logarithmic`'s rising steps: 3–5 are typical; near δ* the root is double
and Newton halves its error per step (about 55 to rounding)."""

_NEWTON_TOL = 4.0 * 2.0**-52  # a rise below 4 ulps of max(1, |u|) ends the iteration


class _Form(enum.Enum):
    LOGARITHMIC = "logarithmic"
    LIU = "liu"
    POWER = "power"
    PERSSON = "persson"


_FORMS = {
    ContactLaw.JOHNSON: _Form.LOGARITHMIC,
    ContactLaw.RADZIMOVSKY: _Form.LOGARITHMIC,
    ContactLaw.GOLDSMITH: _Form.LOGARITHMIC,
    ContactLaw.DUBOWSKY_FREUDENSTEIN: _Form.LOGARITHMIC,
    ContactLaw.ESDU_78035: _Form.LOGARITHMIC,
    ContactLaw.LIU: _Form.LIU,
    ContactLaw.PEREIRA: _Form.POWER,
    ContactLaw.PERSSON: _Form.PERSSON,
}

_RECALLED = {
    ContactLaw.GOLDSMITH: "L^3 in its logarithm (DyS writes L) and the line-contact compliance 1/(pi E* L)",
    ContactLaw.DUBOWSKY_FREUDENSTEIN: "the line-contact compliance 1/(pi E* L) (DyS: pi times less force)",
    ContactLaw.ESDU_78035: "the line-contact compliance 1/(pi E* L) (DyS: pi^2 times less force)",
    ContactLaw.PERSSON: "the expression DyS carries but marks not implemented",
}
_warned: set[ContactLaw] = set()


def _persson_root() -> float:
    """s* in (0, 1) where 2 − ln(1 + s) − 2s² = 0 (Newton from s = 0.8, to rounding)."""
    s = 0.8
    for _ in range(50):
        step = (2.0 - math.log1p(s) - 2.0 * s * s) / (-1.0 / (1.0 + s) - 4.0 * s)
        s -= step
        if abs(step) <= _NEWTON_TOL:
            break
    return s


_PERSSON_S = _persson_root()


@dataclass(frozen=True)
class CylinderLaw:
    """One joint's cylindrical law with its constants (SI), as every solver evaluates it.

    Attributes:
        law: the `ContactLaw` (one of `clearance.model.CYLINDRICAL_LAWS`).
        compliance: k = 1/(π E* L) [m/N] of the logarithmic laws; 0 for the others.
        reference_force: F₀ [N] of the logarithmic laws; 0 for the others.
        offset: β [-] of the logarithmic laws; 0 for the others.
        stiffness: LIU (π/2) E* L [N/m]; PEREIRA K [N/m^n]; PERSSON π E* c L [N]; 0 for the
            logarithmic laws.
        exponent: PEREIRA's n [-]; 0 for the others.
        clearance: c [m].
        max_penetration: δ* [m], the deepest penetration the law gives a force for (inf for
            LIU and PEREIRA).
    """

    law: ContactLaw
    compliance: float
    reference_force: float
    offset: float
    stiffness: float
    exponent: float
    clearance: float
    max_penetration: float

    @property
    def logarithmic(self) -> bool:
        """Whether the law gives δ(F) (solved by `solve_logarithmic`)."""
        return _FORMS[self.law] is _Form.LOGARITHMIC


def bearing_length(clearance: Clearance) -> float:
    """The bearing length L [m] the cylindrical laws use for a joint.

    ``clearance.bearing_length`` where given; otherwise L = 2 R_B, a bearing as long as its
    bore (L/D = 1, in the 0.5–1.5 of plain-bearing design practice [recalled]): 20 mm for the
    catalogue's 10 mm bearing radius.

    Args:
        clearance: the joint's clearance.

    Returns:
        L [m] > 0.
    """
    if clearance.bearing_length is not None:
        return float(clearance.bearing_length)
    return 2.0 * float(clearance.bearing_radius)


def _pereira(c: float, length: float, modulus: float) -> tuple[float, float]:
    """(K [N/m^n], n) of Pereira et al.'s internal-contact fit at clearance c [m]."""
    lo, hi = PEREIRA_CLEARANCE_RANGE
    if not lo <= c <= hi:
        raise ValueError(
            f"law 'pereira' is fitted for radial clearances of 0.005-10 mm (got {c * 1e3:g} mm): "
            "choose another cylindrical law for this joint"
        )
    c_mm = c * 1e3
    y = 1.51 * math.log(c_mm * 1e3) ** -0.151 if c_mm <= 0.34954 else 0.0151 * c_mm + 1.151
    n = y * c_mm**-0.005
    k_mm = (0.965 * c_mm + 0.0965) * (length * 1e3) * (modulus * 1e-6) / c_mm  # N/mm^n
    return k_mm * 1000.0**n, n


def cylinder_law_from(
    law: ContactLaw,
    *,
    bearing_radius: float,
    radial_clearance: float,
    bearing_material: Material,
    journal_material: Material,
    bearing_length: float,
) -> CylinderLaw:
    """The constants of a cylindrical law for a journal in a bearing (module docstring).

    Warns once per process (`laws.UnverifiedLawWarning`) for a [recalled] law.

    Args:
        law: one of `clearance.model.CYLINDRICAL_LAWS`.
        bearing_radius: R_B [m], > 0.
        radial_clearance: c = R_B − R_J [m], 0 < c < R_B.
        bearing_material: elastic material of the bearing.
        journal_material: elastic material of the journal.
        bearing_length: L [m], > 0.

    Returns:
        The `CylinderLaw`.

    Raises:
        ValueError: a law that is not cylindrical, a radius or length out of range, or a
            clearance outside PEREIRA's fitted range.
    """
    if law not in CYLINDRICAL_LAWS:
        raise ValueError(
            f"law must be one of the cylindrical laws {sorted(m.value for m in CYLINDRICAL_LAWS)} (got {law!r})"
        )
    rb = positive("bearing_radius", bearing_radius, "m")
    c = positive("radial_clearance", radial_clearance, "m")
    if c >= rb:
        raise ValueError(f"radial_clearance must be < bearing_radius = {rb} m (got {radial_clearance!r} m)")
    length = positive("bearing_length", bearing_length, "m")
    rj = rb - c
    modulus = 1.0 / sum((1.0 - m.poisson_ratio**2) / m.youngs_modulus for m in (bearing_material, journal_material))
    if law in _RECALLED and law not in _warned:
        _warned.add(law)
        warnings.warn(
            f"contact law '{law.value}' is recalled, not checked against its paper or an implementation we did "
            f"not write: it is taken with {_RECALLED[law]} (docs/references.md); check it before relying on "
            "the results",
            UnverifiedLawWarning,
            stacklevel=3,
        )
    form = _FORMS[law]
    if form is not _Form.LOGARITHMIC:
        if form is _Form.LIU:
            stiffness, exponent, deepest = 0.5 * math.pi * modulus * length, 0.0, math.inf
        elif form is _Form.POWER:
            stiffness, exponent = _pereira(c, length, modulus)
            deepest = math.inf
        else:
            stiffness, exponent = math.pi * modulus * c * length, 0.0
            deepest = 2.0 * c * _PERSSON_S / (1.0 - _PERSSON_S)
        return CylinderLaw(law, 0.0, 0.0, 0.0, stiffness, exponent, c, deepest)
    pel = math.pi * modulus * length  # 1/k
    beta, f0 = {
        ContactLaw.JOHNSON: (-1.0, 4.0 * pel * c),
        ContactLaw.RADZIMOVSKY: (2.0 / 3.0, 6.25 * modulus * c * length),
        ContactLaw.GOLDSMITH: (1.0, pel * length**2 * c / (rb * rj)),
        ContactLaw.DUBOWSKY_FREUDENSTEIN: (1.0, pel * length**2 * c / (rb * rj)),
        ContactLaw.ESDU_78035: (1.0, 4.0 * pel * c),
    }[law]
    k = 1.0 / pel
    return CylinderLaw(law, k, f0, beta, 0.0, 0.0, c, k * f0 * math.exp(beta - 1.0))


def cylinder_law(clearance: Clearance) -> CylinderLaw:
    """`cylinder_law_from` with a joint's radii, materials, law and `bearing_length`.

    Args:
        clearance: a clearance whose law is cylindrical.

    Returns:
        The `CylinderLaw`.

    Raises:
        ValueError: as `cylinder_law_from`.
    """
    return cylinder_law_from(
        clearance.law,
        bearing_radius=clearance.bearing_radius,
        radial_clearance=clearance.radial_clearance,
        bearing_material=clearance.bearing_material,
        journal_material=clearance.journal_material,
        bearing_length=bearing_length(clearance),
    )


def solve_logarithmic(compliance: float, reference_force: float, offset: float, delta: float) -> float:
    """F [N] with δ = k F [β + ln(F₀/F)], on the rising branch (F <= F₀ e^(β−1)), to rounding.

    With x = F/F₀, D = δ/(k F₀) and u = ln x the equation is φ(u) = u + ln(β − u) − ln D = 0,
    increasing and concave for u < β − 1. The start u₀ (one fixed-point step from ln D) lies
    right of the root; Newton's first step lands at or left of it, and from there every step
    rises monotonically to the root (quadratically; linearly where the root is double, at δ*):

        ln D = log(δ/(k F₀));  u = ln D − log(β − ln D)
        s = newton(u); u = u − s                              (first step, s >= 0)
        repeat at most NEWTON_MAX_ITERATIONS times:
            s = newton(u)
            stop if not s < 0                                 (no rise left: rounding)
            u = u − s
            stop if −s <= 4·2⁻⁵² · max(1, |u|)
        F = F₀ exp(u)

    where newton(u) = (u + log(w) − ln D) · w/(w − 1), w = β − u. D >= e^(β−1) (δ at or
    beyond δ*) returns F* = F₀ e^(β−1) without iterating; callers refuse δ > δ* first.

    Args:
        compliance: k [m/N], > 0.
        reference_force: F₀ [N], > 0.
        offset: β [-].
        delta: δ [m], > 0.

    Returns:
        F [N] > 0.
    """
    ln_d = math.log(delta / (compliance * reference_force))
    if ln_d >= offset - 1.0:
        return reference_force * math.exp(offset - 1.0)
    u = ln_d - math.log(offset - ln_d)
    u -= _newton_step(u, offset, ln_d)
    for _ in range(NEWTON_MAX_ITERATIONS):
        step = _newton_step(u, offset, ln_d)
        if not step < 0.0:
            break
        u -= step
        if -step <= _NEWTON_TOL * max(1.0, abs(u)):
            break
    return reference_force * math.exp(u)


def _newton_step(u: float, offset: float, ln_d: float) -> float:
    w = offset - u
    return (u + math.log(w) - ln_d) * w / (w - 1.0)


def elastic_force(cyl: CylinderLaw, delta: float) -> float:
    """Elastic force F_el [N] at penetration δ [m] (a plain float, no validation).

    0 for δ <= 0 and +inf beyond δ* (a wall for an integrator's trial step: `elastic`
    refuses such a state). The operations are the ones the compiled contact reproduces.
    """
    if delta <= 0.0:
        return 0.0
    if delta > cyl.max_penetration:
        return math.inf
    form = _FORMS[cyl.law]
    if form is _Form.LOGARITHMIC:
        return solve_logarithmic(cyl.compliance, cyl.reference_force, cyl.offset, delta)
    if form is _Form.LIU:
        return cyl.stiffness * delta * math.sqrt(delta / (2.0 * (cyl.clearance + delta)))
    if form is _Form.POWER:
        return cyl.stiffness * delta**cyl.exponent
    s = delta / (2.0 * cyl.clearance + delta)
    den = 2.0 - math.log1p(s) - 2.0 * s * s
    return cyl.stiffness * s * (1.0 + s) / den if den > 0.0 else math.inf


def damped_force(cyl: CylinderLaw, chi: float, delta: float, delta_dot: float, approach_speed: float) -> float:
    """F_el(δ) [1 + χ δ̇/δ̇⁻] clipped at 0 [N] (plain floats, no validation; see `elastic_force`).

    Args:
        cyl: the law.
        chi: hysteresis factor χ [-] (`laws.hysteresis_factor`).
        delta: δ [m].
        delta_dot: δ̇ [m/s] (> 0 approaching).
        approach_speed: δ̇⁻ [m/s] > 0.
    """
    f = elastic_force(cyl, delta)
    if f == 0.0:
        return 0.0
    f *= 1.0 + chi * (delta_dot / approach_speed)  # the operations of laws._dissipative
    return f if f > 0.0 else 0.0


def _checked(cyl: CylinderLaw, delta: ArrayLike) -> np.ndarray:
    if not isinstance(cyl, CylinderLaw):
        raise ValueError(f"cyl must be a CylinderLaw (got {cyl!r})")
    d = np.asarray(delta, dtype=float)
    if np.any(np.isnan(d)):
        raise ValueError(f"penetration must not be NaN (got {delta!r})")
    deepest = float(np.max(d, initial=-math.inf))
    if deepest > cyl.max_penetration:
        raise ValueError(
            f"penetration {deepest:.6g} m is beyond the deepest the '{cyl.law.value}' law gives a force for, "
            f"{cyl.max_penetration:.6g} m at c = {cyl.clearance:g} m: the law is refused there"
        )
    return d


def _out(x: np.ndarray) -> Force:
    return float(x) if np.ndim(x) == 0 else x


def elastic(cyl: CylinderLaw, delta: ArrayLike) -> Force:
    """Elastic force F_el(δ) [N] of a cylindrical law, any shape.

    Args:
        cyl: the law (`cylinder_law`).
        delta: δ [m], any shape; F = 0 where δ <= 0.

    Returns:
        F_el [N] >= 0, the shape of ``delta`` (float for a scalar).

    Raises:
        ValueError: a penetration beyond the law's δ* (no force gives it), or NaN.
    """
    d = _checked(cyl, delta)
    return _out(np.vectorize(lambda x: elastic_force(cyl, x), otypes=[float])(d))


def cylindrical_force(
    cyl: CylinderLaw, delta: ArrayLike, delta_dot: ArrayLike, approach_speed: ArrayLike, *, restitution: float
) -> Force:
    """Normal force of a cylindrical law with LN hysteresis: F_el(δ) [1 + 3(1 − cₑ²)/4 · δ̇/δ̇⁻] >= 0.

    Args:
        cyl: the law (`cylinder_law`).
        delta: δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: δ̇ [m/s] (> 0 approaching), broadcast with ``delta``.
        approach_speed: δ̇⁻ [m/s] > 0, broadcastable.
        restitution: cₑ [-] in [0, 1].

    Returns:
        F [N] >= 0, the broadcast shape (float for scalars).

    Raises:
        ValueError: as `elastic`, an approach speed that is not positive and finite, or
            restitution out of range.
    """
    v = np.asarray(approach_speed, dtype=float)
    if not np.all(np.isfinite(v) & (v > 0)):
        raise ValueError(f"approach_speed must be positive and finite everywhere (got {approach_speed!r} m/s)")
    chi = hysteresis_factor(cyl.law, restitution)
    el = np.asarray(elastic(cyl, delta), dtype=float)
    return _out(np.maximum(el * (1.0 + chi * (np.asarray(delta_dot, dtype=float) / v)), 0.0))


def penetration(cyl: CylinderLaw, force: ArrayLike) -> Force:
    """δ(F) = k F [β + ln(F₀/F)] [m] of a logarithmic law (the law as its paper writes it).

    Args:
        cyl: a logarithmic law (`CylinderLaw.logarithmic`).
        force: F [N] > 0, any shape.

    Returns:
        δ [m], the shape of ``force`` (float for a scalar).

    Raises:
        ValueError: for a law that is not logarithmic, or a force that is not positive.
    """
    if not cyl.logarithmic:
        raise ValueError(
            f"law '{cyl.law.value}' gives the force explicitly; penetration(F) is for the logarithmic laws"
        )
    f = np.asarray(force, dtype=float)
    if not np.all(f > 0):
        raise ValueError(f"force must be > 0 [N] (got {force!r})")
    return _out(cyl.compliance * f * (cyl.offset + np.log(cyl.reference_force / f)))


_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(24)


def elastic_energy(cyl: CylinderLaw, delta: float) -> float:
    """Elastic energy ∫₀^δ F_el [J] stored at penetration δ [m] (0 for δ <= 0).

    Logarithmic laws F δ/2 − k F²/4; PEREIRA F δ/(n + 1); LIU (S/√2)[√(δ(c+δ))(2δ − 3c)/4 +
    (3c²/4) asinh(√(δ/c))] with S = (π/2) E* L; PERSSON 24-point Gauss–Legendre.

    Args:
        cyl: the law.
        delta: δ [m], at most the law's δ*.

    Returns:
        Energy [J] >= 0 (inf at PERSSON's δ*).
    """
    if delta <= 0.0:
        return 0.0
    f = elastic_force(cyl, delta)
    form = _FORMS[cyl.law]
    if form is _Form.LOGARITHMIC:
        return f * delta / 2.0 - cyl.compliance * f * f / 4.0
    if form is _Form.POWER:
        return f * delta / (cyl.exponent + 1.0)
    c = cyl.clearance
    if form is _Form.LIU:
        root = math.sqrt(delta * (c + delta)) * (2.0 * delta - 3.0 * c) / 4.0
        return cyl.stiffness / math.sqrt(2.0) * (root + 0.75 * c * c * math.asinh(math.sqrt(delta / c)))
    if not math.isfinite(f):
        return math.inf
    x = 0.5 * delta * (_GAUSS_X + 1.0)
    return 0.5 * delta * float(sum(w * elastic_force(cyl, float(xi)) for xi, w in zip(x, _GAUSS_W)))
