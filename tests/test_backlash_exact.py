"""The exact backlash stop (`Backlash.stop = 'exact'`): the gear mesh's law in the compiled plugin.

The flywheel of tests/test_backlash_stop.py (its MJCF imported) is given backlash closed by the
plugin `clearance.backlash_stop`; its load side is set spinning towards the stop at known
speeds over a decade while the motor stands, and the stop's peak torque and restitution are
compared with the 1-DOF impact of the law (`impact.law_impact`, Lankarani–Nikravesh with n = 1)
at the effective inertia worked out by hand. The goal is the issue's for the compiled exact
law: within 1 % at every speed. The same retrofitted model is then run at four times the
inertia (armature and wheel both scaled in the compiled model, nothing refitted): the exact
stop is the law at any inertia, where the fitted spring-damper's rebound drifts with it
(tests/test_backlash_stop.py). gymnasium's reacher with exact stops at both hinges runs half a
second without a MuJoCo warning, and the run's readout reads the plugin's torque.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from gym_assets import gym_model
from test_backlash_stop import ARMATURE, FLYWHEEL, J_EFF, SPEEDS, WHEEL_MASS, B

from clearance import contact_plugin
from clearance.contact_calibration import laws
from clearance.contact_calibration.impact import law_impact
from clearance.contact_calibration.torsional_stop import OMEGA_H
from clearance.model import ContactLaw
from clearance.retrofit import Backlash, SineControl
from clearance.retrofit.backlash import add_backlash, stop_plugin_name
from clearance.retrofit.manifest import BacklashRecord
from clearance.retrofit.motion import control_signal, initial_data
from clearance.run.backlash_readout import BacklashReader, add_backlash_sensors

pytestmark = pytest.mark.skipif(not contact_plugin.is_available(), reason="compiled contact plugin not built")

GOAL = 0.01  # the goal for the compiled exact law: peak torque and restitution within 1 %


def _flywheel(stiffness: float, restitution: float):
    spec = mujoco.MjSpec.from_string(FLYWHEEL)
    return add_backlash(spec, {"shaft": Backlash(B, mesh_stiffness=stiffness, restitution=restitution, stop="exact")})


def _impact(model: mujoco.MjModel, speed: float, stiffness: float, restitution: float) -> tuple[float, float, int]:
    """(peak stop torque [N m], restitution [-], warnings) of the load closing on the stop at ``speed``; every
    step in contact checks the plugin's torque against `laws.mesh_torque` at the plugin's own d, d' and d'0."""
    d = mujoco.MjData(model)
    load, motor = model.joint("shaft").dofadr[0], model.joint("shaft__motor").dofadr[0]
    adr = int(model.sensor(stop_plugin_name("shaft")).adr[0])
    d.qvel[load] = speed
    peak, touched = 0.0, False
    for _ in range(int(10 * B / speed / model.opt.timestep)):
        mujoco.mj_step(model, d)
        torque, delta, rate, vin = (
            d.sensordata[adr],
            d.sensordata[adr + 2],
            d.sensordata[adr + 3],
            d.sensordata[adr + 4],
        )
        if delta > 0:
            touched = True
            peak = max(peak, float(torque))
            # the plugin's torque is laws.mesh_torque at its own d, d' and approach speed: the same few
            # operations in C and in Python (measured equal); 1e-12 leaves thousands of ulps
            expected = laws.mesh_torque(delta, rate, vin, stiffness=stiffness, restitution=restitution)
            assert torque == pytest.approx(expected, rel=1e-12, abs=1e-12)
        elif touched:
            break
    # the sensor's impact peak: the largest of the same torques (measured equal)
    assert touched and peak == pytest.approx(d.sensordata[adr + 7], rel=1e-12)
    return peak, -float(d.qvel[load] - d.qvel[motor]) / speed, int(sum(w.number for w in d.warning))


@pytest.mark.parametrize("stiffness, restitution", [(1e4, 0.8), (3e3, 0.9)])
def test_flywheel_exact_stop_is_the_law_within_1_percent_at_two_inertias(stiffness, restitution):
    out = _flywheel(stiffness, restitution)
    m = out.model
    stop = out.hinges["shaft"].stop
    assert stop.kind == "exact" and stop.fit is None and not m.tendon_limited[0]  # no limit: the plugin stops it
    # the mass matrix's inverse along the band: J_EFF leaves out the motor body's 1e-12 kg m^2 placeholder inertia,
    # 3.6e-10 of J_EFF (measured; rounding adds ~1e-16)
    assert stop.inertia == pytest.approx(J_EFF, rel=1e-9)
    # the step rule of the calibrated stop: omega*h <= OMEGA_H at the band's inertia
    assert m.opt.timestep * math.sqrt(stiffness / J_EFF) <= OMEGA_H
    # the same retrofitted spec (the same stop, the same step), four times the inertia on both sides of the band
    spec = out.spec.copy()
    spec.body("wheel").first_geom().mass = 4 * WHEEL_MASS
    spec.joint("shaft__motor").armature = 4 * ARMATURE
    heavy = spec.compile()
    assert heavy.opt.timestep == m.opt.timestep
    for model, inertia in ((m, J_EFF), (heavy, 4 * J_EFF)):
        for v in SPEEDS:
            law = law_impact(
                ContactLaw.LANKARANI_NIKRAVESH,
                mass=inertia,
                speed=float(v),
                stiffness=stiffness,
                restitution=restitution,
                exponent=1,
            )
            peak, e, warnings = _impact(model, float(v), stiffness, restitution)
            assert warnings == 0
            where = f"{v:.3g} rad/s at J = {inertia:.4g} kg m^2"
            assert peak == pytest.approx(law.peak_force, rel=GOAL), where  # GOAL: the 1 %
            assert e == pytest.approx(law.restitution, rel=GOAL), where  # GOAL: the 1 %


def test_reacher_runs_half_a_second_with_exact_stops_and_the_readout_reads_the_plugin():
    b = math.radians(5 / 60)
    out = add_backlash(
        mujoco.MjSpec.from_file(str(gym_model("reacher"))),
        {"joint0": Backlash(b, stop="exact"), "joint1": Backlash(b, stop="exact")},
    )
    records = [
        BacklashRecord(h.name, h.motor_joint, h.motor_body, h.tendon, h.backlash.half_width, h.actuators, h.stop.kind)
        for h in out.hinges.values()
    ]
    spec = out.spec.copy()
    add_backlash_sensors(spec, records)  # adds nothing for an exact stop: its plugin's sensor is there
    assert len(spec.sensors) == len(out.spec.sensors)
    m = spec.compile()
    assert not m.tendon_limited.any()  # no tendon limit: the plugins are the stops
    reader = BacklashReader(m, records)
    d = initial_data(m)
    n = int(round(0.5 / m.opt.timestep))
    u = control_signal(m, SineControl(), np.arange(n) * m.opt.timestep)
    sens, q = np.zeros((n, m.nsensordata)), np.zeros((n, m.nq))
    for i in range(n):
        d.ctrl[:] = u[i]
        mujoco.mj_step(m, d)
        sens[i], q[i] = d.sensordata, d.qpos
    assert sum(w.number for w in d.warning) == 0 and np.isfinite(d.qpos).all()
    got = reader.read(sens, q)
    for h in out.hinges.values():
        angle, torque = got[f"backlash/{h.name}/angle"], got[f"backlash/{h.name}/torque"]
        adr = int(m.sensor(stop_plugin_name(h.name)).adr[0])
        assert np.array_equal(torque, sens[:, adr])  # the plugin's torque T >= 0, read as it is: copied, exact
        # each band closes (the motor drives its link through the stop, which pushes back) and opens past b only by
        # the stop's penetration under the 200 N m drive: 3 b bounds it, as for the calibrated stop
        # (tests/test_backlash_stop.py)
        assert torque.max() > 0 and b <= np.abs(angle).max() < 3 * b


@pytest.mark.parametrize(
    ("kw", "expected"),
    [
        ({"half_width": -1.0}, "half_width must be > 0"),
        ({"stiffness": math.inf}, "stiffness must be a finite number"),
        ({"restitution": 1.5}, "restitution must be in [0, 1]"),
        ({"load_joint": "nope"}, "load_joint = 'nope' is not a hinge"),
        ({"motor_joint": "shaft"}, "load_joint and motor_joint are both 'shaft'"),
    ],
)
def test_add_backlash_stop_refuses_bad_attributes_before_compiling(kw, expected):
    from clearance.contact_plugin.backlash_stop import add_backlash_stop

    spec = mujoco.MjSpec.from_string(FLYWHEEL)
    args = {"load_joint": "shaft", "motor_joint": "other", "half_width": B, "stiffness": 1e4, "restitution": 0.8}
    spec.body("wheel").add_body(name="rotor").add_joint(name="other", type=mujoco.mjtJoint.mjJNT_HINGE)
    with pytest.raises(ValueError, match=expected.replace("[", r"\[").replace("]", r"\]")):
        add_backlash_stop(spec, name="stop", **{**args, **kw})
    assert not list(spec.plugins)


def test_cli_writes_an_exact_stop_that_the_written_model_and_manifest_keep(tmp_path, capsys):
    from clearance.cli import main
    from clearance.retrofit.manifest import read_manifest

    out = tmp_path / "exact"
    mesh = "joint1:backlash_arcmin=5,mesh_stiffness=2e3,restitution=0.9"
    argv = ["retrofit", str(gym_model("reacher")), "--out", str(out), "--joint", mesh, "--backlash-stop", "exact"]
    assert main(argv) == 0
    report = (out / "retrofit.md").read_text()
    assert "| joint1 | exact (the law, compiled plugin) | 2000 | 0.9 | 1 |" in report
    assert "lowered from the model's 0.01 s" in report  # the calibrated stop's step rule applies
    written = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    assert written.nplugin == 1 and not written.tendon_limited.any() and written.opt.timestep < 0.01
    (record,) = read_manifest(out).backlash
    assert record.stop == "exact"
    capsys.readouterr()
