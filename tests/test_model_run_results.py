"""Run results a robotics user can read (`clearance run --model`): a start-up window with steady-state
statistics after it, contact statistics from every step when the rows are thinned, deviations in a
floating base's frame, and the twin against itself nudged by rounding (chaos or play).

gymnasium's reacher (a fixed base) and hopper (a planar floating base: rootx, rootz, rooty), with
coarse rings or the exact contact so that each run is a few thousand steps.
"""

from __future__ import annotations

import csv

import mujoco
import numpy as np
import pytest
from cli_runner import run_cli
from gym_assets import gym_model

from clearance.analysis.metrics.site_deviation import add_frame_outputs
from clearance.analysis.metrics.summary import summary_of_series
from clearance.model import Material
from clearance.results import SimulationResult
from clearance.retrofit import RadialPlay, RetrofitOptions, SineControl, retrofit, write_retrofit
from clearance.run.play_candidates import floating_base
from clearance.run.retrofit_rows import default_output_interval, row_bytes
from clearance.run.retrofitted import load_retrofitted, simulate_retrofitted
from clearance.run.sensitivity import CHAOS_SHARE, Sensitivity, is_chaos, twin_sensitivity

POLYMER = Material(2.4e9, 0.4)


def _retrofit(name: str, hinges: list[str], out, **options) -> None:
    path = gym_model(name)
    play = RadialPlay.make(2e-4, 0.01, bearing_material=POLYMER, journal_material=POLYMER)
    defaults = {"contact_mode": "nominal", "segments": 32, "accept_inaccurate": True}  # fast, coarse rings
    r = retrofit(
        mujoco.MjSpec.from_file(str(path)),
        dict.fromkeys(hinges, play),
        RetrofitOptions(measure_speed=False, sizing_duration=0.3, **(defaults | options)),
    )
    write_retrofit(r, out, source_dir=path.parent)


@pytest.fixture(scope="module")
def reacher(tmp_path_factory):
    out = tmp_path_factory.mktemp("reacher")
    _retrofit("reacher", ["joint0", "joint1"], out)
    return out


def _summary(path) -> dict[str, dict[str, float]]:
    with open(path) as f:
        return {row["joint"]: {k: float(v) for k, v in row.items() if k != "joint"} for row in csv.DictReader(f)}


def test_the_startup_window_splits_the_statistics_and_thinning_keeps_them(reacher, tmp_path, capsys):
    base = ["run", "--model", str(reacher), "--duration-ms", "60", "--startup-ms", "20", "--site", "fingertip"]
    code, every, err = run_cli([*base, "--output-every-us", "0", "--out", str(tmp_path / "every")], capsys)
    assert code == 0, err
    code, thinned, err = run_cli([*base, "--output-every-us", "50", "--out", str(tmp_path / "thin")], capsys)
    assert code == 0, err
    assert "steady state after the first 20 ms" in every and "joint0, after 20 ms: peak force" in every
    full = SimulationResult.load(tmp_path / "every" / "result")
    thin = SimulationResult.load(tmp_path / "thin" / "result")
    h = load_retrofitted(reacher).manifest.timestep
    assert len(full.times) == round(0.06 / h) and len(thin.times) == round(0.06 / 50e-6)  # one row in 10
    rows = _summary(tmp_path / "every" / "summary.csv")
    for name, row in rows.items():
        j = full.joints[name]
        # the steady values are those of the rows after the window, every step kept here
        expect = summary_of_series(name, full.times, j.penetration, j.force_magnitude, startup=0.02)
        assert row["startup_window"] == 0.02
        for key in ("steady_peak_force", "steady_p95_force", "steady_max_penetration", "steady_contact_fraction"):
            assert row[key] == pytest.approx(getattr(expect, key), rel=1e-5)  # the CSV's 6 digits
        assert row["steady_impacts"] == expect.steady_impacts >= 0
        assert row["impacts"] >= row["steady_impacts"] and row["peak_force"] >= row["steady_peak_force"]
    # thinned rows, statistics from every step: the same summary, a tenth of the rows
    np.testing.assert_equal(_summary(tmp_path / "thin" / "summary.csv"), rows)  # NaN (no ideal output) equals NaN
    report = (tmp_path / "thin" / "report.md").read_text()
    assert "start-up window: the first 20 ms" in report and "(thinned)" in report
    assert "| joint0 | after 20 ms |" in report
    assert "## Chaos or play" in report and "the deviation is the play's" in report


def test_the_default_window_is_a_sinusoid_period_and_a_longer_one_is_refused(reacher, tmp_path, capsys):
    code, out, err = run_cli(["run", "--model", str(reacher), "--sine-frequency-hz", "40", "--duration-ms", "60",
                              "--out", str(tmp_path / "a")], capsys)  # fmt: skip
    assert code == 0, err
    assert "steady state after the first 250 ms" not in out and "no steady state" in out  # 0.25 s > 60 ms
    code, out, err = run_cli(["run", "--model", str(reacher), "--duration-ms", "50", "--startup-ms", "50",
                              "--out", str(tmp_path / "b")], capsys)  # fmt: skip
    assert code == 2 and "--startup-ms 50: the start-up window must be shorter than the run (50 ms)" in err
    assert not (tmp_path / "b").exists()


def test_default_rows_keep_a_six_hinge_second_under_the_budget():
    model = mujoco.MjModel.from_xml_path(str(gym_model("half_cheetah")))  # 8 bodies and the world
    per_row = row_bytes(model, 6, 1, 0)
    model.opt.timestep = 2e-6  # the exact contact's step on it (benchmarks/retrofit_corpus.md)
    interval = default_output_interval(model, 1.0, per_row, 20e6)
    assert interval is not None and interval == pytest.approx(round(interval / 2e-6) * 2e-6)  # whole steps
    assert round(1.0 / interval) * per_row <= 20e6 < round(1.0 / (interval - 2e-6)) * per_row  # the fewest cut
    assert default_output_interval(model, 1e-3, per_row, 20e6) is None  # a short run keeps every step


def test_a_floating_base_gets_its_frame_and_a_fixed_one_does_not(tmp_path, capsys):
    hopper = mujoco.MjModel.from_xml_path(str(gym_model("hopper")))
    assert floating_base(hopper, "foot") == "torso"
    assert floating_base(mujoco.MjModel.from_xml_path(str(gym_model("reacher"))), "fingertip") is None
    _retrofit("hopper", ["foot_joint"], tmp_path / "hopper", contact_mode="exact", segments=None)
    code, out, err = run_cli(["run", "--model", str(tmp_path / "hopper"), "--duration-ms", "40", "--startup-ms",
                              "10", "--out", str(tmp_path / "run")], capsys)  # fmt: skip
    assert code == 0, err
    assert "foot in the frame of its floating base torso: deviation from the twin up to" in out
    assert "the world position carries where the floating base torso went" in out
    rows = list(csv.DictReader(open(tmp_path / "run" / "site_deviation.csv")))
    assert {r["output"] for r in rows} >= {"site/foot/x", "site/foot/in torso/x"}
    report = (tmp_path / "run" / "report.md").read_text()
    assert "in the frame of its floating base torso" in report and "includes where the base went" in report


def test_frame_outputs_are_the_point_in_the_bodys_frame():
    model = mujoco.MjModel.from_xml_path(str(gym_model("hopper")))
    data = mujoco.MjData(model)
    data.qpos[:] = [0.1, 1.2, 0.3, -0.2, -0.4, 0.5]  # any pose: x, z, pitch and the three leg joints
    mujoco.mj_kinematics(model, data)
    torso, foot = model.body("torso").id, model.body("foot").id
    run = SimulationResult.__new__(SimulationResult)
    run.metadata = {"bodies": [model.body(b).name for b in range(model.nbody)]}
    run.body_poses = np.concatenate([data.xpos, data.xquat], axis=1)[None]
    run.outputs = {f"site/foot/{a}": np.array([data.xpos[foot, k]]) for k, a in enumerate("xyz")}
    names = add_frame_outputs(run, "foot", "torso")
    local = data.xmat[torso].reshape(3, 3).T @ (data.xpos[foot] - data.xpos[torso])
    np.testing.assert_allclose([run.outputs[n][0] for n in names], local, atol=1e-15)  # two roundings of 1 m


def test_the_nudged_twin_starts_where_it_was_told_and_chaos_is_called_at_a_tenth(reacher):
    loaded = load_retrofitted(reacher)
    drive = SineControl(0.5, 2.0)
    twin = simulate_retrofitted(loaded, drive, 0.01, twin=True, sites=["fingertip"])
    nudged = twin_sensitivity(loaded, drive, twin, "fingertip", perturbation=1e-6)
    # both hinges 1 urad off, the arm straight: the tip (0.21 m from the shoulder, 0.11 m from the elbow) moves
    # 1e-6 x 0.32 m, to the second order of the angle (1e-6 relative)
    assert nudged.distance[0] == pytest.approx(1e-6 * (0.21 + 0.11), rel=1e-5)
    rounding = twin_sensitivity(loaded, drive, twin, "fingertip")
    assert rounding.max_distance < 1e-9  # the reacher is not chaotic over 10 ms: rounding stays at rounding
    s = Sensitivity("tip", 1e-12, np.zeros(1), np.array([1.0]))
    assert is_chaos(s, 1.0 / CHAOS_SHARE) and not is_chaos(s, 1.01 / CHAOS_SHARE)
