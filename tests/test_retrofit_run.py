"""Running what `clearance retrofit` wrote: `clearance run --model DIR` and `simulate_retrofitted`.

gymnasium's reacher with radial play at both hinges (polymer bushing, nominal contact, 32
segments: a 5 µs step, so 50 ms of motion is 10,000 steps).
"""

from __future__ import annotations

import json
import shutil
from functools import partial

import mujoco
import numpy as np
import pytest
from chunking import assert_chunking_is_invisible
from cli_runner import run_cli as _cli
from gym_assets import gym_model

from clearance.analysis.metrics.site_deviation import site_deviation
from clearance.model import Material
from clearance.results import SimulationResult
from clearance.retrofit import RadialPlay, RetrofitError, RetrofitOptions, SineControl, retrofit, write_retrofit
from clearance.retrofit.drive import ControlTable, actuator_labels, drive_controls, read_control_file
from clearance.run.retrofitted import load_retrofitted, simulate_retrofitted
from clearance.run.simulation import SimulationError

POLYMER = Material(2.4e9, 0.4)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A written retrofit of the reacher, both hinges."""
    path = gym_model("reacher")
    spec = mujoco.MjSpec.from_file(str(path))
    play = RadialPlay.make(2e-4, 0.01, bearing_material=POLYMER, journal_material=POLYMER)
    r = retrofit(
        spec,
        {"joint0": play, "joint1": play},
        RetrofitOptions(
            contact_mode="nominal", segments=32, measure_speed=False, sizing_duration=0.3, accept_inaccurate=True
        ),  # a coarse ring (over its ripple bound) keeps the runs fast; these tests are about running it
    )
    out = tmp_path_factory.mktemp("reacher_retrofit")
    write_retrofit(r, out, source_dir=path.parent)
    return out


def test_manifest_records_the_time_step_and_each_hinge(folder):
    loaded = load_retrofitted(folder)
    m = loaded.manifest
    assert [h.name for h in m.hinges] == ["joint0", "joint1"]
    assert loaded.model.opt.timestep == loaded.twin.opt.timestep == m.timestep < m.original_timestep
    for h in m.hinges:
        for s in h.slides:
            assert mujoco.mj_name2id(loaded.model, mujoco.mjtObj.mjOBJ_JOINT, s) >= 0
        assert h.radial_clearance == 2e-4 and h.penetration_limit > 0


def test_cli_runs_the_model_and_its_twin_under_the_sinusoid(folder, tmp_path, capsys):
    out = tmp_path / "run"
    argv = [
        "run",
        "--model",
        str(folder / "model.xml"),
        "--duration-ms",
        "50",
        "--site",
        "fingertip",
        "--out",
        str(out),
    ]
    code, stdout, err = _cli(argv, capsys)
    assert code == 0, err
    assert "joint0, whole run: peak force" in stdout and "joint1, whole run: peak force" in stdout
    result = SimulationResult.load(out / "result")
    twin = SimulationResult.load(out / "ideal")
    h = load_retrofitted(folder).manifest.timestep
    # 50 ms of steps of h, one row each (no thinning asked for)
    assert len(result.times) == len(twin.times) == round(0.05 / h)
    assert result.body_poses.shape == (len(result.times), 5, 7)  # world + 4 bodies of the reacher
    # unit quaternions (MuJoCo normalises them; 1e-9 is round-off)
    assert np.abs(np.linalg.norm(result.body_poses[:, :, 3:], axis=2) - 1).max() < 1e-9
    for name, j in result.joints.items():
        assert j.penetration.max() > 0, f"{name}: the journal never touched its ring, the checks below say nothing"
        contact = j.force_magnitude > 0  # a row's contacts are found at its step: a first touch reads no force
        assert contact.sum() > 0.5 * (j.penetration > 0).sum()
        # the force on the journal points back to the centre: against e (cosine -1, 1e-3 for the
        # segments' polygon: a sphere segment's normal is off the radius by up to pi/N = 0.1 rad)
        cos = np.sum(j.contact_force[contact] * j.eccentricity[contact], axis=1)
        cos /= j.force_magnitude[contact] * np.hypot(*j.eccentricity[contact].T)
        assert cos.max() < -0.99
        # the slides' velocity is the eccentricity's rate: central differences agree to O(h^2 e''')
        de = np.gradient(j.eccentricity[:, 0], result.times)
        assert np.median(np.abs(de - j.eccentricity_rate[:, 0])) < 1e-2 * np.abs(j.eccentricity_rate[:, 0]).max()
    assert twin.joints == {} and "site/fingertip/x" in twin.outputs
    assert (out / "summary.csv").read_text().count("\n") == 3  # header + one row per hinge
    # the tip is a body of the reacher: its output is that body's pose's position
    tip = result.metadata["bodies"].index("fingertip")
    for a, axis in enumerate("xyz"):
        np.testing.assert_array_equal(result.body_poses[:, tip, a], result.outputs[f"site/fingertip/{axis}"])
    report = (out / "report.md").read_text()
    for figure in ("orbit_joint0.png", "orbit_joint1.png", "contact_force.png", "site_deviation_x.png"):
        assert f"({figure})" in report and (out / figure).stat().st_size > 10_000
    assert "planar play only" in report and "## Deviation of fingertip from the unmodified twin" in report
    assert "fingertip: deviation from the twin up to" in stdout


def test_site_deviation_statistics_are_those_of_the_two_runs(folder):
    loaded = load_retrofitted(folder)
    drive = SineControl(0.5, 2.0)
    result = simulate_retrofitted(loaded, drive, 0.05, sites=["fingertip"])
    twin = simulate_retrofitted(loaded, drive, 0.05, twin=True, sites=["fingertip"])
    dev = site_deviation(result, twin, "fingertip")
    assert set(dev.axes) == {"site/fingertip/x", "site/fingertip/y"}  # the reacher moves in its plane only
    for name, stats in dev.axes.items():
        d = result.outputs[name] - twin.outputs[name]  # the same time grid: no interpolation
        assert stats.max_deviation == pytest.approx(np.abs(d).max(), rel=1e-12)  # round-off
        assert stats.rms_deviation == pytest.approx(np.sqrt(np.mean(d**2)), rel=1e-12)
    assert dev.max_distance > 0  # the play moves the tip: otherwise the statistics say nothing
    with pytest.raises(KeyError, match="site 'hand'"):
        site_deviation(result, twin, "hand")


def test_control_file_is_interpolated_linearly_and_held_beyond_its_rows(folder, tmp_path):
    loaded = load_retrofitted(folder)
    assert actuator_labels(loaded.model) == ["#0", "#1"]  # the reacher's motors have no names
    path = tmp_path / "ctrl.csv"
    path.write_text("time_s,#1,#0\n0,0,1\n0.1,1,-1\n")  # columns in any order
    table = read_control_file(path, actuator_labels(loaded.model))
    u = drive_controls(loaded.model, table, np.array([-1.0, 0.0, 0.025, 0.05, 0.1, 5.0]))
    np.testing.assert_allclose(u[:, 0], [1, 1, 0.5, 0, -1, -1])  # exact: linear data
    np.testing.assert_allclose(u[:, 1], [0, 0, 0.25, 0.5, 1, 1])


def test_the_twin_under_a_sampled_sinusoid_follows_the_sinusoid(folder, tmp_path):
    """The same motion from a control file and from the built-in sinusoid."""
    loaded = load_retrofitted(folder)
    sine = SineControl(0.5, 2.0)
    t = np.arange(0, 0.0205, 0.0005)
    table = ControlTable(t, drive_controls(loaded.model, sine, t), "sampled")
    a = simulate_retrofitted(loaded, sine, 0.02, twin=True, sites=["fingertip"])
    b = simulate_retrofitted(loaded, table, 0.02, twin=True, sites=["fingertip"])
    ta = np.array([a.outputs[f"site/fingertip/{x}"] for x in "xy"])
    tb = np.array([b.outputs[f"site/fingertip/{x}"] for x in "xy"])
    moved = np.abs(ta - ta[:, :1]).max()
    # linear interpolation of sin at 0.5 ms errs by at most (2 pi f dt)^2 / 8 = 4e-5 of the amplitude
    assert np.abs(ta - tb).max() < 1e-3 * moved


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("time_s,#0\n0,0\n", "the header lacks actuator '#1'"),
        ("time_s,#0,#1\n0,0,nan\n", "line 2, column '#1': 'nan' is not a finite number"),
        ("time_s,#0,elbow\n0,0,1\n", "unknown actuator 'elbow'"),
        ("time_s,#0,#1\n0,0,1\n0.1,1\n", "line 3: 2 columns, expected 3"),
        ("t,#0,#1\n0,0,1\n", "the first column must be 'time_s'"),
        ("time_s,#0,#1\n0,0,1\n0,1,1\n", "line 3: the times must increase strictly"),
    ],
)
def test_bad_control_files_are_refused_before_any_work(folder, tmp_path, capsys, content, expected):
    ctrl = tmp_path / "ctrl.csv"
    ctrl.write_text(content)
    out = tmp_path / "never"
    code, _, err = _cli(["run", "--model", str(folder), "--control", str(ctrl), "--out", str(out)], capsys)
    assert code == 2
    assert expected in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--site", "hand"], "site 'hand' does not exist"),
        (["--rpm", "100"], "--rpm sets a catalogue scenario"),
        (["--control", "c.csv", "--sine-amplitude", "1"], "give one drive, not both"),
        (["--control", "missing.csv"], "control file missing.csv does not exist"),
    ],
)
def test_bad_model_runs_are_refused_before_any_work(folder, tmp_path, capsys, extra, expected):
    out = tmp_path / "never"
    code, _, err = _cli(["run", "--model", str(folder), "--out", str(out), *extra], capsys)
    assert code == 2 and expected in err and err.count("\n") == 1
    assert not out.exists()


def test_model_options_need_a_model_and_a_folder_needs_its_record(tmp_path, capsys):
    code, _, err = _cli(["run", "--site", "tip", "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "--site is for a retrofitted model's run: give --model DIR too" in err
    code, _, err = _cli(["run", "--model", str(tmp_path), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "no retrofit.json" in err


def test_a_run_that_diverges_stops_naming_time_hinge_and_remedy(folder, tmp_path, capsys):
    """The record's step raised 100x past what the stability rule chose: a journal goes through its ring."""
    bad = tmp_path / "too_large_a_step"
    shutil.copytree(folder, bad)
    record = json.loads((bad / "retrofit.json").read_text())
    record["timestep"] = 5e-4
    (bad / "retrofit.json").write_text(json.dumps(record))
    loaded = load_retrofitted(bad)
    with pytest.raises(SimulationError) as caught:
        simulate_retrofitted(loaded, SineControl(), 0.2)
    err = caught.value
    assert err.joint in ("joint0", "joint1") and "Remedy: retrofit again with a smaller time step" in str(err)
    partial = err.partial
    assert partial is not None and 0 < len(partial.times) and partial.times[-1] < err.time
    pen = max(partial.joints[h.name].penetration.max() for h in loaded.manifest.hinges)
    assert pen <= max(h.penetration_limit for h in loaded.manifest.hinges)  # only rows before the bad one kept
    out = tmp_path / "run"
    code, _, stderr = _cli(["run", "--model", str(bad), "--duration-ms", "200", "--out", str(out)], capsys)
    assert code == 2 and "diverged at t = " in stderr and (out / "result.npz").exists()


def test_an_unknown_site_is_refused_by_the_function_too(folder):
    with pytest.raises(RetrofitError, match="site 'hand' does not exist"):
        simulate_retrofitted(load_retrofitted(folder), SineControl(), 0.01, sites=["hand"])


def test_rerun_recording_holds_the_bodies_of_both_models_and_the_orbits(folder, tmp_path, capsys):
    from test_rerun import F32_RTOL, _read, _view_names

    out = tmp_path / "run"
    rrd = tmp_path / "run.rrd"
    argv = ["run", "--model", str(folder), "--duration-ms", "10", "--site", "fingertip", "--out", str(out)]
    code, stdout, err = _cli([*argv, "--rerun", str(rrd)], capsys)
    assert code == 0, err
    assert "rerun recording written to" in stdout
    result, twin = SimulationResult.load(out / "result"), SimulationResult.load(out / "ideal")
    store, blueprints = _read(rrd)
    assert {"model (twin in grey) [m]", "orbit joint0 [µm, bearing frame]", "contact force [N]"} <= _view_names(
        blueprints
    )
    tip = result.metadata["bodies"].index("fingertip")
    for root, res in (("model", result), ("twin", twin)):
        logged = store[(f"/{root}/bodies/fingertip", False)]
        t = logged["sim_time"] * 1e-9
        rows = np.searchsorted(res.times, t - 1e-12)
        np.testing.assert_allclose(res.times[rows], t, atol=1e-12)  # display rows are rows of the run
        pos = logged["Transform3D:translation"][:, 0]
        # Transform3D stores float32 translations
        np.testing.assert_allclose(pos, res.body_poses[rows, tip, :3], rtol=2 * F32_RTOL, atol=1e-9)
        geoms = {k[0].rsplit("/", 1)[1] for k in store if k[0].startswith(f"/{root}/bodies/fingertip/geoms/")}
        assert geoms == {"fingertip"}  # the reacher's tip geom, named
    orbit = store[("/joints/joint1/orbit", False)]
    e = result.joints["joint1"].eccentricity * 1e6
    np.testing.assert_allclose(orbit["Points2D:positions"].reshape(-1, 2), e, rtol=F32_RTOL, atol=1e-6)


def test_exact_mode_retrofit_runs_with_the_compiled_contact(tmp_path):
    """No ring: the compiled plugin between the hinge's two sites, read back through the run."""
    from clearance.contact_calibration.laws import bearing_stiffness
    from clearance.contact_plugin import is_available

    if not is_available():
        pytest.skip("the compiled contact plugin is not built")
    path = gym_model("reacher")
    play = RadialPlay.make(2e-4, 0.01, bearing_material=POLYMER, journal_material=POLYMER)
    r = retrofit(
        mujoco.MjSpec.from_file(str(path)),
        {"joint0": play, "joint1": play},
        RetrofitOptions(contact_mode="exact", measure_speed=False, sizing_duration=0.3),
    )
    assert (r.model.npair, r.model.nplugin) == (0, 2)
    assert r.model.ngeom == r.twin.ngeom  # no journal, no ring
    write_retrofit(r, tmp_path, source_dir=path.parent)
    assert "compiled plugin instance `clr_joint0__contact`" in (tmp_path / "retrofit.md").read_text()
    res = simulate_retrofitted(load_retrofitted(tmp_path), SineControl(), 0.1)
    K = bearing_stiffness(play.clearance)
    for name, j in res.joints.items():
        assert j.penetration.max() > 0, f"{name}: no contact, the checks below say nothing"
        # at the deepest row the approach speed is ~0 (a sampled maximum): the law's force is the
        # Hertz term K delta^1.5; the step's share of the approach (h |delta''| ~ 1e-3 of the
        # LN factor's scale) leaves it within 2 %
        k = int(np.argmax(j.penetration))
        assert j.force_magnitude[k] == pytest.approx(K * j.penetration[k] ** 1.5, rel=0.02)
        # frictionless: the force on the journal points to the bearing centre
        e = j.eccentricity[k] / np.hypot(*j.eccentricity[k])
        assert j.contact_force[k] @ e == pytest.approx(-j.force_magnitude[k], rel=1e-9)


def test_chunked_and_thinned_runs_of_the_retrofit_and_its_twin_are_one_run_bitwise(folder):
    # radial play (ring contact rows): chunks carry the state and the solver's warm start (tests/test_chunked_runs.py)
    loaded = load_retrofitted(folder)
    h = loaded.manifest.timestep
    for twin in (False, True):
        assert_chunking_is_invisible(
            partial(simulate_retrofitted, loaded, SineControl(0.5, 2.0), sites=["fingertip"], twin=twin),
            h,
            3000,
        )
