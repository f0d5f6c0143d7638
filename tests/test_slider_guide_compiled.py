"""The compiled slider-guide contact (contact_plugin/slider_guide.c) against the reference solver.

A free block with play in a ground-fixed guide, as `clearance.reference.slider_in_guide` builds it,
meets each contact case (one corner, one side, two diagonal corners); each is run in MuJoCo at
the default step and compared with the reference: the corners that touch, the first impact's
peak force, the largest tilt.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest
from test_contact_plugin import needs_plugin

from clearance.contact_plugin.slider_guide import add_slider_guide, slider_sensor_offsets
from clearance.model import ContactLaw
from clearance.reference import simulate_system, slider_in_guide
from clearance.translational import SliderContact, TranslationalClearance

GUIDE = TranslationalClearance(1e-3, 0.1, 0.05, stiffness=1e10, restitution=0.4, law=ContactLaw.FLORES)
MASS = 0.076  # the benchmark's slider [kg]
INERTIA = MASS * (0.1**2 + 0.05**2) / 12  # a uniform 100 mm x 50 mm block [kg m^2]
STEP = 3e-6  # the exact contact's default step [s]


def _mujoco(tc: TranslationalClearance, duration: float, *, across=0.0, tilt=0.0, velocity=(0.0, 0.0), spin=0.0):
    """(times, sensor rows) of the block in MuJoCo, the sensors read at each step's start."""
    spec = mujoco.MjSpec()
    spec.option.timestep = STEP
    spec.option.gravity = [0, 0, 0]
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.worldbody.add_site(name="guide")
    block = spec.worldbody.add_body(name="block")
    dofs = (("along", "SLIDE", [1, 0, 0]), ("across", "SLIDE", [0, 1, 0]), ("tilt", "HINGE", [0, 0, 1]))
    for joint, kind, axis in dofs:
        block.add_joint(name=joint, axis=axis, type=getattr(mujoco.mjtJoint, f"mjJNT_{kind}"))
    block.explicitinertial = True
    block.mass = MASS
    block.inertia = [INERTIA] * 3
    block.add_site(name="centre")
    add_slider_guide(spec, name="guide", slider_site="centre", guide_site="guide", tc=tc)
    model = spec.compile()
    data = mujoco.MjData(model)
    data.qpos[:] = [0.0, across, tilt]
    data.qvel[:] = [velocity[0], velocity[1], spin]
    n = int(round(duration / STEP))
    rows = np.empty((n, model.nsensordata))
    for i in range(n):
        mujoco.mj_forward(model, data)
        rows[i] = data.sensordata
        mujoco.mj_step(model, data)
    assert not any(w.number for w in data.warning), "MuJoCo warnings"
    return np.arange(n) * STEP, rows, slider_sensor_offsets(model, "guide")


def _reference(tc: TranslationalClearance, duration: float, **start):
    system, q0, qd0 = slider_in_guide(tc, mass=MASS, inertia=INERTIA, **start)
    return simulate_system(system, q0, qd0, duration, output_interval=1e-6)


CASES = {
    "one corner": (0.6e-3, dict(tilt=0.5 * GUIDE.max_tilt, velocity=(0.0, -1.0)), SliderContact.ONE_CORNER),
    "one side": (2e-3, dict(velocity=(0.5, -1.0)), SliderContact.ONE_SIDE),
    "diagonal": (5e-3, dict(spin=5.0), SliderContact.DIAGONAL),
}


LN_FRICTION = dataclasses.replace(GUIDE, law=ContactLaw.LANKARANI_NIKRAVESH, restitution=0.9, friction=0.1)


@needs_plugin
@pytest.mark.parametrize("tc", [GUIDE, LN_FRICTION], ids=["flores", "LN with friction"])
@pytest.mark.parametrize("case", list(CASES))
def test_each_contact_case_against_the_reference(case: str, tc: TranslationalClearance) -> None:
    # measured: peak corner forces within 0.01-0.6 %, largest tilts to 1e-5 rad
    duration, start, expected = CASES[case]
    ref = _reference(tc, duration, **start)
    _, rows, at = _mujoco(tc, duration, **start)
    cases = set(rows[:, at["contact_case"]].astype(int))
    assert expected.value in cases
    sr = ref.sliders["guide"]
    touched_ref = {k for k in range(4) if sr.corner_penetration[:, k].max() > 0}
    touched = {k for k in range(4) if rows[:, at[f"penetration_{k}"]].max() > 0}
    assert touched == touched_ref
    for k in touched:
        # the peak corner force: 1 % at the default step (the goal for first impacts)
        assert rows[:, at[f"normal_force_{k}"]].max() == pytest.approx(sr.corner_force[:, k].max(), rel=0.01), k
    # the largest tilt (the diagonal case wedges at the guide's largest tilt): 1 % of it
    tilt, tilt_ref = np.abs(rows[:, at["tilt"]]).max(), np.abs(sr.tilt).max()
    assert tilt == pytest.approx(tilt_ref, rel=0.01, abs=0.01 * tc.max_tilt)
