"""Bad input and faults as a user meets them: one clear line, exit 2, before any work.

The battery runs every command (run, reference, mjcf, calibrate, sweep, rank, bench) with
bad options, bad paths and bad scenario files in-process, with the preparation, the
simulations, the reference solver, the sweeps and the calibration replaced by a guard that
fails the test if it is reached: each case must be refused before any work, with exit status
2, one error line naming the option or file, and no traceback, and must leave nothing behind.
The faults that need real processes -- two runs into one folder, a sweep killed with SIGKILL
or stopped with Ctrl-C -- run the console command in subprocesses.
"""

from __future__ import annotations

import functools
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from clearance.cli import main

FAST_GUARDS = {
    "clearance.run.preparation.prepare": "prepare",
    "clearance.run.simulation.simulate_prepared": "simulate_prepared",
    "clearance.run.simulation.simulate": "simulate",
    "clearance.reference.run_reference": "run_reference",
    "clearance.analysis.sweeps.bifurcation.run_bifurcation": "run_bifurcation",
    "clearance.analysis.sweeps.criticality.run_criticality": "run_criticality",
    "clearance.contact_calibration.store.calibrate_joint": "calibrate_joint",
    "clearance.retrofit.retrofit": "retrofit",
    "clearance.analysis.sweeps.robot_ranking.run_robot_ranking": "run_robot_ranking",
    "clearance.analysis.design.allocation.allocate": "allocate",
    "clearance.analysis.design.optimise.optimise_design": "optimise_design",
    "clearance.run.retrofitted.simulate_retrofitted": "simulate_retrofitted",
    "clearance.retrofit.add_backlash": "add_backlash",
}
"""Everything that does work, by dotted path: a refused command must reach none of it."""

SCENARIOS = {
    "tiny.toml": '[mechanism]\nbuilder = "slider_crank"\ncrank_length_mm = 1e-300\n',
    "huge.toml": '[mechanism]\nbuilder = "slider_crank"\nrod_length_mm = 1e300\n',
    "nobuilder.toml": "[mechanism]\ncrank_length_mm = 50\n",
    "broken.toml": "[mechanism\nbuilder =\n",
    "inf.toml": '[mechanism]\nbuilder = "slider_crank"\ncrank_length_mm = inf\n',
    "fast.toml": '[mechanism]\nbuilder = "slider_crank"\ncrank_speed_rpm = 1e9\n',
    "thin.toml": '[mechanism]\nbuilder = "slider_crank"\nbearing_radius_mm = 0.5\nclearance_mm = 0.49\n',
    "ok.toml": '[mechanism]\nbuilder = "slider_crank"\n',
    "arm.xml": '<mujoco><worldbody><body name="arm"><joint name="elbow" axis="0 0 1"/>'
    '<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/></body></worldbody>'
    '<actuator><motor joint="elbow"/></actuator></mujoco>',
    "arm_limited.xml": '<mujoco><worldbody><body name="arm"><joint name="elbow" axis="0 0 1"/>'
    '<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/></body></worldbody>'
    '<actuator><motor name="m" joint="elbow" ctrllimited="true" ctrlrange="-1 1"/></actuator></mujoco>',
    "over.csv": "time_s,m\n0,0\n0.5,1\n1,1.5\n",
    "neg_speed.toml": '[mechanism]\nbuilder = "slider_crank"\ncrank_speed_rpm = -3000\n',
    "alloc_cost.toml": '[mechanism]\nbuilder = "slider_crank"\n\n[allocation.cost.crank_rod]\na = 0\nb = -1\n',
    "alloc_extra.toml": '[mechanism]\nbuilder = "slider_crank"\n\n[allocation.foo]\nx = 1\n',
    "opt_unknown.toml": '[mechanism]\nbuilder = "slider_crank"\n\n[optimise]\nbogus = 1\n',
    "both_sections.toml": '[mechanism]\nbuilder = "slider_crank"\n\n[optimise]\nruns = 2\n\n[bogus]\nx = 1\n',
    # a retrofit's record edited by hand: a negative time step
    "rf_neg/retrofit.json": '{"format": 1, "model": "model.xml", "original": "original.xml", "timestep": -1e-6, '
    '"original_timestep": 0.002, "contact_mode": "exact", "hinges": [], "qpos_map": [0], "qvel_map": [0]}',
}

FULL_FORM_EDITS = {
    "full-mass-tiny.toml": ("mass_kg = 0.3", "mass_kg = 1e-300"),
    "full-gravity-huge.toml": ("gravity_m_per_s2 = [0.0, -0.0]", "gravity_m_per_s2 = [0.0, -1e300]"),
    "full-point-huge.toml": ("pin = [0.05, 0.0]", "pin = [1e300, 0.0]"),
    "full-modulus-huge.toml": ("youngs_modulus_pa = 207000000000.0", "youngs_modulus_pa = 1e300"),
    "full-speed-huge.toml": ("speed_rad_per_s = 523.5987755982989", "speed_rad_per_s = 1e300"),
}
"""Whole-mechanism scenario files: the default slider-crank written out, one value changed."""

RPM_CAP = "at most 60,000"
NO_RING = "the exact contact has no ring"

# (id, argv with {tmp} {file} {dir} {ro} placeholders, words the error line must hold)
BATTERY: list[tuple[str, list[str], list[str]]] = [
    # output paths: every command, before any work
    ("run-out-is-a-file", ["run", "--out", "{file}"], ["--out {file}", "is a file, not a folder"]),
    ("run-out-under-a-file", ["run", "--out", "{file}/sub"], ["--out {file}/sub", "{file} is a file"]),
    ("run-out-empty", ["run", "--out", ""], ["--out", "empty path"]),
    ("run-out-broken-link", ["run", "--out", "{tmp}/broken"], ["--out {tmp}/broken", "is a link to", "does not exist"]),
    ("mjcf-out-broken-link", ["mjcf", "--out", "{tmp}/broken"], ["--out {tmp}/broken", "is a link to"]),
    ("run-out-not-writable", ["run", "--out", "{ro}"], ["--out {ro}", "cannot write in this folder"]),
    ("run-out-in-not-writable", ["run", "--out", "{ro}/new"], ["--out {ro}/new", "cannot create a folder in {ro}"]),
    ("run-out-system-folder", ["run", "--out", "/sys/clearance-out"], ["--out /sys/clearance-out", "/sys"]),
    ("run-rerun-is-a-folder", ["run", "--rerun", "{dir}"], ["--rerun {dir}", "is a folder"]),
    ("run-rerun-under-a-file", ["run", "--rerun", "{file}/x.rrd"], ["--rerun {file}/x.rrd", "is a file"]),
    ("run-rerun-not-writable", ["run", "--rerun", "{ro}/x.rrd"], ["--rerun {ro}/x.rrd", "cannot write in {ro}"]),
    ("run-rerun-system-folder", ["run", "--rerun", "/sys/x.rrd"], ["--rerun /sys/x.rrd", "cannot write in /sys"]),
    ("run-rerun-empty", ["run", "--rerun", ""], ["--rerun", "empty path"]),
    ("mjcf-out-is-a-folder", ["mjcf", "--out", "{dir}"], ["--out {dir}", "is a folder", "model.xml"]),
    ("mjcf-out-under-a-file", ["mjcf", "--out", "{file}/m.xml"], ["--out {file}/m.xml", "is a file"]),
    ("mjcf-out-not-writable", ["mjcf", "--out", "{ro}/m.xml"], ["--out {ro}/m.xml", "cannot write in"]),
    ("mjcf-out-system-folder", ["mjcf", "--out", "/sys/m.xml"], ["--out /sys/m.xml", "cannot write in /sys"]),
    ("reference-out-is-a-file", ["reference", "--out", "{file}"], ["--out {file}", "is a file"]),
    ("reference-rerun-is-a-folder", ["reference", "--rerun", "{dir}"], ["--rerun {dir}", "is a folder"]),
    ("calibrate-out-is-a-file", ["calibrate", "--out", "{file}"], ["--out {file}", "is a file"]),
    ("calibrate-out-system-folder", ["calibrate", "--out", "/sys/c"], ["--out /sys/c", "cannot create"]),
    ("sweep-out-is-a-file", ["sweep", "--out", "{file}"], ["--out {file}", "is a file"]),
    ("sweep-out-not-writable", ["sweep", "--out", "{ro}/s"], ["--out {ro}/s", "cannot create"]),
    ("rank-out-is-a-file", ["rank", "--out", "{file}"], ["--out {file}", "is a file"]),
    ("rank-out-system-folder", ["rank", "--out", "/sys/r"], ["--out /sys/r", "cannot create"]),
    ("bench-out-is-a-file", ["bench", "--out", "{file}"], ["--out {file}", "is a file"]),
    ("bench-out-under-a-file", ["bench", "--out", "{file}/b"], ["--out {file}/b", "is a file"]),
    # scenario files
    ("scenario-missing", ["run", "--scenario", "{tmp}/no.toml"], ["--scenario {tmp}/no.toml", "No such file"]),
    ("scenario-is-a-folder", ["run", "--scenario", "{dir}"], ["--scenario {dir}", "is a folder"]),
    (
        "scenario-length-1e-300",
        ["run", "--scenario", "{tmp}/tiny.toml"],
        ["tiny.toml, line 3", "crank_length_mm", "between"],
    ),
    (
        "scenario-length-1e300",
        ["run", "--scenario", "{tmp}/huge.toml"],
        ["huge.toml, line 3", "rod_length_mm", "between"],
    ),
    (
        "scenario-no-builder",
        ["run", "--scenario", "{tmp}/nobuilder.toml"],
        ["nobuilder.toml", "missing key 'builder'", "[[links]]"],
    ),
    ("scenario-not-toml", ["run", "--scenario", "{tmp}/broken.toml"], ["broken.toml", "not valid TOML"]),
    ("scenario-not-utf8", ["run", "--scenario", "{tmp}/binary.toml"], ["binary.toml", "not UTF-8"]),
    ("scenario-inf", ["run", "--scenario", "{tmp}/inf.toml"], ["inf.toml", "crank_length_mm", "finite number"]),
    ("scenario-too-fast", ["run", "--scenario", "{tmp}/fast.toml"], ["fast.toml", "crank_speed_rpm", "between"]),
    (
        "scenario-thin-journal",
        ["run", "--scenario", "{tmp}/thin.toml"],
        ["thin.toml", "journal of radius 0.01 mm", "bearing of radius 0.5 mm"],
    ),
    (
        "scenario-with-mechanism",
        ["run", "--scenario", "{tmp}/ok.toml", "--mechanism", "four_bar"],
        ["--scenario", "--mechanism", "cannot be given"],
    ),
    (
        "scenario-with-rpm",
        ["run", "--scenario", "{tmp}/ok.toml", "--rpm", "100"],
        ["--scenario", "--rpm", "cannot be given"],
    ),
    (
        "scenario-with-clearance",
        ["mjcf", "--scenario", "{tmp}/ok.toml", "--clearance-mm", "0.2"],
        ["--clearance-mm", "cannot be given"],
    ),
    ("full-form-mass-tiny", ["run", "--scenario", "{tmp}/full-mass-tiny.toml"], ["'crank'", "mass_kg", "1e-300 kg"]),
    ("full-form-gravity-huge", ["run", "--scenario", "{tmp}/full-gravity-huge.toml"], ["gravity_m_per_s2", "at most"]),
    ("full-form-point-huge", ["run", "--scenario", "{tmp}/full-point-huge.toml"], ["[points_m]", "'pin'", "at most"]),
    ("full-form-modulus-huge", ["run", "--scenario", "{tmp}/full-modulus-huge.toml"], ["youngs_modulus_pa"]),
    ("full-form-speed-huge", ["run", "--scenario", "{tmp}/full-speed-huge.toml"], ["speed_rad_per_s", "6283.19"]),
    (
        "mjcf-scenario-missing",
        ["mjcf", "--scenario", "{tmp}/no.toml", "--out", "{tmp}/m.xml"],
        ["--scenario", "No such file"],
    ),
    (
        "calibrate-scenario-missing",
        ["calibrate", "--scenario", "{tmp}/no.toml", "--out", "{tmp}/c"],
        ["--scenario", "No such file"],
    ),
    (
        "reference-scenario-length",
        ["reference", "--scenario", "{tmp}/tiny.toml", "--out", "{tmp}/r"],
        ["crank_length_mm"],
    ),
    # MuJoCo numerics
    (
        "segments-100000",
        ["run", "--segments", "100000", "--contact-mode", "calibrated"],
        ["--segments", "at most 1,024"],
    ),
    ("segments-0", ["run", "--segments", "0", "--contact-mode", "calibrated"], ["--segments", "at least 8"]),
    ("segments-text", ["run", "--segments", "many", "--contact-mode", "nominal"], ["--segments", "whole number"]),
    ("segments-with-exact", ["run", "--segments", "36"], ["--segments", NO_RING]),
    (
        "segment-geom-with-exact",
        ["run", "--segment-geom", "box", "--contact-mode", "exact"],
        ["--segment-geom", NO_RING],
    ),
    (
        "journal-geom-with-exact",
        ["mjcf", "--journal-geom", "capsule", "--contact-mode", "exact", "--out", "{tmp}/m.xml"],
        ["--journal-geom", NO_RING],
    ),
    ("timestep-huge", ["run", "--timestep-us", "1e9"], ["--timestep-us", "at most 10,000"]),
    ("timestep-nan", ["run", "--timestep-us", "nan"], ["--timestep-us", "finite number"]),
    (
        "timestep-tiny",
        ["run", "--timestep-us", "1e-9", "--duration-ms", "1"],
        ["--duration-ms 1", "time steps", "20,000,000"],
    ),
    ("duration-huge", ["run", "--duration-ms", "1e12"], ["--duration-ms 1e+12", "time steps"]),
    ("duration-inf", ["run", "--duration-ms", "inf"], ["--duration-ms", "finite number"]),
    ("revolutions-huge", ["run", "--revolutions", "1e9"], ["--revolutions 1e+09", "time steps"]),
    ("revolutions-zero", ["run", "--revolutions", "0"], ["--revolutions", "> 0"]),
    # clearances and joints
    (
        "clearance-9.99-in-10mm",
        ["run", "--clearance-mm", "9.99"],
        ["--clearance-mm 9.99", "journal of radius 0.01 mm", "bearing of radius 10 mm", "at least 50%"],
    ),
    ("clearance-nan", ["run", "--clearance-mm", "nan"], ["--clearance-mm", "must be a finite number"]),
    ("clearance-inf", ["run", "--clearance-mm", "inf"], ["--clearance-mm", "must be a finite number"]),
    ("clearance-negative", ["run", "--clearance-mm", "-1"], ["--clearance-mm", "> 0"]),
    ("clearance-is-the-bearing", ["run", "--clearance-mm", "10"], ["--clearance-mm 10", "radial_clearance"]),
    ("clearance-1e-12", ["run", "--clearance-mm", "1e-12"], ["--clearance-mm 1e-12", "smallest accepted"]),
    (
        "clearance-at-unknown",
        ["run", "--clearance-at", "nosuch"],
        ["--clearance-at nosuch", "unknown joint", "rod_slider"],
    ),
    ("clearance-at-twice", ["run", "--clearance-at", "rod_slider", "rod_slider"], ["--clearance-at", "more than once"]),
    ("mechanism-unknown", ["run", "--mechanism", "nosuch"], ["--mechanism", "invalid choice"]),
    # drive speeds
    ("rpm-1e9", ["run", "--rpm", "1e9"], ["--rpm", RPM_CAP]),
    ("rpm-zero", ["run", "--rpm", "0"], ["--rpm", "> 0"]),
    ("rpm-negative", ["run", "--rpm", "-5"], ["--rpm", "> 0"]),
    ("rpm-text", ["run", "--rpm", "fast"], ["--rpm", "must be a number"]),
    ("rpm-inf-mjcf", ["mjcf", "--rpm", "inf", "--out", "{tmp}/m.xml"], ["--rpm", "finite number"]),
    ("press-rpm-1e5", ["run", "--mechanism", "seven_bar_press", "--rpm", "1e5"], ["--rpm", RPM_CAP]),
    ("reference-rpm-1e9", ["reference", "--rpm", "1e9"], ["--rpm", RPM_CAP]),
    # the reference solver
    ("reference-rtol-1", ["reference", "--rtol", "1"], ["--rtol", "at most 0.001"]),
    ("reference-rtol-1e-20", ["reference", "--rtol", "1e-20"], ["--rtol", "at least 1e-13"]),
    (
        "reference-output-longer-than-run",
        ["reference", "--output-us", "1e9", "--duration-ms", "0.1"],
        ["--output-us", "longer than the run"],
    ),
    ("reference-duration-huge", ["reference", "--duration-ms", "1e9"], ["--duration-ms 1e+09", "output samples"]),
    ("reference-segments", ["reference", "--segments", "36"], ["does not take --segments"]),
    # sweeps
    ("sweep-workers-0", ["sweep", "--workers", "0"], ["--workers", "> 0"]),
    ("sweep-workers-negative", ["sweep", "--workers", "-1"], ["--workers", "> 0"]),
    ("sweep-start-above-stop", ["sweep", "--start", "1", "--stop", "0.1"], ["--start 1 must be below --stop 0.1"]),
    ("sweep-start-is-stop", ["sweep", "--start", "0.5", "--stop", "0.5", "--points", "3"], ["--start", "below --stop"]),
    (
        "sweep-speed-default-start-above-stop",
        ["sweep", "--parameter", "speed", "--stop", "500"],
        ["--start must be below --stop", "1000 to 500 rpm"],
    ),
    ("sweep-points-0", ["sweep", "--points", "0"], ["--points", "at least 1"]),
    ("sweep-points-1e8", ["sweep", "--points", "100000000"], ["--points", "at most 100,000"]),
    ("sweep-periods-1", ["sweep", "--periods", "1"], ["--periods", "at least 2"]),
    ("sweep-sampled-0", ["sweep", "--sampled", "0"], ["--sampled", "> 0"]),
    (
        "sweep-sampled-above-periods",
        ["sweep", "--periods", "5", "--sampled", "10"],
        ["--sampled 10 must be below --periods 5"],
    ),
    ("sweep-periods-huge", ["sweep", "--periods", "1000000", "--sampled", "1"], ["--periods 1e+06", "time steps"]),
    ("sweep-stop-after-0", ["sweep", "--stop-after", "0"], ["--stop-after", "> 0"]),
    ("sweep-mechanism-unknown", ["sweep", "--mechanism", "nosuch"], ["--mechanism", "invalid choice"]),
    ("sweep-quantity-unknown", ["sweep", "--quantity", "bogus"], ["--quantity 'bogus'"]),
    ("sweep-stop-beyond-bearing", ["sweep", "--stop", "20"], ["--stop 20", "radial_clearance"]),
    ("sweep-stop-thin-journal", ["sweep", "--stop", "9.99"], ["--stop 9.99", "journal of radius 0.01 mm"]),
    (
        "sweep-speed-above-cap",
        ["sweep", "--parameter", "speed", "--start", "1000", "--stop", "1e6"],
        ["--stop 1e+06", "60,000 rpm"],
    ),
    ("sweep-rpm-above-cap", ["sweep", "--rpm", "1e7"], ["--rpm", RPM_CAP]),
    ("sweep-clearance-in-clearance-sweep", ["sweep", "--clearance-mm", "0.3"], ["--clearance-mm", "sweep over speed"]),
    ("sweep-rpm-in-speed-sweep", ["sweep", "--parameter", "speed", "--rpm", "1000"], ["--rpm", "sweep over clearance"]),
    ("sweep-clearance-at-unknown", ["sweep", "--clearance-at", "nosuch"], ["--clearance-at nosuch", "unknown joint"]),
    ("sweep-segments-with-exact", ["sweep", "--segments", "36"], ["--segments", NO_RING]),
    ("sweep-timestep-zero", ["sweep", "--timestep-us", "0"], ["--timestep-us", "> 0"]),
    ("rank-workers-0", ["rank", "--workers", "0"], ["--workers", "> 0"]),
    ("rank-periods-2", ["rank", "--periods", "2"], ["--periods", "at least 3"]),
    ("rank-joints-unknown", ["rank", "--joints", "nosuch"], ["--joints", "rod_slider"]),
    (
        "rank-clearance-beyond-bearing",
        ["rank", "--clearances-mm", "0.1", "20"],
        ["--clearances-mm 20", "radial_clearance"],
    ),
    ("rank-clearance-thin-journal", ["rank", "--clearances-mm", "9.99"], ["--clearances-mm 9.99", "journal of radius"]),
    ("rank-rpm-above-cap", ["rank", "--rpm", "1000", "1e9"], ["--rpm", RPM_CAP]),
    ("rank-stop-after-negative", ["rank", "--stop-after", "-1"], ["--stop-after", "> 0"]),
    ("rank-mechanism-unknown", ["rank", "--mechanism", "nosuch"], ["--mechanism", "invalid choice"]),
    # a robot's ranking (clearance rank --model)
    ("rank-model-missing", ["rank", "--model", "{tmp}/none.xml"], ["--model", "none.xml does not exist"]),
    ("rank-model-joint-unknown", ["rank", "--model", "{tmp}/arm.xml", "--joints", "nosuch"], ["--joints", "'nosuch'"]),
    (
        "rank-model-amplitude-above-1",
        ["rank", "--model", "{tmp}/arm.xml", "--amplitudes", "2"],
        ["--amplitudes", "at most 1"],
    ),
    (
        "rank-model-too-few-periods",
        ["rank", "--model", "{tmp}/arm.xml", "--frequencies-hz", "1"],
        ["--frequencies-hz", "whole period"],
    ),
    (
        "rank-model-out-is-a-file",
        ["rank", "--model", "{tmp}/arm.xml", "--out", "{file}"],
        ["--out {file}", "is a file"],
    ),
    # the benchmark
    ("bench-workers-0", ["bench", "--workers", "0"], ["--workers must be >= 1"]),
    ("bench-scenario-unknown", ["bench", "--scenarios", "nosuch"], ["unknown scenario", "slider_crank"]),
    ("bench-settings-match-nothing", ["bench", "--settings", "zzz*"], ["--settings zzz*", "matches no setting"]),
    (
        "bench-report-without-runs",
        ["bench", "--stage", "report", "--out", "{tmp}/b"],
        ["no reference files", "run the bench first"],
    ),
    # calibration
    ("calibrate-speeds-reversed", ["calibrate", "--speeds", "5", "1"], ["--speeds", "LO must be below HI"]),
    ("calibrate-speeds-zero", ["calibrate", "--speeds", "0", "1"], ["--speeds", "> 0"]),
    ("calibrate-speeds-huge", ["calibrate", "--speeds", "1", "1e9"], ["--speeds", "at most 100"]),
    (
        "calibrate-n-speeds-huge",
        ["calibrate", "--speeds", "0.1", "1", "--n-speeds", "1000"],
        ["--n-speeds", "at most 64"],
    ),
    ("calibrate-n-speeds-alone", ["calibrate", "--n-speeds", "3"], ["--n-speeds needs --speeds"]),
    ("calibrate-no-clearance-joint", ["calibrate", "--clearance-at"], ["no clearance joint"]),
    ("calibrate-segments-text", ["calibrate", "--segments", "x"], ["--segments", "whole number"]),
    # retrofit of a user's model
    (
        "retrofit-out-is-a-file",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "{file}"],
        ["--out {file}", "is a file"],
    ),
    (
        "retrofit-out-under-a-file",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "{file}/r"],
        ["--out {file}/r", "is a file"],
    ),
    (
        "retrofit-out-system-folder",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "/sys/r"],
        ["--out /sys/r", "cannot create"],
    ),
    (
        "retrofit-thin-journal",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow:clearance_mm=9.99", "--out", "{tmp}/r"],
        ["--joint elbow:clearance_mm=9.99", "journal of radius 0.01 mm", "bearing of radius 10 mm"],
    ),
    (
        "retrofit-segments-100000",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "{tmp}/r", "--segments", "100000"],
        ["--segments", "at most 1,024"],
    ),
    (
        "retrofit-timestep-huge",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "{tmp}/r", "--timestep-us", "1e9"],
        ["--timestep-us", "at most 10,000"],
    ),
    (
        "retrofit-sizing-huge",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "{tmp}/r", "--sizing-duration-s", "1e9"],
        ["--sizing-duration-s 1e+09", "time steps"],
    ),
    (
        "retrofit-model-missing",
        ["retrofit", "{tmp}/none.xml", "--joint", "elbow", "--out", "{tmp}/r"],
        ["none.xml does not exist"],
    ),
    # the newer commands: allocate
    ("allocate-no-budget", ["allocate"], ["--budget", "required"]),
    ("allocate-joint-unknown", ["allocate", "--joints", "nosuch", "--budget", "100"], ["--joints", "nosuch"]),
    (
        "allocate-levels-sub-micron",
        ["allocate", "--budget", "100", "--levels-mm", "0.0001", "0.05"],
        ["--levels-mm 0.0001", "outside every joint's bounds"],
    ),
    (
        "allocate-levels-twice",
        ["allocate", "--budget", "100", "--levels-mm", "0.05", "0.05"],
        ["--levels-mm 0.05", "twice"],
    ),
    (
        "allocate-cost-negative",
        ["allocate", "--budget", "100", "--cost", "crank_rod:1:-1"],
        ["--cost crank_rod:1:-1", "crank_rod's cost b", "> 0"],
    ),
    (
        "allocate-cost-joint-unknown",
        ["allocate", "--budget", "100", "--cost", "nosuch:1:1"],
        ["--cost nosuch:1:1", "'nosuch'"],
    ),
    (
        "allocate-cost-in-scenario",
        ["allocate", "--budget", "100", "--scenario", "{tmp}/alloc_cost.toml"],
        ["alloc_cost.toml", "[allocation.cost.crank_rod]", "cost b"],
    ),
    (
        "allocate-scenario-extra-table",
        ["allocate", "--budget", "100", "--scenario", "{tmp}/alloc_extra.toml"],
        ["alloc_extra.toml", "[allocation] takes only 'cost'"],
    ),
    (
        "allocate-bounds-reversed",
        ["allocate", "--budget", "100", "--bounds", "crank_rod:0.2:0.1"],
        ["--bounds crank_rod:0.2:0.1", "lower bound 0.2 mm", "upper bound 0.1 mm"],
    ),
    (
        "allocate-bounds-twice",
        ["allocate", "--budget", "100", "--bounds", "crank_rod:0.05:0.1", "crank_rod:0.06:0.1"],
        ["--bounds crank_rod:0.06:0.1", "give each joint once"],
    ),
    (
        "allocate-bounds-below-a-micron",
        ["allocate", "--budget", "100", "--bounds", "crank_rod:0.0001:0.1"],
        ["--bounds crank_rod:0.0001:0.1", "smallest clearance accepted"],
    ),
    ("allocate-min-above-max", ["allocate", "--budget", "100", "--min-mm", "0.5"], ["--min-mm 0.5 --max-mm 0.3"]),
    ("allocate-measure-unknown", ["allocate", "--budget", "100", "--measure", "median"], ["--measure median"]),
    ("allocate-rpm-above-cap", ["allocate", "--budget", "100", "--rpm", "1e9"], ["--rpm", RPM_CAP]),
    ("allocate-stop-after-0", ["allocate", "--budget", "100", "--stop-after", "0"], ["--stop-after", "> 0"]),
    ("allocate-out-is-a-file", ["allocate", "--budget", "100", "--out", "{file}"], ["--out {file}", "is a file"]),
    (
        "allocate-out-name-too-long",
        ["allocate", "--budget", "100", "--out", "{tmp}/o/" + "a" * 300 + "/x"],
        ["--out", "300 bytes long", "one name"],
    ),
    # optimise
    ("optimise-no-variable", ["optimise"], ["--vary"]),
    ("optimise-vary-reversed", ["optimise", "--vary", "rod_length_mm=200:100"], ["--vary rod_length_mm=200:100"]),
    (
        "optimise-clearance-beyond-bearing",
        ["optimise", "--vary", "rod_length_mm=100:200", "--clearance-mm", "20"],
        ["--clearance-mm 20", "bearing_radius"],
    ),
    (
        "optimise-clearance-thin-journal",
        ["optimise", "--vary", "rod_length_mm=100:200", "--clearance-mm", "9.99"],
        ["--clearance-mm 9.99", "journal of radius 0.01 mm"],
    ),
    (
        "optimise-budget-below-samples",
        ["optimise", "--vary", "rod_length_mm=100:200", "--samples", "2", "--budget", "3"],
        ["--budget 3", "--samples + 2"],
    ),
    ("optimise-stroke-one-number", ["optimise", "--vary", "rod_length_mm=100:200", "--stroke", "5"], ["--stroke 5"]),
    (
        "optimise-scenario-unknown-option",
        ["optimise", "--scenario", "{tmp}/opt_unknown.toml"],
        ["opt_unknown.toml", "bogus"],
    ),
    (
        "optimise-out-is-a-file",
        ["optimise", "--vary", "rod_length_mm=100:200", "--out", "{file}"],
        ["--out {file}", "is a file"],
    ),
    # a robot's ranking
    (
        "rank-model-frequency-1e9",
        ["rank", "--model", "{tmp}/arm.xml", "--frequencies-hz", "1e9"],
        ["--frequencies-hz 1e+09", "at most 50 Hz"],
    ),
    ("rank-model-amplitude-0", ["rank", "--model", "{tmp}/arm.xml", "--amplitudes", "0"], ["--amplitudes", "> 0"]),
    # a retrofitted model's run
    (
        "run-model-with-clearance-mm",
        ["run", "--model", "{dir}", "--clearance-mm", "0.2"],
        ["--clearance-mm", "with --model the retrofit's model"],
    ),
    ("run-model-a-model-file", ["run", "--model", "{tmp}/arm.xml"], ["--model {tmp}/arm.xml", "retrofit it first"]),
    ("run-model-missing", ["run", "--model", "{tmp}/none"], ["--model {tmp}/none", "does not exist"]),
    ("run-model-empty-folder", ["run", "--model", "{dir}"], ["--model {dir}", "no retrofit.json"]),
    (
        "run-model-negative-time-step",
        ["run", "--model", "{tmp}/rf_neg"],
        ["--model {tmp}/rf_neg", "timestep must be a finite time step > 0", "-1e-06"],
    ),
    (
        "run-model-control-and-sine",
        ["run", "--model", "{dir}", "--control", "{tmp}/over.csv", "--sine-amplitude", "0.5"],
        ["--control", "--sine-amplitude", "give one drive"],
    ),
    ("run-sine-without-model", ["run", "--sine-amplitude", "0.5"], ["--sine-amplitude", "give --model DIR too"]),
    # retrofit
    (
        "retrofit-joint-key-twice",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow:clearance_mm=0.1,clearance_mm=0.2", "--out", "{tmp}/r"],
        ["--joint 'elbow:clearance_mm=0.1,clearance_mm=0.2'", "clearance_mm is given twice"],
    ),
    (
        "retrofit-joint-unknown-key",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow:foo=1", "--out", "{tmp}/r"],
        ["'foo=1' is not key=value"],
    ),
    (
        "retrofit-sine-amplitude-0",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "{tmp}/r", "--sine-amplitude", "0"],
        ["--sine-amplitude", "> 0"],
    ),
    (
        "retrofit-sine-beyond-ctrlrange",
        ["retrofit", "{tmp}/arm_limited.xml", "--joint", "elbow", "--out", "{tmp}/r", "--sine-amplitude", "2"],
        ["--sine-amplitude 2", "ctrlrange of m"],
    ),
    (
        "retrofit-control-beyond-ctrlrange",
        [
            "retrofit",
            "{tmp}/arm_limited.xml",
            "--joint",
            "elbow",
            "--out",
            "{tmp}/r",
            "--sizing-control",
            "{tmp}/over.csv",
        ],
        ["--sizing-control {tmp}/over.csv", "column 'm'", "1.5 at t = 1 s", "ctrlrange [-1, 1]"],
    ),
    (
        "retrofit-out-name-too-long",
        ["retrofit", "{tmp}/arm.xml", "--joint", "elbow", "--out", "{tmp}/o/" + "b" * 300],
        ["--out", "300 bytes long"],
    ),
    # scenario files
    (
        "scenario-negative-speed",
        ["run", "--scenario", "{tmp}/neg_speed.toml"],
        ["neg_speed.toml, line 3", "crank_speed_rpm", "must be > 0"],
    ),
    (
        "scenario-design-section-and-unknown-table",
        ["run", "--scenario", "{tmp}/both_sections.toml"],
        ["both_sections.toml", "'bogus'", "unknown key"],
    ),
    # the viewer
    ("view-missing", ["view", "{tmp}/none.xml"], ["no such file or folder", "none.xml"]),
    ("view-folder-without-model", ["view", "{dir}"], ["folder {dir} has no model.xml"]),
    ("view-ideal-of-a-file", ["view", "--ideal", "{tmp}/arm.xml"], ["--ideal", "arm.xml is a file"]),
    # the command itself
    ("no-command", [], ["required: command"]),
    ("unknown-command", ["simulate"], ["invalid choice: 'simulate'"]),
    ("unknown-option", ["run", "--bogus"], ["unrecognized arguments: --bogus"]),
]


@functools.cache
def _full_form() -> str:
    """The default slider-crank as a whole-mechanism scenario file."""
    from clearance.builders import slider_crank
    from clearance.builders.scenario import dumps_scenario

    return dumps_scenario(slider_crank())


def _unwritable(folder: Path) -> bool:
    """Make ``folder`` unwritable for this user (chmod, or chattr +i as root); whether it worked."""
    if os.geteuid() != 0:
        folder.chmod(0o500)
    elif (
        shutil.which("chattr") is None or subprocess.run(["chattr", "+i", str(folder)], capture_output=True).returncode
    ):
        return False
    try:
        (folder / "probe").touch()
    except OSError:
        return True
    (folder / "probe").unlink()
    return False


def _writable_again(folder: Path) -> None:
    if os.geteuid() != 0:
        folder.chmod(0o700)
    else:
        subprocess.run(["chattr", "-i", str(folder)], capture_output=True)


def _sys_is_read_only() -> bool:
    try:
        os.mkdir("/sys/clearance-probe")
    except OSError:
        return os.path.isdir("/sys")
    os.rmdir("/sys/clearance-probe")
    return False


@pytest.fixture
def no_work(monkeypatch):
    """Replace everything that does work with a guard that fails the test when reached."""
    import importlib

    def guard(name):
        def refuse(*args, **kwargs):
            raise AssertionError(f"{name} was reached: the bad input was not refused before the work")

        return refuse

    # every module is imported before any is patched: one importing another's name at its own
    # import would otherwise keep the guard after this test
    modules = {path: importlib.import_module(path.rsplit(".", 1)[0]) for path in FAST_GUARDS}
    for path, name in FAST_GUARDS.items():
        monkeypatch.setattr(modules[path], path.rsplit(".", 1)[1], guard(name))

    def bench_guard(scenarios, out_dir, *, stages=("accuracy", "timing"), **kwargs):
        assert not stages, "the benchmark ran: the bad input was not refused before the work"
        return Path(out_dir)

    monkeypatch.setattr("clearance.cli.bench.run_speed_error", bench_guard)


def _call(argv: list[str], capsys) -> tuple[int, str, str]:
    """``clearance ARGV`` in this process: (exit status, stdout, stderr)."""
    try:
        rc = main(argv)
    except SystemExit as exc:  # argparse's refusals
        rc = exc.code
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.mark.parametrize("argv,words", [pytest.param(a, w, id=i) for i, a, w in BATTERY])
def test_bad_input_battery(argv, words, tmp_path, monkeypatch, capsys, no_work):
    """Refused before any work: exit 2, one error line with the option or file and why, no traceback."""
    monkeypatch.chdir(tmp_path)  # default output folders land here, and are checked not to appear
    (tmp_path / "afile").write_text("not a folder")
    (tmp_path / "adir").mkdir()
    (tmp_path / "broken").symlink_to(tmp_path / "nowhere")
    for name, text in SCENARIOS.items():
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(text)
    (tmp_path / "binary.toml").write_bytes(b"\xff\xfe\x00[mechanism]")
    full = _full_form()
    for name, (old, new) in FULL_FORM_EDITS.items():
        assert old in full, old
        (tmp_path / name).write_text(full.replace(old, new, 1))
    places = {"{tmp}": str(tmp_path), "{file}": str(tmp_path / "afile"), "{dir}": str(tmp_path / "adir")}
    if any("/sys" in a for a in argv) and not _sys_is_read_only():
        pytest.skip("no read-only /sys on this system")
    ro = None
    if any("{ro}" in a for a in argv):
        ro = tmp_path / "readonly"
        ro.mkdir()
        if not _unwritable(ro):
            _writable_again(ro)
            pytest.skip("cannot make a folder unwritable for this user here")
        places["{ro}"] = str(ro)

    def fill(text: str) -> str:
        for k, v in places.items():
            text = text.replace(k, v)
        return text

    before = sorted(tmp_path.rglob("*"))
    try:
        t0 = time.perf_counter()
        rc, out, err = _call([fill(a) for a in argv], capsys)
        elapsed = time.perf_counter() - t0
        after = sorted(tmp_path.rglob("*"))
    finally:
        if ro is not None:
            _writable_again(ro)
    assert rc == 2, (rc, out, err)
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if "error" in ln]
    assert len(lines) == 1, err
    for w in words:
        assert fill(w) in lines[0], (fill(w), lines[0])
    assert after == before, "a refused command left something behind"
    # the guard proves no work was reached; the time shows the checks are cheap: parsing and checks
    # take milliseconds (a command's first import of its modules up to about 0.5 s here), 2 s leaves
    # room for a loaded machine
    assert elapsed < 2.0, elapsed


@pytest.mark.parametrize("command", ["sweep", "rank"])
def test_scheduler_without_dask_names_the_install_command(command, tmp_path, monkeypatch, capsys, no_work):
    monkeypatch.setitem(sys.modules, "dask", None)  # `import dask...` now raises ImportError, as without Dask
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    out = tmp_path / "s"
    rc, _, err = _call([command, "--scheduler", "tcp://127.0.0.1:8786", "--out", str(out)], capsys)
    assert rc == 2 and "Traceback" not in err
    assert "--scheduler tcp://127.0.0.1:8786" in err and "pip install 'dask[distributed]'" in err
    assert not out.exists()


def test_an_unreachable_scheduler_is_one_line_after_the_stated_wait(tmp_path, capsys):
    from clearance.analysis.sweeps.executor import SCHEDULER_TIMEOUT

    pytest.importorskip("dask.distributed")
    out = tmp_path / "s"
    argv = ["sweep", "--points", "1", "--start", "0.5", "--stop", "0.5", "--periods", "2", "--sampled", "1"]
    argv += ["--out", str(out)]
    t0 = time.perf_counter()
    rc, _, err = _call([*argv, "--scheduler", "tcp://127.0.0.1:9", "--no-progress"], capsys)  # port 9: nobody listens
    elapsed = time.perf_counter() - t0
    assert rc == 2 and "Traceback" not in err, err
    assert "--scheduler tcp://127.0.0.1:9" in err and "cannot reach the Dask scheduler" in err, err
    # refused after the stated wait, not Dask's own 30 s; 10 s more covers the sweep's imports and preparation
    assert elapsed < SCHEDULER_TIMEOUT + 10, elapsed


def test_scenario_builder_sizes_out_of_range_are_refused_naming_the_key():
    """Every catalogue builder argument with a unit, at 1e-300 and 1e300 in its first unit: a
    ScenarioError naming the key (or a builder's own refusal), never ZeroDivisionError or
    OverflowError, and never silently accepted."""
    import inspect

    from clearance.builders import CATALOGUE, ScenarioError
    from clearance.builders.scenario import loads_scenario
    from clearance.units import UNITS, quantity_of

    accepted, tried = [], 0
    for name, entry in CATALOGUE.items():
        for param, p in inspect.signature(entry.builder).parameters.items():
            q = quantity_of(param)
            if q is None:
                continue
            unit = next(iter(UNITS[q]))
            pair = isinstance(p.default, tuple)
            for v in ("1e-300", "1e300"):
                key = f"{param}_{unit}"
                tried += 1
                try:
                    loads_scenario(f'[mechanism]\nbuilder = "{name}"\n{key} = {f"[{v}, {v}]" if pair else v}\n')
                except ScenarioError as err:
                    assert "[mechanism]" in str(err), str(err)
                    continue
                accepted.append((name, key, v, q, pair))
    # tiny angles and accelerations are harmless (a start angle of 1e-300 rad is 0) and pairs are
    # coordinates, which may be 0 or tiny; every other value is refused
    wrong = [a for a in accepted if not (a[2] == "1e-300" and (a[3] in ("angle", "acceleration") or a[4]))]
    assert not wrong
    assert tried > 100  # every builder's arguments were tried (12 builders)


def test_at_the_speed_cap_a_run_completes_and_the_time_step_remedy_works(tmp_path, capsys):
    """The stated cap is a speed the default run completes at, and where a time step is refused
    as too large, the step the message gives (halved, as it says to stay well below) runs."""
    import re

    out = tmp_path / "out"
    # 0.5 ms: half a revolution at 60,000 rpm, through the first impact
    rc, _, err = _call(["run", "--rpm", "60000", "--duration-ms", "0.5", "--out", str(out), "--no-progress"], capsys)
    assert rc == 0, err
    ring = ["run", "--rpm", "60000", "--contact-mode", "nominal", "--duration-ms", "1", "--no-progress"]
    rc, _, err = _call([*ring, "--timestep-us", "20", "--out", str(tmp_path / "refused")], capsys)
    below = re.search(r"Use a time step below ([0-9.e+-]+) s", err)
    assert rc == 2 and below, err
    step_us = float(below.group(1)) * 1e6 / 2
    rc, _, err = _call([*ring, "--timestep-us", f"{step_us:g}", "--out", str(tmp_path / "remedy")], capsys)
    assert rc == 0, err


def test_run_keeps_other_files_and_says_where_the_recording_went(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    rrd = tmp_path / "rec" / "run.rrd"  # a folder that does not exist yet
    # 0.3 ms: a short run; the point is what is written, kept and said
    rc, stdout, err = _call(
        ["run", "--duration-ms", "0.3", "--out", str(out), "--rerun", str(rrd), "--no-progress"], capsys
    )
    assert rc == 0, err
    assert (out / "notes.txt").read_text() == "mine"  # a run never deletes files it did not write
    assert not (out / ".clearance.lock").exists()  # the lock goes with the command
    assert rrd.stat().st_size > 0
    assert f"rerun recording written to {rrd.resolve()} (open it with: rerun {rrd.resolve()})" in stdout


def test_a_folder_in_use_is_refused_naming_the_holder(tmp_path, capsys, no_work):
    from clearance.cli.paths import folder_lock

    out = tmp_path / "out"
    with folder_lock(out):
        rc, _, err = _call(["run", "--out", str(out)], capsys)
    assert rc == 2 and "Traceback" not in err
    assert f"--out {out}: another clearance command is writing there (pid {os.getpid()} on " in err
    assert list(out.iterdir()) == []  # the refused command wrote nothing, and the lock went with its holder
    # a lock file left by a killed command holds no lock (the system releases it with the process)
    (out / ".clearance.lock").write_text('{"pid": 1, "host": "gone", "started": 0, "command": "killed"}')
    with folder_lock(out):
        assert _holder_pid(out / ".clearance.lock") == os.getpid()


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _command(*args: str) -> list[str]:
    return [sys.executable, "-m", "clearance.cli", *args]


def _holder_pid(lock: Path) -> int | None:
    try:
        return int(json.loads(lock.read_text())["pid"])
    except (OSError, ValueError, KeyError):
        return None


def test_two_runs_into_one_folder_one_completes_whole_the_other_is_refused(tmp_path):
    """Two real processes: the second starts while the first holds the folder; never a mix."""
    out = tmp_path / "out"
    common = ["run", "--out", str(out), "--no-progress"]
    # 200 ms at 3 us (about 3 s with its ideal twin, report and figures) outlasts the second's start-up
    first = subprocess.Popen(
        _command(*common, "--clearance-mm", "0.3", "--duration-ms", "200"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while _holder_pid(out / ".clearance.lock") != first.pid:
        assert first.poll() is None, first.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.01)
    second = subprocess.run(
        _command(*common, "--clearance-mm", "0.5", "--duration-ms", "200"), capture_output=True, text=True, timeout=120
    )
    first_out, first_err = first.communicate(timeout=300)
    assert first.returncode == 0, first_err
    assert second.returncode == 2 and "Traceback" not in second.stderr
    assert f"--out {out}: another clearance command is writing there (pid {first.pid} on " in second.stderr
    assert second.stdout == ""  # refused before it prepared anything
    # every file is the first run's (c = 0.3 mm)
    assert json.loads((out / "result.json").read_text())["parameters"]["radial_clearance"] == pytest.approx(0.3e-3)
    assert '<config key="clearance" value="0.0003"/>' in (out / "model.xml").read_text()
    for name in ("result.npz", "ideal.npz", "ideal_model.xml", "summary.csv", "report.md"):
        assert (out / name).stat().st_size > 0, name
    assert not (out / ".clearance.lock").exists()


def _descendants(pid: int) -> set[int]:
    """Live processes below ``pid`` (from /proc; zombies count as gone)."""
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[0] != "Z":
            children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    found, todo = set(), [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            if c not in found:
                found.add(c)
                todo.append(c)
    return found


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


SWEEP = ["sweep", "--points", "200", "--periods", "3", "--sampled", "1", "--workers", "2", "--no-progress"]
"""A sweep that runs for tens of seconds (200 points); the tests stop it within seconds."""


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_a_killed_sweep_leaves_no_worker(tmp_path):
    proc = subprocess.Popen(
        _command(*SWEEP, "--out", str(tmp_path / "s")), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    deadline = time.monotonic() + 120
    workers: set[int] = set()
    while len(workers) < 2:  # the two workers (and the resource tracker) are up
        assert proc.poll() is None and time.monotonic() < deadline
        workers = {p for p in _descendants(proc.pid) if b"spawn_main" in Path(f"/proc/{p}/cmdline").read_bytes()}
        time.sleep(0.05)
    family = _descendants(proc.pid)
    proc.kill()  # SIGKILL: the parent cleans nothing up
    proc.wait()
    deadline = time.monotonic() + 10  # workers check their parent every 0.2 s (executor.PARENT_POLL_S)
    while any(_alive(p) for p in family) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [p for p in family if _alive(p)], "processes outlived the killed sweep"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_ctrl_c_stops_a_sweep_with_one_line_and_keeps_its_points(tmp_path):
    out = tmp_path / "s"
    proc = subprocess.Popen(
        _command(*SWEEP, "--out", str(out)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group, as a shell gives a command
        # and Ctrl-C's default action, as a terminal's shell gives it: a test run started in the
        # background (`cmd &` in a script) ignores SIGINT, and its children would inherit that
        preexec_fn=_default_sigint,
    )
    deadline = time.monotonic() + 120
    while not list(out.glob("points/point_*.json")):  # the first point is kept
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    family = _descendants(proc.pid)
    os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C in a terminal does: the whole group gets SIGINT
    _, err = proc.communicate(timeout=60)
    kept = len(list((out / "points").glob("point_*.json")))
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert err.strip().splitlines() == [f"interrupted; {kept} points kept in {out}, rerun to resume"]
    assert 1 <= kept < 200
    deadline = time.monotonic() + 10
    while any(_alive(p) for p in family) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [p for p in family if _alive(p)]
    assert not (out / ".clearance.lock").exists()


def test_a_truncated_point_file_is_computed_again(tmp_path, capsys):
    out = tmp_path / "s"
    # two points of 2 periods at 5 us (a few seconds, most of it starting the worker)
    argv = ["sweep", "--points", "2", "--periods", "2", "--sampled", "1", "--workers", "1", "--no-progress"]
    assert main([*argv, "--out", str(out)]) == 0
    point = out / "points" / "point_000001.json"
    whole = json.loads(point.read_text())
    point.write_text(point.read_text()[:50])  # cut short, as by a full disk
    capsys.readouterr()
    assert main([*argv, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"warning: point file {point} is unreadable" in err and "computes it again" in err
    again = json.loads(point.read_text())
    assert again["index"] == 1 and again["poincare"] == whole["poincare"]  # runs are deterministic


def test_an_unreadable_manifest_or_digest_says_how_to_recover(tmp_path):
    from concurrent.futures import ThreadPoolExecutor

    from clearance.analysis.sweeps.run_store import RunSpec, RunStore, run_batch
    from clearance.analysis.sweeps.sweep import KeywordFactory, run_sweep
    from clearance.builders import slider_crank

    (tmp_path / "sweep.json").write_text('{"points": [')
    with pytest.raises(ValueError, match=r"sweep\.json is unreadable .* delete that folder to start over"):
        run_sweep([{"radial_clearance": 5e-4}], KeywordFactory(slider_crank), out_dir=tmp_path, progress=False)
    store = tmp_path / "store"
    # 0.2 ms runs in a thread: the point is the digest file, not the simulation
    spec = RunSpec("a", KeywordFactory(slider_crank), {}, duration=2e-4)
    with ThreadPoolExecutor(1) as ex:
        run_batch([spec], store, executor=ex, progress=False)
        digest = store / "a.digest.json"
        digest.write_text(digest.read_text()[:40])
        with pytest.raises(ValueError, match=r"a\.digest\.json is unreadable .* delete it and run the batch again"):
            RunStore(store).digest("a")
        with pytest.warns(RuntimeWarning, match=r"a\.digest\.json is unreadable .* simulated again"):
            run_batch([spec], store, executor=ex, progress=False)
    assert RunStore(store).digest("a").status == "ok", RunStore(store).digest("a").error


@pytest.mark.parametrize(
    "argv",
    [
        ["allocate", "--joints", "crank_rod", "rod_slider", "--budget", "100", "--timestep-us", "1000"],
        ["optimise", "--vary", "rod_length_mm=100:200", "--samples", "2", "--budget", "4", "--timestep-us", "1000"],
    ],
    ids=["allocate", "optimise"],
)
def test_a_time_step_every_run_would_refuse_is_one_line_naming_the_option(argv, tmp_path, capsys):
    """The design tools prepare one model before their batch: a time step the contact cannot take is
    refused once, naming --timestep-us, not reported as 'nan +- nan' or a traceback after every run failed."""
    out = tmp_path / "o"
    rc, _, err = _call([*argv, "--out", str(out), "--no-progress"], capsys)
    assert rc == 2 and "Traceback" not in err, err
    (line,) = err.strip().splitlines()
    assert line.startswith("error: --timestep-us 1000: time step 0.001 s is too large") and "nan" not in line
    assert not out.exists()  # refused before the folder was made


def test_a_scenario_with_a_design_tools_section_runs_its_mechanism(tmp_path, capsys):
    scenario = tmp_path / "s.toml"
    scenario.write_text(SCENARIOS["ok.toml"] + "\n[allocation.cost.crank_rod]\na = 1\nb = 2\n\n[optimise]\nruns = 4\n")
    out = tmp_path / "out"
    # 0.1 ms: the point is which parts of the file are read, not the run
    rc, _, err = _call(["run", "--scenario", str(scenario), "--duration-ms", "0.1", "--out", str(out)], capsys)
    assert rc == 0, err
    assert err.strip() == (
        f"note: --scenario {scenario}: [allocation] is for clearance allocate, [optimise] is for clearance "
        "optimise; this command reads the mechanism"
    )


def test_a_sweep_resumed_with_other_settings_is_refused_naming_what_differs(tmp_path, capsys):
    out = tmp_path / "s"
    # one point of 2 periods at 5 us: a second or two; the point is the second command's refusal
    argv = ["sweep", "--points", "1", "--start", "0.5", "--stop", "0.5", "--sampled", "1", "--workers", "1"]
    assert _call([*argv, "--periods", "2", "--out", str(out), "--no-progress"], capsys)[0] == 0
    rc, _, err = _call([*argv, "--periods", "3", "--out", str(out), "--no-progress"], capsys)
    assert rc == 2 and "Traceback" not in err, err
    (line,) = err.strip().splitlines()
    assert str(out) in line and "duration" in line, line


def test_a_stopped_run_says_so_at_the_head_of_its_report(tmp_path):
    from clearance.cli.outputs import note_stop

    report = tmp_path / "report.md"
    report.write_text("# slider_crank\n")
    note_stop(report, "simulation diverged at t = 1 ms")
    assert report.read_text().splitlines()[0] == (
        "**This run stopped before its end: simulation diverged at t = 1 ms. Every file here holds the run up to "
        "that time.**"
    )
