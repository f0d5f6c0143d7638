"""Contact parameters of a retrofitted bearing, and their writing into its pairs.

The parameters come from `clearance.contact_calibration` exactly as a mechanism's ring gets
them in `clearance.run.preparation`: nominal (closed form) or calibrated (fitted to the
contact law's impacts at the bearing's effective mass, impact speeds from
impact_speed / 50 to impact_speed, the time step and the ring's geoms and segments; stored
and reused). They are written as `clearance.mjcf.contact.apply_contact` writes them:
direct-mode solref (-k Â, -b Â), Â the contact rows' approximate inverse inertia (the two
bodies' ``body_invweight0`` translational terms at qpos0), and the impedance rise's solimp.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import mujoco

from clearance.contact_calibration.fit import CalibrationResult
from clearance.contact_calibration.nominal import nominal_parameters
from clearance.contact_calibration.store import calibrate
from clearance.mjcf.bearing import RingGeometry
from clearance.mjcf.contact import row_solimp
from clearance.model import Clearance
from clearance.options import ContactMode, ContactParameters, ModelOptions
from clearance.retrofit.sizing import PlaySizing

__all__ = ["PlayContact", "play_contact", "row_inverse_weight", "write_pair_contact"]


@dataclass(frozen=True)
class PlayContact:
    """Contact parameters of one bearing and where they come from.

    Attributes:
        parameters: per-row stiffness, damping and impedance rise.
        calibration: the fit (calibrated mode), with its accuracy per speed; None when nominal.
        file: the stored calibration (None when nominal or not stored).
    """

    parameters: ContactParameters
    calibration: CalibrationResult | None = None
    file: Path | None = None


def play_contact(
    clearance: Clearance,
    ring: RingGeometry,
    sizing: PlaySizing,
    options: ModelOptions,
    *,
    use_cache: bool = True,
) -> PlayContact:
    """The bearing's contact parameters in ``options.contact_mode`` (nominal or calibrated).

    Raises:
        CalibrationStabilityError: the fitted contact is unstable at the time step.
        ValueError: a contact law that cannot be calibrated (IMPACT).
    """
    if options.contact_mode is ContactMode.NOMINAL:
        return PlayContact(nominal_parameters(clearance, ring, effective_mass=sizing.effective_mass))
    result, path = calibrate(
        clearance,
        ring,
        options,
        mass=sizing.effective_mass,
        impact_speed=sizing.impact_speed,
        mass_range=sizing.effective_mass_range,
        max_penetration=sizing.penetration_limit,
        use_cache=use_cache,
    )
    params = dataclasses.replace(result.parameters, source=f"calibrated: {path or 'not cached'}")
    return PlayContact(params, result, path)


def row_inverse_weight(model: mujoco.MjModel, journal_body: int, bearing_body: int) -> float:
    """Â [1/kg] of the contact rows between two bodies (translational ``body_invweight0`` terms)."""
    return float(model.body_invweight0[journal_body, 0] + model.body_invweight0[bearing_body, 0])


def write_pair_contact(
    pairs: Sequence[mujoco.MjsPair],
    params: ContactParameters,
    a_hat: float,
    radial_clearance: float,
) -> None:
    """Set the pairs' direct-mode solref (-k Â, -b Â) and, with an impedance rise, their solimp."""
    solref = [-params.stiffness * a_hat, -params.damping * a_hat]
    for pair in pairs:
        pair.solref = solref
        solimp = row_solimp(params, float(pair.solimp[1]), radial_clearance)
        if solimp is not None:
            pair.solimp = solimp
