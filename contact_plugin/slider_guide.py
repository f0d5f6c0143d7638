"""Add `clearance.slider_guide` plugin instances (a slider with play in its guide) to an MjSpec.

The compiled contact (contact_plugin/slider_guide.c, whose header is the full specification)
gives each of the slider's four corners the exact geometry against the guide's two lines, the
joint's point law and Ambrósio friction, with the journal bearing's in-step treatment. Every
attribute is validated here before anything is compiled.

Sensor block: `SLIDER_SENSOR_FIELDS` (24 values): per corner k (order of
`clearance.translational.CORNERS`) ``normal_force_k`` [N], ``tangential_force_k`` [N] (on the
slider along the guide), ``penetration_k`` [m], ``penetration_rate_k`` [m/s] (entering the law),
``approach_speed_k`` [m/s]; then ``contact_case`` (`clearance.translational.SliderContact`
code), ``potential_energy`` [J], ``dissipated_work`` [J], ``tilt`` [rad].
"""

from __future__ import annotations

import mujoco

from clearance.contact_calibration import laws
from clearance.contact_plugin.instances import add_instance, number_attribute, sensor_block, site_of
from clearance.model import CYLINDRICAL_LAWS, ContactLaw
from clearance.translational import TranslationalClearance

__all__ = ["SLIDER_PLUGIN_NAME", "SLIDER_SENSOR_FIELDS", "add_slider_guide", "slider_sensor_offsets"]

_WHAT = "slider-guide contact"

SLIDER_PLUGIN_NAME = "clearance.slider_guide"
"""The compiled slider-guide contact's plugin name."""

SLIDER_SENSOR_FIELDS: tuple[str, ...] = (
    *(
        f"{field}_{k}"
        for k in range(4)
        for field in ("normal_force", "tangential_force", "penetration", "penetration_rate", "approach_speed")
    ),
    "contact_case",
    "potential_energy",
    "dissipated_work",
    "tilt",
)
"""Names of the plugin sensor's values, in order (units in the module docstring)."""


def add_slider_guide(
    spec: mujoco.MjSpec,
    *,
    name: str,
    slider_site: str,
    guide_site: str,
    tc: TranslationalClearance,
    v0: float = 1e-4,
    v1: float = 1e-3,
    min_approach_speed: float = laws.MIN_APPROACH_SPEED,
    c_max: float | None = None,
    d_max: float | None = None,
) -> None:
    """Add one slider-guide contact (plugin instance + its sensor, both named ``name``).

    Args:
        spec: the model under construction; modified in place.
        name: name of the plugin instance and of its sensor (unique among both).
        slider_site: site at the block's centre on the slider body, its x axis along the
            block's length.
        guide_site: site on the guide body at the guide's centre line, its x axis along the
            guide, its z axis the plane's normal.
        tc: the joint's play (clearance, block size, corner stiffness, law, restitution,
            friction); a point law (the cylindrical laws are for a pin in a hole).
        v0: Ambrósio's no-friction speed [m/s], >= 0.
        v1: Ambrósio's full-friction speed [m/s], > v0.
        min_approach_speed: floor on the recorded approach speed [m/s], > 0.
        c_max: IMPACT's maximum damping [N s/m] (IMPACT only).
        d_max: IMPACT's full-damping penetration [m] (IMPACT only).

    Raises:
        TypeError: ``tc`` is not a `TranslationalClearance`.
        ValueError: naming the contact, the attribute, its value and what was expected (sites
            missing or on one body, a duplicate name, a cylindrical law, IMPACT without c_max
            and d_max, a number out of range).
        clearance.contact_plugin.PluginUnavailableError: installed without the compiled plugin.
    """
    if not isinstance(tc, TranslationalClearance):
        raise TypeError(f"slider-guide contact '{name}': tc must be a TranslationalClearance (got {tc!r})")
    if not isinstance(name, str) or not name:
        raise ValueError(f"slider-guide contact: name must be a non-empty string (got {name!r})")
    if any(p.name == name for p in spec.plugins) or spec.sensor(name) is not None:
        raise ValueError(f"slider-guide contact '{name}': the name is already used by a plugin or a sensor")
    slider = site_of(spec, name, "slider_site", slider_site, _WHAT)
    guide = site_of(spec, name, "guide_site", guide_site, _WHAT)
    if slider.parent.name == guide.parent.name:
        raise ValueError(
            f"slider-guide contact '{name}': slider_site and guide_site are on the same body "
            f"{slider.parent.name!r}; expected the slider's body and the guide's"
        )
    if tc.law in CYLINDRICAL_LAWS:
        raise ValueError(
            f"slider-guide contact '{name}': law '{tc.law.value}' is a law of a pin in a hole; a slider's "
            "corners take the point laws (hertz, lankarani_nikravesh, ...)"
        )
    config: dict[str, float | str] = {
        "slider_site": slider_site,
        "guide_site": guide_site,
        "clearance": tc.clearance,
        "slider_length": tc.slider_length,
        "slider_height": tc.slider_height,
        "law": tc.law.value,
        "stiffness": tc.stiffness,
        "exponent": 1.5,
        "friction": tc.friction,
        "v0": number_attribute(name, "v0", v0, ">= 0 [m/s]", lambda v: v >= 0, _WHAT),
        "min_approach_speed": number_attribute(
            name, "min_approach_speed", min_approach_speed, "> 0 [m/s]", lambda v: v > 0, _WHAT
        ),
    }
    low = float(config["v0"])
    config["v1"] = number_attribute(name, "v1", v1, f"> v0 = {low} [m/s]", lambda v: v > low, _WHAT)
    if tc.law not in (ContactLaw.HERTZ, ContactLaw.IMPACT):
        laws.hysteresis_factor(tc.law, tc.restitution)  # the per-law range of c_e; warns for HU_GUO
        config["restitution"] = tc.restitution
    if tc.law is ContactLaw.IMPACT:
        if c_max is None or d_max is None:
            raise ValueError(f"slider-guide contact '{name}': law IMPACT needs c_max [N s/m] and d_max [m]")
        config["c_max"] = number_attribute(name, "c_max", c_max, ">= 0 [N s/m]", lambda v: v >= 0, _WHAT)
        config["d_max"] = number_attribute(name, "d_max", d_max, "> 0 [m]", lambda v: v > 0, _WHAT)
    add_instance(spec, SLIDER_PLUGIN_NAME, name, config)


def slider_sensor_offsets(model: mujoco.MjModel, name: str) -> dict[str, int]:
    """Index in ``mjData.sensordata`` (and in rollout sensor arrays) of each sensor field.

    Args:
        model: a compiled model.
        name: the contact's name (as given to `add_slider_guide`).

    Returns:
        ``{field: index}`` for every field of `SLIDER_SENSOR_FIELDS`.

    Raises:
        ValueError: the model has no such slider-guide sensor.
    """
    return sensor_block(model, name, SLIDER_SENSOR_FIELDS, "slider-guide contact")
