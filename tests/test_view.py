"""``clearance view``: the model opens at the run's initial state; bad paths get one-line errors.

No test opens a window: `initial_state` is what the viewer is given, and the command's path
to ``mujoco.viewer.launch`` is followed with the launcher replaced.
"""

from __future__ import annotations

import sys

import mujoco
import numpy as np
import pytest

import clearance.contact_plugin as cp
from clearance.builders import slider_crank
from clearance.cli import main
from clearance.cli.view import RUN_IDEAL_MODEL, RUN_MODEL, display_problem, initial_state
from clearance.options import ContactMode, ModelOptions
from clearance.run.preparation import prepare

needs_plugin = pytest.mark.skipif(
    not cp.is_available(), reason="installed without a C compiler: no contact plugin library"
)

STEPS = 100
"""Steps taken from the opened state to see whether the mechanism moves."""


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    """A folder with the two models `clearance run` writes for the default scenario (exact contact)."""
    if not cp.is_available():
        pytest.skip("installed without a C compiler: no contact plugin library")
    folder = tmp_path_factory.mktemp("run")
    mech = slider_crank()
    options = ModelOptions(contact_mode=ContactMode.EXACT)
    (folder / RUN_MODEL).write_text(prepare(mech, options).to_xml())
    (folder / RUN_IDEAL_MODEL).write_text(prepare(mech.ideal_twin(), options).to_xml())
    return folder


@pytest.fixture(scope="module")
def ring_file(tmp_path_factory):
    """A ring model file of the default scenario (nominal contact: no calibration to fit)."""
    path = tmp_path_factory.mktemp("ring") / "ring.xml"
    path.write_text(prepare(slider_crank(), ModelOptions(contact_mode=ContactMode.NOMINAL)).to_xml())
    return path


def crank_turn(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Crank angle gained over `STEPS` steps from ``data`` [rad]."""
    adr = model.joint("crank_pivot").qposadr[0]
    start = float(data.qpos[adr])
    for _ in range(STEPS):
        mujoco.mj_step(model, data)
    return float(data.qpos[adr]) - start


def assert_at_keyframe_and_driven(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """``data`` holds keyframe 0, from which the crank turns at the drive's speed (from the default: not at all)."""
    assert model.nkey == 1
    np.testing.assert_array_equal(data.qpos, model.key_qpos[0])
    np.testing.assert_array_equal(data.qvel, model.key_qvel[0])
    np.testing.assert_array_equal(data.ctrl, model.key_ctrl[0])
    speed = 5000 * 2 * np.pi / 60  # the default scenario's 5000 rpm [rad/s]
    # the keyframe holds the drive speed as MJCF text: 6 significant digits (523.599), so 1e-5
    assert data.qvel[model.joint("crank_pivot").dofadr[0]] == pytest.approx(speed, rel=1e-5)
    # the velocity servo (kv h >> crank inertia) holds the speed: measured 3e-7 off; 1e-4 leaves room
    assert crank_turn(model, data) == pytest.approx(speed * STEPS * model.opt.timestep, rel=1e-4)
    # MuJoCo's default state of the same model: qvel 0, ctrl 0, nothing moves (exactly: no force acts)
    assert crank_turn(model, mujoco.MjData(model)) == 0.0


@needs_plugin
def test_run_folder_opens_its_model_at_keyframe_0(run_folder):
    model, data = initial_state(run_folder)
    assert model.nplugin >= 1  # the exact contact's plugin instance compiled (the plugin was loaded)
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "rod_slider__journal") >= 0
    assert_at_keyframe_and_driven(model, data)


@needs_plugin
def test_ideal_opens_the_folders_ideal_twin(run_folder):
    model, data = initial_state(run_folder, ideal=True)
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "rod_slider__journal") == -1  # no clearance joint
    assert_at_keyframe_and_driven(model, data)


@needs_plugin
def test_a_written_exact_model_file_opens_at_keyframe_0(run_folder):
    model, data = initial_state(run_folder / RUN_MODEL)
    assert_at_keyframe_and_driven(model, data)


def test_a_written_ring_model_opens_at_keyframe_0(ring_file):
    model, data = initial_state(ring_file)
    assert model.nplugin == 0  # the portable ring model needs no plugin
    assert_at_keyframe_and_driven(model, data)


def test_a_model_without_keyframe_opens_in_the_default_state(tmp_path):
    path = tmp_path / "plain.xml"
    path.write_text("<mujoco><worldbody><body><joint/><geom size='0.1'/></body></worldbody></mujoco>")
    model, data = initial_state(path)
    assert model.nkey == 0 and data.qpos[0] == 0.0 and data.qvel[0] == 0.0


def one_line_error(capsys, argv: list[str]) -> str:
    """Run ``clearance ARGV``; assert exit 2 and a single ``error:`` line; return it."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: clearance view") and "\n" not in err, err
    return err


def test_missing_path(capsys, tmp_path):
    err = one_line_error(capsys, ["view", str(tmp_path / "absent")])
    assert "no such file or folder" in err and str(tmp_path / "absent") in err


def test_folder_without_model(capsys, tmp_path):
    err = one_line_error(capsys, ["view", str(tmp_path)])
    assert f"has no {RUN_MODEL}" in err and "it holds no model" in err


def test_folder_without_ideal_model(capsys, tmp_path, ring_file):
    (tmp_path / RUN_MODEL).write_text(ring_file.read_text())
    err = one_line_error(capsys, ["view", str(tmp_path), "--ideal"])
    assert f"has no {RUN_IDEAL_MODEL}" in err and f"it holds {RUN_MODEL}" in err


def test_ideal_with_a_file_is_refused(capsys, ring_file):
    err = one_line_error(capsys, ["view", str(ring_file), "--ideal"])
    assert "--ideal" in err and "is a file" in err


@pytest.mark.parametrize(
    ("text", "mujoco_says"),
    [
        ("<mujoco><worldbody>", "XML parse error"),  # not XML
        ("<mujoco><worldbody><geom type='sphere'/></worldbody></mujoco>", "size 0 must be positive"),
    ],
)
def test_xml_that_does_not_compile(capsys, tmp_path, text, mujoco_says):
    path = tmp_path / "broken.xml"
    path.write_text(text)
    err = one_line_error(capsys, ["view", str(path)])
    assert "does not compile in MuJoCo" in err and mujoco_says in err and str(path) in err


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="macOS and Windows always have a display")
def test_no_display_says_how_to_view_instead(capsys, monkeypatch, ring_file):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert display_problem() is not None
    err = one_line_error(capsys, ["view", str(ring_file)])
    assert "no display" in err and f"clearance view {ring_file}" in err and "python -m mujoco.viewer" in err


@pytest.fixture
def fake_launch(monkeypatch):
    """A display, and ``mujoco.viewer.launch`` replaced by a recorder of what it is given."""
    viewer = pytest.importorskip("mujoco.viewer", reason="MuJoCo's viewer needs glfw")
    monkeypatch.setenv("DISPLAY", ":0")
    given: list[tuple[mujoco.MjModel, mujoco.MjData]] = []
    monkeypatch.setattr(viewer, "launch", lambda model, data: given.append((model, data)))
    return given


def test_the_viewer_is_given_the_keyframe_state(capsys, fake_launch, ring_file):
    assert main(["view", str(ring_file)]) == 0
    assert "keyframe 0 applied" in capsys.readouterr().out
    [(model, data)] = fake_launch
    assert_at_keyframe_and_driven(model, data)


def test_a_window_that_cannot_open_is_one_line(capsys, monkeypatch, fake_launch, ring_file):
    import mujoco.viewer

    def refuse(model: mujoco.MjModel, data: mujoco.MjData) -> None:
        raise mujoco.FatalError("could not initialize GLFW")

    monkeypatch.setattr(mujoco.viewer, "launch", refuse)
    err = one_line_error(capsys, ["view", str(ring_file)])
    assert "cannot open a window (could not initialize GLFW)" in err


def test_a_retrofit_folder_opens_its_model_and_with_ideal_its_unmodified_twin(tmp_path):
    # a folder written by `clearance retrofit` holds model.xml and original.xml (no ideal_model.xml)
    twin = mujoco.MjSpec.from_string(
        '<mujoco><worldbody><body name="a"><joint name="h" type="hinge" axis="0 0 1"/>'
        '<geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01"/></body></worldbody>'
        '<keyframe><key qpos="0.3"/></keyframe></mujoco>'
    )
    (tmp_path / "original.xml").write_text(twin.to_xml())
    twin.body("a").add_joint(name="clr_h__x", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0])
    twin.keys[0].qpos = [0.3, 0.0]  # the stand-in model only needs one more coordinate to tell it apart
    (tmp_path / "model.xml").write_text(twin.to_xml())
    model, data = initial_state(tmp_path)
    assert model.nq == 2 and data.qpos[0] == pytest.approx(0.3, abs=0)  # keyframe 0 applied exactly
    model, data = initial_state(tmp_path, ideal=True)
    assert model.nq == 1 and data.qpos[0] == pytest.approx(0.3, abs=0)


@pytest.mark.parametrize("plugin", [cp.PLUGIN_NAME, "clearance.backlash_stop"])
def test_a_plugin_model_without_the_library_says_how_to_install(capsys, monkeypatch, ring_file, plugin):
    """Either plugin's model, on an installation without the library, gets the install advice."""

    def unknown_plugin(path):
        raise ValueError(f"Error: unknown plugin '{plugin}'")  # MuJoCo's words for a plugin nobody registered

    monkeypatch.setattr(cp, "is_available", lambda: False)
    monkeypatch.setattr(mujoco.MjModel, "from_xml_path", staticmethod(unknown_plugin))
    assert main(["view", str(ring_file)]) == 2
    err = capsys.readouterr().err
    assert "not available" in err and err.count("\n") == 1, err
