"""The energy meter: MuJoCo's energy sensors and the `clearance.work` plugin, added to an MjSpec.

MuJoCo measures the kinetic energy (½ v'Mv, armature included) and the potential energy
(gravity and springs) with its own sensors, but has no sensor for the work of the forces
that change them. The `clearance.work` engine plugin (``contact_plugin/work_meter.c``,
whose comment is its specification) integrates, once per step, the work done on the model by
each kind of force: actuators, equality constraint rows (``connect`` loop closures), contact
constraint rows (the ring bearings), other constraint rows (limits, friction loss), MuJoCo's
own dampers, and the passive forces of engine plugins (the compiled contacts). With these, an
energy balance closes from sensor rows of ``mujoco.rollout``, with no Python per step.

Sensors added by `add_energy_meter` (names with the prefix ``energy__``):

=========================  ======================================================
sensor                     value
=========================  ======================================================
``energy__kinetic``        kinetic energy [J] (mjSENS_E_KINETIC)
``energy__potential``      gravity (and spring) potential energy [J]
                           (mjSENS_E_POTENTIAL)
``energy__work``           `WORK_FIELDS`, 8 values (plugin sensor)
=========================  ======================================================

Work done on the model is positive. Sensor row i of a rollout (the state at t_i) holds the
works of steps 0 .. i-1, i.e. the work from t_0 to t_i.
"""

from __future__ import annotations

import mujoco

from clearance.contact_plugin import require

__all__ = [
    "KINETIC_SENSOR",
    "POTENTIAL_SENSOR",
    "WORK_FIELDS",
    "WORK_PLUGIN_NAME",
    "WORK_SENSOR",
    "add_energy_meter",
    "energy_sensor_addresses",
    "has_energy_meter",
]

WORK_PLUGIN_NAME = "clearance.work"
"""Name under which the library registers the work plugin with MuJoCo."""

KINETIC_SENSOR = "energy__kinetic"
POTENTIAL_SENSOR = "energy__potential"
WORK_SENSOR = "energy__work"
"""Names of the meter's sensors (and of its plugin instance: `WORK_SENSOR`)."""

WORK_FIELDS: tuple[str, ...] = (
    "actuator_work",
    "equality_work",
    "contact_work",
    "other_constraint_work",
    "damper_work",
    "plugin_passive_work",
    "constraint_power",
    "steps",
)
"""Values of the work sensor, in order: six works from t_0 [J] (actuators; equality, contact and
other constraint rows; MuJoCo's dampers, fluid, adhesion and gravity compensation; passive
forces of engine plugins), the constraint power Σ efc_force·efc_vel at the row's state [W] and
the number of steps recorded."""


def add_energy_meter(spec: mujoco.MjSpec) -> None:
    """Add the kinetic and potential energy sensors and the work plugin to a spec.

    Args:
        spec: the model under construction (modified in place), without a meter yet.

    Raises:
        ValueError: if the spec already has a sensor or plugin instance of the meter's names.
        clearance.contact_plugin.PluginUnavailableError: if the package was installed without the
            compiled plugin library.
    """
    for name in (KINETIC_SENSOR, POTENTIAL_SENSOR, WORK_SENSOR):
        if spec.sensor(name) is not None or any(p.name == name for p in spec.plugins):
            raise ValueError(f"the spec already has a sensor or plugin named {name!r}: it has an energy meter")
    require()
    spec.add_sensor(name=KINETIC_SENSOR, type=mujoco.mjtSensor.mjSENS_E_KINETIC)
    spec.add_sensor(name=POTENTIAL_SENSOR, type=mujoco.mjtSensor.mjSENS_E_POTENTIAL)
    spec.activate_plugin(WORK_PLUGIN_NAME)
    plugin = spec.add_plugin(name=WORK_SENSOR, plugin_name=WORK_PLUGIN_NAME, active=True)
    sensor = spec.add_sensor(name=WORK_SENSOR, type=mujoco.mjtSensor.mjSENS_PLUGIN)
    sensor.plugin = plugin


def has_energy_meter(model: mujoco.MjModel) -> bool:
    """Whether a compiled model carries the energy meter of `add_energy_meter`."""
    return all(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, n) >= 0 for n in (KINETIC_SENSOR, WORK_SENSOR))


def energy_sensor_addresses(model: mujoco.MjModel) -> dict[str, int]:
    """Index in a sensordata row of the kinetic and potential energy and of every `WORK_FIELDS` value.

    Args:
        model: a compiled model with the energy meter.

    Returns:
        ``{"kinetic": i, "potential": j, <work field>: k, ...}``.

    Raises:
        ValueError: if the model has no energy meter.
    """
    ids = {n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, n) for n in (KINETIC_SENSOR, POTENTIAL_SENSOR)}
    work = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, WORK_SENSOR)
    if min(*ids.values(), work) < 0 or model.sensor_dim[work] != len(WORK_FIELDS):
        raise ValueError("the model has no energy meter (clearance.contact_plugin.energy.add_energy_meter)")
    out = {
        "kinetic": int(model.sensor_adr[ids[KINETIC_SENSOR]]),
        "potential": int(model.sensor_adr[ids[POTENTIAL_SENSOR]]),
    }
    adr = int(model.sensor_adr[work])
    out.update({field: adr + k for k, field in enumerate(WORK_FIELDS)})
    return out
