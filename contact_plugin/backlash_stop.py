"""Add `clearance.backlash_stop` plugin instances to an MjSpec: the exact stop of a backlash band.

One instance per band closes the dead band ±b between a load hinge and a motor hinge on the
same axis with the gear mesh's impact law, `clearance.contact_calibration.laws.mesh_torque`
(angular Lankarani–Nikravesh, T = K δⁿ [1 + 3(1 − cₑ²)/4 · δ̇/δ̇⁻], δ = |q_load − q_motor| − b),
evaluated in C operation by operation and applied as passive torques (−s T on the load, +s T
on the motor, s the side of the band). The approach speed δ̇⁻ of each impact is kept in the
plugin's state; contact_plugin/backlash_stop.c's header is the full specification.

Every attribute is validated here, in Python, before anything is compiled (as
`clearance.contact_plugin.attributes` does for the journal bearing).

Sensor block: each instance gets one plugin sensor of 8 values, `SENSOR_FIELDS` in order:

====  ===================  ======  =========================================================
slot  field                unit    meaning
====  ===================  ======  =========================================================
0     torque               N m     T >= 0 of the law
1     load_torque          N m     −s T, the stop's torque on the load hinge
2     penetration          rad     δ = |q_load − q_motor| − b (negative: inside the band)
3     penetration_rate     rad/s   δ̇ entering the law (> 0 closing)
4     approach_speed       rad/s   δ̇⁻ of the current impact (0 out of contact)
5     potential_energy     J       K δ^(n+1)/(n+1) for δ > 0, else 0
6     dissipated_work      J       the law's damping work so far (>= 0)
7     impact_peak_torque   N m     largest T of the current impact, or of the last one
====  ===================  ======  =========================================================
"""

from __future__ import annotations

from typing import Any

import mujoco

from clearance.contact_calibration import laws
from clearance.contact_plugin.instances import add_instance, number_attribute, sensor_block

__all__ = ["PLUGIN_NAME", "SENSOR_FIELDS", "add_backlash_stop", "sensor_offsets"]

_WHAT = "backlash stop"

PLUGIN_NAME = "clearance.backlash_stop"
"""Name under which the library registers the backlash stop with MuJoCo."""

SENSOR_FIELDS: tuple[str, ...] = (
    "torque",
    "load_torque",
    "penetration",
    "penetration_rate",
    "approach_speed",
    "potential_energy",
    "dissipated_work",
    "impact_peak_torque",
)
"""Names of the plugin sensor's values, in order (units in the module docstring)."""


def _hinge(spec: mujoco.MjSpec, stop: str, attribute: str, name: Any) -> str:
    if not isinstance(name, str) or not name:
        raise ValueError(f"backlash stop '{stop}': {attribute} must be a hinge name (got {name!r})")
    joint = spec.joint(name)
    if joint is None or joint.type != mujoco.mjtJoint.mjJNT_HINGE:
        raise ValueError(f"backlash stop '{stop}': {attribute} = {name!r} is not a hinge of the spec")
    return name


def add_backlash_stop(
    spec: mujoco.MjSpec,
    *,
    name: str,
    load_joint: str,
    motor_joint: str,
    half_width: float,
    stiffness: float,
    restitution: float,
    exponent: float = laws.GEAR_MESH_EXPONENT,
    min_approach_speed: float = laws.MIN_APPROACH_SPEED,
) -> None:
    """Add one exact backlash stop (plugin instance + its sensor, both named ``name``).

    Args:
        spec: the model under construction; modified in place.
        name: name of the plugin instance and of its sensor (unique among both).
        load_joint: the load side's hinge (the link).
        motor_joint: the motor side's hinge on the same axis.
        half_width: b [rad], > 0.
        stiffness: K [N m/rad^n], > 0.
        restitution: cₑ [-], in [0, 1].
        exponent: n [-], > 0 (1 for a gear mesh).
        min_approach_speed: floor on the recorded approach speed δ̇⁻ [rad/s], > 0.

    Raises:
        ValueError: naming the stop, the attribute, its value and what was expected: a name
            already used, a joint that is not a hinge of the spec, the same hinge twice, a
            non-finite or out-of-range number.
        clearance.contact_plugin.PluginUnavailableError: if the package was installed without
            the compiled plugin (checked after the attributes).
    """
    if not isinstance(name, str) or not name:
        raise ValueError(f"backlash stop: name must be a non-empty string (got {name!r})")
    if any(p.name == name for p in spec.plugins) or spec.sensor(name) is not None:
        raise ValueError(
            f"backlash stop '{name}': name {name!r} is already used by a plugin instance or a sensor of the spec"
        )
    load = _hinge(spec, name, "load_joint", load_joint)
    motor = _hinge(spec, name, "motor_joint", motor_joint)
    if load == motor:
        raise ValueError(f"backlash stop '{name}': load_joint and motor_joint are both {load!r}; expected two hinges")
    config = {
        "load_joint": load,
        "motor_joint": motor,
        "half_width": number_attribute(name, "half_width", half_width, "> 0 [rad]", lambda v: v > 0, _WHAT),
        "stiffness": number_attribute(name, "stiffness", stiffness, "> 0 [N m/rad^n]", lambda v: v > 0, _WHAT),
        "exponent": number_attribute(name, "exponent", exponent, "> 0", lambda v: v > 0, _WHAT),
        "restitution": number_attribute(name, "restitution", restitution, "in [0, 1]", lambda v: 0 <= v <= 1, _WHAT),
        "min_approach_speed": number_attribute(
            name, "min_approach_speed", min_approach_speed, "> 0 [rad/s]", lambda v: v > 0, _WHAT
        ),
    }
    add_instance(spec, PLUGIN_NAME, name, config)


def sensor_offsets(model: mujoco.MjModel, name: str) -> dict[str, int]:
    """Index in ``mjData.sensordata`` (and in rollout sensor arrays) of each field of a stop's sensor.

    Args:
        model: a compiled model.
        name: the stop's name (as given to `add_backlash_stop`).

    Returns:
        ``{field: index}`` for every field of `SENSOR_FIELDS`.

    Raises:
        ValueError: if the model has no such plugin sensor.
    """
    return sensor_block(model, name, SENSOR_FIELDS, "backlash stop")
