"""Normal and tangential contact force laws of a revolute clearance joint (pure NumPy).

Every law here is a pure function of the penetration δ [m], its rate δ̇ [m/s] and, for the
dissipative laws, the normal approach speed δ̇⁻ > 0 [m/s] recorded at contact onset and kept
for the whole impact (Lankarani and Nikravesh 1990; docs/references.md). No MuJoCo dependency: these functions are
the independent reference the MuJoCo contact is calibrated against.

Conventions:
  * δ > 0 is penetration; for δ ≤ 0 every force is exactly 0.
  * δ̇ > 0 while the bodies approach (compression), δ̇ < 0 while they separate.
  * The normal force is a compressive magnitude [N], >= 0. Where a law's damping term would
    make it negative (late in restitution, when the bodies separate faster than the surfaces
    recover) it is clipped at 0: contact cannot pull (no adhesion).
  * Inputs broadcast like NumPy arrays; a 0-d result is returned as a Python float.

The dissipative laws share the form F = K δⁿ [1 + χ(cₑ) δ̇/δ̇⁻]; `hysteresis_factor`
returns χ. Hu–Guo's factor is recalled, not checked: docs/references.md notes that one public
code uses half of it, and its first use warns (`UnverifiedLawWarning`). `MIN_APPROACH_SPEED`
is the floor on δ̇⁻ shared by every solver that records it. Ambrósio's friction thresholds
v₀ = 1e-4 m/s and v₁ = 1e-3 m/s are recalled values (another code uses 1e-3 and 5e-2 m/s).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from clearance.checks import positive
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw, Material

__all__ = [
    "contact_omega",
    "GEAR_MESH_EXPONENT",
    "mesh_torque",
    "mesh_omega",
    "bearing_stiffness",
    "bearing_stiffness_from",
    "hertz",
    "lankarani_nikravesh",
    "hunt_crossley",
    "flores",
    "gonthier",
    "hu_guo",
    "impact_law",
    "hysteresis_factor",
    "normal_force",
    "ambrosio_friction",
    "STIFFNESS_FORMULA",
    "MIN_APPROACH_SPEED",
    "UnverifiedLawWarning",
]

STIFFNESS_FORMULA = "K = 4/(3(sigma_B + sigma_J)) sqrt(R_B R_J/(R_B - R_J)), sigma = (1 - nu^2)/E"
"""The stiffness convention used by `bearing_stiffness` (record it with every output)."""

MIN_APPROACH_SPEED = 1e-3
"""Floor [m/s] on the approach speed δ̇⁻ recorded at contact onset.

The dissipative laws divide their damping term by δ̇⁻; a grazing onset, or a contact
already present at t = 0, would otherwise give a near-infinite damping. Both the exact-LN
MuJoCo mode and the reference solver record max(δ̇ at onset, this floor)."""

Force = Any  # float for scalar inputs, np.ndarray otherwise


class UnverifiedLawWarning(UserWarning):
    """A contact law whose coefficient is recalled, not checked against its paper, is in use."""


_warned_unverified: set[ContactLaw] = set()


def _warn_unverified(law: ContactLaw) -> None:
    """Warn once per process that Hu–Guo's hysteresis factor is unverified."""
    if law is ContactLaw.HU_GUO and law not in _warned_unverified:
        _warned_unverified.add(law)
        warnings.warn(
            "contact law 'hu_guo': its hysteresis factor 3(1 - c_e)/(2 c_e) is recalled, not "
            "checked against Hu and Guo 2015 (docs/references.md: one public code uses half this "
            "factor); check it before relying on the results",
            UnverifiedLawWarning,
            stacklevel=3,
        )


def _out(x: np.ndarray) -> Force:
    return float(x) if np.ndim(x) == 0 else x


def _positive_array(name: str, value: ArrayLike, unit: str) -> np.ndarray:
    a = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(a) & (a > 0)):
        raise ValueError(
            f"{name} must be positive and finite everywhere (got {value!r} {unit}); the "
            "dissipative laws divide by the approach speed recorded at contact onset"
        )
    return a


def _restitution(value: float, *, allow_zero: bool) -> float:
    try:
        e = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"restitution must be a number in (0, 1] (got {value!r})") from None
    lo_ok = e >= 0 if allow_zero else e > 0
    if not (math.isfinite(e) and lo_ok and e <= 1):
        rng = "[0, 1]" if allow_zero else "(0, 1]"
        raise ValueError(f"restitution must be in {rng} (got {value!r})")
    return e


def bearing_stiffness_from(
    bearing_radius: float,
    journal_radius: float,
    bearing_material: Material,
    journal_material: Material,
) -> float:
    """Contact stiffness of a journal inside a bearing.

    K = 4 / (3 (σ_B + σ_J)) · sqrt(R_B R_J / (R_B − R_J)),  σ = (1 − ν²)/E: the sphere-type
    formula used throughout the clearance-joint literature (Flores and Ambrósio 2004;
    docs/references.md, [checked]; see `STIFFNESS_FORMULA`). Steel, R_B = 10 mm gives 6.61e10 N/m^1.5 at
    c = 0.5 mm.

    Args:
        bearing_radius: R_B [m], > 0.
        journal_radius: R_J [m], 0 < R_J < R_B.
        bearing_material: elastic material of the bearing.
        journal_material: elastic material of the journal.

    Returns:
        K [N/m^1.5].

    Raises:
        ValueError: if a radius is not positive and finite or R_J >= R_B.
    """
    rb = positive("bearing_radius", bearing_radius, "m")
    rj = positive("journal_radius", journal_radius, "m")
    if rj >= rb:
        raise ValueError(f"journal_radius must be < bearing_radius = {rb} m (got {journal_radius!r} m)")
    sigma = sum((1.0 - m.poisson_ratio**2) / m.youngs_modulus for m in (bearing_material, journal_material))
    return 4.0 / (3.0 * sigma) * math.sqrt(rb * rj / (rb - rj))


def bearing_stiffness(clearance: Clearance) -> float:
    """Contact stiffness K [N/m^1.5] of a clearance joint (see `bearing_stiffness_from`).

    Args:
        clearance: the joint's clearance (radii and materials).

    Returns:
        K [N/m^1.5].
    """
    return bearing_stiffness_from(
        clearance.bearing_radius,
        clearance.journal_radius,
        clearance.bearing_material,
        clearance.journal_material,
    )


def _elastic(delta: ArrayLike, stiffness: float, exponent: float) -> np.ndarray:
    d = np.maximum(np.asarray(delta, dtype=float), 0.0)
    return stiffness * d**exponent


def _dissipative(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike,
    stiffness: float,
    chi: float,
    exponent: float,
) -> np.ndarray:
    """K δⁿ [1 + χ δ̇/δ̇⁻] clipped at >= 0; no validation (callers validate once)."""
    ratio = np.asarray(delta_dot, dtype=float) / approach_speed
    return np.maximum(_elastic(delta, stiffness, exponent) * (1.0 + chi * ratio), 0.0)


def hertz(delta: ArrayLike, *, stiffness: float, exponent: float = 1.5) -> Force:
    """Hertz elastic contact F = K δⁿ (Hertz 1882; docs/references.md).

    Args:
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        stiffness: K [N/m^n], > 0.
        exponent: n [-], > 0 (1.5 for metals).

    Returns:
        Normal force [N], same shape as ``delta`` (float for scalars).

    Raises:
        ValueError: if stiffness or exponent is not positive and finite.
    """
    k = positive("stiffness", stiffness, "N/m^n")
    n = positive("exponent", exponent, "")
    return _out(_elastic(delta, k, n))


def _law(
    law: ContactLaw,
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike,
    stiffness: float,
    restitution: float,
    exponent: float,
) -> Force:
    k = positive("stiffness", stiffness, "N/m^n")
    n = positive("exponent", exponent, "")
    v = _positive_array("approach_speed", approach_speed, "m/s")
    chi = hysteresis_factor(law, restitution)
    return _out(_dissipative(delta, delta_dot, v, k, chi, n))


def lankarani_nikravesh(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike,
    *,
    stiffness: float,
    restitution: float,
    exponent: float = 1.5,
) -> Force:
    """Lankarani–Nikravesh (1990): F = K δⁿ [1 + 3(1 − cₑ²)/4 · δ̇/δ̇⁻].

    Lankarani and Nikravesh 1990 (docs/references.md) [checked]. Derived for cₑ close to 1
    (good for cₑ ≳ 0.7); the
    restitution of the impact it produces is slightly above cₑ (about 0.913 at cₑ = 0.9).

    Args:
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: penetration rate δ̇ [m/s] (> 0 approaching), broadcast with ``delta``.
        approach_speed: δ̇⁻ [m/s], > 0: the normal approach speed at contact onset, kept for
            the whole impact; scalar or broadcastable array.
        stiffness: K [N/m^n], > 0.
        restitution: coefficient of restitution cₑ [-], [0, 1].
        exponent: n [-], > 0 (1.5 for metals).

    Returns:
        Normal force [N] >= 0, broadcast shape of the inputs (float for scalars). The total
        is clipped at 0 where the damping term would make it negative (no adhesion).

    Raises:
        ValueError: if approach_speed is not positive and finite, or stiffness, exponent or
            restitution is out of range.
    """
    return _law(ContactLaw.LANKARANI_NIKRAVESH, delta, delta_dot, approach_speed, stiffness, restitution, exponent)


def hunt_crossley(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike,
    *,
    stiffness: float,
    restitution: float,
    exponent: float = 1.5,
) -> Force:
    """Hunt–Crossley (1975): F = K δⁿ [1 + 3(1 − cₑ)/2 · δ̇/δ̇⁻].

    Hunt and Crossley 1975 (docs/references.md) [checked].

    Args:
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: penetration rate δ̇ [m/s] (> 0 approaching), broadcast with ``delta``.
        approach_speed: δ̇⁻ [m/s], > 0: the normal approach speed at contact onset, kept for
            the whole impact; scalar or broadcastable array.
        stiffness: K [N/m^n], > 0.
        restitution: coefficient of restitution cₑ [-], [0, 1].
        exponent: n [-], > 0 (1.5 for metals).

    Returns:
        Normal force [N] >= 0, broadcast shape of the inputs (float for scalars). The total
        is clipped at 0 where the damping term would make it negative (no adhesion).

    Raises:
        ValueError: if approach_speed is not positive and finite, or stiffness, exponent or
            restitution is out of range.
    """
    return _law(ContactLaw.HUNT_CROSSLEY, delta, delta_dot, approach_speed, stiffness, restitution, exponent)


def flores(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike,
    *,
    stiffness: float,
    restitution: float,
    exponent: float = 1.5,
) -> Force:
    """Flores et al. (2011): F = K δⁿ [1 + 8(1 − cₑ)/(5cₑ) · δ̇/δ̇⁻].

    Flores, Machado, Silva and Martins 2011 (docs/references.md) [checked]; meant for the whole range of cₑ.

    Args:
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: penetration rate δ̇ [m/s] (> 0 approaching), broadcast with ``delta``.
        approach_speed: δ̇⁻ [m/s], > 0: the normal approach speed at contact onset, kept for
            the whole impact; scalar or broadcastable array.
        stiffness: K [N/m^n], > 0.
        restitution: coefficient of restitution cₑ [-], (0, 1].
        exponent: n [-], > 0 (1.5 for metals).

    Returns:
        Normal force [N] >= 0, broadcast shape of the inputs (float for scalars). The total
        is clipped at 0 where the damping term would make it negative (no adhesion).

    Raises:
        ValueError: if approach_speed is not positive and finite, or stiffness, exponent or
            restitution is out of range.
    """
    return _law(ContactLaw.FLORES, delta, delta_dot, approach_speed, stiffness, restitution, exponent)


def gonthier(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike,
    *,
    stiffness: float,
    restitution: float,
    exponent: float = 1.5,
) -> Force:
    """Gonthier et al. (2004): F = K δⁿ [1 + (1 − cₑ²)/cₑ · δ̇/δ̇⁻].

    Gonthier, McPhee, Lange and Piedbœuf 2004 (docs/references.md) [checked].

    Args:
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: penetration rate δ̇ [m/s] (> 0 approaching), broadcast with ``delta``.
        approach_speed: δ̇⁻ [m/s], > 0: the normal approach speed at contact onset, kept for
            the whole impact; scalar or broadcastable array.
        stiffness: K [N/m^n], > 0.
        restitution: coefficient of restitution cₑ [-], (0, 1].
        exponent: n [-], > 0 (1.5 for metals).

    Returns:
        Normal force [N] >= 0, broadcast shape of the inputs (float for scalars). The total
        is clipped at 0 where the damping term would make it negative (no adhesion).

    Raises:
        ValueError: if approach_speed is not positive and finite, or stiffness, exponent or
            restitution is out of range.
    """
    return _law(ContactLaw.GONTHIER, delta, delta_dot, approach_speed, stiffness, restitution, exponent)


def hu_guo(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike,
    *,
    stiffness: float,
    restitution: float,
    exponent: float = 1.5,
) -> Force:
    """Hu–Guo (2015): F = K δⁿ [1 + 3(1 − cₑ)/(2cₑ) · δ̇/δ̇⁻]. UNVERIFIED.

    Hu and Guo 2015; docs/references.md marks this factor [recalled]: one public code uses half of it.
    Check it against the paper before relying on it. The first use of the law in a process
    emits an `UnverifiedLawWarning` saying so.

    Args:
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: penetration rate δ̇ [m/s] (> 0 approaching), broadcast with ``delta``.
        approach_speed: δ̇⁻ [m/s], > 0: the normal approach speed at contact onset, kept for
            the whole impact; scalar or broadcastable array.
        stiffness: K [N/m^n], > 0.
        restitution: coefficient of restitution cₑ [-], (0, 1].
        exponent: n [-], > 0 (1.5 for metals).

    Returns:
        Normal force [N] >= 0, broadcast shape of the inputs (float for scalars). The total
        is clipped at 0 where the damping term would make it negative (no adhesion).

    Raises:
        ValueError: if approach_speed is not positive and finite, or stiffness, exponent or
            restitution is out of range.
    """
    return _law(ContactLaw.HU_GUO, delta, delta_dot, approach_speed, stiffness, restitution, exponent)


def _step_cubic(delta: np.ndarray, d_max: float) -> np.ndarray:
    z = np.clip(delta / d_max, 0.0, 1.0)
    return z * z * (3.0 - 2.0 * z)


def _impact(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    stiffness: float,
    exponent: float,
    c_max: float,
    d_max: float,
) -> np.ndarray:
    d = np.asarray(delta, dtype=float)
    damping = c_max * _step_cubic(d, d_max) * np.asarray(delta_dot, dtype=float)
    f = np.maximum(_elastic(d, stiffness, exponent) + damping, 0.0)
    return np.where(d > 0, f, 0.0)


def impact_law(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    *,
    stiffness: float,
    exponent: float = 1.5,
    c_max: float,
    d_max: float,
) -> Force:
    """MSC Adams IMPACT: F = max(0, K δⁿ + STEP(δ; 0, 0, d_max, C_max) δ̇) for δ > 0.

    MSC Adams IMPACT (docs/references.md) [checked]: STEP rises from 0 at δ = 0 to C_max at δ = d_max as
    the cubic z²(3 − 2z), z = δ/d_max, and stays at C_max beyond. The max(0, ·) is the
    commercial definition (IMPACT(x, x', x1, k, e, cmax, d) = max(0, k (x1 − x)^e −
    STEP(x, x1 − d, cmax, x1, 0) x') in the Adams-derived solvers' manuals), so this law
    too never pulls.

    Args:
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: penetration rate δ̇ [m/s] (> 0 approaching), broadcast with ``delta``.
        stiffness: K [N/m^n], > 0.
        exponent: n [-], > 0.
        c_max: maximum damping coefficient C_max [N s/m], >= 0.
        d_max: penetration d_max [m] > 0 at which full damping applies.

    Returns:
        Normal force [N] >= 0, broadcast shape of the inputs (float for scalars).

    Raises:
        ValueError: if an argument is out of range.
    """
    k = positive("stiffness", stiffness, "N/m^n")
    n = positive("exponent", exponent, "")
    c, d = _impact_params(c_max, d_max)
    return _out(_impact(delta, delta_dot, k, n, c, d))


def _impact_params(c_max: float | None, d_max: float | None) -> tuple[float, float]:
    if c_max is None or d_max is None:
        raise ValueError(f"the IMPACT law needs c_max [N s/m] and d_max [m] (got c_max={c_max!r}, d_max={d_max!r})")
    c = float(c_max)
    if not (math.isfinite(c) and c >= 0):
        raise ValueError(f"c_max must be >= 0 and finite (got {c_max!r} N s/m)")
    return c, positive("d_max", d_max, "m")


_FACTORS = {
    ContactLaw.LANKARANI_NIKRAVESH: (True, lambda e: 3.0 * (1.0 - e * e) / 4.0),
    ContactLaw.HUNT_CROSSLEY: (True, lambda e: 1.5 * (1.0 - e)),
    ContactLaw.FLORES: (False, lambda e: 8.0 * (1.0 - e) / (5.0 * e)),
    ContactLaw.GONTHIER: (False, lambda e: (1.0 - e * e) / e),
    ContactLaw.HU_GUO: (False, lambda e: 3.0 * (1.0 - e) / (2.0 * e)),
}
# the cylindrical laws take LN's hysteresis (`cylindrical_laws`)
_FACTORS.update(dict.fromkeys(CYLINDRICAL_LAWS, _FACTORS[ContactLaw.LANKARANI_NIKRAVESH]))


def hysteresis_factor(law: ContactLaw, restitution: float) -> float:
    """The factor χ(cₑ) of F = K δⁿ [1 + χ δ̇/δ̇⁻] (docs/references.md).

    LN 3(1 − cₑ²)/4; Hunt–Crossley 3(1 − cₑ)/2; Flores 8(1 − cₑ)/(5cₑ); Gonthier
    (1 − cₑ²)/cₑ; Hu–Guo 3(1 − cₑ)/(2cₑ) (recalled, unverified); Hertz 0; the cylindrical
    laws (`cylindrical_laws`) LN's.

    Args:
        law: the contact law.
        restitution: cₑ [-]; in [0, 1] for LN and Hunt–Crossley, (0, 1] for the laws that
            divide by cₑ; ignored for Hertz.

    Every user of a law resolves its factor here (the laws below, the impact reference, the
    exact-LN mode, the reference solver), so this is where an `UnverifiedLawWarning` is
    emitted, once per process, the first time Hu–Guo is used.

    Returns:
        χ [-] >= 0.

    Raises:
        ValueError: for IMPACT (its damping is C_max, not a hysteresis factor), a non-law,
            or restitution out of range.
    """
    if not isinstance(law, ContactLaw):
        raise ValueError(f"law must be a ContactLaw (got {law!r})")
    if law is ContactLaw.HERTZ:
        return 0.0
    if law is ContactLaw.IMPACT:
        raise ValueError("the IMPACT law has no hysteresis factor: its damping is set by c_max")
    _warn_unverified(law)
    allow_zero, factor = _FACTORS[law]
    return factor(_restitution(restitution, allow_zero=allow_zero))


def normal_force(
    law: ContactLaw,
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_speed: ArrayLike | None,
    *,
    stiffness: float,
    restitution: float,
    exponent: float = 1.5,
    c_max: float | None = None,
    d_max: float | None = None,
) -> Force:
    """Normal contact force [N] of any `ContactLaw` (dispatch to the functions above).

    Args:
        law: the contact law.
        delta: penetration δ [m], any shape; F = 0 where δ <= 0.
        delta_dot: penetration rate δ̇ [m/s] (> 0 approaching).
        approach_speed: δ̇⁻ [m/s] > 0 for the dissipative laws; ignored (may be None) for
            HERTZ and IMPACT.
        stiffness: K [N/m^n], > 0.
        restitution: cₑ [-] (ignored by HERTZ and IMPACT).
        exponent: n [-], > 0.
        c_max: IMPACT's maximum damping [N s/m]; required for IMPACT only.
        d_max: IMPACT's full-damping penetration [m]; required for IMPACT only.

    Returns:
        Normal force [N] >= 0, broadcast shape of the inputs (float for scalars).

    Raises:
        ValueError: on an unknown law, a cylindrical law (`cylindrical_laws` gives those),
            IMPACT without c_max/d_max, or bad arguments.
    """
    if not isinstance(law, ContactLaw):
        raise ValueError(f"law must be a ContactLaw (got {law!r})")
    if law is ContactLaw.HERTZ:
        return hertz(delta, stiffness=stiffness, exponent=exponent)
    if law in CYLINDRICAL_LAWS:
        raise ValueError(
            f"the {law.value} law is a cylindrical law: its force needs the joint's radii, materials and "
            "bearing length, not a stiffness; use contact_calibration.cylindrical_laws.cylindrical_force"
        )
    if law is ContactLaw.IMPACT:
        c, d = _impact_params(c_max, d_max)
        return impact_law(delta, delta_dot, stiffness=stiffness, exponent=exponent, c_max=c, d_max=d)
    if approach_speed is None:
        raise ValueError(
            f"the {law.value} law needs approach_speed > 0 [m/s] (got None): the dissipative laws "
            "divide by the approach speed recorded at contact onset"
        )
    return _law(law, delta, delta_dot, approach_speed, stiffness, restitution, exponent)


def ambrosio_friction(
    normal_force: ArrayLike,
    tangential_velocity: ArrayLike,
    *,
    friction: float,
    v0: float = 1e-4,
    v1: float = 1e-3,
) -> Force:
    """Ambrósio's modified Coulomb friction: F_T = −μ c_d(|v_T|) F_N v_T/|v_T|.

    Ambrósio 2002 (docs/references.md) [checked]: c_d = 0 for |v_T| <= v₀, (|v_T| − v₀)/(v₁ − v₀)
    between, 1 above v₁. The defaults v₀ = 1e-4 m/s, v₁ = 1e-3 m/s are [recalled] values
    (another code uses 1e-3 and 5e-2 m/s). The law cannot stick: c_d = 0 at rest.

    Args:
        normal_force: F_N [N] >= 0, any shape.
        tangential_velocity: relative tangential velocity v_T [m/s], broadcast with F_N.
        friction: Coulomb coefficient μ [-], >= 0.
        v0: speed below which there is no friction [m/s], >= 0.
        v1: speed above which full friction acts [m/s], > v0.

    Returns:
        Tangential force F_T [N], signed, opposing v_T (float for scalars).

    Raises:
        ValueError: if friction < 0, or not 0 <= v0 < v1 (all finite).
    """
    mu = float(friction)
    if not (math.isfinite(mu) and mu >= 0):
        raise ValueError(f"friction must be >= 0 and finite (got {friction!r})")
    a, b = float(v0), float(v1)
    if not (math.isfinite(a) and math.isfinite(b) and 0 <= a < b):
        raise ValueError(f"v0 and v1 must satisfy 0 <= v0 < v1 [m/s] (got v0={v0!r}, v1={v1!r})")
    return _out(_friction(normal_force, tangential_velocity, mu, a, b))


def _friction(fn: ArrayLike, vt: ArrayLike, mu: float, v0: float, v1: float) -> np.ndarray:
    v = np.asarray(vt, dtype=float)
    cd = np.clip((np.abs(v) - v0) / (v1 - v0), 0.0, 1.0)
    return -mu * cd * np.asarray(fn, dtype=float) * np.sign(v) + 0.0  # + 0.0: no -0.0


def contact_omega(stiffness: float, penetration: float, mass: float) -> float:
    """Contact frequency ω = sqrt(k_t / m) [rad/s] of the Hertz spring at a penetration.

    k_t = 1.5 K sqrt(δ) is the tangent stiffness of K δ^1.5 at δ. Explicit contact stepping
    is stable for ω h < 2 (docs/mujoco_notes.md); the run and the retrofit check their time
    steps against it at the largest expected penetration.

    Args:
        stiffness: K [N/m^1.5].
        penetration: δ [m].
        mass: effective mass along the contact normal [kg].
    """
    return math.sqrt(1.5 * stiffness * math.sqrt(penetration) / mass)


GEAR_MESH_EXPONENT = 1.0
"""Exponent n of a gear mesh's torsional stop [-]: a tooth pair in contact is a line contact
whose load grows about linearly with its deflection, so the mesh is a linear torsional
spring (the mesh stiffness of gear standards is a constant per unit face width)."""


def mesh_torque(
    delta: ArrayLike,
    delta_dot: ArrayLike,
    approach_rate: ArrayLike,
    *,
    stiffness: float,
    restitution: float,
    exponent: float = GEAR_MESH_EXPONENT,
) -> Force:
    """Torque of a backlash stop, Lankarani–Nikravesh in angular form: T = K δⁿ [1 + 3(1 − cₑ²)/4 · δ̇/δ̇⁻].

    δ = |θ_load − θ_motor| − b [rad] is the angular penetration past the dead band of
    half-width b, δ̇ its rate [rad/s] (> 0 closing) and δ̇⁻ the closing rate at the stop's
    onset; K [N m/rad^n] the torsional mesh stiffness. The same law, hysteresis factor and
    clipping as `lankarani_nikravesh`, with torque for force and angle for length.

    Args:
        delta: angular penetration δ [rad], any shape; T = 0 where δ <= 0.
        delta_dot: its rate δ̇ [rad/s] (> 0 closing), broadcast with ``delta``.
        approach_rate: δ̇⁻ [rad/s], > 0, the closing rate at onset.
        stiffness: K [N m/rad^n], > 0.
        restitution: cₑ [-], [0, 1].
        exponent: n [-], > 0 (`GEAR_MESH_EXPONENT` = 1 for a gear mesh).

    Returns:
        Torque [N m] >= 0 (float for scalars).

    Raises:
        ValueError: if an argument is out of range.
    """
    return _law(ContactLaw.LANKARANI_NIKRAVESH, delta, delta_dot, approach_rate, stiffness, restitution, exponent)


def mesh_omega(stiffness: float, penetration: float, inertia: float, exponent: float = GEAR_MESH_EXPONENT) -> float:
    """Frequency ω = sqrt(k_t / J) [rad/s] of a backlash stop at an angular penetration.

    k_t = n K δ^(n−1) is the tangent stiffness of K δⁿ at δ [N m/rad] (K itself for the
    linear gear mesh, n = 1); J the effective inertia along the band [kg m^2]. Explicit
    stepping is stable for ω h < 2, as for `contact_omega`.

    Args:
        stiffness: K [N m/rad^n], > 0.
        penetration: δ [rad], > 0.
        inertia: J [kg m^2], > 0.
        exponent: n [-], > 0.
    """
    k = positive("stiffness", stiffness, "N m/rad^n")
    n = positive("exponent", exponent, "")
    d = positive("penetration", penetration, "rad")
    return math.sqrt(n * k * d ** (n - 1.0) / positive("inertia", inertia, "kg m^2"))
