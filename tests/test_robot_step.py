"""Backlash at the robot's own time step (`clearance.retrofit.robot_step`, `clearance.retrofit.step_stop`).

The flywheel of tests/test_backlash_stop.py at two steps inside the feasible region (0.5 ms with
a 12' band, 1 ms with 100': the smallest bands `smallest_common_band` finds there, measured in
benchmarks/robot_step_feasibility.md): its load set spinning into the step-limited stop while
the motor stands, rebound and impulse per impact against the same flywheel closed by the
compiled exact stop at its fine step. A band outside the region is refused, and the step and the
band the refusal names are each accepted when asked for. The written model's band is the
requested number, bitwise: it is copied, never fitted; ``clearance run --model`` runs it at the step.
"""

from __future__ import annotations

import math
import re

import mujoco
import pytest
from cli_runner import run_cli as _cli
from test_backlash_stop import FLYWHEEL, J_EFF

from clearance import contact_plugin
from clearance.contact_calibration.torsional_stop import MeshLaw
from clearance.retrofit import Backlash
from clearance.retrofit.backlash import add_backlash, stop_plugin_name
from clearance.retrofit.play import RetrofitError
from clearance.retrofit.robot_step import ROBOT_STEP_STOP, add_robot_step_backlash
from clearance.retrofit.step_stop import MAX_PENETRATION, fit_step_stop, step_impact

pytestmark = pytest.mark.skipif(not contact_plugin.is_available(), reason="compiled contact plugin not built")

INSIDE = [(0.5e-3, 12.0), (1e-3, 100.0)]  # (step [s], band [arcmin]) inside the region (module docstring)
SPEEDS = (0.3, 1.0, 2.5)  # rad/s: closing speeds over the flywheel's sizing motion's range (0.4-2.9 rad/s)


def _impact(model: mujoco.MjModel, speed: float) -> tuple[float, float, float]:
    """(rebound, impulse / (J v), deepest penetration [rad]) of the load closing on the stop at ``speed``.

    The stop's torque on the load is the tendon limit's row force, or the exact stop's plugin
    sensor; the load starts at the band's centre, the motor standing.
    """
    d = mujoco.MjData(model)
    load, motor = model.joint("shaft").dofadr[0], model.joint("shaft__motor").dofadr[0]
    tendon = model.tendon("clr_shaft__backlash").id
    b = math.radians(0.5) if not model.tendon_limited[tendon] else float(model.tendon_range[tendon, 1])
    plugin = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, stop_plugin_name("shaft"))
    h = float(model.opt.timestep)
    d.qvel[load] = speed
    impulse, deepest, touched = 0.0, 0.0, False
    for _ in range(int(20 * b / speed / h) + 20000):
        mujoco.mj_step(model, d)  # efc and sensors describe the state the step started from
        if plugin >= 0:
            torque = -float(d.sensordata[model.sensor_adr[plugin] + 1])  # the load's torque, -s T
        else:
            torque = sum(float(d.efc_force[i]) for i in range(d.nefc) if d.efc_id[i] == tendon)
        if torque > 0:
            touched = True
            impulse += torque * h
        deepest = max(deepest, float(d.qpos[load] - d.qpos[motor]) - b)
        if touched and torque == 0:
            break
    assert touched
    return -float(d.qvel[load] - d.qvel[motor]) / speed, impulse / (J_EFF * speed), deepest


@pytest.fixture(scope="module")
def exact():
    """The flywheel closed by the exact stop at its fine step (the plugin; band 30', irrelevant to an impact)."""
    return add_backlash(mujoco.MjSpec.from_string(FLYWHEEL), {"shaft": Backlash(math.radians(0.5), stop="exact")})


@pytest.mark.parametrize(("step", "arcmin"), INSIDE)
def test_fitted_stop_follows_the_fine_step_exact_stop_on_the_flywheel(exact, step, arcmin):
    out = add_robot_step_backlash(
        mujoco.MjSpec.from_string(FLYWHEEL), {"shaft": Backlash.from_arcmin(arcmin)}, robot_step=step
    )
    model = out.retrofit.model
    assert model.opt.timestep == step and out.retrofit.twin.opt.timestep == step
    assert model.nplugin == 0 and out.retrofit.hinges["shaft"].stop.kind == ROBOT_STEP_STOP
    band = out.bands["shaft"]
    assert band.smallest_band <= band.half_width  # inside the region, as the docstring says
    for v in SPEEDS:
        ref_rebound, ref_impulse, _ = _impact(exact.model, v)
        rebound, impulse, deepest = _impact(model, v)
        # 3 %: the fit's own worst onset phase is 1.4 % in rebound and 0.7 % in impulse (the 1-DOF scene,
        # step_stop.PHASES); an impact in the model starts at another phase, between the sampled ones
        assert rebound == pytest.approx(ref_rebound, rel=0.03)
        assert impulse == pytest.approx(ref_impulse, rel=0.03)
        # the penetration per speed is the fitted stop's worst phase p h, up to 5 % for phases between samples
        assert deepest <= 1.05 * out.stop.penetration * v
        if v <= band.closing_speed:
            assert deepest <= 1.05 * MAX_PENETRATION * band.half_width


def test_step_limited_stop_is_one_dimensionless_stop():
    law = MeshLaw(1e4, 0.8)
    a, b = (fit_step_stop(law, timestep=h, integrator=0, inertia=1e-3, speed=1.0) for h in (1e-3, 2e-3))
    # the same system in units of the step: zeta and p = penetration / h agree to the fit's xtol (1e-10 in log zeta)
    assert a.dampratio == pytest.approx(b.dampratio, rel=1e-6)
    assert a.penetration / a.timestep == pytest.approx(b.penetration / b.timestep, rel=1e-6)
    # and at any inertia: the impedance 0.99 scales MuJoCo's regulariser with the inverse weight (rounding only)
    light, heavy = (
        step_impact(dampratio=a.dampratio, timestep=1e-3, integrator=0, phase=0.3, inertia=j) for j in (1e-4, 1.0)
    )
    assert light.rebound == pytest.approx(heavy.rebound, rel=1e-9)
    assert light.penetration == pytest.approx(heavy.penetration, rel=1e-9)


def test_band_outside_the_region_is_refused_naming_a_usable_step_and_band():
    spec = mujoco.MjSpec.from_string(FLYWHEEL)
    with pytest.raises(RetrofitError) as err:
        add_robot_step_backlash(spec, {"shaft": Backlash.from_arcmin(5)}, robot_step=1e-3)
    text = str(err.value)
    assert "\n" not in text and "not represented at a 1 ms step" in text
    step = float(re.search(r"largest usable step for these bands is ([0-9.e+-]+) ms", text).group(1))
    band = float(re.search(r"the smallest band is ([0-9.e+-]+) arcmin", text).group(1))
    assert step < 1.0 and band > 5.0
    # each answer is accepted when asked for: the same sizing motion runs again at it
    add_robot_step_backlash(spec, {"shaft": Backlash.from_arcmin(5)}, robot_step=step * 1e-3)
    add_robot_step_backlash(spec, {"shaft": Backlash.from_arcmin(band)}, robot_step=1e-3)


def test_cli_writes_the_requested_band_exactly_and_refuses_outside(tmp_path, capsys):
    source = tmp_path / "flywheel.xml"
    source.write_text(FLYWHEEL)
    out = tmp_path / "out"
    argv = ["retrofit", str(source), "--out", str(out), "--robot-step", "0.5"]
    code, stdout, err = _cli([*argv, "--joint", "shaft:backlash_arcmin=12"], capsys)
    assert code == 0, err
    written = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    b = Backlash.from_arcmin(12).half_width
    tendon = written.tendon("clr_shaft__backlash").id
    assert written.tendon_range[tendon, 0] == -b and written.tendon_range[tendon, 1] == b  # copied: bitwise
    assert written.opt.timestep == 5e-4 and written.nplugin == 0
    assert mujoco.MjModel.from_xml_path(str(out / "original.xml")).opt.timestep == 5e-4
    assert "At the robot's step (0.5 ms)" in (out / "retrofit.md").read_text() and "step-limited stop" in stdout
    run = tmp_path / "run"
    code, stdout, err = _cli(["run", "--model", str(out), "--duration-ms", "600", "--out", str(run)], capsys)
    assert code == 0, err
    assert "at h = 500 µs (the model's own 500 µs)" in stdout and "impacts at its ends" in stdout
    refused = tmp_path / "refused"
    code, _, err = _cli(
        ["retrofit", str(source), "--out", str(refused), "--robot-step", "2", "--joint", "shaft:backlash_arcmin=5"],
        capsys,
    )
    assert code == 2 and err.count("\n") == 1 and "not represented at a 2 ms step" in err
    assert not refused.exists()


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--robot-step", "0"], "--robot-step"),
        (["--robot-step", "nan"], "--robot-step"),
        (["--robot-step", "1", "--backlash-stop", "exact"], "give one of the two"),
    ],
)
def test_cli_refuses_bad_robot_steps_before_any_work(tmp_path, capsys, extra, expected):
    source = tmp_path / "flywheel.xml"
    source.write_text(FLYWHEEL)
    out = tmp_path / "out"
    code, _, err = _cli(
        ["retrofit", str(source), "--out", str(out), "--joint", "shaft:backlash_arcmin=12", *extra], capsys
    )
    assert code == 2 and expected in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()
