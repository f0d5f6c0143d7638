"""Running a backlash retrofit: `clearance run --model DIR` on gymnasium's reacher with backlash at both hinges.

The calibrated stops lower the reacher's 10 ms step to 6 µs (`clearance.retrofit.backlash_stop`).
"""

from __future__ import annotations

import csv
import json
import math
from functools import partial

import mujoco
import numpy as np
import pytest
from chunking import assert_chunking_is_invisible
from gym_assets import gym_model

from clearance.cli import main
from clearance.retrofit import SineControl
from clearance.run.backlash_readout import torque_sensor_name
from clearance.run.retrofitted import load_retrofitted, simulate_retrofitted

B_ARCMIN = 30.0


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The reacher with 30' of backlash at both hinges, written by clearance retrofit."""
    out = tmp_path_factory.mktemp("reacher_backlash") / "r"
    joints = [f"joint{i}:backlash_arcmin={B_ARCMIN:g}" for i in (0, 1)]
    code = main(["retrofit", str(gym_model("reacher")), "--out", str(out), *sum((["--joint", j] for j in joints), [])])
    assert code == 0
    return out


def test_manifest_records_each_band_and_where_the_twins_coordinates_sit(folder):
    record = json.loads((folder / "retrofit.json").read_text())
    assert record["hinges"] == [] and [b["name"] for b in record["backlash"]] == ["joint0", "joint1"]
    loaded = load_retrofitted(folder)
    m = loaded.manifest
    assert m.backlash[1].half_width == pytest.approx(math.radians(B_ARCMIN / 60), rel=1e-12)  # JSON keeps 17 digits
    assert m.backlash[0].actuators == ("#0",) and m.backlash[0].motor_joint == "joint0__motor"
    model, twin = loaded.model, loaded.twin
    assert m.timestep == model.opt.timestep == twin.opt.timestep < 0.01  # the calibrated stops' step, below the model's
    for i in range(twin.njnt):  # every joint of the twin at its mapped place in the retrofitted model
        j = model.joint(twin.joint(i).name)
        assert m.qpos_map[int(twin.jnt_qposadr[i])] == int(j.qposadr[0])
        assert m.qvel_map[int(twin.jnt_dofadr[i])] == int(j.dofadr[0])


def test_backlash_outputs_are_the_tendon_length_and_the_stop_constraint_torque(folder):
    loaded = load_retrofitted(folder)
    drive = SineControl(0.5, 1.0)
    res = simulate_retrofitted(loaded, drive, 0.25)
    # the same model stepped by hand: the band's angle from qpos, the stop's torque from its constraint row
    model = loaded.model
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    from clearance.retrofit.drive import drive_controls

    ctrl = drive_controls(model, drive, res.times)
    tendon = model.tendon("clr_joint1__backlash").id
    angle, torque = [], []
    for i in range(len(res.times)):
        data.ctrl[:] = ctrl[i]
        warm = data.qacc_warmstart.copy()  # mj_forward overwrites the solver's warm start with its own solution
        mujoco.mj_forward(model, data)
        angle.append(data.ten_length[tendon])
        rows = [
            r
            for r in range(data.nefc)
            if data.efc_type[r] == mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON and data.efc_id[r] == tendon
        ]
        torque.append(abs(sum(data.efc_force[r] for r in rows)))
        data.qacc_warmstart[:] = warm
        mujoco.mj_step(model, data)
    # bitwise by construction: each mj_step starts from the state, controls and warm start mujoco.rollout's step
    # starts from (the warm start restored: left at mj_forward's solution, the two agree only while the solver stops
    # at once on it; a different warm start moved the angle up to 4e-8 rad, measured with a cold start every step),
    # and mj_forward at that state computes the ten_length and efc_force the readout's sensors copy
    np.testing.assert_array_equal(res.outputs["backlash/joint1/angle"], angle)
    np.testing.assert_array_equal(res.outputs["backlash/joint1/torque"], torque)
    assert max(torque) > 0  # the motion reaches the stop, so the comparison is not of zeros
    assert model.sensor(torque_sensor_name("joint1")).type == mujoco.mjtSensor.mjSENS_TENDONLIMITFRC


def test_cli_runs_a_backlash_retrofit_and_reports_angles_impacts_and_torques(folder, tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["run", "--model", str(folder), "--site", "fingertip", "--duration-ms", "300", "--out", str(out)])
    stdout = capsys.readouterr().out
    assert code == 0
    rows = list(csv.DictReader((out / "backlash_summary.csv").open()))
    assert [r["hinge"] for r in rows] == ["joint0", "joint1"]
    res = np.load(out / "result.npz")
    keys = set(res.files)
    for r in rows:
        angle = [k for k in keys if "backlash" in k and r["hinge"] in k and "angle" in k]
        assert angle, keys
        assert int(r["impacts"]) == int(r["impacts_upper"]) + int(r["impacts_lower"]) >= 1
        assert float(r["peak_torque"]) > 0
        assert f"{r['hinge']}: backlash angle in [" in stdout and "peak stop torque" in stdout
    report = (out / "report.md").read_text()
    assert "## Backlash at the actuated hinges" in report and "## Deviation of fingertip" in report
    assert "Contact at the retrofitted hinges" not in report  # no journals in this model
    assert (out / "backlash_joint0.png").stat().st_size > 0 and (out / "site_deviation.csv").is_file()
    assert "fingertip: deviation from the twin up to" in stdout


def test_the_pusher_with_backlash_at_every_actuated_hinge_runs_a_second(tmp_path, capsys):
    """Gymnasium's seven-joint arm, 5' at each hinge: one second without a MuJoCo warning (a warning stops the
    run with exit 2), every hinge's angle, impacts and stop torque reported."""
    from clearance.run.play_candidates import actuated_hinges

    path = gym_model("pusher")
    hinges = actuated_hinges(mujoco.MjModel.from_xml_path(str(path)))
    joints = sum((["--joint", f"{h}:backlash_arcmin=5"] for h in hinges), [])
    assert main(["retrofit", str(path), "--out", str(tmp_path / "r"), *joints]) == 0
    out = tmp_path / "run"
    code = main(["run", "--model", str(tmp_path / "r"), "--site", "tips_arm", "--out", str(out)])
    stdout = capsys.readouterr().out
    assert code == 0
    rows = list(csv.DictReader((out / "backlash_summary.csv").open()))
    assert [r["hinge"] for r in rows] == hinges and len(hinges) == 7
    assert all(int(r["impacts"]) > 0 and float(r["peak_torque"]) > 0 for r in rows)
    assert stdout.count("peak stop torque") == 7


def test_without_site_the_end_effector_is_reported(folder, tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["run", "--model", str(folder), "--duration-ms", "20", "--out", str(out)])
    stdout = capsys.readouterr().out
    assert code == 0
    # the reacher's deepest named body below joint0 and joint1 is its fingertip
    assert "fingertip: deviation from the twin up to" in stdout and "the end effector by default" in stdout
    assert (out / "site_deviation.csv").is_file()


def test_chunked_and_thinned_runs_of_the_retrofit_and_its_twin_are_one_run_bitwise(folder):
    # backlash (tendon limit rows): chunks carry the state and the solver's warm start (tests/test_chunked_runs.py)
    loaded = load_retrofitted(folder)
    h = loaded.manifest.timestep
    for twin in (False, True):
        assert_chunking_is_invisible(partial(simulate_retrofitted, loaded, SineControl(0.5, 2.0), twin=twin), h, 3000)
