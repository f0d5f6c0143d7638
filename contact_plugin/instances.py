"""What every compiled contact's Python side does alike: check an attribute, add an instance
with its sensor to an MjSpec, find a sensor's block in a compiled model.

The journal bearing (`clearance.contact_plugin.attributes`), the slider guide
(`clearance.contact_plugin.slider_guide`) and the backlash stop
(`clearance.contact_plugin.backlash_stop`) each validate their attributes in Python before
anything is compiled, then add one plugin instance and one plugin sensor of the same name.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco

from clearance.contact_plugin import require

__all__ = ["add_instance", "number_attribute", "sensor_block", "site_of"]


def number_attribute(
    contact: str, attribute: str, value: Any, expected: str, ok: Any, what: str = "journal-bearing contact"
) -> float:
    """``value`` as a float if finite and ``ok(value)``, else a ValueError saying what was expected.

    Args:
        contact: the contact's name, for the message.
        attribute: the attribute's name.
        value: the value given.
        expected: what was expected, in words (with the unit).
        ok: a predicate on the float.
        what: the kind of contact, for the message.

    Raises:
        ValueError: ``value`` not a finite number or ``ok`` false.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(float(value)):
        raise ValueError(f"{what} '{contact}': {attribute} must be a finite number {expected} (got {value!r})")
    v = float(value)
    if not ok(v):
        raise ValueError(f"{what} '{contact}': {attribute} must be {expected} (got {value!r})")
    return v


def site_of(
    spec: mujoco.MjSpec, contact: str, attribute: str, name: Any, what: str = "journal-bearing contact"
) -> mujoco.MjsSite:
    """The spec's site named ``name``, else a ValueError naming the contact and the attribute.

    Args:
        spec: the model under construction.
        contact: the contact's name, for the message.
        attribute: the attribute that names the site.
        name: the site's name.
        what: the kind of contact, for the message.

    Raises:
        ValueError: ``name`` not a non-empty string or no such site.
    """
    if not isinstance(name, str) or not name:
        raise ValueError(f"{what} '{contact}': {attribute} must be a site name (got {name!r})")
    site = spec.site(name)
    if site is None:
        raise ValueError(f"{what} '{contact}': {attribute} = {name!r} is not a site of the spec")
    return site


def add_instance(spec: mujoco.MjSpec, plugin_name: str, name: str, config: dict[str, Any]) -> None:
    """Add one instance of a compiled contact and its plugin sensor, both named ``name``.

    Args:
        spec: the model under construction.
        plugin_name: the plugin's registered name (``clearance.journal_bearing``, ...).
        name: the instance's and the sensor's name.
        config: the attributes, already checked: strings as they are, numbers written with
            ``repr`` (every digit of a float).

    Raises:
        PluginUnavailableError: the package was installed without its compiled library.
    """
    require()
    spec.activate_plugin(plugin_name)
    plugin = spec.add_plugin(name=name, plugin_name=plugin_name, active=True)
    plugin.config = {k: v if isinstance(v, str) else repr(float(v)) for k, v in config.items()}
    sensor = spec.add_sensor(name=name, type=mujoco.mjtSensor.mjSENS_PLUGIN)
    sensor.plugin = plugin


def sensor_block(model: mujoco.MjModel, name: str, fields: tuple[str, ...], what: str) -> dict[str, int]:
    """Index in ``mjData.sensordata`` (and in rollout sensor arrays) of each field of a compiled
    contact's sensor.

    Args:
        model: a compiled model.
        name: the contact's name (its sensor's).
        fields: the sensor's fields, in order.
        what: the kind of contact, for the message.

    Returns:
        ``{field: index}`` for every field of ``fields``.

    Raises:
        ValueError: the model has no plugin sensor of that name and length.
    """
    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
    if i < 0 or model.sensor_type[i] != mujoco.mjtSensor.mjSENS_PLUGIN or model.sensor_dim[i] != len(fields):
        raise ValueError(f"the model has no {what} sensor named {name!r}")
    adr = int(model.sensor_adr[i])
    return {field: adr + k for k, field in enumerate(fields)}
