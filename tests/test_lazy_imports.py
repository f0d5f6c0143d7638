"""Imports that cost tenths of a second are paid only where they are used.

A fresh interpreter parses the command line, prepares the default run, simulates it and
computes the numbers of its summary and report, and says after each step which of the
costly packages are loaded: none of them, and no part of scipy (see
benchmarks/startup_time.md for what the run's time is made of).
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import clearance.contact_plugin as cp

COSTLY = (
    "matplotlib",
    "rerun",
    "tqdm",
    "scipy.stats",
    "scipy.signal",
    "scipy.integrate",
    "scipy.optimize",
    "scipy.spatial",
    "scipy.interpolate",
)
"""Packages that take 0.03-0.6 s to import (measured with python -X importtime)."""

SCRIPT = """
import json, sys
COSTLY = {costly!r}
loaded = {{}}
def note(step):
    loaded[step] = sorted(c for c in COSTLY if c in sys.modules)
    loaded[step + "/scipy"] = sorted(  # scipy's public subpackages
        m for m in sys.modules if m.count(".") == 1 and m.startswith("scipy.") and m[6] != "_" and m != "scipy.version"
    )

import clearance.cli
clearance.cli.build_parser().parse_args(["run", "--out", "unused"])
note("parse")
import clearance.contact_calibration
note("contact_calibration")
import clearance.contact_calibration.fit, clearance.contact_calibration.nominal, clearance.contact_calibration.store
note("calibration_store")
from clearance.builders import slider_crank
from clearance.options import ContactMode, ModelOptions
from clearance.run.preparation import prepare
mech = slider_crank()
options = ModelOptions(contact_mode=ContactMode.EXACT)
run, ideal = prepare(mech, options), prepare(mech.ideal_twin(), options)
note("prepare")
from clearance.run.simulation import simulate_prepared
result = simulate_prepared(run, duration=0.03, progress=False)
twin = simulate_prepared(ideal, duration=0.03, progress=False)
note("simulate")
from clearance.analysis.chaos.poincare import run_section
from clearance.analysis.metrics.response import compare_response, contact_modes
from clearance.analysis.metrics.statistics import deviation_statistics
from clearance.analysis.metrics.summary import summarise
summarise(result, twin, startup=mech.drive_period)
for output in result.outputs:
    deviation_statistics(result, twin, output)
    compare_response(result, twin, output)
contact_modes(result, "rod_slider")
run_section(result, ["rod_slider.ex", "rod_slider.ey"], skip=mech.drive_period)
note("numbers")
clearance.contact_calibration.clearance_impact
note("impact")
print(json.dumps(loaded))
"""


@pytest.fixture(scope="module")
def loaded() -> dict[str, list[str]]:
    """Costly packages loaded after each step of a default run, in a fresh interpreter."""
    if not cp.is_available():
        pytest.skip("installed without a C compiler: no contact plugin library (the default run's contact)")
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT.format(costly=COSTLY)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_parsing_the_command_line_loads_nothing_costly(loaded):
    assert loaded["parse"] == [] and loaded["parse/scipy"] == []


def test_the_contact_package_loads_its_impact_reference_on_first_use(loaded):
    assert loaded["contact_calibration"] == []
    assert "scipy.integrate" in loaded["impact"]  # the lazy name still works


def test_a_cached_calibration_is_read_without_the_fitting_machinery(loaded):
    # a calibrated run with its calibration cached imports the store (and so fit and nominal)
    assert loaded["calibration_store"] == [] and loaded["calibration_store/scipy"] == []


def test_preparing_and_simulating_a_run_loads_nothing_costly(loaded):
    assert loaded["prepare"] == [] and loaded["prepare/scipy"] == []
    assert loaded["simulate"] == [] and loaded["simulate/scipy"] == []


def test_a_runs_numbers_load_nothing_costly(loaded):
    # the deviation tests, lag, contact modes and Poincare section of the summary and report
    assert loaded["numbers"] == [] and loaded["numbers/scipy"] == []
