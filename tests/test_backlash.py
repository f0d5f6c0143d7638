"""Backlash at actuated hinges: a motor side driving a load side through a dead band of +-b.

A flywheel driven from rest by a constant motor torque: the motor turns alone through the
band, then the stop (the tendon limit, calibrated) carries the load. gymnasium's reacher with
backlash at both actuated hinges (MuJoCo's default stop, the recipe) runs without warnings and
keeps its masses.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from cli_runner import run_cli as _cli
from gym_assets import gym_model

from clearance.retrofit import Backlash, RetrofitError
from clearance.retrofit.backlash import MOTOR_ARMATURE_FRACTION, MOTOR_MASS, add_backlash

FLYWHEEL = """<mujoco model="flywheel"><option timestep="0.0005"/>
<worldbody><body name="wheel" pos="0 0 0.1"><joint name="shaft" type="hinge" axis="0 0 1" armature="0.002"/>
<geom type="cylinder" size="0.1 0.01" mass="1"/></body>
<body name="free_wheel"><joint name="idle" type="hinge" axis="0 1 0"/><geom type="sphere" size="0.05"/></body>
</worldbody>
<actuator><motor name="drive" joint="shaft" gear="1"/></actuator>
<sensor><jointpos name="shaft_angle" joint="shaft"/></sensor>
<keyframe><key name="start" qpos="0.3 0.1"/></keyframe></mujoco>"""

B = math.radians(1.0)


@pytest.fixture(scope="module")
def flywheel():
    return add_backlash(mujoco.MjSpec.from_string(FLYWHEEL), {"shaft": Backlash(B)})


def _warnings(data: mujoco.MjData) -> int:
    return int(sum(w.number for w in data.warning))


def test_flywheel_load_lags_the_motor_in_the_band_then_hits_the_stop(flywheel):
    m = flywheel.model
    d = mujoco.MjData(m)
    load, motor = m.joint("shaft").qposadr[0], m.joint("shaft__motor").qposadr[0]
    d.ctrl[0] = 0.05  # N m
    lag = []
    for _ in range(int(round(0.2 / m.opt.timestep))):  # 0.2 s at the step the calibrated stop chose
        mujoco.mj_step(m, d)
        lag.append(d.qpos[motor] - d.qpos[load])
    lag = np.array(lag)
    first = int(np.argmax(lag >= B))
    assert lag[first] >= B, "the motor never took up the band"
    # before the stop the load does not move (nothing drives it): the lag is the motor's own travel, inside the band
    # 1e-12: rounding of a zero load angle (measured: the load stays at exactly 0, the lag is >= 2.2e-8 rad)
    assert (lag[:first] >= -1e-12).all() and (lag[:first] < B).all()
    # the calibrated stop's penetration: the motor closes the band at about sqrt(2 (0.05/0.002) b) = 0.93 rad/s and
    # the mesh law's largest penetration is v sqrt(J/K) = 3.5e-4 rad = 0.02 b (J = 1.4e-3 kg m^2, K = 1e4 N m/rad)
    assert lag.max() < 1.05 * B
    assert d.qpos[load] > 0.1  # rad; the stop carried the load: 0.05 N m over ~0.005 kg m^2 for ~0.15 s
    assert _warnings(d) == 0
    # the sensor stays on the load side
    assert m.sensor_objid[0] == m.joint("shaft").id
    mujoco.mj_forward(m, d)
    assert d.sensordata[0] == d.qpos[load]  # a jointpos sensor copies qpos: exact


def test_flywheel_edit_moves_the_armature_and_actuator_and_keeps_the_rest(flywheel):
    m, twin = flywheel.model, flywheel.twin
    h = flywheel.hinges["shaft"]
    assert h.actuators == ("drive",) and h.motor_armature == 0.002 and "moved" in h.armature_source
    assert m.actuator_trnid[0, 0] == m.joint("shaft__motor").id
    assert m.dof_armature[m.joint("shaft").dofadr[0]] == 0.0
    assert m.body(h.motor_body).mass[0] == MOTOR_MASS
    assert m.tendon_range[m.tendon(h.tendon).id].tolist() == [-B, B]
    # float sum rounding: two sums of ~1.5 kg (ulp 2.2e-16), 3 roundings of half an ulp at most, 3.3e-16 (measured
    # 8.9e-17); 1e-15 is 3x that bound and still 1e-3 of the 1e-12 kg motor
    assert np.isclose(m.body_mass.sum() - twin.body_mass.sum(), MOTOR_MASS, rtol=0, atol=1e-15)
    # keyframe: the twin's angles where their joints sit now, the motor at the load's angle
    key = m.key("start").qpos
    assert key[m.joint("shaft").qposadr[0]] == 0.3 and key[m.joint("shaft__motor").qposadr[0]] == 0.3
    assert key[m.joint("idle").qposadr[0]] == 0.1


SENSED = FLYWHEEL.replace(
    '<sensor><jointpos name="shaft_angle" joint="shaft"/></sensor>',
    '<sensor><jointpos name="shaft_angle" joint="shaft"/><jointvel name="shaft_speed" joint="shaft"/>'
    '<jointactuatorfrc name="shaft_torque" joint="shaft"/><jointpos name="idle_angle" joint="idle"/></sensor>',
)


@pytest.mark.parametrize("side", ["load", "motor"])
def test_sensors_stay_on_the_load_side_unless_asked_and_actuator_force_follows_the_actuator(side):
    out = add_backlash(mujoco.MjSpec.from_string(SENSED), {"shaft": Backlash(B, stop="recipe", sensors=side)})
    m = out.model
    on = {m.sensor(k).name: int(m.sensor_objid[k]) for k in range(m.nsensor)}
    state = m.joint("shaft__motor").id if side == "motor" else m.joint("shaft").id
    assert on["shaft_angle"] == state and on["shaft_speed"] == state
    assert on["shaft_torque"] == m.joint("shaft__motor").id  # the actuator's torque acts on the motor hinge now
    assert on["idle_angle"] == m.joint("idle").id  # another joint's sensor is untouched
    moved = {"shaft_torque"} | ({"shaft_angle", "shaft_speed"} if side == "motor" else set())
    assert set(out.hinges["shaft"].moved_sensors) == moved
    d = mujoco.MjData(m)
    d.ctrl[0] = 0.05  # N m
    mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)
    torque = d.sensordata[m.sensor("shaft_torque").adr[0]]
    assert torque == pytest.approx(0.05, rel=1e-12)  # the motor's torque, read where it acts: rounding only


def test_a_model_retrofitted_already_is_refused():
    once = add_backlash(mujoco.MjSpec.from_string(FLYWHEEL), {"shaft": Backlash(B, stop="recipe")})
    with pytest.raises(RetrofitError, match="is it retrofitted already.*cannot be stacked"):
        add_backlash(once.spec, {"shaft": Backlash(B, stop="recipe")})


def test_bad_sensor_side_is_refused():
    with pytest.raises(RetrofitError, match="sensors must be one of load, motor"):
        Backlash(B, sensors="encoder")


def test_flywheel_without_armature_gets_a_stated_fraction():
    spec = mujoco.MjSpec.from_string(FLYWHEEL.replace(' armature="0.002"', ""))
    out = add_backlash(spec, {"shaft": Backlash.from_arcmin(30)})
    h = out.hinges["shaft"]
    # the stated fraction of the wheel's inertia m r^2 / 2 = 0.005 kg m^2
    assert h.motor_armature == pytest.approx(MOTOR_ARMATURE_FRACTION * 0.005, rel=1e-9)  # cylinder inertia, rounding
    assert out.model.tendon_range[0, 1] == pytest.approx(math.radians(0.5), rel=1e-12)  # in memory: rounding only


def test_reacher_with_backlash_at_both_hinges_runs_without_warnings():
    spec = mujoco.MjSpec.from_file(str(gym_model("reacher")))
    recipe = {"joint0": Backlash.from_arcmin(5, stop="recipe"), "joint1": Backlash.from_arcmin(5, stop="recipe")}
    out = add_backlash(spec, recipe)
    m, twin = out.model, out.twin
    kept = [m.body(twin.body(i).name).id for i in range(twin.nbody)]
    # exact: each kept body's mass is compiled from its own geoms, by the same compiler in this process
    assert np.array_equal(m.body_mass[kept], twin.body_mass)
    assert m.nbody == twin.nbody + 2 and m.nu == twin.nu
    for name in ("joint0", "joint1"):  # the hinges' armature 1 and damping 1 (gymnasium's defaults) moved
        assert m.dof_armature[m.joint(f"{name}__motor").dofadr[0]] == 1.0
        assert m.dof_armature[m.joint(name).dofadr[0]] == 0.0
    d = mujoco.MjData(m)
    d.ctrl[:] = np.random.default_rng(0).uniform(-1, 1, m.nu)
    b = math.radians(5 / 60)
    pairs = [(m.joint(n).qposadr[0], m.joint(f"{n}__motor").qposadr[0]) for n in ("joint0", "joint1")]
    most = np.zeros(2)
    for _ in range(int(0.2 / m.opt.timestep)):
        mujoco.mj_step(m, d)
        most = np.maximum(most, [abs(d.qpos[load] - d.qpos[motor]) for load, motor in pairs])
    assert _warnings(d) == 0 and np.isfinite(d.qpos).all()
    # each motor took up its band and drove its link through the stop (the default stop at the model's 10 ms step
    # lets the band open to 3.2 b and 7.6 b here: what the calibrated stop is for)
    assert (most >= b).all()


@pytest.mark.parametrize(
    "joints, expected",
    [
        ({"nope": Backlash(B)}, "no joint of that name"),
        ({"idle": Backlash(B)}, "no actuator with joint="),
    ],
)
def test_bad_hinges_are_refused(joints, expected):
    with pytest.raises(RetrofitError, match=expected):
        add_backlash(mujoco.MjSpec.from_string(FLYWHEEL), joints)


def test_slide_is_refused():
    xml = FLYWHEEL.replace('name="idle" type="hinge"', 'name="idle" type="slide"')
    with pytest.raises(RetrofitError, match="is a slide joint: only a hinge can be given backlash"):
        add_backlash(mujoco.MjSpec.from_string(xml), {"idle": Backlash(B)})


@pytest.mark.parametrize("b", [-0.01, 0.0, math.nan, math.inf, math.radians(10.5)])
def test_bad_bands_are_refused(b):
    with pytest.raises(ValueError, match="half_width"):
        Backlash(b)


def test_cli_writes_the_reacher_with_backlash(tmp_path, capsys):
    out = tmp_path / "reacher"
    argv = ["retrofit", str(gym_model("reacher")), "--out", str(out)]
    code, stdout, err = _cli(
        [*argv, "--joint", "joint0:backlash_arcmin=5", "--joint", "joint1:backlash_arcmin=5"], capsys
    )
    assert code == 0, err
    written = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    twin = mujoco.MjModel.from_xml_path(str(out / "original.xml"))
    assert written.nq == twin.nq + 2 and written.ntendon == twin.ntendon + 2
    assert written.tendon_range[written.tendon("clr_joint1__backlash").id, 1] == pytest.approx(
        math.radians(5 / 60),
        rel=1e-6,  # MuJoCo's MJCF writer keeps 6 significant digits
    )
    report = (out / "retrofit.md").read_text()
    assert "| joint1 | 5 | joint1__motor |" in report and "| joint1 | calibrated | 10000 | 0.8 | 1 |" in report
    assert "moved to 'joint0__motor'" in stdout


def test_cli_puts_the_sensors_on_the_motor_side_when_asked(tmp_path, capsys):
    source = tmp_path / "flywheel.xml"
    source.write_text(SENSED)
    out = tmp_path / "out"
    argv = ["retrofit", str(source), "--out", str(out), "--joint", "shaft:backlash_arcmin=30"]
    code, stdout, err = _cli([*argv, "--backlash-stop", "recipe", "--backlash-sensors", "motor"], capsys)
    assert code == 0, err
    written = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    assert written.sensor_objid[written.sensor("shaft_angle").id] == written.joint("shaft__motor").id
    report = (out / "retrofit.md").read_text()
    assert "| shaft_angle, shaft_speed, shaft_torque |" in report and "--backlash-sensors motor" in report
    assert "sensors on the motor side: shaft_angle, shaft_speed, shaft_torque" in stdout


@pytest.mark.parametrize(
    ("joints", "expected"),
    [
        (["joint0:backlash_arcmin=5", "joint1"], "backlash and radial play cannot be mixed"),
        (["joint0:backlash_arcmin=5,clearance_mm=0.1"], "takes no radial play keys (got clearance_mm)"),
        (["joint0:backlash_arcmin=-1"], "backlash_arcmin must be in (0, 600]"),
        (["joint0:backlash_arcmin=601"], "backlash_arcmin must be in (0, 600]"),
        (["joint0:backlash_arcmin=nan"], "backlash_arcmin must be a finite number"),
        (["nope:backlash_arcmin=5"], "no joint of that name"),
    ],
)
def test_cli_refuses_bad_backlash_before_any_work(tmp_path, capsys, joints, expected):
    out = tmp_path / "out"
    argv = ["retrofit", str(gym_model("reacher")), "--out", str(out)]
    for j in joints:
        argv += ["--joint", j]
    code, _, err = _cli(argv, capsys)
    assert code == 2
    assert expected in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


NESTED = """<mujoco><worldbody>
<body name="base"><joint name="yaw" type="hinge" axis="0 0 1"/><geom type="sphere" size="0.1"/>
<body name="arm" pos="0.2 0 0"><joint name="pitch" type="hinge" axis="0 1 0"/><geom type="sphere" size="0.05"/></body>
</body>
<body name="other" pos="1 0 0"><joint name="roll" type="hinge" axis="1 0 0"/><geom type="sphere" size="0.05"/></body>
</worldbody>
<tendon><fixed name="coupler"><joint joint="roll" coef="1"/></fixed></tendon>
<actuator><motor joint="pitch"/><motor tendon="coupler"/></actuator>
<keyframe><key qpos="0.1 0.2 0.3" qvel="1 2 3"/></keyframe></mujoco>"""


def test_keyframes_follow_joints_whose_coordinates_moved():
    """The motor body of 'pitch' is a child of 'base', so 'roll' comes after it in the coordinates."""
    out = add_backlash(mujoco.MjSpec.from_string(NESTED), {"pitch": Backlash(B)})
    m = out.model
    assert m.joint("roll").qposadr[0] == 3  # moved from 2: the case the mapping exists for
    q, v = m.key_qpos[0], m.key_qvel[0]
    for name, angle, speed in (("yaw", 0.1, 1), ("pitch", 0.2, 2), ("roll", 0.3, 3), ("pitch__motor", 0.2, 2)):
        assert q[m.joint(name).qposadr[0]] == angle and v[m.joint(name).dofadr[0]] == speed


@pytest.mark.parametrize(
    ("xml", "joint", "expected"),
    [
        (NESTED, "roll", "drives it through a tendon"),
        (
            NESTED.replace('<joint name="pitch"', '<joint name="pitch2" type="slide"/><joint name="pitch"'),
            "pitch",
            "its body has 2 joints",
        ),
    ],
)
def test_tendon_drives_and_shared_bodies_are_refused(xml, joint, expected):
    with pytest.raises(RetrofitError, match=expected):
        add_backlash(mujoco.MjSpec.from_string(xml), {joint: Backlash(B)})
