"""The compiled exact contact wherever a run goes: chunked runs, sweep workers, written models."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from clearance import ModelOptions, simulate
from clearance.builders import slider_crank
from clearance.run.preparation import prepare
from clearance.run.simulation import simulate_prepared

EXACT = ModelOptions(contact_mode="exact")


def test_chunked_run_is_bitwise_the_one_long_run():
    # the plugin's state (approach speed, history) travels in mjSTATE_PLUGIN between chunks, and
    # model_stepper carries the constraint solver's warm start: chunks of 37 steps through the
    # first impact give the same arrays to the bit, by construction
    prepared = prepare(slider_crank(), EXACT)
    one = simulate_prepared(prepared, duration=0.4e-3, chunk_steps=100_000)
    many = simulate_prepared(prepared, duration=0.4e-3, chunk_steps=37)
    a, b = one.joints["rod_slider"], many.joints["rod_slider"]
    assert a.force_magnitude.max() > 1e4  # the window holds the first impact (45.9 kN)
    np.testing.assert_array_equal(a.contact_force, b.contact_force)
    np.testing.assert_array_equal(a.eccentricity, b.eccentricity)
    np.testing.assert_array_equal(one.outputs["slider_x"], many.outputs["slider_x"])


def test_a_spawned_sweep_worker_loads_the_plugin_by_itself(tmp_path):
    # a spawn-context worker starts a fresh interpreter: the plugin must arrive through the
    # mujoco.plugins entry point, not through anything the parent process did
    from clearance.analysis.sweeps.sweep import KeywordFactory, run_sweep

    out = run_sweep(
        [{"radial_clearance": 0.5e-3}],
        KeywordFactory(slider_crank),
        out_dir=tmp_path / "sweep",
        duration=2.1 * slider_crank().drive_period,  # the row's statistics skip the first period
        options=EXACT,
        max_workers=1,
        progress=False,
    )
    assert out.complete
    row = out.rows[0]
    assert row["status"] == "ok", row.get("error")


def test_the_written_model_opens_in_a_fresh_process_with_only_import_mujoco(tmp_path):
    # what MuJoCo's viewer does with `clearance run`'s model.xml: import mujoco, load the file
    xml = tmp_path / "model.xml"
    xml.write_text(prepare(slider_crank(), EXACT).to_xml())
    code = (
        "import sys, mujoco; m = mujoco.MjModel.from_xml_path(sys.argv[1]); d = mujoco.MjData(m); "
        "mujoco.mj_step(m, d); print(m.nplugin)"
    )
    done = subprocess.run([sys.executable, "-c", code, str(xml)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "1"  # one clearance joint, one plugin instance


def test_exact_mode_is_refused_cleanly_without_the_compiled_plugin(monkeypatch):
    import clearance.contact_plugin as plugin

    monkeypatch.setattr(plugin, "library_path", lambda: None)
    monkeypatch.setattr(plugin, "is_available", lambda: False)
    with pytest.raises(plugin.PluginUnavailableError, match="calibrated"):
        simulate(slider_crank(), duration=1e-4, options=EXACT)


def test_the_default_command_falls_back_to_the_ring_without_the_plugin(monkeypatch, tmp_path, capsys):
    # installed without a C compiler: `clearance run` (no --contact-mode) runs the calibrated
    # ring and says so once; asked for --contact-mode exact, it is refused before any work
    import json

    import clearance.cli.options as cli_options
    from clearance.cli import main

    monkeypatch.setattr(cli_options, "plugin_available", lambda: False)
    out = tmp_path / "out"
    assert main(["run", "--duration-ms", "0.1", "--out", str(out), "--no-progress"]) == 0
    assert json.loads((out / "result.json").read_text())["contact_mode"] == "calibrated"
    assert capsys.readouterr().err.count("compiled contact plugin is not installed") == 1

    import clearance.contact_plugin as plugin

    monkeypatch.setattr(plugin, "is_available", lambda: False)
    monkeypatch.setattr(plugin, "library_path", lambda: None)
    argv = ["run", "--contact-mode", "exact", "--duration-ms", "0.1", "--out", str(tmp_path / "x"), "--no-progress"]
    assert main(argv) == 2  # a usage error, no traceback
    assert "--contact-mode calibrated" in capsys.readouterr().err  # the message names the way out
    assert not (tmp_path / "x").exists()  # refused before any output
