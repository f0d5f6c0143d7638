"""Add `clearance.journal_bearing` plugin instances to an MjSpec, and read their outputs.

Every attribute is validated here, in Python, before anything is compiled: the plugin's C
``init`` runs inside ``mj_makeData`` (during ``MjSpec.compile`` and again for every
``MjData``, possibly inside rollout threads), where an error can only surface as MuJoCo's
"plugin->init failed". The C code re-checks the same ranges, but it must never be the place a
user error is first found.

Sensor block: each instance gets one plugin sensor of 10 values, `SENSOR_FIELDS` in order:

====  =====================  ======  ====================================================
slot  field                  unit    meaning
====  =====================  ======  ====================================================
0     normal_force           N       F_n >= 0 of the contact law
1     tangential_force       N       F_t on the journal along t = z x n (Ambrósio)
2     penetration            m       δ = |e| − c (negative: gap)
3     penetration_rate       m/s     δ̇ entering the law (> 0 approaching): the step's mean rate
4     approach_speed         m/s     δ̇⁻ of the current impact (0 out of contact)
5     potential_energy       J       K δ^(n+1)/(n+1) for δ > 0, else 0
6     dissipated_work        J       normal damping + friction work so far (>= 0)
7     eccentricity           m       |e|, journal centre from bearing centre, in plane
8     film_normal_force      N       a lubricated joint's film force on the journal along n
                                     (negative: towards the centre); 0 for a dry joint
9     film_tangential_force  N       the film force on the journal along t; 0 for a dry joint
====  =====================  ======  ====================================================

Plugin state: `STATE_FIELDS` (11 values), then 2 ``nv`` values (the last step's velocity change
from every force but the joint's own, and its whole velocity change), per instance in
``mjData.plugin_state`` (part of
``mjSTATE_PLUGIN``); see journal_bearing.c's header for their use.
"""

from __future__ import annotations

import math

import mujoco

from clearance.contact_calibration import laws
from clearance.contact_calibration.cylindrical_laws import CylinderLaw, cylinder_law
from clearance.contact_plugin import PLUGIN_NAME
from clearance.contact_plugin.instances import add_instance, number_attribute, sensor_block, site_of
from clearance.lubrication import Lubrication
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw

__all__ = [
    "COMPILED_LAWS",
    "require_compiled_law",
    "SENSOR_FIELDS",
    "STATE_FIELDS",
    "add_for_clearance",
    "add_journal_bearing",
    "sensor_address",
    "sensor_offsets",
    "state_address",
    "state_size",
]

SENSOR_FIELDS: tuple[str, ...] = (
    "normal_force",
    "tangential_force",
    "penetration",
    "penetration_rate",
    "approach_speed",
    "potential_energy",
    "dissipated_work",
    "eccentricity",
    "film_normal_force",
    "film_tangential_force",
)
"""Names of the plugin sensor's values, in order (units in the module docstring)."""

STATE_FIELDS: tuple[str, ...] = (
    "sample_time",
    "sample_penetration",
    "sample_rate",
    "sample_friction_force",
    "has_sample",
    "in_contact",
    "approach_speed",
    "dissipated_work",
    "steps",
    "sample_geometric_rate",
    "sample_film_rate",
)
"""Names of one instance's first values in ``mjData.plugin_state``, in order; two blocks of ``nv``
more follow (`state_size`): the last step's velocity change from every force but the joint's
own, then its whole velocity change."""

COMPILED_LAWS: tuple[ContactLaw, ...] = tuple(ContactLaw)
"""The laws the compiled contact knows (``kLawNames`` of contact_laws.c, codes in `ContactLaw`
order): all of them, the point laws and the cylindrical ones. A law added to `ContactLaw` before
its port is refused before anything is compiled (`require_compiled_law`)."""

_DISSIPATIVE = (
    ContactLaw.LANKARANI_NIKRAVESH,
    ContactLaw.HUNT_CROSSLEY,
    ContactLaw.FLORES,
    ContactLaw.GONTHIER,
    ContactLaw.HU_GUO,
)


def require_compiled_law(law: ContactLaw, joint: str) -> None:
    """Refuse a law the compiled contact does not know yet, in one line naming the joint.

    Args:
        law: the joint's law.
        joint: the joint (or contact) name, for the message.

    Raises:
        ValueError: ``law`` is not in `COMPILED_LAWS`.
    """
    if law not in COMPILED_LAWS:
        raise ValueError(
            f"joint '{joint}': law '{law.value}' is not in the compiled exact contact yet (it knows "
            f"{', '.join(m.value for m in COMPILED_LAWS)}); run it with contact_mode 'nominal' or 'calibrated', "
            "or in the reference solver"
        )


def add_journal_bearing(
    spec: mujoco.MjSpec,
    *,
    name: str,
    journal_site: str,
    bearing_site: str,
    clearance: float,
    journal_radius: float,
    law: ContactLaw,
    stiffness: float,
    exponent: float = 1.5,
    restitution: float | None = None,
    c_max: float | None = None,
    d_max: float | None = None,
    friction: float = 0.0,
    v0: float = 1e-4,
    v1: float = 1e-3,
    min_approach_speed: float = laws.MIN_APPROACH_SPEED,
    lubrication: Lubrication | None = None,
    bearing_length: float | None = None,
    cylinder: CylinderLaw | None = None,
) -> None:
    """Add one journal–bearing contact (plugin instance + its sensor, both named ``name``).

    The journal site must sit at the journal centre on the journal body, the bearing site at
    the bearing centre on the bearing body; the joint's plane is the bearing site's local x-y
    plane. The plugin is activated in the spec; the spec can then be compiled in any process
    that imported mujoco (the entry point loads the library).

    Args:
        spec: the model under construction; modified in place.
        name: name of the plugin instance and of its sensor (unique among both).
        journal_site: site at the journal centre, on the journal body.
        bearing_site: site at the bearing centre, on the bearing body.
        clearance: radial clearance c = R_B − R_J [m], > 0.
        journal_radius: R_J [m], > 0.
        law: the normal contact law.
        stiffness: K [N/m^n], > 0.
        exponent: n [-], > 0.
        restitution: cₑ [-] of the dissipative laws (required for them, in [0, 1] for
            Lankarani–Nikravesh and Hunt–Crossley, (0, 1] for the others); ignored by HERTZ
            and IMPACT, as in `laws.normal_force`.
        c_max: IMPACT's maximum damping C_max [N s/m], >= 0; IMPACT only.
        d_max: IMPACT's full-damping penetration d_max [m], > 0; IMPACT only.
        friction: Ambrósio friction coefficient μ [-], >= 0 (0: frictionless).
        v0: Ambrósio's no-friction speed [m/s], >= 0.
        v1: Ambrósio's full-friction speed [m/s], > v0.
        min_approach_speed: floor on the recorded approach speed δ̇⁻ [m/s], > 0.
        lubrication: the joint's oil film (`clearance.lubrication.Lubrication`), or None for a
            dry joint; its force (`clearance.contact_calibration.film`) adds to the law's.
        bearing_length: L [m] > 0, the film's length (required with ``lubrication``).
        cylinder: a cylindrical law's constants (`cylindrical_laws.cylinder_law`), required for
            the laws of `clearance.model.CYLINDRICAL_LAWS` (their ``stiffness`` and ``exponent``
            are then the constants' own), None for the point laws.

    Raises:
        ValueError: naming the joint, the attribute, its value and what was expected, for a
            missing site, sites on one body, a duplicate name, a non-finite or out-of-range
            number, a law that is not a `ContactLaw`, a missing law parameter, c_max/d_max
            with a law other than IMPACT, or a film without a bearing length or with a
            transition thickness not below the clearance.
        clearance.contact_plugin.PluginUnavailableError: if the package was installed without
            the compiled plugin (checked after the attributes).
    """
    if not isinstance(name, str) or not name:
        raise ValueError(f"journal-bearing contact: name must be a non-empty string (got {name!r})")
    j = name
    if any(p.name == name for p in spec.plugins) or spec.sensor(name) is not None:
        raise ValueError(
            f"journal-bearing contact '{j}': name {name!r} is already used by a plugin instance or a sensor of the spec"
        )
    journal = site_of(spec, j, "journal_site", journal_site)
    bearing = site_of(spec, j, "bearing_site", bearing_site)
    if journal.parent.name == bearing.parent.name:
        raise ValueError(
            f"journal-bearing contact '{j}': journal_site {journal_site!r} and bearing_site "
            f"{bearing_site!r} are on the same body {journal.parent.name!r}; expected the "
            "journal's body and the bearing's body"
        )
    if not isinstance(law, ContactLaw):
        raise ValueError(
            f"journal-bearing contact '{j}': law must be a ContactLaw member (got {law!r}); "
            f"expected one of {', '.join(m.name for m in ContactLaw)}"
        )
    require_compiled_law(law, j)
    config = {
        "journal_site": journal_site,
        "bearing_site": bearing_site,
        "clearance": number_attribute(j, "clearance", clearance, "> 0 [m]", lambda v: v > 0),
        "journal_radius": number_attribute(j, "journal_radius", journal_radius, "> 0 [m]", lambda v: v > 0),
        "law": law.value,
        "stiffness": number_attribute(j, "stiffness", stiffness, "> 0 [N/m^n]", lambda v: v > 0),
        "exponent": number_attribute(j, "exponent", exponent, "> 0", lambda v: v > 0),
        "friction": number_attribute(j, "friction", friction, ">= 0", lambda v: v >= 0),
        "v0": number_attribute(j, "v0", v0, ">= 0 [m/s]", lambda v: v >= 0),
        "min_approach_speed": number_attribute(
            j, "min_approach_speed", min_approach_speed, "> 0 [m/s]", lambda v: v > 0
        ),
    }
    config["v1"] = number_attribute(j, "v1", v1, f"> v0 = {config['v0']} [m/s]", lambda v: v > config["v0"])

    if law in CYLINDRICAL_LAWS:
        if not isinstance(cylinder, CylinderLaw) or cylinder.law is not law:
            raise ValueError(
                f"journal-bearing contact '{j}': law {law.name} needs its constants "
                f"(cylindrical_laws.cylinder_law of the joint; got {cylinder!r})"
            )
        config["stiffness"] = cylinder.stiffness if cylinder.stiffness > 0 else 1.0  # unused by the logarithmic
        config["exponent"] = cylinder.exponent if cylinder.exponent > 0 else 1.5
        config["clearance"] = cylinder.clearance
        config["max_penetration"] = cylinder.max_penetration if math.isfinite(cylinder.max_penetration) else "inf"
        if cylinder.logarithmic:
            config["compliance"] = cylinder.compliance
            config["reference_force"] = cylinder.reference_force
            config["offset"] = cylinder.offset
        if restitution is None:
            raise ValueError(f"journal-bearing contact '{j}': law {law.name} needs restitution")
        config["restitution"] = number_attribute(j, "restitution", restitution, "in [0, 1]", lambda v: 0 <= v <= 1)
    elif cylinder is not None:
        raise ValueError(
            f"journal-bearing contact '{j}': cylinder constants are for the cylindrical laws, not {law.name}"
        )
    if law in _DISSIPATIVE:
        if restitution is None:
            raise ValueError(f"journal-bearing contact '{j}': law {law.name} needs restitution")
        e = number_attribute(j, "restitution", restitution, "in [0, 1]", lambda v: 0 <= v <= 1)
        try:
            laws.hysteresis_factor(law, e)  # the per-law range; warns once for HU_GUO
        except ValueError as err:
            raise ValueError(f"journal-bearing contact '{j}': {err} for law {law.name}") from None
        config["restitution"] = e
    if law is ContactLaw.IMPACT:
        if c_max is None or d_max is None:
            raise ValueError(
                f"journal-bearing contact '{j}': law IMPACT needs c_max [N s/m] and d_max [m] "
                f"(got c_max={c_max!r}, d_max={d_max!r})"
            )
        config["c_max"] = number_attribute(j, "c_max", c_max, ">= 0 [N s/m]", lambda v: v >= 0)
        config["d_max"] = number_attribute(j, "d_max", d_max, "> 0 [m]", lambda v: v > 0)
    elif c_max is not None or d_max is not None:
        raise ValueError(
            f"journal-bearing contact '{j}': c_max/d_max (got {c_max!r}, {d_max!r}) are used by "
            f"law IMPACT only, not {law.name}; expected None"
        )

    if lubrication is not None:
        if not isinstance(lubrication, Lubrication):
            raise TypeError(f"journal-bearing contact '{j}': lubrication must be a Lubrication (got {lubrication!r})")
        if bearing_length is None:
            raise ValueError(f"journal-bearing contact '{j}': a lubricated joint needs bearing_length [m]")
        config["film"] = lubrication.film.value
        config["viscosity"] = lubrication.viscosity
        config["bearing_length"] = number_attribute(j, "bearing_length", bearing_length, "> 0 [m]", lambda v: v > 0)
        config["transition_thickness"] = number_attribute(
            j,
            "transition_thickness",
            lubrication.transition_thickness,
            f"in (0, clearance = {config['clearance']}) [m]",
            lambda v: 0 < v < config["clearance"],
        )

    add_instance(spec, PLUGIN_NAME, name, config)


def add_for_clearance(
    spec: mujoco.MjSpec,
    clearance: Clearance,
    *,
    name: str,
    journal_site: str,
    bearing_site: str,
    c_max: float | None = None,
    d_max: float | None = None,
    v0: float = 1e-4,
    v1: float = 1e-3,
    min_approach_speed: float = laws.MIN_APPROACH_SPEED,
) -> None:
    """`add_journal_bearing` with the law, cₑ, μ, radii and K (`laws.bearing_stiffness`) of a joint.

    Args:
        spec: the model under construction; modified in place.
        clearance: the joint's clearance (radii, materials, law, restitution, friction).
        name: name of the plugin instance and of its sensor.
        journal_site: site at the journal centre, on the journal body.
        bearing_site: site at the bearing centre, on the bearing body.
        c_max: IMPACT's maximum damping [N s/m] (IMPACT only).
        d_max: IMPACT's full-damping penetration [m] (IMPACT only).
        v0: Ambrósio's no-friction speed [m/s].
        v1: Ambrósio's full-friction speed [m/s].
        min_approach_speed: floor on the recorded approach speed [m/s].

    Raises:
        ValueError: as `add_journal_bearing`.
        clearance.contact_plugin.PluginUnavailableError: as `add_journal_bearing`.
    """
    law = clearance.law
    add_journal_bearing(
        spec,
        name=name,
        journal_site=journal_site,
        bearing_site=bearing_site,
        clearance=clearance.radial_clearance,
        journal_radius=clearance.journal_radius,
        law=law,
        stiffness=laws.bearing_stiffness(clearance),
        exponent=1.5,
        restitution=clearance.restitution,
        c_max=c_max,
        d_max=d_max,
        friction=clearance.friction,
        v0=v0,
        v1=v1,
        min_approach_speed=min_approach_speed,
        lubrication=clearance.lubrication,
        bearing_length=clearance.bearing_length,
        cylinder=cylinder_law(clearance) if law in CYLINDRICAL_LAWS else None,
    )


def _id(model: mujoco.MjModel, objtype: mujoco.mjtObj, name: str, what: str) -> int:
    i = mujoco.mj_name2id(model, objtype, name)
    if i < 0:
        raise ValueError(f"the model has no journal-bearing {what} named {name!r}")
    return i


def sensor_address(model: mujoco.MjModel, name: str) -> int:
    """Address of a journal-bearing contact's sensor block in ``mjData.sensordata``.

    Args:
        model: a compiled model.
        name: the contact's name (as given to `add_journal_bearing`).

    Returns:
        The index of `SENSOR_FIELDS[0]`; the block is ``len(SENSOR_FIELDS)`` values long.

    Raises:
        ValueError: if the model has no such plugin sensor.
    """
    return sensor_offsets(model, name)[SENSOR_FIELDS[0]]


def sensor_offsets(model: mujoco.MjModel, name: str) -> dict[str, int]:
    """Index in ``mjData.sensordata`` (and in rollout sensor arrays) of each sensor field.

    Args:
        model: a compiled model.
        name: the contact's name.

    Returns:
        ``{field: index}`` for every field of `SENSOR_FIELDS`.

    Raises:
        ValueError: if the model has no such plugin sensor.
    """
    return sensor_block(model, name, SENSOR_FIELDS, "journal-bearing")


def state_size(model: mujoco.MjModel) -> int:
    """Values of one journal-bearing contact's state: `STATE_FIELDS`, then 2 ``model.nv`` values.

    Args:
        model: a compiled model.
    """
    return len(STATE_FIELDS) + 2 * int(model.nv)


def state_address(model: mujoco.MjModel, name: str) -> int:
    """Address of a journal-bearing contact's state in ``mjData.plugin_state``.

    Args:
        model: a compiled model.
        name: the contact's name.

    Returns:
        The index of `STATE_FIELDS[0]`; the block is `state_size` values long.

    Raises:
        ValueError: if the model has no such plugin instance.
    """
    return int(model.plugin_stateadr[_id(model, mujoco.mjtObj.mjOBJ_PLUGIN, name, "plugin")])
