"""The command line as a user runs it: outputs written, bad options rejected."""

from __future__ import annotations

import csv

import mujoco
import pytest

from clearance.cli import main


def test_run_writes_everything(tmp_path):
    out = tmp_path / "out"
    # a short run (2 ms) of the default scenario keeps the test fast
    rc = main(["run", "--duration-ms", "2", "--out", str(out), "--no-progress"])
    assert rc == 0
    for name in (
        "result.npz",
        "result.json",
        "ideal.npz",
        "summary.csv",
        "model.xml",
        "ideal_model.xml",
        "report.md",
        "response_vs_ideal.png",
        "deviation.png",
        "contact_force.png",
        "orbit_rod_slider.png",
    ):
        assert (out / name).stat().st_size > 0, name
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert rows[0]["joint"] == "rod_slider" and float(rows[0]["peak_force"]) > 0
    mujoco.MjModel.from_xml_path(str(out / "model.xml"))


def test_mjcf_command(tmp_path):
    path = tmp_path / "m.xml"
    assert main(["mjcf", "--out", str(path), "--segments", "36"]) == 0
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.npair == 36


@pytest.mark.parametrize("argv", [["run", "--clearance-mm", "-1"], ["run", "--rpm", "0"], ["run", "--bogus"]])
def test_bad_options_exit_with_usage_error(argv, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    assert "error" in capsys.readouterr().err


def test_bad_values_reported_clearly(tmp_path, capsys):
    rc = main(["run", "--clearance-mm", "20", "--out", str(tmp_path), "--no-progress"])
    assert rc == 2
    assert "radial_clearance" in capsys.readouterr().err


def test_reference_command(tmp_path):
    out = tmp_path / "ref"
    # 0.4 ms covers the first impact (about 0.25 ms after the start) and stays fast
    assert main(["reference", "--duration-ms", "0.4", "--out", str(out), "--no-progress"]) == 0
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert float(rows[0]["peak_force"]) > 1e3  # Flores and Ambrósio 2004, docs/references.md: forces of order 1e4 N
    assert (out / "orbit_rod_slider.png").stat().st_size > 0


def test_catalogue_mechanism_and_scenario_file(tmp_path):
    from importlib.resources import files

    path = tmp_path / "fb.xml"
    assert main(["mjcf", "--mechanism", "four_bar", "--segments", "36", "--out", str(path)]) == 0
    assert mujoco.MjModel.from_xml_path(str(path)).npair == 36  # one clearance joint (B) by default
    toml = files("clearance.builders") / "scenarios" / "slider_crank.toml"
    assert main(["mjcf", "--scenario", str(toml), "--segments", "36", "--out", str(path)]) == 0


def test_rpm_sets_the_catalogue_mechanisms_driven_crank(tmp_path, monkeypatch):
    """--rpm goes to the builder's own speed keyword (the press: crank 2, not 'crank_speed')."""
    import math

    from clearance.builders import CATALOGUE
    from clearance.cli import options as cli_options

    built = []
    real = cli_options.mechanism_from_args

    def keep(args):
        built.append(real(args))
        return built[-1]

    monkeypatch.setattr("clearance.cli.mjcf.mechanism_from_args", keep)
    path = tmp_path / "press.xml"
    # nominal rows: what is checked is the builder's speed, not the rows (calibrating the press took 15 s)
    argv = ["mjcf", "--mechanism", "seven_bar_press", "--rpm", "45", "--segments", "36", "--contact-mode", "nominal"]
    assert main([*argv, "--out", str(path)]) == 0
    assert CATALOGUE["seven_bar_press"].speed_keyword == "crank2_speed"
    drive = built[0].drives[0]
    assert drive.speed == pytest.approx(45 * 2 * math.pi / 60, rel=1e-12)  # exact unit conversion


def test_run_contact_mode_option(tmp_path, capsys):
    import json

    out = tmp_path / "out"
    # the default is the compiled exact contact at 3 us (benchmarks/speed_error.md); 0.3 ms covers
    # the start of the first impact and stays fast
    assert main(["run", "--duration-ms", "0.3", "--out", str(out), "--no-progress"]) == 0
    meta = json.loads((out / "result.json").read_text())
    assert meta["contact_mode"] == "exact" and meta["time_step"] == 3e-6
    assert meta["contact"]["rod_slider"]["source"].startswith("exact: compiled plugin")
    assert (
        main(["run", "--contact-mode", "calibrated", "--duration-ms", "0.3", "--out", str(out), "--no-progress"]) == 0
    )
    meta = json.loads((out / "result.json").read_text())
    assert meta["contact_mode"] == "calibrated" and meta["time_step"] == 2e-6  # the ring's own default step
    assert meta["contact"]["rod_slider"]["source"].startswith("calibrated: ")
    assert main(["run", "--contact-mode", "nominal", "--duration-ms", "0.3", "--out", str(out), "--no-progress"]) == 0
    meta = json.loads((out / "result.json").read_text())
    assert meta["contact_mode"] == "nominal" and meta["contact"]["rod_slider"]["source"] == "nominal"
    assert main(["run", "--contact-mode", "exact_ln", "--duration-ms", "0.3", "--out", str(out), "--no-progress"]) == 0
    assert json.loads((out / "result.json").read_text())["contact_mode"] == "exact"  # 'exact_ln' is its earlier name
    capsys.readouterr()
    with pytest.raises(SystemExit) as info:
        main(["run", "--contact-mode", "ln"])
    assert info.value.code == 2
    assert "--contact-mode: invalid choice: 'ln'" in capsys.readouterr().err


def test_calibrate_writes_the_calibration_a_calibrated_run_reuses(tmp_path, monkeypatch, capsys):
    """`clearance calibrate` sizes like `prepare`: the run and `prepare` read its file, no refit."""
    import json

    from clearance.builders import slider_crank
    from clearance.contact_calibration import store
    from clearance.contact_calibration.store import cache_dir
    from clearance.options import ModelOptions
    from clearance.run.preparation import prepare

    monkeypatch.setenv("CLEARANCE_CACHE_DIR", str(tmp_path / "cache"))  # an empty cache: fits are counted
    fits = []
    real_fit = store.fit_contact

    def counting_fit(*args, **kwargs):
        fits.append(kwargs["mass_range"])
        return real_fit(*args, **kwargs)

    monkeypatch.setattr(store, "fit_contact", counting_fit)
    assert main(["calibrate", "--out", str(tmp_path / "cal")]) == 0
    assert "Contact calibration: rod_slider" in capsys.readouterr().out
    files = list(cache_dir().glob("calib-*.json"))
    assert len(fits) == 1 and len(files) == 1
    prepared = prepare(slider_crank(), ModelOptions(contact_mode="calibrated"))
    assert len(fits) == 1, "prepare refitted instead of reading the file clearance calibrate wrote"
    assert prepared.contact["rod_slider"].source == f"calibrated: {files[0]}"
    # keyed with the cycle's (min, max) effective mass, as prepare sizes it (not (m, m))
    key = json.loads(files[0].read_text())["key"]
    # (stored to store.MASS_DIGITS = 9 significant figures: equal within 1e-8 relative)
    assert key["mass_range"] == pytest.approx(list(prepared.sizing["rod_slider"].effective_mass_range), rel=1e-8)
    assert key["mass_range"][0] < key["mass_range"][1]
    out = tmp_path / "run"
    assert (
        main(["run", "--contact-mode", "calibrated", "--duration-ms", "0.3", "--out", str(out), "--no-progress"]) == 0
    )
    assert len(fits) == 1, "clearance run --contact-mode calibrated refitted"
    meta = json.loads((out / "result.json").read_text())
    assert meta["contact"]["rod_slider"]["source"] == f"calibrated: {files[0]}"


@pytest.mark.parametrize(
    "flag,value",
    [
        ("--segments", "36"),
        ("--timestep-us", "2"),
        ("--journal-geom", "capsule"),
        ("--segment-geom", "box"),
        ("--contact-mode", "calibrated"),
    ],
)
def test_reference_refuses_mujoco_numerics(flag, value, tmp_path, capsys):
    assert main(["reference", flag, value, "--duration-ms", "0.1", "--out", str(tmp_path), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"clearance reference does not take {flag}" in err
    assert "exact circle-in-circle geometry" in err and "adaptive steps" in err
    assert not list(tmp_path.iterdir())  # refused before any work


def test_joint_that_never_touched_prints_no_contact(tmp_path, capsys):
    # 0.1 ms ends before the first impact (about 0.25 ms, docs/references.md, "The default scenario, measured")
    assert main(["reference", "--duration-ms", "0.1", "--out", str(tmp_path), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "rod_slider: no contact" in out and "max penetration" not in out


def test_torque_driven_scenario_runs_and_refuses_revolutions(tmp_path, capsys):
    """A mechanism driven by torques alone has no period: the run says what it simulates and
    the statistics skip no transient; --revolutions is refused, not ignored."""
    import dataclasses

    from clearance.builders import dump_scenario, slider_crank
    from clearance.model import Drive, DriveKind

    mech = slider_crank(gravity=9.81)
    drive = mech.drives[0]
    torque_driven = dataclasses.replace(
        mech, drives=(Drive(drive.name, drive.joint, kind=DriveKind.TORQUE, torque=0.05),)
    )
    path = tmp_path / "torque.toml"
    dump_scenario(torque_driven, path)
    out = tmp_path / "out"
    assert main(["run", "--scenario", str(path), "--revolutions", "2", "--out", str(out), "--no-progress"]) == 2
    assert "--revolutions 2: mechanism 'slider_crank' is driven by torques alone" in capsys.readouterr().err
    assert not out.exists()  # refused before any work
    # 1 ms at 20 us: a short, cheap run; the point is that every output is written
    assert (
        main(
            [
                "run",
                "--scenario",
                str(path),
                "--duration-ms",
                "1",
                "--timestep-us",
                "20",
                "--segments",
                "72",
                "--contact-mode",
                "nominal",
                "--out",
                str(out),
                "--no-progress",
            ]
        )
        == 0
    )
    assert (out / "report.md").stat().st_size > 0 and (out / "summary.csv").stat().st_size > 0


def test_refused_time_step_leaves_no_output_folder(tmp_path, capsys):
    out = tmp_path / "out"
    # 20 us is far above the default joint's stable step (benchmarks/stability.md: TimeStepError)
    assert main(["run", "--timestep-us", "20", "--contact-mode", "nominal", "--out", str(out), "--no-progress"]) == 2
    assert "time step" in capsys.readouterr().err.lower()
    assert not out.exists()


def test_summary_gives_start_up_and_steady_state_side_by_side(tmp_path, capsys):
    # the start-up impact of a journal released from the bearing centre (45.9 kN at 0.25 ms)
    # is not the steady state: summary.csv and the console give both, labelled
    out = tmp_path / "out"
    assert main(["run", "--duration-ms", "25", "--out", str(out), "--no-progress"]) == 0
    row = next(csv.DictReader((out / "summary.csv").open()))
    assert float(row["startup_window"]) == pytest.approx(0.012, rel=1e-12)  # one period at 5000 rpm
    assert 0 < float(row["steady_peak_force"]) < float(row["peak_force"])  # the start-up peak is the largest
    assert int(row["steady_impacts"]) < int(row["impacts"])
    text = capsys.readouterr().out
    assert "whole run: peak force" in text and "steady state after the start-up window" in text
    # a run no longer than the window says so instead of printing steady-state numbers
    assert main(["run", "--duration-ms", "5", "--out", str(tmp_path / "short"), "--no-progress"]) == 0
    row = next(csv.DictReader((tmp_path / "short" / "summary.csv").open()))
    assert row["steady_impacts"] == "-1" and row["steady_peak_force"] == "nan"
    assert "no steady state" in capsys.readouterr().out


def test_run_writes_joint_reactions_beside_the_summary(tmp_path, capsys):
    # every joint's bearing load and the drive torque, for the run and its ideal twin, in
    # reactions.csv, the report (with its figure) and the console
    out = tmp_path / "out"
    assert main(["run", "--duration-ms", "25", "--out", str(out), "--no-progress"]) == 0
    rows = {r["name"]: r for r in csv.DictReader((out / "reactions.csv").open())}
    assert set(rows) == {"crank_pivot", "crank_rod", "rod_slider", "slider_guide", "crank"}
    assert rows["crank"]["unit"] == "N m" and rows["rod_slider"]["unit"] == "N"
    # the ideal twin's rod-slider pin peaks at 2,718.7 N at 5000 rpm (inverse dynamics); the
    # reactions meet it within the 0.1 % (csv keeps 6 significant digits)
    assert float(rows["rod_slider"]["ideal_steady_peak"]) == pytest.approx(2718.7, rel=1e-3)
    assert float(rows["crank"]["ideal_steady_peak"]) == pytest.approx(138.5, rel=1e-3)  # drive torque, N m
    for r in rows.values():  # clearance makes every joint's steady peak larger than the ideal twin's
        assert float(r["steady_peak"]) > float(r["ideal_steady_peak"]) > 0
    assert (out / "joint_reactions.png").stat().st_size > 0
    assert "## Joint reactions" in (out / "report.md").read_text()
    assert "joint reactions, steady-state peaks: crank_pivot" in capsys.readouterr().out
