"""Sizing and contact of every slider with play in a prepared model.

Sizing follows the journals' (`clearance.run.preparation.JointSizing`), per corner: the ideal
prismatic pair's normal force N and moment M over one drive cycle load a corner with about
|N|/2 + |M|/L (two corners share the force, the moment is a couple over the block's length);
the peak corner load, the corner's effective mass along the guide's normal
(`clearance.contact_calibration.effective_mass`) and the clearance give the impact speed
sqrt(2 F c / m), and the divergence bound is 4 x the Hertz penetration of that impact, at least
4 x that under the peak load, with the corner's stiffness K.

Contact: in the exact mode one instance of the compiled `clearance.slider_guide` contact per
slider (`clearance.contact_plugin.slider_guide.add_slider_guide`); in the ring modes the corner
pairs of the portable form get nominal or calibrated parameters
(`clearance.contact_calibration.corner_fit`).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from clearance.contact_calibration.effective_mass import EffectiveMass
from clearance.mjcf import BuiltModel
from clearance.mjcf.contact import apply_corner_contact
from clearance.mjcf.guide import guide_site, slider_site
from clearance.model import Mechanism
from clearance.options import ContactMode, ContactParameters, ModelOptions
from clearance.run.sizing import JointSizing, size_joint

__all__ = ["corner_loads", "slider_sizing", "add_slider_contacts", "guide_metadata"]


def corner_loads(mechanism: Mechanism, pairs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Each slider's corner load |N|/2 + |M|/L over the cycle [N] (module docstring).

    Args:
        mechanism: the mechanism.
        pairs: joint name -> (n, 2) multipliers of the ideal pairs (`clearance.loads`): for a
            prismatic pair (moment [N m], normal force [N]).
    """
    out = {}
    for j in mechanism.translational_joints:
        lam = pairs[j.name]
        out[j.name] = 0.5 * np.abs(lam[:, 1]) + np.abs(lam[:, 0]) / j.require_translational().slider_length
    return out


def slider_sizing(
    mechanism: Mechanism, loads: dict[str, np.ndarray], masses: dict[str, EffectiveMass]
) -> dict[str, JointSizing]:
    """Each slider's `JointSizing` from its corner loads [N] and corner effective masses (no segments).

    Args:
        mechanism: the mechanism.
        loads: slider -> (n,) corner load over the cycle [N] (`corner_loads`).
        masses: slider -> its corners' effective mass over the cycle.
    """
    return {
        j.name: size_joint(
            stiffness=j.require_translational().stiffness,
            loads=loads[j.name],
            clearance=j.require_translational().clearance,
            mass=masses[j.name],
            segments=0,
        )
        for j in mechanism.translational_joints
    }


def add_slider_contacts(
    built: BuiltModel,
    model: mujoco.MjModel,
    mechanism: Mechanism,
    sizing: dict[str, JointSizing],
    options: ModelOptions,
    params: dict[str, ContactParameters],
    name: Any,
) -> dict[str, dict[str, Any]]:
    """Give every slider with play its contact; returns each one's contact metadata.

    Args:
        built: the built model (its spec gets plugin instances or corner parameters).
        model: the compiled spec (the corner pairs' parameters are written into it too).
        mechanism: the mechanism.
        sizing: slider -> its sizing.
        options: model options (the contact mode).
        params: joint -> per-corner parameters given by the caller (ring modes only).
        name: joint name -> the compiled contact's name (`clearance.run.exact_contact_name`).

    Raises:
        CalibrationStabilityError: a corner's contact is unstable at the time step.
    """
    meta: dict[str, dict[str, Any]] = {}
    for j in mechanism.translational_joints:
        play = j.require_translational()
        if options.contact_mode is ContactMode.EXACT:
            from clearance.contact_plugin.slider_guide import SLIDER_PLUGIN_NAME, add_slider_guide

            add_slider_guide(
                built.spec, name=name(j.name), slider_site=slider_site(j.name), guide_site=guide_site(j.name), tc=play
            )
            meta[j.name] = {
                "law": play.law.value,
                "stiffness": play.stiffness,
                "exponent": 1.5,
                "restitution": play.restitution,
                "friction": play.friction,
                "source": f"exact: compiled plugin {SLIDER_PLUGIN_NAME}",
            }
            continue
        from clearance.contact_calibration.corner_fit import CornerContact, check_corner_stability, corner_parameters
        from clearance.contact_calibration.fit import CalibrationStabilityError

        s = sizing[j.name]
        try:
            if j.name in params:  # the caller's, checked on the lightest mass a row sees as a fit is
                contact = CornerContact(params[j.name], s.effective_mass)
                lightest = min(s.effective_mass, s.effective_mass_range[0])
                check_corner_stability(
                    contact, mass=lightest, timestep=options.timestep, max_penetration=s.penetration_limit
                )
            else:
                calibrated = options.contact_mode is ContactMode.CALIBRATED
                contact = corner_parameters(play, s, options, calibrated=calibrated)
        except CalibrationStabilityError as exc:
            raise CalibrationStabilityError(f"joint '{j.name}': {exc}") from None
        apply_corner_contact(built.spec, model, built.guides[j.name], contact.parameters)
        p = contact.parameters
        meta[j.name] = {
            "stiffness_per_corner": p.stiffness,
            "damping_per_corner": p.damping,
            "calibration_mass": contact.mass,
            "corner_radius": built.guides[j.name].corner_radius,
            "source": p.source,
        }
    return meta


def guide_metadata(mechanism: Mechanism) -> dict[str, dict[str, float]]:
    """Each slider's clearance, block size [m] and largest tilt [rad], as the reference records them."""
    return {
        j.name: {
            "clearance": j.require_translational().clearance,
            "slider_length": j.require_translational().slider_length,
            "slider_height": j.require_translational().slider_height,
            "max_tilt": j.require_translational().max_tilt,
        }
        for j in mechanism.translational_joints
    }
