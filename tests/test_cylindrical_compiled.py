"""The cylindrical laws in the compiled contact (contact_laws.c) against
`contact_calibration.cylindrical_laws`, value by value, and against the reference solver on the
default scenario's first impact.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from plugin_scenes import add_joint, planar_body
from test_contact_plugin import R_J, C, needs_plugin

from clearance import ModelOptions, simulate
from clearance.builders import slider_crank
from clearance.contact_calibration import laws
from clearance.contact_calibration.cylindrical_laws import (
    cylinder_law_from,
    damped_force,
    elastic_energy,
)
from clearance.contact_plugin import attributes
from clearance.model import CYLINDRICAL_LAWS, ContactLaw, Material
from clearance.reference import run_reference

STEEL = Material(207e9, 0.3)
CYLINDRICAL = sorted(CYLINDRICAL_LAWS, key=list(ContactLaw).index)
pytestmark = pytest.mark.filterwarnings("ignore::clearance.contact_calibration.laws.UnverifiedLawWarning")


def _scene(law: ContactLaw) -> tuple[mujoco.MjModel, object]:
    """A journal on slide x, slide y, hinge z in a fixed bearing (c = 0.5 mm, L = 20 mm, steel),
    RK4: the law sees the state's own rate."""
    cyl = cylinder_law_from(
        law,
        bearing_radius=R_J + C,
        radial_clearance=C,
        bearing_material=STEEL,
        journal_material=STEEL,
        bearing_length=0.02,
    )
    spec = mujoco.MjSpec()
    spec.option.gravity = [0, 0, 0]
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    spec.worldbody.add_site(name="bearing")
    planar_body(spec.worldbody, "journal", mass=0.15, inertia=1e-5)
    add_joint(
        spec,
        clearance=C,
        journal_radius=R_J,
        law=law,
        stiffness=1.0,
        restitution=0.9,
        cylinder=cyl,
    )
    return spec.compile(), cyl


@needs_plugin
@pytest.mark.parametrize("law", CYLINDRICAL)
def test_compiled_cylindrical_law_equals_python(law: ContactLaw) -> None:
    model, cyl = _scene(law)
    data = mujoco.MjData(model)
    adr = attributes.state_address(model, "joint")
    s = {name: k for k, name in enumerate(attributes.STATE_FIELDS)}
    y = attributes.sensor_offsets(model, "joint")
    chi = laws.hysteresis_factor(ContactLaw.LANKARANI_NIKRAVESH, 0.9)
    rng = np.random.default_rng(9)
    deepest = min(cyl.max_penetration, 40e-6)
    for delta in np.concatenate([rng.uniform(-5e-6, deepest, 30), [1e-7, 1e-6, 1e-5]]):
        rate, approach = rng.uniform(-3, 3), rng.uniform(1e-3, 3)
        mujoco.mj_resetData(model, data)
        data.qpos[:3] = [C + delta, 0.0, 0.0]
        data.qvel[:3] = [rate, 0.0, 0.0]
        data.plugin_state[adr + s["in_contact"]] = 1.0
        data.plugin_state[adr + s["approach_speed"]] = approach
        mujoco.mj_forward(model, data)
        fields = ("normal_force", "penetration", "penetration_rate", "approach_speed")
        fn, d, dd, vin = (data.sensordata[y[k]] for k in fields)
        expected = damped_force(cyl, chi, d, dd, vin) if d > 0 else 0.0
        # rtol 1e-12: the same operations in the same order; the logarithmic laws are iterated to
        # rounding in both (their counts may differ at the last ulp: a few ulps of (1 + |u|))
        assert fn == pytest.approx(expected, rel=1e-12, abs=0.0), delta
        energy = data.sensordata[y["potential_energy"]]
        assert energy == pytest.approx(elastic_energy(cyl, d) if d > 0 else 0.0, rel=1e-12, abs=0.0), delta


@needs_plugin
@pytest.mark.parametrize("law", CYLINDRICAL)
def test_default_scenario_first_impact_within_one_percent_of_the_reference(law: ContactLaw) -> None:
    mech = slider_crank(law=law, bearing_length=0.02)
    ref = run_reference(mech, 0.6e-3, output_interval=1e-7, rtol=1e-10)
    run = simulate(mech, duration=0.6e-3, options=ModelOptions(contact_mode="exact"))
    peak, peak_ref = run.joints["rod_slider"].force_magnitude.max(), ref.joints["rod_slider"].force_magnitude.max()
    assert peak > 1e4  # the window holds the first impact
    assert peak == pytest.approx(peak_ref, rel=0.01)  # the 1 % at the default step
