"""The calibrated backlash stop against the gear mesh's impact law, and on a robot.

A flywheel (one wheel on an actuated hinge) given backlash: its load side is set spinning at a
known speed towards the stop while its motor side stands, and the stop's peak torque and
restitution are compared with the 1-DOF impact of the law (`impact.law_impact`, Lankarani–
Nikravesh with n = 1) at the effective inertia worked out here by hand (the wheel's m r^2/2
and the motor armature in series), over a decade of closing speeds. The goal is the issue's:
within 5 % at every speed. gymnasium's reacher with backlash at both hinges at the default
mesh runs one second of a sinusoidal control without a MuJoCo warning, its links in their
limits and its bands closed to within the stop's penetration.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from gym_assets import gym_model

from clearance.cli import main
from clearance.contact_calibration.impact import law_impact
from clearance.contact_calibration.torsional_stop import OMEGA_H, StopStabilityError, stop_at
from clearance.model import ContactLaw
from clearance.retrofit import Backlash, SineControl
from clearance.retrofit.backlash import add_backlash
from clearance.retrofit.motion import control_signal, initial_data

WHEEL_MASS, WHEEL_RADIUS, ARMATURE = 1.0, 0.1, 0.002
FLYWHEEL = f"""<mujoco model="flywheel"><option timestep="0.001" gravity="0 0 0"/>
<worldbody><body name="wheel"><joint name="shaft" type="hinge" axis="0 0 1" armature="{ARMATURE}"/>
<geom type="cylinder" size="{WHEEL_RADIUS} 0.01" mass="{WHEEL_MASS}"/></body></worldbody>
<actuator><motor name="drive" joint="shaft" gear="1" ctrlrange="-1 1"/></actuator></mujoco>"""
J_WHEEL = WHEEL_MASS * WHEEL_RADIUS**2 / 2  # a solid cylinder about its axis
J_EFF = J_WHEEL * ARMATURE / (J_WHEEL + ARMATURE)  # the wheel and the rotor in series across the band
B = math.radians(0.5)
SPEEDS = np.geomspace(0.2, 2.0, 4)  # rad/s: a decade of closing speeds


def _warnings(data: mujoco.MjData) -> int:
    return int(sum(w.number for w in data.warning))


def _flywheel_impact(model: mujoco.MjModel, speed: float) -> tuple[float, float, int]:
    """(peak stop torque [N m], restitution [-], warnings) of the load closing on the stop at ``speed``."""
    d = mujoco.MjData(model)
    load, motor = model.joint("shaft").dofadr[0], model.joint("shaft__motor").dofadr[0]
    d.qvel[load] = speed
    limit = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON)
    peak, touched = 0.0, False
    for _ in range(int(10 * B / speed / model.opt.timestep)):
        mujoco.mj_step(model, d)
        rows = [i for i in range(d.nefc) if d.efc_type[i] == limit]
        if rows:
            touched = True
            peak = max(peak, float(d.efc_force[rows[0]]))
        elif touched:
            break
    rate = d.qvel[load] - d.qvel[motor]
    return peak, -float(rate) / speed, _warnings(d)


@pytest.mark.parametrize("stiffness, restitution", [(1e4, 0.8), (3e3, 0.9)])
def test_flywheel_stop_follows_the_mesh_law_over_a_decade_of_speeds(stiffness, restitution):
    spec = mujoco.MjSpec.from_string(FLYWHEEL)
    out = add_backlash(spec, {"shaft": Backlash(B, mesh_stiffness=stiffness, restitution=restitution)})
    m = out.model
    stop = out.hinges["shaft"].stop
    # the mass matrix's inverse along the band: J_EFF leaves out the motor body's 1e-12 kg m^2 placeholder inertia,
    # 3.6e-10 of J_EFF (measured; rounding adds ~1e-16)
    assert stop.inertia == pytest.approx(J_EFF, rel=1e-9)
    # the speed fitted around: the motor (armature only) crossing 2b from rest under the drive's 1 N m; the same
    # placeholder inertia makes it 2.5e-10 slower (measured)
    assert stop.impact_speed == pytest.approx(math.sqrt(2 * (2 * B) * 1.0 / ARMATURE), rel=1e-9)
    assert stop.fit is not None and stop.fit.speeds[-1] / stop.fit.speeds[0] == pytest.approx(10.0, rel=1e-12)
    # the step is lowered to omega*h <= OMEGA_H with omega = sqrt(K/J) (rounded down to one digit)
    assert m.opt.timestep * math.sqrt(stiffness / J_EFF) <= OMEGA_H
    for v in SPEEDS:
        law = law_impact(
            ContactLaw.LANKARANI_NIKRAVESH,
            mass=J_EFF,
            speed=v,
            stiffness=stiffness,
            restitution=restitution,
            exponent=1,
        )
        peak, e, warnings = _flywheel_impact(m, float(v))
        assert warnings == 0
        # 5 %: the goal for the calibrated stop, peak torque and restitution at every speed
        assert peak == pytest.approx(law.peak_force, rel=0.05), f"{v:.3g} rad/s"
        assert e == pytest.approx(law.restitution, rel=0.05), f"{v:.3g} rad/s"


def test_the_stops_rebound_drifts_with_the_inertia_as_documented():
    out = add_backlash(mujoco.MjSpec.from_string(FLYWHEEL), {"shaft": Backlash(B)})
    stop = out.hinges["shaft"].stop
    assert stop.fit is not None
    # one body: every pose alike; 3.6e-10 off J_EFF, the motor body's placeholder inertia (as above)
    assert stop.inertia_range == pytest.approx((J_EFF, J_EFF), rel=1e-9)
    same, heavier = stop_at(stop.fit, J_EFF, 1.0), stop_at(stop.fit, 2 * J_EFF, 1.0)
    assert abs(same.restitution_err) < 0.01  # at the inertia fitted at: the fit's own accuracy (< 0.4 % measured)
    # a linear damper's damping ratio falls like 1/sqrt(J): at twice the inertia the rebound is about 5 % high (the
    # module's measurement on the reacher's elbow, 5.1 %); 3 % and 8 % bracket it
    assert 0.03 < heavier.restitution_err < 0.08


def test_recipe_keeps_mujocos_default_stop_and_the_models_step():
    spec = mujoco.MjSpec.from_string(FLYWHEEL)
    out = add_backlash(spec, {"shaft": Backlash(B, stop="recipe")})
    m = out.model
    t = m.tendon("clr_shaft__backlash").id
    assert m.opt.timestep == 0.001 and out.hinges["shaft"].stop.fit is None
    assert m.tendon_solref_lim[t].tolist() == [0.02, 1.0]  # MuJoCo's default solref
    law = law_impact(ContactLaw.LANKARANI_NIKRAVESH, mass=J_EFF, speed=1.0, stiffness=1e4, restitution=0.8, exponent=1)
    peak, _, _ = _flywheel_impact(m, 1.0)
    # the default stop (time constant 0.02 s) is far softer than a 1e4 N m/rad mesh: a third of the law's torque at most
    assert peak < law.peak_force / 3


def test_a_stop_too_stiff_for_any_step_is_refused():
    spec = mujoco.MjSpec.from_string(FLYWHEEL)
    with pytest.raises(StopStabilityError, match="smaller mesh_stiffness"):
        add_backlash(spec, {"shaft": Backlash(B, mesh_stiffness=1e12)})


@pytest.mark.parametrize(
    "kw, expected",
    [
        ({"restitution": 0.0}, "restitution must be in"),
        ({"restitution": 1.5}, "restitution must be in"),
        ({"mesh_stiffness": -1.0}, "mesh_stiffness"),
        ({"mesh_stiffness": math.nan}, "mesh_stiffness"),
        ({"stop": "soft"}, "stop must be one of"),
        ({"mesh_exponent": 0.5}, "mesh_exponent must be >= 1"),
    ],
)
def test_bad_stops_are_refused(kw, expected):
    with pytest.raises(ValueError, match=expected):
        Backlash(B, **kw)


def _run(model: mujoco.MjModel, seconds: float, joint: str, tendons: list[int]) -> tuple[float, np.ndarray, int]:
    """(largest |angle| of ``joint``, largest |length| of each tendon, warnings) under the sinusoid."""
    d = initial_data(model)
    n = int(round(seconds / model.opt.timestep))
    u = control_signal(model, SineControl(), np.arange(n) * model.opt.timestep)
    adr = model.joint(joint).qposadr[0]
    widest, most = np.zeros(len(tendons)), 0.0
    for i in range(n):
        d.ctrl[:] = u[i]
        mujoco.mj_step(model, d)
        widest = np.maximum(widest, np.abs(d.ten_length[tendons]))
        most = max(most, abs(float(d.qpos[adr])))
    assert np.isfinite(d.qpos).all()
    return most, widest, _warnings(d)


def test_reacher_runs_one_second_with_calibrated_stops_at_both_hinges():
    spec = mujoco.MjSpec.from_file(str(gym_model("reacher")))
    b = math.radians(5 / 60)
    out = add_backlash(spec, {"joint0": Backlash(b), "joint1": Backlash(b)})
    m = out.model
    elbow, widest, warnings = _run(m, 1.0, "joint1", [m.tendon(h.tendon).id for h in out.hinges.values()])
    twin = out.twin
    motor, load = m.joint("joint1__motor").id, twin.joint("joint1").id
    assert m.jnt_limited[motor] and m.jnt_range[motor].tolist() == twin.jnt_range[load].tolist()  # the limit copied
    twin.opt.timestep = m.opt.timestep
    twin_elbow, _, twin_warnings = _run(twin, 1.0, "joint1", [])
    assert warnings == 0 and twin_warnings == 0
    # the elbow's soft limit (+-3 rad) stops the link where it stopped the twin's (3.19 rad at this step): the load
    # is within +-b of its motor, and the motor carries the limit (MuJoCo's default stop let it reach 10 rad)
    assert abs(elbow - twin_elbow) < 2 * b
    # each band closes (the motor drives its link through the stop) and opens by no more than the stop's
    # penetration under the 200 N m drive; 3 b bounds it (measured 1.1 b and 1.9 b)
    assert (widest >= b).all() and (widest < 3 * b).all()


def test_cli_takes_the_mesh_and_the_recipe_and_reports_the_stop_against_the_law(tmp_path, capsys):
    argv = ["retrofit", str(gym_model("reacher"))]
    mesh = "joint1:backlash_arcmin=5,mesh_stiffness=2e3,restitution=0.9"
    assert main([*argv, "--out", str(tmp_path / "cal"), "--joint", mesh]) == 0
    written = mujoco.MjModel.from_xml_path(str(tmp_path / "cal" / "model.xml"))
    report = (tmp_path / "cal" / "retrofit.md").read_text()
    assert "| joint1 | calibrated | 2000 | 0.9 | 1 |" in report and "goal 5 %; met" in report
    assert "the band 2b crossed from rest" in report and "lowered from the model's 0.01 s" in report
    assert written.opt.timestep < 0.01 and written.tendon_solref_lim[0, 0] < 0  # direct mode: -stiffness
    assert main([*argv, "--out", str(tmp_path / "rec"), "--joint", mesh, "--backlash-stop", "recipe"]) == 0
    recipe = mujoco.MjModel.from_xml_path(str(tmp_path / "rec" / "model.xml"))
    assert recipe.opt.timestep == 0.01 and recipe.tendon_solref_lim[0].tolist() == [0.02, 1.0]
    assert "recipe (MuJoCo's default limit)" in (tmp_path / "rec" / "retrofit.md").read_text()
    capsys.readouterr()


@pytest.mark.parametrize(
    ("joint", "expected"),
    [
        ("joint0:backlash_arcmin=5,mesh_stiffness=0", "mesh_stiffness must be > 0"),
        ("joint0:backlash_arcmin=5,restitution=1.5", "restitution must be in (0, 1]"),
        ("joint0:mesh_stiffness=1e4", "give backlash_arcmin too"),
        ("joint0:backlash_arcmin=5,mesh_stiffness=1e12", "give a smaller mesh_stiffness"),
    ],
)
def test_cli_refuses_a_bad_mesh_before_any_work(tmp_path, capsys, joint, expected):
    out = tmp_path / "out"
    assert main(["retrofit", str(gym_model("reacher")), "--out", str(out), "--joint", joint]) == 2
    err = capsys.readouterr().err
    assert expected in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


def test_a_narrow_band_closing_fast_fits_as_a_wide_one():
    """The fit's scene is one impact on one stop: a band crossed in a step (UR5e's wrist at 0.1': 5.8e-5 rad
    against ~1e-4 rad per step at 1e3 rad/s and 1e-7 s) must not reach its far stop before the impact separates."""
    from clearance.contact_calibration.torsional_stop import MeshLaw, fit_stop, stop_speeds

    law, inertia, step = MeshLaw(1e4, 0.8, 1.0), 1.3e-8, 1e-7
    speeds = stop_speeds(1e3)
    assert speeds[-1] * step > 2 * math.radians(0.1 / 60)  # the fastest closing crosses the narrow band in a step
    narrow, wide = (
        fit_stop(law, inertia=inertia, half_width=b, speeds=speeds, timestep=step)
        for b in (math.radians(0.1 / 60), 1.0)
    )
    # the same scene but for where its stop sits: equal up to the rounding of the positions (b - q)
    assert narrow.stiffness == pytest.approx(wide.stiffness, rel=1e-6)
    assert narrow.damping == pytest.approx(wide.damping, rel=1e-6)
