"""Contact parameters of a slider's corners in the portable form: nominal and calibrated.

The portable form of a slider with play (`clearance.mjcf.guide`) makes each corner a sphere
against a guide plate: one contact row per touching corner, a physical spring-damper k [N/m],
b [N s/m] emitted as a ring's rows are (`clearance.mjcf.contact.apply_corner_contact`: solref
(-k Â, -b Â) at a small constant impedance). The corner's law (the joint's
`clearance.translational.TranslationalClearance`: K δ^1.5 with the law's hysteresis and cₑ) is
what it is calibrated against, as a ring is against its journal's.

What is the ring's (`clearance.contact_calibration.fit`, `.store`, `.scene_impact`): the emission,
the impact reference (`impact.law_impact` with the corner's K, law and cₑ), the effective mass
along the load (a corner row's along the guide's normal over the ideal cycle:
`effective_mass.cycle_effective_mass`), the fit speeds (`fit.default_speeds` of the sizing's
impact speed), the residuals and their goals (`fit.GOALS`), the least squares of (log k, log b)
(`fit.fit_stages`' first stage), the measured quantities of a MuJoCo impact
(`scene_impact.measure_impact`), the accuracy rows and the calibration files
(`store.load_calibration`, `store.save_calibration`: JSON keyed by every input).

What is new: the scene (one corner sphere of mass m on a slide across the guide, falling on a
plate, with the run's own pair: `clearance.mjcf.guide.add_corner_pair`); one row instead of a
ring, so no geometry makes the force Hertz-like: a single linear row cannot follow δ^1.5 over a
range of speeds (its peak force times penetration is m v² where the law's is 1.25 m v²), and no
impedance shape is fitted (the ring's ε corrects its ring's softening with depth, which one row
does not have); the nominal stiffness k = m v²/δ_ref² (the law impact's largest penetration
δ_ref at the sizing's impact speed v, undamped); and the mass a row's stability is checked at.
A corner's row sees very different masses: level on one side, each of the two rows carries half
the slider's landing mass (the calibration mass, along the load); tilted, one corner alone takes
the impact and turns the block (on the published slider-crank of Flores, Leine and Glocker
(2010), whose slider's J is 2.7e-6 kg m², 48 g against 1.1 g). A physical row keeps its k and b,
so the lone corner is damped far more than the law damps it (2.7 times critical there: its
impacts barely rebound) and its explicit damping bounds the step: the check is made at the
lightest corner alone, with the margin two corners of one side need when they rock the block
together (`check_corner_stability`), and that slider needs h <= 0.5-1 µs. Rows
normalised by the mass they see (nearly hard MuJoCo rows whose reference acceleration sets k/m
and b/m) kept the law's restitution at every mass but were tried and dropped: their stiffness
jumps when the slider goes from one corner to level with the rows pressed in, which gave energy
to the slider (a rebound of 1.2), and a resting corner chatters at the a0 h² scale.
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

import mujoco
import mujoco.rollout
import numpy as np

from clearance.contact_calibration.fit import (
    CalibrationResult,
    CalibrationStabilityError,
    Stability,
    default_speeds,
    fit_speeds,
    fit_stages,
    fitted_result,
    speed_rows,
    valid_mass_range,
)
from clearance.contact_calibration.scene_impact import SceneImpact, measure_impact
from clearance.contact_calibration.store import (
    CalibrationCacheWarning,
    calibration_path,
    fit_key,
    load_calibration,
    save_calibration,
)
from clearance.mjcf.guide import CORNER_RADIUS_FRACTION, add_corner_pair
from clearance.mjcf.probe import probe_spec
from clearance.model import ContactLaw
from clearance.options import ContactParameters, ModelOptions
from clearance.translational import TranslationalClearance

if TYPE_CHECKING:
    from clearance.contact_calibration.impact import ImpactResult
    from clearance.contact_calibration.store import Sizing

__all__ = [
    "CornerContact",
    "corner_reference_impacts",
    "corner_scene",
    "corner_impacts",
    "corner_errors",
    "nominal_corner_parameters",
    "check_corner_stability",
    "fit_corner",
    "corner_calibration_key",
    "corner_parameters",
]

_LEAD_STEPS = 2  # free-flight steps before first contact
_CORNER = 2  # the scene's corner: a lower one, above the -n plate


@dataclasses.dataclass(frozen=True)
class CornerContact:
    """A slider's per-corner contact: a row's stiffness and damping, and the mass fitted at.

    Attributes:
        parameters: the rows' stiffness k [N/m] and damping b [N s/m] (ε = 0).
        mass: the calibration mass m [kg] (the level landing's per row, along the load).
    """

    parameters: ContactParameters
    mass: float


def corner_reference_impacts(play: TranslationalClearance, *, mass: float, speeds: np.ndarray) -> list[ImpactResult]:
    """A corner's impacts under its law (K δ^1.5, the law's hysteresis, cₑ) at each speed.

    Raises:
        ValueError: for the IMPACT law (it needs c_max and d_max, not a restitution).
    """
    from clearance.contact_calibration.impact import law_impact  # scipy.integrate: only when fitting

    if play.law is ContactLaw.IMPACT:
        raise ValueError("calibration of a slider's corners against the IMPACT law is not supported")
    return [
        law_impact(
            play.law, mass=mass, speed=float(v), stiffness=play.stiffness, restitution=play.restitution, n_samples=400
        )
        for v in speeds
    ]


def corner_scene(
    play: TranslationalClearance, options: ModelOptions, contact: CornerContact, *, mass: float
) -> mujoco.MjModel:
    """One corner sphere of ``mass`` [kg] on a slide across the guide above its plate (compiled).

    The sphere (radius r = `clearance.mjcf.guide.CORNER_RADIUS_FRACTION` c) sits at the body's
    origin and the plate's top face at y = 0, so the penetration is r − y; the pair is the run's
    (`add_corner_pair`) with the run's emission, solref (−k Â, −b Â), Â = 1/m.
    """
    r = CORNER_RADIUS_FRACTION * play.clearance
    spec, body = probe_spec("corner_probe", "corner", options.timestep, mass=mass, axes=("y",))
    nocol = dict(contype=0, conaffinity=0, mass=0)
    thick = 0.25 * play.slider_height
    spec.worldbody.add_geom(
        name="corner__plate_neg", type=mujoco.mjtGeom.mjGEOM_BOX, size=[1.0, thick, 0.004], pos=[0, -thick, 0], **nocol
    )
    body.add_geom(name=f"corner__corner{_CORNER}_sphere", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[r, 0, 0], **nocol)
    add_corner_pair(spec, "corner", _CORNER, play.friction, options.impedance)
    model = spec.compile()
    p, a_hat = contact.parameters, float(model.body_invweight0[1, 0])
    model.pair_solref[:] = [-p.stiffness * a_hat, -p.damping * a_hat]
    return model


def corner_impacts(model: mujoco.MjModel, *, mass: float, speeds: np.ndarray, nstep: int) -> list[SceneImpact]:
    """Impacts of a compiled `corner_scene` at each speed [m/s], one batched rollout.

    Raises:
        RuntimeError: an impact did not separate within ``nstep`` steps, or MuJoCo warned.
    """
    speeds = np.asarray(speeds, dtype=float)
    h = float(model.opt.timestep)
    r = float(model.geom_size[1, 0])
    data = mujoco.MjData(model)
    kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
    init = np.zeros((len(speeds), mujoco.mj_stateSize(model, kind)))
    for k, v in enumerate(speeds):
        mujoco.mj_resetData(model, data)
        data.qpos[0] = r + _LEAD_STEPS * v * h
        data.qvel[0] = -v
        mujoco.mj_getState(model, data, init[k], kind)
    state, _ = mujoco.rollout.rollout(model, data, init, nstep=nstep)
    state = np.concatenate([init[:, None, :], state], axis=1)
    if not np.all(np.isfinite(state)) or int(data.warning.number.sum()) > 0:
        raise RuntimeError("the MuJoCo corner impact diverged: the contact parameters are unstable at this time step")
    y, vy = state[..., 1], state[..., 2]
    return [measure_impact(y[k] - r, r - y[k], -vy[k], mass=mass, h=h, speed=float(v)) for k, v in enumerate(speeds)]


def corner_errors(
    play: TranslationalClearance,
    options: ModelOptions,
    contact: CornerContact,
    *,
    mass: float,
    refs: list[ImpactResult],
) -> np.ndarray:
    """(n_v, 1, 4) errors [F rel, δ rel, T rel, e abs] of the scene's impacts against ``refs``.

    Raises:
        RuntimeError: a diverged or unseparated impact.
    """
    nstep = int(math.ceil(2.5 * max(r.duration for r in refs) / options.timestep)) + 8
    speeds = np.array([r.approach_speed for r in refs])
    imps = corner_impacts(corner_scene(play, options, contact, mass=mass), mass=mass, speeds=speeds, nstep=nstep)
    return np.array(
        [
            [
                [
                    i.peak_force / r.peak_force - 1.0,
                    i.max_penetration / r.max_penetration - 1.0,
                    i.duration / r.duration - 1.0,
                    i.restitution - r.restitution,
                ]
            ]
            for i, r in zip(imps, refs)
        ]
    )


def nominal_corner_parameters(play: TranslationalClearance, *, mass: float, impact_speed: float) -> ContactParameters:
    """A corner row's stiffness and damping from formulas (module docstring), ε = 0.

    k = m v² / δ_ref², the law impact's largest penetration δ_ref at v = ``impact_speed``
    reached by an undamped linear row; b the damping for which the closed-form row
    (max(k δ + b δ̇, 0)) rebounds with the law impact's restitution there, as the ring's
    nominal damping is found.

    Args:
        play: the slider's play (law, K, cₑ).
        mass: a corner's effective mass [kg].
        impact_speed: v [m/s].
    """
    from scipy.optimize import brentq

    from clearance.contact_calibration.impact import simulate_impact

    ref = corner_reference_impacts(play, mass=mass, speeds=np.array([impact_speed]))[0]
    k = mass * impact_speed**2 / ref.max_penetration**2
    if ref.restitution >= 1.0 - 1e-9:
        return ContactParameters(k, 0.0, "nominal")

    def miss(b: float) -> float:
        def force(d: Any, dd: Any, _v: float) -> Any:
            return np.maximum(k * np.maximum(d, 0.0) + b * np.asarray(dd, dtype=float), 0.0)

        return simulate_impact(force, mass=mass, speed=impact_speed).restitution - ref.restitution

    b_hi = 2.0 * math.sqrt(k * mass)  # critical damping bounds the search
    return ContactParameters(k, brentq(miss, 0.0, b_hi, xtol=b_hi * 1e-6), "nominal")


def check_corner_stability(
    contact: CornerContact, *, mass: float, timestep: float, max_penetration: float, raise_error: bool = True
) -> Stability:
    """Explicit-step stability of a slider's corner rows on ``mass`` [kg]: ω² = k/m, β = b/m,
    stable for h²ω² + 2hβ < 2.

    One row alone is stable for h²ω² + 2hβ < 4 (`clearance.contact_calibration.fit.check_stability`).
    The two corners of one side, both pressed, act together on the slider's tilt, whose inertia
    over (L/2)² is the lone corner's mass: that mode's ω² and β are twice one row's, so the
    bound is halved. Measured on the published slider-crank of Flores, Leine and Glocker (2010),
    without friction: at h²ω² + 2hβ = 3.6 (nominal rows, 1 µs) and 3.8 (calibrated, 2 µs) the
    slider rocks by 1.3-1.6 mrad within 60 ms where the reference stays level, its corners
    chattering (40 and 64 onsets against 20); at 2.8 and below it stays level
    (benchmarks/translational_clearance_mujoco.md).

    Args:
        contact: the corner contact.
        mass: the mass checked [kg]: the lightest a row sees (a corner alone).
        timestep: h [s].
        max_penetration: the penetration recorded with the check [m] (a linear row's stability
            does not depend on it).
        raise_error: raise on instability (else only report).

    Raises:
        CalibrationStabilityError: unstable (when ``raise_error``).
    """
    p = contact.parameters
    omega = math.sqrt(p.stiffness / mass)
    beta = p.damping / mass
    h = float(timestep)
    st = Stability(float(max_penetration), p.stiffness, p.damping, omega * h, (omega * h) ** 2 + 2 * h * beta)
    if raise_error and st.damped_bound >= 2.0:  # implies omega h < 1.42
        h_max = (math.sqrt(beta * beta + 2.0 * omega * omega) - beta) / (omega * omega)  # h²ω² + 2hβ = 2
        raise CalibrationStabilityError(
            f"slider corner contact (stiffness {p.stiffness:.4g} N/m, damping {p.damping:.4g} N s/m) is unstable "
            f"at time step {h:g} s on a corner of {mass:.3g} kg: h^2 omega^2 + 2 h beta = {st.damped_bound:.3f} "
            f"(must be < 2, two corners rocking the block together); use a time step below {h_max:.3g} s"
        )
    return st


def fit_corner(
    play: TranslationalClearance,
    options: ModelOptions,
    *,
    mass: float,
    speeds: np.ndarray,
    mass_range: tuple[float, float] | None = None,
    max_penetration: float | None = None,
) -> CalibrationResult:
    """Fit a corner row's stiffness, damping and impedance rise to its law over ``speeds``.

    Args:
        play: the slider's play (law, K, cₑ, friction).
        options: model options (time step, impedance).
        mass: a corner's effective mass [kg] (median over the cycle).
        speeds: (n_v,) impact speeds [m/s], >= 2 (`clearance.contact_calibration.fit.default_speeds`).
        mass_range: (min, max) effective mass over the cycle [kg] (the valid range).
        max_penetration: largest expected penetration for the stability check [m]; default 4x
            the reference's at the top speed.

    Returns:
        The calibration (its ``mass`` is the mass the rows are emitted at).

    Raises:
        CalibrationStabilityError: the fitted row is unstable at the time step.
        ValueError: bad mass or speeds, or the IMPACT law.
    """
    t0 = time.perf_counter()
    speeds = fit_speeds(mass, speeds)
    refs = corner_reference_impacts(play, mass=mass, speeds=speeds)
    start = nominal_corner_parameters(play, mass=mass, impact_speed=float(np.sqrt(speeds[0] * speeds[-1])))

    def errors(p: ContactParameters) -> np.ndarray:
        return corner_errors(play, options, CornerContact(p, mass), mass=mass, refs=refs)

    params, messages, nfev = fit_stages(errors, start, n_residuals=4 * len(speeds), shape=False)
    err = errors(params)
    dmax = max_penetration if max_penetration is not None else 4 * refs[-1].max_penetration
    low = valid_mass_range(mass, mass_range)[0]
    stab = check_corner_stability(
        CornerContact(params, mass), mass=min(mass, low), timestep=options.timestep, max_penetration=dmax
    )
    return fitted_result(
        params,
        start,
        mass=mass,
        mass_range=mass_range,
        options=options,
        speeds=speeds,
        directions=np.zeros(1),
        rows=speed_rows(speeds, err, refs),
        stability=stab,
        nfev=nfev,
        started=t0,
        meta={
            "contact": "slider corner",
            "law": play.law.value,
            "optimizer": "least_squares: " + "; ".join(messages),
        },
    )


def corner_calibration_key(
    play: TranslationalClearance,
    options: ModelOptions,
    *,
    mass: float,
    mass_range: tuple[float, float],
    speeds: np.ndarray,
) -> dict[str, Any]:
    """Everything a corner calibration depends on (`clearance.contact_calibration.store`'s rules:
    the effective masses rounded to `MASS_DIGITS` significant figures)."""

    return {
        "contact": "slider corner",
        "clearance": float(play.clearance),
        "corner_radius": float(CORNER_RADIUS_FRACTION * play.clearance),
        "stiffness": float(play.stiffness),
        "law": play.law.value,
        "restitution": float(play.restitution),
        "friction": float(play.friction),
    } | fit_key(options, mass=mass, mass_range=mass_range, speeds=speeds)


def corner_parameters(
    play: TranslationalClearance, sizing: Sizing, options: ModelOptions, *, calibrated: bool
) -> CornerContact:
    """A slider's corner contact for a run: nominal, or calibrated and cached like a ring's.

    Args:
        play: the slider's play.
        sizing: its sizing (a corner's effective mass and range [kg], impact speed [m/s],
            penetration limit [m]).
        options: model options.
        calibrated: fit (or reuse the stored fit) instead of the nominal formulas.

    Raises:
        CalibrationStabilityError: the contact is unstable at the time step on the lightest mass a
            row sees (a corner alone: the minimum of the sizing's effective-mass range).
    """
    m, v = float(sizing.effective_mass), float(sizing.impact_speed)
    lightest = min(m, float(sizing.effective_mass_range[0]))  # a corner alone
    if not calibrated:
        contact = CornerContact(nominal_corner_parameters(play, mass=m, impact_speed=v), m)
    else:
        speeds = default_speeds(v)
        mrange = valid_mass_range(m, sizing.effective_mass_range)
        key = corner_calibration_key(play, options, mass=m, mass_range=mrange, speeds=speeds)
        result = load_calibration(key)
        path: Path | None = calibration_path(key)
        if result is None:
            result = fit_corner(
                play, options, mass=m, speeds=speeds, mass_range=mrange, max_penetration=sizing.penetration_limit
            )
            try:
                save_calibration(key, result)
            except OSError as exc:
                warnings.warn(
                    f"could not store the corner calibration in {path} ({exc}); using it without caching it",
                    CalibrationCacheWarning,
                    stacklevel=2,
                )
                path = None
        source = f"calibrated: {path or 'not cached'}"
        contact = CornerContact(dataclasses.replace(result.parameters, source=source), result.mass)
    check_corner_stability(contact, mass=lightest, timestep=options.timestep, max_penetration=sizing.penetration_limit)
    return contact
