"""Retrofit: radial play at hinges of third-party MuJoCo models (gymnasium's reacher and pusher)
and of a test model with every kind of element, in ring mode.

The gymnasium models run with a polymer bushing (E = 2.4 GPa, c = 0.2 mm) and 32 segments per
ring: the step the stability rule then chooses (2-5 µs) lets 0.2 s of motion run in a few
seconds; a steel bearing on these light links needs 0.5-1 µs (benchmarks/retrofit_speed.md).
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from cli_runner import run_cli as _cli
from gym_assets import gym_model

from clearance.cli import main
from clearance.contact_calibration.laws import contact_omega
from clearance.model import Material
from clearance.retrofit import PREFIX, RadialPlay, RetrofitError, RetrofitOptions, retrofit, write_retrofit
from clearance.retrofit.frames import in_plane_axes
from clearance.retrofit.motion import fired_warnings
from clearance.retrofit.sizing import STEP_OMEGA_H, choose_time_step
from clearance.retrofit.speed import run_controlled

POLYMER = Material(2.4e9, 0.4)
NUMERICS = RetrofitOptions(contact_mode="nominal", segments=32, measure_speed=False, accept_inaccurate=True)
"""32 segments keep these tests fast; they miss the 2 % ripple bound at these loads (refused without
accept_inaccurate: tests/test_retrofit_conventions.py), which these tests of the edit do not need."""


def _hinges(model: mujoco.MjModel) -> list[str]:
    return [
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        for j in range(model.njnt)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
    ]


def _bushing() -> RadialPlay:
    return RadialPlay.make(2e-4, 0.01, bearing_material=POLYMER, journal_material=POLYMER)


@pytest.fixture(scope="module", params=["reacher", "pusher"])
def gym(request):
    """(twin spec, the retrofit of every hinge) of a gymnasium model."""
    spec = mujoco.MjSpec.from_file(str(gym_model(request.param)))
    hinges = _hinges(spec.compile())
    return spec, retrofit(spec, {h: _bushing() for h in hinges}, NUMERICS)


def _names(model: mujoco.MjModel) -> set[tuple[int, str]]:
    out = set()
    for objtype, count in (
        (mujoco.mjtObj.mjOBJ_BODY, model.nbody),
        (mujoco.mjtObj.mjOBJ_JOINT, model.njnt),
        (mujoco.mjtObj.mjOBJ_GEOM, model.ngeom),
        (mujoco.mjtObj.mjOBJ_SITE, model.nsite),
        (mujoco.mjtObj.mjOBJ_PAIR, model.npair),
        (mujoco.mjtObj.mjOBJ_SENSOR, model.nsensor),
        (mujoco.mjtObj.mjOBJ_ACTUATOR, model.nu),
    ):
        out |= {(int(objtype), n) for i in range(count) if (n := mujoco.mj_id2name(model, objtype, i))}
    return out


def _mass_properties(model: mujoco.MjModel) -> np.ndarray:
    return np.concatenate(
        [model.body_mass, model.body_inertia.ravel(), model.body_ipos.ravel(), model.body_iquat.ravel()]
    )


def test_gym_models_compile_and_keep_masses_and_counts(gym):
    spec, r = gym
    twin, model = r.twin, r.model
    n = len(r.hinges)
    assert n == len(_hinges(twin)) and n >= 2
    # exact: every added geom and site is massless, so MuJoCo sums the same inertias
    np.testing.assert_array_equal(_mass_properties(model), _mass_properties(twin))
    assert (model.nbody, model.nu, model.nkey, model.ntendon, model.neq) == (
        twin.nbody,
        twin.nu,
        twin.nkey,
        twin.ntendon,
        twin.neq,
    )
    assert model.nsensor == twin.nsensor + 2 * n
    assert (model.njnt, model.nq, model.nv) == (twin.njnt + 2 * n, twin.nq + 2 * n, twin.nv + 2 * n)
    # the ring's pairs, and an explicit pair for each of the model's contacts whose inverse weight the slides
    # moved (clearance.retrofit.contact_softness: named clr_contact__k)
    kept = [model.pair(k).name for k in range(model.npair) if model.pair(k).name.startswith("clr_contact__")]
    assert model.npair == twin.npair + 32 * n + len(kept)
    assert model.opt.integrator == twin.opt.integrator
    assert model.opt.timestep == r.timestep < twin.opt.timestep
    # the step rule: omega*h at most STEP_OMEGA_H at every bearing, and within 2.5x of it (1-2-5 rounding)
    worst = max(h.sizing.omega for h in r.hinges.values()) * r.timestep
    assert STEP_OMEGA_H / 2.5 < worst <= STEP_OMEGA_H * (1 + 1e-12)
    # the user's spec is not changed
    assert spec.compile().nq == twin.nq


def test_gym_models_added_names_are_prefixed_and_kept(gym):
    _, r = gym
    before, after = _names(r.twin), _names(r.model)
    assert before <= after
    added = after - before
    assert added and all(name.startswith(PREFIX) for _, name in added)


def test_slides_do_not_take_the_models_joint_defaults(gym):
    """gymnasium's arms default joints to damping 1 and armature 1 or 0.04: the slides must not get them."""
    _, r = gym
    model = r.model
    for h in r.hinges.values():
        for slide in h.elements.slides:
            j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, slide)
            dof = model.jnt_dofadr[j]
            assert model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE
            assert (model.dof_damping[dof], model.dof_armature[dof], model.jnt_limited[j]) == (0, 0, 0)
        # the hinge keeps its own values
        jt, jm = h.hinge.joint_id, mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, h.name)
        for field in ("jnt_range", "jnt_limited", "jnt_axis", "jnt_pos"):
            np.testing.assert_array_equal(getattr(model, field)[jm], getattr(r.twin, field)[jt])
        assert model.qpos0[model.jnt_qposadr[jm]] == r.twin.qpos0[r.twin.jnt_qposadr[jt]]
        dt, dm = r.twin.jnt_dofadr[jt], model.jnt_dofadr[jm]
        assert (model.dof_damping[dm], model.dof_armature[dm]) == (r.twin.dof_damping[dt], r.twin.dof_armature[dt])


def _sensor(model: mujoco.MjModel, sensordata: np.ndarray, name: str) -> np.ndarray:
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
    adr, dim = model.sensor_adr[sid], model.sensor_dim[sid]
    return sensordata[..., adr : adr + dim]


def test_gym_models_run_a_fifth_of_a_second_without_warnings(gym):
    _, r = gym
    n = int(round(0.2 / r.timestep))
    run = run_controlled(r.model, r.options.control, n)
    assert run.warnings == {}
    assert np.isfinite(run.states).all()
    for h in r.hinges.values():
        e = _sensor(r.model, run.sensordata, h.elements.sensors[0])
        # planar play: the journal never leaves its bearing's plane (round-off only)
        assert np.abs(e[:, 2]).max() < 1e-12
        pen = np.hypot(e[:, 0], e[:, 1]) - h.play.clearance.radial_clearance
        assert pen.max() > 0, f"{h.name}: the journal never reached its ring, so the check below says nothing"
        # the divergence bound of the sizing: 4x the Hertz penetration of the sized impact
        assert pen.max() < h.sizing.penetration_limit, h.name


def test_written_model_reloads_in_stock_mujoco(gym, tmp_path):
    _, r = gym
    paths = write_retrofit(r, tmp_path / "out")
    model = mujoco.MjModel.from_xml_path(str(paths["model"]))
    twin = mujoco.MjModel.from_xml_path(str(paths["original"]))
    assert (model.nq, model.npair, model.nsensor, model.opt.timestep) == (
        r.model.nq,
        r.model.npair,
        r.model.nsensor,
        r.timestep,
    )
    assert twin.nq == r.twin.nq and twin.opt.timestep == r.twin.opt.timestep
    # both files written the same way: their bodies compile identically
    np.testing.assert_array_equal(_mass_properties(model), _mass_properties(twin))
    # MuJoCo writes 6 significant digits (fromto becomes pos and a rounded quat)
    np.testing.assert_allclose(_mass_properties(twin), _mass_properties(r.twin), rtol=1e-5, atol=1e-9)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, 100)
    assert np.isfinite(data.qpos).all() and fired_warnings(data) == {}
    assert "Planar play only: no tilt" in paths["report"].read_text()


# A model with every kind of element the retrofit must keep: an include, a mesh in a mesh folder,
# default classes that would leak into new elements, a tilted hinge axis, a keyframe, a tendon, an
# equality, actuators and sensors; and joints that cannot be given play.
_MAIN = """<mujoco model="kit_arm">
  <compiler angle="radian" meshdir="assets" autolimits="true"/>
  <option integrator="RK4" timestep="0.002"/>
  <default>
    <joint damping="0.3" armature="0.01"/>
    <geom density="800" margin="0.001"/>
    <default class="servo"><position kp="20"/></default>
  </default>
  <asset><mesh name="tet" file="tet.obj"/></asset>
  <worldbody>
    <body name="base" pos="0 0 0.3">
      <geom type="box" size="0.05 0.05 0.02"/>
      <body name="upper" pos="0 0 -0.05" euler="0.2 0 0">
        <joint name="shoulder" type="hinge" axis="0 1 1" pos="0.01 0 0" range="-2 2"/>
        <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02"/>
        <body name="lower" pos="0.2 0 0">
          <joint name="elbow" type="hinge" axis="0 0 1"/>
          <geom type="capsule" fromto="0 0 0 0.15 0 0" size="0.015"/>
          <geom type="mesh" mesh="tet" pos="0.15 0 0"/>
          <site name="tip" pos="0.17 0 0"/>
        </body>
      </body>
    </body>
    <body name="carriage" pos="0.5 0 0">
      <joint name="rail" type="slide" axis="1 0 0"/>
      <joint name="swivel" type="hinge" axis="0 0 1"/>
      <geom type="sphere" size="0.03"/>
    </body>
    <body name="knob" pos="-0.5 0 0"><joint name="socket" type="ball"/><geom type="sphere" size="0.02"/></body>
    <body name="loose" pos="0 0.5 0"><freejoint name="float"/><geom type="box" size="0.02 0.02 0.02"/></body>
  </worldbody>
  <equality><connect name="loop" body1="loose" body2="world" anchor="0 0 0"/></equality>
  <tendon><fixed name="couple"><joint joint="shoulder" coef="1"/><joint joint="elbow" coef="-1"/></fixed></tendon>
  <include file="actuation.xml"/>
  <keyframe>
    <key name="bent" qpos="0.3 0.7 0.1 0.2 1 0 0 0 0 0.5 0 1 0 0 0"
         qvel="0.5 -1 0 0 0 0 0 0 0 0 0 0 0" ctrl="0.2 0.1"/>
  </keyframe>
</mujoco>
"""
_INCLUDED = """<mujoco>
  <actuator>
    <position class="servo" joint="shoulder"/>
    <motor joint="elbow" ctrlrange="-1 1"/>
  </actuator>
  <sensor>
    <jointpos joint="elbow"/>
    <framepos objtype="site" objname="tip"/>
  </sensor>
</mujoco>
"""
_TET = "v 0 0 0\nv 0.03 0 0\nv 0 0.03 0\nv 0 0 0.03\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.fixture(scope="module")
def kit(tmp_path_factory) -> Path:
    """The test model's file (with its include and mesh folder)."""
    folder = tmp_path_factory.mktemp("kit")
    (folder / "assets").mkdir()
    (folder / "assets" / "tet.obj").write_text(_TET)
    (folder / "actuation.xml").write_text(_INCLUDED)
    (folder / "arm.xml").write_text(_MAIN)
    return folder / "arm.xml"


@pytest.fixture(scope="module")
def kit_retrofit(kit):
    spec = mujoco.MjSpec.from_file(str(kit))
    plays = {
        "shoulder": RadialPlay.make(1e-4, 0.008, initial_eccentricity=(3e-5, -2e-5)),
        "elbow": RadialPlay.make(1e-4, 0.006),
    }
    options = RetrofitOptions(contact_mode="nominal", segments=24, measure_speed=False, accept_inaccurate=True)
    return retrofit(spec, plays, options)


def test_keyframes_extended_and_the_journal_starts_where_asked(kit_retrofit):
    r = kit_retrofit
    model, twin, cmap = r.model, r.twin, r.cmap
    assert model.nkey == twin.nkey == 1 == r.keyframes
    np.testing.assert_array_equal(model.key_qpos[0][cmap.qpos], twin.key_qpos[0])
    np.testing.assert_array_equal(model.key_qvel[0][cmap.qvel], twin.key_qvel[0])
    np.testing.assert_array_equal(model.key_qpos[0][cmap.slide_qpos["shoulder"]], [3e-5, -2e-5])
    np.testing.assert_array_equal(model.key_qpos[0][cmap.slide_qpos["elbow"]], [0.0, 0.0])
    assert not model.key_qvel[0][np.concatenate(list(cmap.slide_dof.values()))].any()
    np.testing.assert_array_equal(model.key_ctrl, twin.key_ctrl)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    # the slides live in the bearing frame whatever the hinge angle (0.3 rad here): round-off only
    # (measured 1.2e-17 m, 1/80 of the bound)
    np.testing.assert_allclose(_sensor(model, data.sensordata, "clr_shoulder__ecc"), [3e-5, -2e-5, 0.0], atol=1e-15)
    np.testing.assert_allclose(_sensor(model, data.sensordata, "clr_elbow__ecc"), 0.0, atol=1e-15)
    # the model's own sensors read the same as the unmodified model's at that keyframe (same pose but the offset)
    tdata = mujoco.MjData(twin)
    mujoco.mj_resetDataKeyframe(twin, tdata, 0)
    mujoco.mj_forward(twin, tdata)
    np.testing.assert_allclose(data.sensordata[:1], tdata.sensordata[:1], atol=1e-15)  # the elbow angle


def test_ring_lies_in_the_plane_normal_to_a_tilted_hinge_axis(kit_retrofit):
    r = kit_retrofit
    model = r.model
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    h = r.hinges["shoulder"]
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, h.elements.bearing_site)
    centre, axes = data.site_xpos[site], data.site_xmat[site].reshape(3, 3)
    hinge = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "shoulder")
    # the bearing frame's z is the hinge axis (world), up to round-off
    np.testing.assert_allclose(axes[:, 2], data.xaxis[hinge], atol=1e-12)
    for name in h.elements.segments:
        g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
        d = axes.T @ (data.geom_xpos[g] - centre)
        assert abs(d[2]) < 1e-12  # in the plane
        assert math.isclose(math.hypot(d[0], d[1]), h.ring.bearing_radius + h.ring.segment_radius, rel_tol=1e-12)


def test_everything_else_of_the_kit_model_is_kept(kit_retrofit, tmp_path, kit):
    r = kit_retrofit
    model, twin = r.model, r.twin
    np.testing.assert_array_equal(_mass_properties(model), _mass_properties(twin))  # exact: massless additions
    assert (model.nu, model.ntendon, model.neq, model.nmesh, model.nkey) == (2, 1, 1, 1, 1)
    assert model.nsensor == twin.nsensor + 4
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4
    # the model's default geom margin (0.001) and density do not reach the new geoms
    for h in r.hinges.values():
        for name in (h.elements.journal_geom, *h.elements.segments):
            g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
            assert (model.geom_margin[g], model.geom_contype[g], model.geom_conaffinity[g]) == (0, 0, 0)
    # written two folders away, the mesh folder still resolves
    paths = write_retrofit(r, tmp_path / "a" / "b", source_dir=kit.parent)
    reloaded = mujoco.MjModel.from_xml_path(str(paths["model"]))
    assert reloaded.nmesh == 1 and reloaded.nq == model.nq
    assert "meshdir" in paths["report"].read_text()
    twin_file = mujoco.MjModel.from_xml_path(str(paths["original"]))
    assert twin_file.nq == twin.nq and twin_file.nmesh == 1


@pytest.mark.parametrize(
    ("joint", "expected"),
    [
        ("rail", "joint 'rail' is a slide joint"),
        ("socket", "joint 'socket' is a ball joint"),
        ("float", "joint 'float' is a free joint"),
        ("swivel", "shares body 'carriage' with other joints (rail)"),
        ("loop", "connect 'loop' of model 'kit_arm': neither body (loose, world) has a hinge"),
        ("wrist", "joint 'wrist' does not exist in model 'kit_arm'; its hinges that can take radial play are"),
    ],
)
def test_joints_that_cannot_be_given_play_are_refused(kit, joint, expected):
    spec = mujoco.MjSpec.from_file(str(kit))
    with pytest.raises(RetrofitError) as err:
        retrofit(spec, {joint: RadialPlay()}, NUMERICS)
    assert expected in str(err.value)


def test_bad_plays_and_models_are_refused(kit):
    with pytest.raises(ValueError, match="radial_clearance must be > 0 and < bearing_radius"):
        RadialPlay.make(0.01, 0.01)
    with pytest.raises(ValueError, match="must be a finite number"):
        RadialPlay.make(float("nan"))
    with pytest.raises(ValueError, match="must be > 0"):
        RadialPlay.make(-1e-4)
    with pytest.raises(RetrofitError, match="initial_eccentricity must be smaller than the radial clearance"):
        RadialPlay.make(1e-4, initial_eccentricity=(1e-4, 0.0))
    with pytest.raises(RetrofitError, match="contact_mode must be 'calibrated', 'nominal' or 'exact'"):
        RetrofitOptions(contact_mode="soft")
    spec = mujoco.MjSpec.from_file(str(kit))
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    with pytest.raises(RetrofitError, match="disables contacts"):
        retrofit(spec, {"elbow": RadialPlay()}, NUMERICS)
    spec = mujoco.MjSpec.from_file(str(kit))
    spec.worldbody.add_site(name=f"{PREFIX}mine")
    with pytest.raises(RetrofitError, match="already has names starting with 'clr_'"):
        retrofit(spec, {"elbow": RadialPlay()}, NUMERICS)
    spec = mujoco.MjSpec.from_file(str(kit))
    spec.meshes[0].file = "missing.obj"
    with pytest.raises(RetrofitError, match="does not compile in MuJoCo: .*missing.obj"):
        retrofit(spec, {"elbow": RadialPlay()}, NUMERICS)


def test_retrofit_time_step_rule_is_the_runs(default_mechanism):
    """The run refuses a step just above 2/omega and takes one just below, omega = contact_omega."""
    from clearance.options import ModelOptions
    from clearance.run.preparation import TimeStepError, prepare

    s = prepare(default_mechanism, ModelOptions(contact_mode="nominal")).sizing["rod_slider"]
    omega = contact_omega(s.stiffness, s.penetration_limit, s.effective_mass)
    with pytest.raises(TimeStepError):
        prepare(default_mechanism, ModelOptions(contact_mode="nominal", timestep=2.01 / omega))
    prepare(default_mechanism, ModelOptions(contact_mode="nominal", timestep=1.99 / omega))


def test_in_plane_axes_are_a_right_handed_frame_about_the_axis():
    rng = np.random.default_rng(1)
    for axis in [np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), *rng.normal(size=(20, 3))]:
        r = in_plane_axes(axis)
        np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-12)  # orthonormal to round-off
        assert np.linalg.det(r) > 0
        np.testing.assert_allclose(r[:, 2], axis / np.linalg.norm(axis), atol=1e-12)
    np.testing.assert_allclose(in_plane_axes(np.array([0.0, 0.0, 2.0])), np.eye(3), atol=1e-15)


def test_choose_time_step_rounds_down_to_1_2_5_and_never_exceeds_the_models():
    from clearance.retrofit.sizing import PlaySizing

    def sizing(omega: float) -> PlaySizing:
        return PlaySizing(1.0, 0, 0, 0, 0, 1.0, (1.0, 1.0), 0, 8, omega)

    assert choose_time_step({"a": sizing(STEP_OMEGA_H / 3.4e-6)}, 0.01) == pytest.approx(2e-6, rel=1e-12)
    assert choose_time_step({"a": sizing(STEP_OMEGA_H / 9.9e-6), "b": sizing(1.0)}, 0.01) == pytest.approx(5e-6)
    assert choose_time_step({"a": sizing(STEP_OMEGA_H / 1e-5)}, 0.01) == pytest.approx(1e-5)
    assert choose_time_step({"a": sizing(1.0)}, 0.002) == 0.002


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--joint", "rail"], "joint 'rail' is a slide joint"),
        (["--joint", "nope"], "its hinges that can take radial play are: shoulder, elbow (a connect"),
        (["--joint", "elbow", "--clearance-mm", "8", "--bearing-radius-mm", "8"], "must be smaller than the bearing"),
        (["--joint", "elbow:clearance_mm=nan"], "clearance_mm must be a finite number"),
        (["--joint", "elbow:clearance_mm=-0.1"], "clearance_mm must be > 0"),
        (["--joint", "elbow:stiffness=3"], "is not key=value with a key among"),
        (["--joint", "elbow:eccentricity_x_mm=0.1"], "initial eccentricity (0.1, 0) mm must be smaller than"),
        (["--joint", "elbow", "--joint", "elbow"], "hinge 'elbow' is named twice"),
    ],
)
def test_cli_refuses_bad_input_before_any_work(kit, tmp_path, capsys, extra, expected):
    out = tmp_path / "out"
    code, _, err = _cli(["retrofit", str(kit), "--out", str(out), *extra], capsys)
    assert code == 2
    assert expected in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


def test_cli_refuses_a_missing_or_broken_model_file(tmp_path, capsys):
    code, _, err = _cli(["retrofit", str(tmp_path / "none.xml"), "--joint", "a", "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "none.xml does not exist" in err
    broken = tmp_path / "broken.xml"
    broken.write_text('<mujoco><worldbody><body><joint name="a"/><geom type="mesh" mesh="m"/></body></worldbody>')
    code, _, err = _cli(["retrofit", str(broken), "--joint", "a", "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "broken.xml" in err and "Traceback" not in err
    for bad in (["--clearance-mm", "inf"], ["--restitution", "1.5"], ["--friction", "-1"]):
        with pytest.raises(SystemExit) as stop:
            main(["retrofit", str(broken), "--joint", "a", "--out", str(tmp_path / "o"), *bad])
        assert stop.value.code == 2
    assert "--friction must be at least 0 (got -1)" in capsys.readouterr().err


def test_cli_retrofits_the_reacher_calibrated(tmp_path, capsys):
    """The command end to end, calibrated (one fit, cached for the session), with the speed cost."""
    model = gym_model("reacher")
    out = tmp_path / "reacher"
    argv = ["retrofit", str(model), "--joint", "joint1", "--out", str(out)]
    argv += ["--clearance-mm", "0.2", "--youngs-modulus-gpa", "2.4", "--poisson-ratio", "0.4", "--segments", "32"]
    argv += ["--sizing-duration-s", "0.3"]
    code, _, err = _cli(argv, capsys)  # 32 segments miss the ring's ripple bound: refused before the fit
    assert code == 2 and "force ripple of" in err and "--segments" in err and "--accept-inaccurate" in err
    assert err.count("\n") == 1 and not out.exists()
    code, stdout, err = _cli([*argv, "--accept-inaccurate"], capsys)
    assert code == 0, err
    assert "joint1: c = 200 µm, 32 segments" in stdout and "speed cost:" in stdout
    assert "warning: accuracy not met, kept with --accept-inaccurate: hinge 'joint1'" in stdout
    report = (out / "retrofit.md").read_text()
    for text in ("Planar play only: no tilt", "calibrated: ", "## Speed cost", "clr_joint1__x", "## Kept"):
        assert text in report
    assert "**Accuracy not met:**" in report and "--accept-inaccurate" in report
    retrofitted = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    twin = mujoco.MjModel.from_xml_path(str(out / "original.xml"))
    assert retrofitted.nq == twin.nq + 2 and retrofitted.npair == 32
    assert retrofitted.pair_solref[0, 0] < 0  # direct-mode stiffness written, not the placeholder -1
    assert retrofitted.pair_solref[0, 0] != -1.0
