"""The command line as a user meets it: --version, one-line refusals, helps that state defaults,
progress in a log, labels that say what a number is, units in the files, --stop-after's exit status.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import re
from pathlib import Path

import pytest
from cli_runner import run_cli

from clearance.cli import build_parser

COMMANDS = [
    "run",
    "reference",
    "mjcf",
    "view",
    "calibrate",
    "sweep",
    "rank",
    "allocate",
    "optimise",
    "bench",
    "retrofit",
]


def _parsers() -> dict[str, argparse.ArgumentParser]:
    """Every command's parser (the commands with a parser of their own and those parsed at the top)."""
    from clearance.cli.allocate import allocate_parser
    from clearance.cli.bench import bench_parser
    from clearance.cli.calibrate import calibrate_parser
    from clearance.cli.optimise import optimise_parser
    from clearance.cli.rank import rank_parser
    from clearance.cli.rank_model import rank_model_parser
    from clearance.cli.sweep import sweep_parser

    top = build_parser()
    sub = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction)).choices
    parsers = {name: p for name, p in sub.items() if name in ("run", "reference", "mjcf", "view", "retrofit")}
    parsers["clearance"] = top
    parsers.update(
        calibrate=calibrate_parser(),
        sweep=sweep_parser(),
        rank=rank_parser(),
        rank_model=rank_model_parser(),
        allocate=allocate_parser(),
        optimise=optimise_parser(),
        bench=bench_parser(),
    )
    return parsers


def test_version_prints_the_package_and_mujoco_versions(capsys):
    from clearance.version import __version__

    code, out, err = run_cli(["--version"], capsys)
    assert code == 0 and err == ""
    assert re.fullmatch(rf"clearance {re.escape(__version__)} \(mujoco [0-9][^,]*, Python 3\.[0-9.]+\)\n", out), out


@pytest.mark.parametrize("command", COMMANDS)
def test_an_unknown_option_is_one_line_naming_the_command(command, capsys):
    argv = [command, "--no-such-option", "1"]
    if command in ("view", "retrofit"):
        argv[1:1] = ["somewhere.xml"]
    code, out, err = run_cli(argv, capsys)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err  # no usage block
    assert lines[0].startswith(f"clearance {command}: error: ") and f"see 'clearance {command} --help'" in lines[0]
    assert "--no-such-option" in lines[0] or "required" in lines[0], lines[0]


def test_a_bad_value_names_the_option_on_one_line(capsys):
    code, _, err = run_cli(["run", "--rpm", "fast"], capsys)
    assert code == 2
    assert err.strip().splitlines() == [
        "clearance run: error: argument --rpm: --rpm must be a number (got 'fast'); see 'clearance run --help'"
    ]


def test_help_still_shows_the_usage_block(capsys):
    code, out, _ = run_cli(["run", "--help"], capsys)
    assert code == 0 and out.startswith("usage: clearance run") and "--clearance-mm" in out


def test_every_option_states_its_default_and_no_help_shows_markup():
    silent = []
    for name, p in _parsers().items():
        text = p.format_help()
        assert "`" not in text and "(ring mode)" not in text, name  # a terminal shows no Markdown
        for a in p._actions:
            if not a.option_strings or a.help == argparse.SUPPRESS or a.required:
                continue
            if a.nargs == 0:
                continue  # a flag (--no-progress, --help, --version): its default is off
            if isinstance(a, argparse._AppendAction) and "repeat" in (a.help or ""):
                continue  # given once per value; none by default
            if "default" not in (a.help or "") and "required" not in (a.help or ""):
                silent.append(f"{name} {a.option_strings[0]}")
    assert not silent, silent


def test_mjcf_help_names_the_mode_it_writes():
    help_text = " ".join(_parsers()["mjcf"].format_help().split())
    assert "default calibrated here" in help_text and "(default exact)" not in help_text
    args = build_parser().parse_args(["mjcf"])
    assert args.contact_mode == "calibrated"  # what the help says is what it writes


def test_stop_after_help_counts_what_its_command_stops_on():
    parsers = _parsers()
    for name, unit in (("sweep", "points"), ("rank", "points"), ("allocate", "simulated runs")):
        (action,) = [a for a in parsers[name]._actions if "--stop-after" in a.option_strings]
        assert f"this many {unit}" in action.help and "exit status 3" in action.help, name
        assert "allocate" not in action.help


def test_periodic_lines_where_stderr_is_not_a_terminal():
    from clearance.progress import LineProgress, progress_bar

    stream = io.StringIO()
    bar = LineProgress(200, desc="simulate", unit="step", every_s=0.0, stream=stream)
    for _ in range(4):
        bar.update(50)
    bar.close()
    lines = stream.getvalue().splitlines()
    assert len(lines) == 4 and "\r" not in stream.getvalue()
    assert lines[0].startswith("simulate: 25% (50 of 200 steps)") and lines[-1].startswith("simulate: 100%")
    quiet = LineProgress(200, desc="simulate", unit="step", every_s=3600.0, stream=stream)
    quiet.update(200)
    quiet.close()
    assert stream.getvalue().splitlines() == lines  # a display shorter than the interval prints nothing
    assert isinstance(progress_bar(10, desc="x", unit="step"), LineProgress)  # pytest's stderr is no terminal


def test_the_run_says_what_each_number_is_and_writes_the_units(tmp_path, capsys):
    out, rrd = tmp_path / "out", tmp_path / "rec.rrd"
    # 15 ms: past the 12 ms start-up window, so both the whole-run and the steady-state values exist
    code, stdout, err = run_cli(
        ["run", "--duration-ms", "15", "--out", str(out), "--rerun", str(rrd), "--no-progress"], capsys
    )
    assert code == 0, err
    assert "15 ms at h = 3 µs, exact contact" in stdout
    deviation = next(line for line in stdout.splitlines() if "RMS deviation" in line)
    assert "over the whole run" in deviation and "in the steady state (after 12 ms" in deviation
    assert re.search(r"peak force [0-9.]+ kN at [0-9.]+ µs", stdout)  # numbers in the unit their size calls for
    assert "e+0" not in stdout and "e-0" not in stdout
    assert stdout.rstrip().endswith(f"wrote {out}/ and {rrd.resolve()}")
    meta = json.loads((out / "result.json").read_text())
    units = meta["units"]
    arrays = units["arrays"]
    assert arrays["times"] == "s" and arrays["output/slider_x_acc"] == "m/s^2"
    assert arrays["joint/rod_slider/contact_force"] == "N" and units["metadata"]["time_step"] == "s"
    import numpy as np

    with np.load(out / "result.npz") as npz:
        assert set(arrays) == set(npz.files)
    assert "see the metadata" not in arrays.values()
    wall = meta["wall_time_s"]
    assert float(f"{wall:.4g}") == wall  # 4 significant digits, not 17
    # the summary's two deviations: whole run (its column of old) and the steady state, which the report gives
    (row,) = csv.DictReader(io.StringIO((out / "summary.csv").read_text()))
    report = (out / "report.md").read_text()
    steady_um = float(row["steady_output_rms_deviation"]) * 1e6
    assert float(row["output_rms_deviation"]) != float(row["steady_output_rms_deviation"])
    shown = re.search(r"\| RMS deviation \| ([0-9.]+) µm \|", report)
    assert shown and float(shown.group(1)) == pytest.approx(steady_um, rel=1e-3)  # the report shows 4 digits
    assert "steady state, 12 ms–15 ms" in report


def test_the_readme_lists_the_unit_of_every_csv_column(tmp_path, capsys):
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    out = tmp_path / "out"
    assert run_cli(["run", "--duration-ms", "13", "--out", str(out), "--no-progress"], capsys)[0] == 0
    for name in ("summary.csv", "reactions.csv"):
        header = (out / name).read_text().splitlines()[0].split(",")
        for column in header:
            row = rf"(?m)^\|[^\n]*`{re.escape(name)}`[^\n]*\|[^\n|]*`{column}`[^\n|]*\|[^\n|]+\|[^\n|]+\|$"
            assert re.search(row, readme), f"{name}: {column} has no row (file, column, unit, meaning) in the README"


@pytest.mark.parametrize(
    "argv,kept,missing",
    [
        (["sweep", "--points", "3", "--periods", "2", "--sampled", "1"], "points", "bifurcation.png"),
        (["rank", "--clearances-mm", "0.1", "--rpm", "1000", "--periods", "3"], "points", "ranking.md"),
    ],
)
def test_stop_after_stops_where_it_says_with_exit_status_3(argv, kept, missing, tmp_path, capsys):
    out = tmp_path / "s"
    code, _, err = run_cli([*argv, "--stop-after", "1", "--workers", "1", "--out", str(out), "--no-progress"], capsys)
    assert code == 3, err
    assert len(list((out / kept).glob("*.json"))) == 1  # exactly the one asked for
    assert not (out / missing).exists()  # nothing that reads as the whole result
    assert "stopped by --stop-after 1" in err and "run the same command again to resume" in err


def test_calibration_says_whether_it_fitted_or_reused_and_where(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("CLEARANCE_CACHE_DIR", str(tmp_path / "cache"))
    argv = ["run", "--contact-mode", "calibrated", "--duration-ms", "0.3", "--no-progress"]
    code, first, err = run_cli([*argv, "--out", str(tmp_path / "a")], capsys)
    assert code == 0, err
    (file,) = (tmp_path / "cache" / "calibration").glob("calib-*.json")
    assert f"rod_slider: contact calibration fitted now and stored in {file}" in first
    import os
    import time

    old = time.time() - 3600  # as if fitted an hour ago
    os.utime(file, (old, old))
    code, second, err = run_cli([*argv, "--out", str(tmp_path / "b")], capsys)
    assert code == 0, err
    assert f"rod_slider: contact calibration reused from {file} (fitted " in second


def test_result_units_cover_every_array_kind():
    from clearance.result_units import array_unit

    assert array_unit("output/rocker_angle", ["rocker_angle"]) == "rad"
    assert array_unit("output/rocker_angle_vel", ["rocker_angle"]) == "rad/s"
    assert array_unit("output/slider_x_vel") == "m/s"
    assert array_unit("energy/kinetic") == "J" and array_unit("drive_torque") == "N m"


def test_a_warning_met_at_every_compile_is_printed_once(tmp_path, capsys):
    """A model with MuJoCo's deprecated settotalmass warns at each of the retrofit's compiles: one line."""
    from retrofit_models import TOTALMASS_ARM

    from clearance.cli import main

    xml = tmp_path / "arm.xml"
    xml.write_text(TOTALMASS_ARM)
    main(["retrofit", str(xml), "--joint", "hip", "--contact-mode", "exact", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert err.count("'settotalmass' is deprecated") == 1, err
