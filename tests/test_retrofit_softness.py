"""A retrofit keeps every constraint of the model as soft as it was (`clearance.retrofit.softness`,
`clearance.retrofit.contact_softness`), and its refusals carry their listed reason (`Refusal`).

The slides a radial play puts before a hinge raise the inverse weight MuJoCo regularises the rows
near it with (``dof_invweight0``, ``body_invweight0`` at qpos0): on the model below, a play at the
shoulder raises the elbow limit's by half and the foot's contact's too. The retrofit rescales solimp
and solref so that the solver's numbers for every row of the twin (R, K times impedance, B) are the
twin's, read from the values both compiled models hold (MuJoCo's own K and B at the first state
follow the same formulas).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from clearance.contact_calibration.torsional_stop import StopStabilityError
from clearance.retrofit import Backlash, RadialPlay, RetrofitError, RetrofitOptions, add_backlash, retrofit
from clearance.retrofit.play import Refusal
from clearance.retrofit.softness import kept_softness, row_softness
from clearance.run.retrofit_check import refusal_of

# an arm on a floor: the elbow starts 0.05 degrees past its limit, both joints have friction loss, the
# foot rests 1 mm into the floor, and a weld ties a mocap body to the hand
ARM = """
<mujoco model="soft_arm">
  <option timestep="0.002" gravity="0 0 -9.81"/>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="upper" pos="0 0 0.6">
      <joint name="shoulder" type="hinge" axis="0 1 0" frictionloss="0.5" damping="0.1"/>
      <geom name="upper" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" contype="0" conaffinity="0"/>
      <inertial pos="0.15 0 0" mass="2" diaginertia="0.02 0.02 0.001"/>
      <body name="lower" pos="0.3 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0" range="0.05 1.5" limited="true" frictionloss="0.3"/>
        <inertial pos="0.15 0 -0.1" mass="1" diaginertia="0.01 0.01 0.001"/>
        <body name="hand" pos="0.2 0 -0.3">
          <inertial pos="0 0 0" mass="0.2" diaginertia="1e-4 1e-4 1e-4"/>
          <geom name="foot" type="sphere" size="0.03" pos="0 0 -0.271"/>
        </body>
      </body>
    </body>
    <body name="target" mocap="true" pos="0.5 0 0.3"/>
  </worldbody>
  <equality>
    <weld name="hold" body1="target" body2="hand" solref="0.05 1"/>
  </equality>
  <actuator>
    <motor joint="shoulder" ctrlrange="-5 5"/>
    <motor joint="elbow" ctrlrange="-5 5"/>
  </actuator>
</mujoco>
"""


def _check_mujoco_uses_row_softness(model: mujoco.MjModel) -> int:
    """MuJoCo's own K and B of every joint-limit row at the first state are `row_softness`'s (K and B from solref
    at dmax, refsafe's raised time constant), so the check below compares the numbers the solver uses; returns
    the rows seen."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    seen = 0
    for i in range(data.nefc):
        if data.efc_type[i] == mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT:
            j = int(data.efc_id[i])
            expect = _softness(model, 1.0, model.jnt_solimp[j], model.jnt_solref[j])
            # row_softness's K d0 over d0, and B, to rounding (1e-12)
            got = [data.efc_KBIP[i, 0], data.efc_KBIP[i, 1]]
            np.testing.assert_allclose(got, [expect[2] / model.jnt_solimp[j, 0], expect[3]], rtol=1e-12)
            seen += 1
    return seen


def _softness(model: mujoco.MjModel, a: float, solimp: np.ndarray, solref: np.ndarray) -> np.ndarray:
    return row_softness(a, solimp, solref, step=float(model.opt.timestep), safe=True)


@pytest.mark.parametrize("mode", ["exact", "nominal"])
def test_every_row_of_the_twin_keeps_its_softness_after_a_play_at_the_shoulder(mode):
    if mode == "exact":
        from clearance.contact_plugin import is_available

        if not is_available():
            pytest.skip("the compiled contact plugin is not built")
    spec = mujoco.MjSpec.from_string(ARM)
    options = RetrofitOptions(
        contact_mode=mode,
        segments=None if mode == "exact" else 64,
        measure_speed=False,
        sizing_duration=0.2,
        accept_inaccurate=True,  # the rows' softness is the point here, not the ring's accuracy
    )
    r = retrofit(spec, {"shoulder": RadialPlay.make(1e-5)}, options)
    t, m = r.twin, r.model
    t.opt.timestep = m.opt.timestep  # both run at the retrofit's step (the twin's K, B at it)
    assert _check_mujoco_uses_row_softness(m) > 0
    for name in ("shoulder", "elbow"):
        tj, mj = t.joint(name), m.joint(name)
        a, b = float(t.dof_invweight0[tj.dofadr[0]]), float(m.dof_invweight0[mj.dofadr[0]])
        if name == "elbow":  # the slides did move the rows' inverse weights: a play that left them tests nothing
            assert b > 1.2 * a
        rows = [("friction loss", "dof_solimp", "dof_solref", tj.dofadr[0], mj.dofadr[0])]
        rows += [("limit", "jnt_solimp", "jnt_solref", tj.id, mj.id)] if t.jnt_limited[tj.id] else []
        for what, imp, ref, i, k in rows:
            old = _softness(t, a, getattr(t, imp)[i], getattr(t, ref)[i])
            new = _softness(m, b, getattr(m, imp)[k], getattr(m, ref)[k])
            # R at d0 and d_width, K d0 and B kept to the rounding of the rescale (a few ulps; 1e-9)
            np.testing.assert_allclose(new, old, rtol=1e-9, err_msg=f"{name} {what}")

    def weld(mm: mujoco.MjModel) -> float:
        return float(mm.body_invweight0[mm.body("hand").id, 0] + mm.body_invweight0[mm.body("target").id, 0])

    eq = t.equality("hold").id
    np.testing.assert_allclose(
        _softness(m, weld(m), m.eq_solimp[eq], m.eq_solref[eq]),
        _softness(t, weld(t), t.eq_solimp[eq], t.eq_solref[eq]),
        rtol=1e-9,  # as above
    )
    # the foot on the floor: an explicit pair with the values MuJoCo mixes for it (both geoms at MuJoCo's
    # defaults, so the mix is the foot's own), rescaled at the foot's inverse weight (the floor's is 0)
    pair = m.pair("clr_contact__0")
    assert {int(pair.geom1[0]), int(pair.geom2[0])} == {m.geom("foot").id, m.geom("floor").id}
    foot_t, foot_m = t.geom("foot").id, m.geom("foot").id
    np.testing.assert_allclose(
        _softness(m, float(m.body_invweight0[m.geom_bodyid[foot_m], 0]), pair.solimp, pair.solref),
        _softness(t, float(t.body_invweight0[t.geom_bodyid[foot_t], 0]), t.geom_solimp[foot_t], t.geom_solref[foot_t]),
        rtol=1e-9,  # as above
    )
    assert any("rescaled to keep the twin's softness" in n for n in r.notes)


@pytest.mark.parametrize(
    "solref", [(0.02, 1.0), (1e-6, 1.0), (-1e4, -10.0)], ids=["time constant", "raised by refsafe", "direct"]
)
def test_kept_softness_gives_the_old_rows_numbers_at_the_new_inverse_weight(solref):
    solimp = (0.9, 0.95, 0.001, 0.5, 2.0)
    for a_new in (0.5, 3.0, 40.0):
        kept = kept_softness(2.0, a_new, solimp, solref, step=2e-6, refsafe=True)
        old = row_softness(2.0, solimp, solref, step=2e-6, safe=True)
        new = row_softness(a_new, kept.solimp, kept.solref, step=2e-6, safe=True)
        if kept.softer == pytest.approx(1.0, abs=1e-12):  # within MuJoCo's impedance bounds: every number kept
            np.testing.assert_allclose(new, old, rtol=1e-12)  # a few roundings of the rescale
        else:  # x20 past the bound (d = 0.9999): R is as close as MuJoCo allows, K d and B still kept
            assert new[0] > old[0] and kept.solimp[1] == pytest.approx(0.9999)
            np.testing.assert_allclose(new[2:], old[2:], rtol=1e-12)  # as above


def test_refusals_carry_their_listed_reason():
    spec = mujoco.MjSpec.from_string(
        """
        <mujoco>
          <worldbody>
            <body name="base">
              <joint name="slide" type="slide"/>
              <joint name="lift" type="slide" axis="1 0 0"/>
              <joint name="turn" type="hinge"/>
              <geom type="box" size="0.1 0.1 0.1" mass="1"/>
              <body name="tip" pos="0.3 0 0">
                <joint name="light" type="hinge" axis="0 0 1"/>
                <geom type="sphere" size="0.01" mass="1e-6"/>
              </body>
              <body name="wrist" pos="0 0.3 0">
                <joint name="roll" type="hinge" axis="1 0 0"/>
                <joint name="pitch" type="hinge" axis="0 1 0"/>
                <geom type="sphere" size="0.02" mass="0.1"/>
              </body>
            </body>
          </worldbody>
          <tendon><fixed name="couple"><joint joint="light" coef="1"/></fixed></tendon>
          <actuator>
            <motor joint="turn" ctrlrange="-1 1"/><motor tendon="couple" ctrlrange="-1 1"/>
            <motor joint="roll" ctrlrange="-1 1"/>
          </actuator>
        </mujoco>
        """
    )
    cases = [
        (lambda: retrofit(spec, {"slide": RadialPlay()}), Refusal.NOT_A_HINGE, "slide"),
        (lambda: retrofit(spec, {"turn": RadialPlay()}), Refusal.FLOATING_BASE, "turn"),  # 2 slides, on the world
        (lambda: add_backlash(spec, {"turn": Backlash.from_arcmin(5)}), Refusal.FLOATING_BASE, "turn"),
        (lambda: retrofit(spec, {"roll": RadialPlay()}), Refusal.SHARED_BODY, "roll"),  # a compound joint
        (lambda: add_backlash(spec, {"roll": Backlash.from_arcmin(5)}), Refusal.SHARED_BODY, "roll"),
        (lambda: add_backlash(spec, {"pitch": Backlash.from_arcmin(5)}), Refusal.NO_ACTUATOR, "pitch"),
        (lambda: add_backlash(spec, {"light": Backlash.from_arcmin(5)}), Refusal.TENDON_DRIVEN, "light"),
        (
            lambda: retrofit(spec, {"light": RadialPlay()}, RetrofitOptions(contact_mode="exact", measure_speed=False)),
            Refusal.TOO_LIGHT,
            "light",
        ),
    ]
    for call, reason, hinge in cases:
        with pytest.raises((RetrofitError, StopStabilityError)) as info:
            call()
        assert refusal_of(info.value) is reason, str(info.value)
        assert getattr(info.value, "hinge", hinge) == hinge
    # the message of a refused hinge lists only hinges that can take play ('turn', 'roll', 'pitch' share bodies)
    with pytest.raises(RetrofitError, match=r"that can: light\)"):
        retrofit(spec, {"turn": RadialPlay()})
