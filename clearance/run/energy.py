"""Energy series of a run, read from the energy meter's sensor rows (no Python per step).

A model carries the energy meter when `clearance.contact_plugin.energy.add_energy_meter` was
applied to its spec (`clearance.run.preparation.prepare` does it for every run it prepares,
when the compiled library is installed). Every term is then
measured on its own, inside ``mujoco.rollout``:

==========================  =============================================================
term                        source
==========================  =============================================================
``kinetic``                 MuJoCo's kinetic energy sensor: ½ v'Mv with M including the
                            armature (so the speed drives' flywheel is in it)
``gravity_potential``       MuJoCo's potential energy sensor: −Σ m g·x_com (and springs)
``contact_potential``       Σ over compiled contacts (journals, sliders' corners) of their
                            sensor's ``potential_energy``;
                            0 in the ring modes, whose contact rows have no potential MuJoCo
                            reports: the energy a ring stores while pressed is inside
                            ``contact_work`` (the rows' work), so the balance still closes
``drive_work``              `clearance.work`: actuator work, with the implicit velocity
                            derivative of the speed drives (implicitfast) accounted for
``equality_work``           `clearance.work`: work of the equality rows (connect closures)
``contact_work``            `clearance.work`: work of the contact rows (ring bearings)
``other_constraint_work``   `clearance.work`: limits, friction loss
``damper_work``             `clearance.work`: MuJoCo's dampers, fluid, adhesion, gravcomp
``dissipated_work``         Σ over compiled contacts of their sensor's ``dissipated_work``
``compiled_contact_work``   `clearance.work`: work of engine-plugin passive forces (the
                            compiled contacts), a check of −Δcontact_potential − dissipated
==========================  =============================================================

Timing: sensor row i describes the state at t_i, before step i is integrated; the works in row
i are those of steps 0 .. i−1 (from t_0 to t_i), each step's work taken with the force the
integrator applied over it and the mean of the step's start and end velocities. The balance's
residual (`clearance.results.energy_residual`) is first order in the time step for MuJoCo's
semi-implicit integrators, like their energy error (tests/test_energy.py measures it).
"""

from __future__ import annotations

import warnings

import numpy as np

from clearance.contact_plugin.attributes import sensor_offsets
from clearance.contact_plugin.energy import energy_sensor_addresses, has_energy_meter
from clearance.contact_plugin.slider_guide import slider_sensor_offsets
from clearance.run.preparation import PreparedModel, exact_contact_name

__all__ = ["read_energy"]

_WORKS = {
    "drive_work": "actuator_work",
    "equality_work": "equality_work",
    "contact_work": "contact_work",
    "other_constraint_work": "other_constraint_work",
    "damper_work": "damper_work",
    "compiled_contact_work": "plugin_passive_work",
}
"""Result term -> field of the work sensor (`clearance.contact_plugin.energy.WORK_FIELDS`)."""


def read_energy(prepared: PreparedModel, times: np.ndarray, sens: np.ndarray) -> dict[str, np.ndarray]:
    """Energy series from sensor rows of a metered model; empty without the meter.

    Args:
        prepared: the prepared model that ran.
        times: (n,) times of the rows [s], multiples of the time step from the run's start.
        sens: (n, nsensordata) sensor rows.

    Returns:
        term -> (n,) [J], the terms of `clearance.results.ENERGY_TERMS`; empty when the model has no
        energy meter, or (with a warning) when the meter missed steps (sensors disabled).
    """
    model = prepared.model
    if not has_energy_meter(model):
        return {}
    at = energy_sensor_addresses(model)
    steps = np.rint(times / model.opt.timestep)
    if not np.isfinite(sens).all():
        return {}  # a diverged chunk: the run stops with its own error, the balance means nothing there
    if not np.array_equal(sens[:, at["steps"]], steps):
        warnings.warn(
            "the energy meter did not record every step (were sensors disabled?): no energy series",
            RuntimeWarning,
            stacklevel=2,
        )
        return {}
    n = len(times)
    out = {"kinetic": sens[:, at["kinetic"]].copy(), "gravity_potential": sens[:, at["potential"]].copy()}
    potential, dissipated = np.zeros(n), np.zeros(n)
    if prepared.built.exact_contact:
        for joint in prepared.built.rings:
            o = sensor_offsets(model, exact_contact_name(joint))
            potential += sens[:, o["potential_energy"]]
            dissipated += sens[:, o["dissipated_work"]]
        for joint in prepared.built.guides:
            o = slider_sensor_offsets(model, exact_contact_name(joint))
            potential += sens[:, o["potential_energy"]]
            dissipated += sens[:, o["dissipated_work"]]
    out["contact_potential"] = potential
    out["dissipated_work"] = dissipated
    out.update({term: sens[:, at[field]].copy() for term, field in _WORKS.items()})
    return out
