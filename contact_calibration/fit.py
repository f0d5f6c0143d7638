"""Fit a ring bearing's per-row contact stiffness, damping and impedance shape to LN impacts.

The same radial impact is run in the one-bearing MuJoCo scene (`scene_impact.impact_scene`:
the joint's geoms, segment count, time step and small impedance) and in the point-mass
reference (`impact.clearance_impact` with the clearance's law, K = `laws.bearing_stiffness`
or a cylindrical law's geometry and length, cₑ and the effective mass), over a range of
impact speeds and a couple of directions. The per-row stiffness k [N/m], damping b [N s/m]
(emitted as direct-mode solref ``(-k Â, -b Â)``) and impedance rise ε (emitted as solimp
``(d(1 − ε), d, c, 0.5, 1)``: the row impedance rises linearly with the row's penetration
r from d(1 − ε) at r = 0 to d at r = c, the radial clearance;
`clearance.mjcf.contact.row_solimp`) minimise, with `scipy.optimize.least_squares`, the
residuals

    (F̂/F_LN − 1)/0.05, (δ̂/δ_LN − 1)/0.05, (T̂/T_LN − 1)/0.10, (ê − e_LN)/0.02

per speed and direction: each error divided by its accuracy goal, so the fit balances
the goals. e_LN is the LN impact's own restitution (slightly above cₑ), not cₑ. The fit
has two stages, as measured in benchmarks/ring_bounded_try.md: (log k, log b) at constant
impedance from the nominal values, then (log k, log b, ε) with 0 ≤ ε ≤ `EPS_MAX` from
ε = `EPS_START` and the first stage's k and b carried to full impedance.

Why ε: N linear rows already sum to a Hertz-like δ^1.5 spring, but the ring's static force
goes like δ^1.5/sqrt(c + δ) (the engaged arc is sqrt(2δ/(c + δ))), so it softens as δ/c
grows. MuJoCo's direct-mode row force is (d(r)/d)² k r + (d(r)/d) b ṙ, so an impedance
rising with r stiffens each row with its own penetration and undoes that softening (the
calibrated ring's first impacts in benchmarks/ring_bounded_try.md: from −3.6…−7.3 % to
−3.3…+0.4 %). What stays: the rows' summed damping grows like sqrt(δ)·δ̇ while LN's grows
like δ^1.5·δ̇/δ̇⁻, so with one b the dissipation per impact drifts with speed (1 − e ∝ v^0.2
roughly): the fit matches restitution in the middle of the range and misses it at the
ends (docs/mujoco_notes.md).

Stability: direct-mode solref is never clamped by MuJoCo, so `check_stability` verifies
ω·h < 2 (and the damped bound h²ω² + 2hβ < 4 of the semi-implicit step) at the largest
expected penetration and raises `CalibrationStabilityError` otherwise.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from clearance.contact_calibration.nominal import nominal_parameters
from clearance.contact_calibration.scene_impact import (
    DEFAULT_DIRECTIONS,
    SceneImpact,
    impact_scene,
    scene_impacts,
)
from clearance.mjcf.bearing import RingGeometry, ring_damping_coefficient, ring_force
from clearance.model import Clearance, ContactLaw
from clearance.options import ContactParameters, ModelOptions

if TYPE_CHECKING:
    from clearance.contact_calibration.impact import ImpactResult

__all__ = [
    "GOALS",
    "SpeedRow",
    "Stability",
    "CalibrationResult",
    "CalibrationStabilityError",
    "default_speeds",
    "reference_impacts",
    "evaluate",
    "accuracy_rows",
    "check_stability",
    "fit_contact",
    "fit_stages",
    "fit_speeds",
    "fitted_result",
    "speed_rows",
]

GOALS = {"peak_force": 0.05, "max_penetration": 0.05, "duration": 0.10, "restitution": 0.02}
"""Accuracy goals: relative for force, penetration and duration; absolute for restitution."""

FIT_VERSION = 2
"""Bumped whenever the fit's procedure changes (part of the calibration cache key).
2: the impedance rise ε fitted with k and b (1: k and b at constant impedance)."""

EPS_START = 0.2
"""Impedance rise ε the second stage starts from [-]: (1 + ε/(1 − ε) r/c)² ≈ 1 + r/(2c) ≈
sqrt(1 + r/c) at ε = 0.2, the ring's softening undone to first order."""

EPS_MAX = 0.9
"""Largest impedance rise ε [-]: d(1 − ε) stays at or above MuJoCo's minimum impedance 1e-4 at
the default d = 1e-3."""

SHAPE_MAX_NFEV = 80
"""Limit on the MuJoCo evaluations of the (log k, log b, ε) stage's least squares."""


class CalibrationStabilityError(ValueError):
    """Fitted contact parameters are unstable at the time step (ω·h too large)."""


@dataclass(frozen=True)
class SpeedRow:
    """Accuracy of the calibrated contact at one impact speed.

    Errors are MuJoCo against LN. ``*_err`` is the mean over directions, ``*_worst`` the
    direction with the largest magnitude (signed). Force, penetration and duration errors
    are relative [-]; restitution errors absolute [-].
    """

    speed: float
    ln_peak_force: float
    ln_max_penetration: float
    ln_duration: float
    ln_restitution: float
    peak_force_err: float
    peak_force_worst: float
    max_penetration_err: float
    max_penetration_worst: float
    duration_err: float
    duration_worst: float
    restitution_err: float
    restitution_worst: float

    def meets_goals(self) -> bool:
        """All four worst-direction errors within `GOALS`."""
        return (
            abs(self.peak_force_worst) <= GOALS["peak_force"]
            and abs(self.max_penetration_worst) <= GOALS["max_penetration"]
            and abs(self.duration_worst) <= GOALS["duration"]
            and abs(self.restitution_worst) <= GOALS["restitution"]
        )


@dataclass(frozen=True)
class Stability:
    """Explicit-step stability of the emitted contact at its largest expected penetration.

    Attributes:
        penetration: the penetration checked [m].
        tangent_stiffness: radial ring stiffness there [N/m].
        radial_damping: radial ring damping there [N s/m].
        omega_h: ω·h with ω = sqrt(k_t/m) [-]; must be < 2.
        damped_bound: h²ω² + 2hβ with β = c_t/m [-]; must be < 4.
    """

    penetration: float
    tangent_stiffness: float
    radial_damping: float
    omega_h: float
    damped_bound: float


@dataclass(frozen=True)
class CalibrationResult:
    """A fitted calibration and how well it reproduces LN.

    Attributes:
        parameters: the fitted per-row stiffness and damping (at full impedance) and
            impedance rise ε (``parameters.impedance_rise``).
        initial: the nominal parameters the fit started from.
        mass: effective mass fitted at [kg].
        mass_range: (min, max) effective mass over the cycle [kg]: the valid range.
        timestep: time step [s].
        speeds: fitted impact speeds [m/s].
        directions: impact directions [rad].
        rows: accuracy per speed.
        stability: stability check of ``parameters``.
        nfev: MuJoCo evaluations used by the fit.
        wall_time: fit time [s].
        meta: free-form provenance (MuJoCo version, law, solref mode, ...).
    """

    parameters: ContactParameters
    initial: ContactParameters
    mass: float
    mass_range: tuple[float, float]
    timestep: float
    speeds: tuple[float, ...]
    directions: tuple[float, ...]
    rows: tuple[SpeedRow, ...]
    stability: Stability
    nfev: int
    wall_time: float
    meta: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON-ready dict (inverse: `from_dict`)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> CalibrationResult:
        """Rebuild from `to_dict` output.

        Raises:
            KeyError, TypeError, ValueError: the dict is not a complete calibration.
        """
        return cls(
            parameters=ContactParameters(**d["parameters"]),
            initial=ContactParameters(**d["initial"]),
            mass=float(d["mass"]),
            mass_range=valid_mass_range(float(d["mass"]), d["mass_range"]),
            timestep=float(d["timestep"]),
            speeds=tuple(float(x) for x in d["speeds"]),
            directions=tuple(float(x) for x in d["directions"]),
            rows=tuple(SpeedRow(**r) for r in d["rows"]),
            stability=Stability(**d["stability"]),
            nfev=int(d["nfev"]),
            wall_time=float(d["wall_time"]),
            meta=dict(d["meta"]),
        )


def valid_mass_range(mass: float, mass_range: Sequence[float] | None) -> tuple[float, float]:
    """(min, max) effective mass [kg] a calibration is valid for: ``mass_range``, else ``mass`` alone.

    Raises:
        ValueError: ``mass_range`` is not a pair.
    """
    if not mass_range:
        return (float(mass), float(mass))
    if len(mass_range) != 2:
        raise ValueError(f"mass_range must be a pair (min, max) [kg] (got {mass_range!r})")
    return (float(mass_range[0]), float(mass_range[1]))


def default_speeds(impact_speed: float, n: int = 8) -> np.ndarray:
    """Log-spaced fit speeds [m/s] from impact_speed/50 to impact_speed (1.7 decades).

    For the default slider-crank (impact speed 5.6 m/s) that is 0.11–5.6 m/s.
    """
    if not (math.isfinite(impact_speed) and impact_speed > 0):
        raise ValueError(f"impact_speed must be positive and finite (got {impact_speed!r} m/s)")
    return np.geomspace(impact_speed / 50.0, impact_speed, n)


def reference_impacts(clearance: Clearance, *, mass: float, speeds: np.ndarray) -> list[ImpactResult]:
    """Point-mass impacts under the clearance's law at each speed (`impact.clearance_impact`:
    K = bearing stiffness for the point laws, the joint's geometry and length for the
    cylindrical ones).

    Raises:
        ValueError: for the IMPACT law (it needs c_max and d_max, not a restitution).
    """
    # here, not at import: the impact reference needs scipy.integrate (0.3 s to import), and a
    # run whose calibration is cached reads this module without fitting
    from clearance.contact_calibration.impact import clearance_impact

    if clearance.law is ContactLaw.IMPACT:
        raise ValueError("calibration against the IMPACT law is not supported (no c_max/d_max in Clearance)")
    return [clearance_impact(clearance, mass=mass, speed=float(v), n_samples=400) for v in speeds]


def _nstep(refs: list[ImpactResult], h: float) -> int:
    return int(math.ceil(2.5 * max(r.duration for r in refs) / h)) + 8


def _scene(
    ring: RingGeometry, options: ModelOptions, params: ContactParameters, mass: float, friction: float
) -> mujoco.MjModel:
    return impact_scene(ring, options, params, mass=mass, friction=friction)


def _errors(imp: SceneImpact, ref: ImpactResult) -> np.ndarray:
    return np.array(
        [
            imp.peak_force / ref.peak_force - 1.0,
            imp.max_penetration / ref.max_penetration - 1.0,
            imp.duration / ref.duration - 1.0,
            imp.restitution - ref.restitution,
        ]
    )


def evaluate(
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    params: ContactParameters,
    *,
    mass: float,
    speeds: np.ndarray,
    directions: np.ndarray | None = None,
    refs: list[ImpactResult] | None = None,
) -> tuple[np.ndarray, list[list[SceneImpact]], list[ImpactResult]]:
    """Run the MuJoCo impacts with ``params`` and compare them with the reference.

    Args:
        clearance: the joint's clearance (law, K, cₑ, friction).
        ring: ring geometry (segments, segment radius).
        options: model options (geoms, time step, impedance).
        params: per-row contact parameters (the impedance shape included).
        mass: effective mass [kg].
        speeds: (n_v,) impact speeds [m/s].
        directions: (n_d,) directions [rad]; default at a segment and between two.
        refs: reference impacts at ``speeds`` (computed when None).

    Returns:
        errors (n_v, n_d, 4) [F rel, δ rel, T rel, e abs], the MuJoCo impacts and the
        reference impacts.
    """
    speeds = np.asarray(speeds, dtype=float)
    if directions is None:
        directions = np.array(DEFAULT_DIRECTIONS) * 2 * math.pi / ring.segments
    refs = refs or reference_impacts(clearance, mass=mass, speeds=speeds)
    model = _scene(ring, options, params, mass, clearance.friction)
    imps = scene_impacts(
        model, ring, mass=mass, speeds=speeds, directions=np.asarray(directions), nstep=_nstep(refs, options.timestep)
    )
    err = np.array([[_errors(imp, ref) for imp in row] for row, ref in zip(imps, refs)])
    return err, imps, refs


def speed_rows(speeds: np.ndarray, err: np.ndarray, refs: list[ImpactResult]) -> tuple[SpeedRow, ...]:
    """One `SpeedRow` per speed from the errors (n_v, n_d, 4) of impacts against ``refs``."""
    out = []
    for v, e, r in zip(speeds, err, refs):
        mean = e.mean(axis=0)
        worst = e[np.argmax(np.abs(e), axis=0), np.arange(4)]
        out.append(
            SpeedRow(
                float(v),
                r.peak_force,
                r.max_penetration,
                r.duration,
                r.restitution,
                *(float(x) for pair in zip(mean, worst) for x in pair),
            )
        )
    return tuple(out)


def accuracy_rows(
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    params: ContactParameters,
    *,
    mass: float,
    speeds: np.ndarray,
    directions: np.ndarray | None = None,
) -> tuple[SpeedRow, ...]:
    """Accuracy of ``params`` against the reference at any ``speeds`` [m/s] (see `evaluate`)."""
    speeds = np.asarray(speeds, dtype=float)
    err, _, refs = evaluate(clearance, ring, options, params, mass=mass, speeds=speeds, directions=directions)
    return speed_rows(speeds, err, refs)


def check_stability(
    ring: RingGeometry,
    params: ContactParameters,
    *,
    mass: float,
    timestep: float,
    max_penetration: float,
    raise_error: bool = True,
) -> Stability:
    """Check that the emitted direct-mode contact is stable at ``timestep``.

    The ring's radial tangent stiffness k_t (numerical derivative of `ring_force`, the
    stiffest of the checked directions) and radial damping c_t at ``max_penetration``, each
    row at the impedance of its own penetration there (``impedance_rise``), give
    ω = sqrt(k_t/m) and β = c_t/m; the semi-implicit step of a spring-damper is stable for
    h²ω² + 2hβ < 4, which is ω·h < 2 without damping (docs/mujoco_notes.md).

    Args:
        ring: ring geometry.
        params: per-row stiffness and damping (at full impedance) and impedance rise.
        mass: effective mass [kg].
        timestep: h [s].
        max_penetration: largest expected penetration [m] (the run's divergence bound).
        raise_error: raise on instability (else only report).

    Returns:
        The stability record.

    Raises:
        CalibrationStabilityError: ω·h >= 2 or h²ω² + 2hβ >= 4 (when ``raise_error``).
    """
    d = max(float(max_penetration), 1e-12)
    psi = np.linspace(0.0, 2 * math.pi / ring.segments, 8, endpoint=False)
    u = np.stack([np.cos(psi), np.sin(psi)], axis=1)

    rise = params.impedance_rise

    def radial(depth: float) -> np.ndarray:
        f = ring_force(ring, (ring.radial_clearance + depth) * u, stiffness=params.stiffness, impedance_rise=rise)
        return -(f * u).sum(axis=1)

    eps = 1e-3 * d
    k_t = float(np.max((radial(d + eps) - radial(d - eps)) / (2 * eps)))
    c_t = params.damping * ring_damping_coefficient(ring, d, impedance_rise=rise)
    omega = math.sqrt(max(k_t, 0.0) / mass)
    h = float(timestep)
    st = Stability(d, k_t, c_t, omega * h, (omega * h) ** 2 + 2 * h * c_t / mass)
    if raise_error and (st.omega_h >= 2.0 or st.damped_bound >= 4.0):
        h_max = 2.0 / omega if omega > 0 else math.inf
        raise CalibrationStabilityError(
            f"calibrated contact (per-row stiffness {params.stiffness:.4g} N/m, damping "
            f"{params.damping:.4g} N s/m) is unstable at time step {h:g} s: omega*h = "
            f"{st.omega_h:.3f} (must be < 2), h^2 omega^2 + 2 h beta = {st.damped_bound:.3f} "
            f"(must be < 4) at penetration {d * 1e6:.2f} um (tangent stiffness {k_t:.4g} N/m, "
            f"effective mass {mass:.4g} kg). Use a time step below {h_max:.3g} s (ideally "
            f"below {0.1 * h_max / 2:.3g} s for accurate peaks)."
        )
    return st


def fit_stages(
    errors: Callable[[ContactParameters], np.ndarray],
    start: ContactParameters,
    *,
    n_residuals: int,
    max_nfev: int = 60,
    shape: bool = True,
) -> tuple[ContactParameters, list[str], int]:
    """The calibration's two least-squares stages for any impact scene (module docstring).

    Stage 1 fits (log k, log b) at constant impedance from ``start``; stage 2, with ``shape``,
    (log k, log b, ε) from ε = `EPS_START`, 0 <= ε <= `EPS_MAX`, the first stage's k and b
    carried to full impedance. Each residual is an error divided by its goal (`GOALS`).

    Args:
        errors: contact parameters -> (..., 4) errors [F rel, δ rel, T rel, e abs] of the
            scene's impacts against the reference; it raises RuntimeError for a diverged or
            failed scene (then every residual counts 1e3).
        start: the nominal parameters.
        n_residuals: how many errors ``errors`` returns (4 per impact).
        max_nfev: limit on stage 1's evaluations (stage 2's is `SHAPE_MAX_NFEV`).
        shape: run stage 2.

    Returns:
        (the fitted parameters with source "calibrated", the optimizer's messages, evaluations).
    """
    from scipy.optimize import least_squares  # here, not at import (see reference_impacts)

    scale = np.array([GOALS["peak_force"], GOALS["max_penetration"], GOALS["duration"], GOALS["restitution"]])
    nfev = 0

    def params_of(x: np.ndarray, source: str) -> ContactParameters:
        eps = min(max(float(x[2]), 0.0), EPS_MAX) if len(x) > 2 else 0.0  # least_squares keeps it inside
        return ContactParameters(float(np.exp(x[0])), float(np.exp(x[1])), source, eps)

    def residuals(x: np.ndarray) -> np.ndarray:
        nonlocal nfev
        nfev += 1
        try:
            err = errors(params_of(x, "fit"))
        except RuntimeError:
            return np.full(n_residuals, 1e3)  # diverged/failed: far off
        return (err / scale).ravel()

    # stage 1: (log k, log b) at constant impedance, from the nominal values
    x0 = np.log([start.stiffness, max(start.damping, 1e-9 * start.stiffness)])
    sol = least_squares(
        residuals, x0, method="trf", diff_step=1e-3, x_scale=1.0, max_nfev=max_nfev, xtol=1e-6, ftol=1e-8
    )
    messages = [f"(log k, log b): {sol.message}"]
    if shape:
        # stage 2: (log k, log b, eps); k and b are the rows' values at full impedance, so the
        # first stage's are carried there (its rows at constant impedance d(1 - eps0))
        first = params_of(sol.x, "fit")
        x1 = np.array(
            [
                math.log(first.stiffness / (1 - EPS_START) ** 2),
                math.log(first.damping / (1 - EPS_START)),
                EPS_START,
            ]
        )
        sol = least_squares(
            residuals,
            x1,
            bounds=([-np.inf, -np.inf, 0.0], [np.inf, np.inf, EPS_MAX]),
            method="trf",
            diff_step=1e-3,
            x_scale=1.0,
            max_nfev=SHAPE_MAX_NFEV,
            xtol=1e-6,
            ftol=1e-8,
        )
        messages.append(f"(log k, log b, eps): {sol.message}")
    return params_of(sol.x, "calibrated"), messages, nfev


def fit_contact(
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    *,
    mass: float,
    speeds: np.ndarray,
    mass_range: tuple[float, float] | None = None,
    max_penetration: float | None = None,
    directions: np.ndarray | None = None,
    max_nfev: int = 60,
    shape_impedance: bool = True,
) -> CalibrationResult:
    """Fit per-row stiffness, damping and impedance rise to the clearance's law over ``speeds``.

    Args:
        clearance: the joint's clearance (law, materials, cₑ, friction).
        ring: ring geometry (segment count and shape).
        options: model options (geom types, time step, impedance).
        mass: effective mass at the contact [kg] (the median over the cycle).
        speeds: (n_v,) impact speeds [m/s] (see `default_speeds`).
        mass_range: (min, max) effective mass over the cycle [kg]; stored as the valid
            range (default (mass, mass)).
        max_penetration: largest expected penetration for the stability check [m];
            default 4× the reference's at the highest speed.
        directions: impact directions [rad]; default at a segment and between two.
        max_nfev: limit on MuJoCo evaluations of the (log k, log b) stage's least squares
            (the (log k, log b, ε) stage's is `SHAPE_MAX_NFEV`).
        shape_impedance: fit the impedance rise ε too (the second stage; the calibrated
            mode's fit); False stops after the first stage, constant impedance (ε = 0).

    Returns:
        The calibration, with accuracy per speed.

    Raises:
        CalibrationStabilityError: the fitted parameters are unstable at the time step.
        ValueError: bad arguments (mass, speeds) or an unsupported law.
    """
    t0 = time.perf_counter()
    speeds = fit_speeds(mass, speeds)
    if directions is None:
        directions = np.array(DEFAULT_DIRECTIONS) * 2 * math.pi / ring.segments
    directions = np.asarray(directions, dtype=float)
    refs = reference_impacts(clearance, mass=mass, speeds=speeds)
    start = nominal_parameters(
        clearance, ring, effective_mass=mass, impact_speed=float(np.sqrt(speeds[0] * speeds[-1]))
    )
    n_res = len(speeds) * len(directions) * 4

    def errors(p: ContactParameters) -> np.ndarray:
        err, _, _ = evaluate(clearance, ring, options, p, mass=mass, speeds=speeds, directions=directions, refs=refs)
        return err

    params, messages, nfev = fit_stages(errors, start, n_residuals=n_res, max_nfev=max_nfev, shape=shape_impedance)
    err, _, _ = evaluate(clearance, ring, options, params, mass=mass, speeds=speeds, directions=directions, refs=refs)
    dmax = max_penetration if max_penetration is not None else 4 * refs[-1].max_penetration
    stab = check_stability(ring, params, mass=mass, timestep=options.timestep, max_penetration=dmax)
    solimp = "(d*(1-eps), d, c, 0.5, 1), eps = impedance_rise" if params.impedance_rise > 0 else None
    return fitted_result(
        params,
        start,
        mass=mass,
        mass_range=mass_range,
        options=options,
        speeds=speeds,
        directions=directions,
        rows=speed_rows(speeds, err, refs),
        stability=stab,
        nfev=nfev,
        started=t0,
        meta={"law": clearance.law.value, "optimizer": "least_squares: " + "; ".join(messages)}
        | ({"solimp": solimp} if solimp else {}),
    )


def fit_speeds(mass: float, speeds: np.ndarray) -> np.ndarray:
    """A fit's impact speeds, sorted, once ``mass`` and ``speeds`` are checked.

    Args:
        mass: the calibration mass [kg].
        speeds: (n_v,) impact speeds [m/s].

    Raises:
        ValueError: a mass that is not positive and finite, or fewer than two speeds or one that
            is not positive and finite.
    """
    if not (math.isfinite(mass) and mass > 0):
        raise ValueError(f"mass must be positive and finite (got {mass!r} kg)")
    out = np.sort(np.asarray(speeds, dtype=float))
    if out.ndim != 1 or len(out) < 2 or not np.all(np.isfinite(out) & (out > 0)):
        raise ValueError(f"speeds must be >= 2 positive finite values [m/s] (got {out!r})")
    return out


def fitted_result(
    params: ContactParameters,
    start: ContactParameters,
    *,
    mass: float,
    mass_range: tuple[float, float] | None,
    options: ModelOptions,
    speeds: np.ndarray,
    directions: np.ndarray,
    rows: tuple[SpeedRow, ...],
    stability: Stability,
    nfev: int,
    started: float,
    meta: Mapping[str, object],
) -> CalibrationResult:
    """A fit's `CalibrationResult`: its inputs, accuracy rows and stability, the time since
    ``started`` (`time.perf_counter`), and ``meta`` over the fields every fit records (MuJoCo's
    version, the emission, the impedance, the fit version and the residuals' goals)."""
    return CalibrationResult(
        parameters=params,
        initial=start,
        mass=float(mass),
        mass_range=valid_mass_range(mass, mass_range),
        timestep=options.timestep,
        speeds=tuple(float(v) for v in speeds),
        directions=tuple(float(d) for d in directions),
        rows=rows,
        stability=stability,
        nfev=nfev,
        wall_time=time.perf_counter() - started,
        meta={
            "mujoco": mujoco.__version__,
            "solref_mode": "direct (-k*A_hat, -b*A_hat)",
            "solimp": "(d, d, 0.001, 0.5, 2) as built",
            "impedance": options.impedance,
            "fit_version": FIT_VERSION,
            "residual_scale": GOALS,
        }
        | dict(meta),
    )
