"""Impacts a run starts in: a journal-bearing contact already closed at the start state.

The compiled contact records an impact's approach speed δ̇⁻ at its onset, from the rate it sees
when the penetration first turns positive. A run that starts in contact has no onset: with no
record, the first step would take the rate it samples as δ̇⁻, and under the semi-implicit
integrators that rate is the one of the half step before the start (`clearance.run.simulation.
start_data`'s velocities), the rate of an acceleration the run never had: a journal pressed
10 µm into its bearing and pushed back out by its elastic force took 0.022 m/s at 3 µs steps
(0.0075 m/s at 1 µs), a damping 22 times too weak, and its force rose to the load over 25 µs
where the reference solver's rises in 2 µs. `record_closed_contacts` records, as the reference
solver does for a journal in penetration at t = 0, the state's own rate (floored at the
contact's minimum approach speed) as the impact's approach speed.
"""

from __future__ import annotations

import mujoco

from clearance.contact_plugin.attributes import SENSOR_FIELDS, STATE_FIELDS, state_size

__all__ = ["record_closed_contacts"]

_PENETRATION = SENSOR_FIELDS.index("penetration")
_APPROACH = SENSOR_FIELDS.index("approach_speed")
_IN_CONTACT = STATE_FIELDS.index("in_contact")
_STATE_APPROACH = STATE_FIELDS.index("approach_speed")


def record_closed_contacts(model: mujoco.MjModel, data: mujoco.MjData) -> list[str]:
    """Record an onset for every journal-bearing contact closed at ``data``'s state.

    ``data``'s sensors must hold an evaluation at the state's own rates (``mj_forward`` under
    RK4: no in-step treatment, no history), whose approach speed is then max(δ̇(0), floor).
    A journal-bearing instance is a plugin instance with a sensor of its own name of
    `SENSOR_FIELDS`' length and a state of `state_size`; other plugins are left alone.

    Args:
        model: the compiled model.
        data: the start state, sensors evaluated; its plugin state is written.

    Returns:
        The names of the contacts recorded as in an impact.
    """
    closed = []
    for i in range(model.nplugin):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_PLUGIN, i)
        sensor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name) if name else -1
        if (
            sensor < 0
            or model.sensor_plugin[sensor] != i
            or model.sensor_dim[sensor] != len(SENSOR_FIELDS)
            or model.plugin_statenum[i] != state_size(model)
        ):
            continue
        values = data.sensordata[model.sensor_adr[sensor] :]
        if values[_PENETRATION] > 0:
            state = model.plugin_stateadr[i]
            data.plugin_state[state + _IN_CONTACT] = 1.0
            data.plugin_state[state + _STATE_APPROACH] = values[_APPROACH]
            closed.append(name)
    return closed
