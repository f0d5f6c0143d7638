"""Radial play at the robot's own step: the tendon stop's geometry, its region and its refusal.

The model is a pendulum of the project's own (1 kg, 0.3 m, hanging at rest under gravity: its
hinge carries m g), with radial play c = 1 mm at its pivot. Its bearing plane is x-z (hinge
about y: the radial tendon's inverse weight at qpos0 is along x, in the plane) or y-z (hinge
about x: the zero-length tendon's x direction is normal to the plane, its inverse weight 0).
"""

from __future__ import annotations

import math
import re

import mujoco
import numpy as np
import pytest
from cli_runner import run_cli
from retrofit_models import HINGES, MODELS

from clearance.retrofit import RadialPlay, RetrofitError, RetrofitOptions, retrofit
from clearance.retrofit.play_tendons import PlayKind, play_tendon_name
from clearance.retrofit.radial_stop import radial_stop_force_name
from clearance.retrofit.randomised_play import PlayDistribution, Uniform, randomise_play
from clearance.retrofit.step_stop import MAX_PENETRATION

C = 1e-3
"""Radial clearance [m]."""

G = 9.81
"""Gravity [m/s^2] (MuJoCo's default)."""


_MOTOR = '<actuator><motor name="m" joint="pivot" ctrlrange="-20 20"/></actuator>'
"""A motor on the pendulum's pivot (20 N m at full control)."""


def _pendulum(axis: str) -> str:
    return f"""<mujoco><option timestep="0.002"/><worldbody>
<body name="link" pos="0 0 1"><joint name="pivot" axis="{axis}" damping="0.05"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02" mass="1"/></body></worldbody></mujoco>"""


def _retrofit(axis: str, *, step: float, c: float = C):
    spec = mujoco.MjSpec.from_string(_pendulum(axis))
    return retrofit(spec, {"pivot": RadialPlay.make(c)}, RetrofitOptions(robot_step=step, measure_speed=False))


@pytest.mark.parametrize("axis", ["0 1 0", "1 0 0"])
def test_the_journal_rests_on_a_circle_of_radius_c(axis):
    step = 5e-4  # c = 1 mm hanging under g needs <= 0.73 ms (test below)
    r = _retrofit(axis, step=step)
    m = r.model
    tendon = m.tendon(play_tendon_name("pivot", PlayKind.RADIAL)).id
    assert m.tendon_range[tendon, 1] == C  # copied, never fitted
    assert not m.nplugin and not any(n.startswith("clr_pivot__seg") for n in (m.geom(i).name for i in range(m.ngeom)))
    d = mujoco.MjData(m)
    n, last = int(round(3.0 / step)), int(round(1.0 / step))
    length, ecc, force = np.zeros(n), np.zeros(n), np.zeros(n)
    for i in range(n):  # centred at rest: the journal falls across c onto the stop and settles
        mujoco.mj_step(m, d)
        length[i] = d.ten_length[tendon]
        ecc[i] = math.hypot(*d.sensor("clr_pivot__ecc").data[:2])
        force[i] = d.sensor(radial_stop_force_name("pivot")).data[0]
    # the tendon's length is |e|: both from the same two site positions (rounding only)
    np.testing.assert_allclose(length, ecc, rtol=1e-9, atol=1e-15)
    # its first impact (at sqrt(2 g c)) stays within the stated share of c
    assert length.max() - C <= MAX_PENETRATION * C
    tail = slice(n - last, n)
    # resting on the stop, |e| = c to within 5 % of c: a one-sided limit under a steady load chatters
    # by a few g h^2 (2.5 um here; measured up to 20 um = 2 % of c with the plane normal to x)
    assert np.abs(length[tail] - C).max() <= 0.05 * C
    # ... and the stop carries the load, m g, on average (measured within 0.1 %; 1 % for the chatter)
    assert force[tail].mean() == pytest.approx(1.0 * G, rel=1e-2)


def test_the_stop_is_inactive_inside_the_clearance_and_at_its_centre():
    r = _retrofit("0 1 0", step=5e-4)
    m = r.model
    m.opt.gravity[:] = 0.0
    tendon = m.tendon(play_tendon_name("pivot", PlayKind.RADIAL)).id
    x, y = (int(m.jnt_qposadr[m.joint(f"clr_pivot__{a}").id]) for a in "xy")
    d = mujoco.MjData(m)

    def limit_rows() -> int:
        return int(np.sum(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON))

    for size in (0.0, 1e-12, 0.5 * C, 0.999 * C):  # |e| = 0: no direction, and no row
        d.qpos[:] = 0.0
        d.qpos[[x, y]] = size * np.array([0.6, 0.8])
        mujoco.mj_forward(m, d)
        assert d.ten_length[tendon] == pytest.approx(size, abs=1e-15)
        assert limit_rows() == 0, size
    d.qpos[[x, y]] = 1.001 * C * np.array([0.6, 0.8])
    mujoco.mj_forward(m, d)
    assert limit_rows() == 1
    # a journal crossing the centre keeps its velocity: no force where the tendon has no direction
    d.qpos[:] = 0.0
    d.qpos[x] = -0.25 * C
    vx = 0.25 * C / (10.5 * m.opt.timestep)  # through e = 0 between the 10th and 11th steps
    d.qvel[:] = 0.0
    d.qvel[int(m.jnt_dofadr[m.joint("clr_pivot__x").id])] = vx
    for _ in range(20):
        mujoco.mj_step(m, d)
        assert not limit_rows()
    # no force acts (no gravity, no row, a translation has no bias force): the speed is kept to rounding
    assert d.qvel[int(m.jnt_dofadr[m.joint("clr_pivot__x").id])] == pytest.approx(vx, rel=1e-12)


def test_a_clearance_outside_the_region_is_refused_naming_what_is_usable():
    step = 2e-3
    with pytest.raises(RetrofitError) as err:
        _retrofit("0 1 0", step=step)
    text = str(err.value)
    assert err.value.hinge == "pivot"
    found = re.search(r"at least ([0-9.]+) um or a step of at most ([0-9.]+) ms", text)
    assert found, text
    smallest, largest = float(found.group(1)) * 1e-6, float(found.group(2)) * 1e-3
    assert smallest > C and largest < step
    # the named values are usable: the stop's penetration per speed is the same at every step
    # (step_stop: p = 1.89 at 1 and 2 ms) and the message rounds to 4 and 3 digits, so 1 % inside
    # each passes
    assert _retrofit("0 1 0", step=step, c=1.01 * smallest).hinges["pivot"].stop is not None
    assert _retrofit("0 1 0", step=0.99 * largest).hinges["pivot"].stop is not None


def test_randomised_radial_stops_without_an_inverse_weight_take_a_size_only():
    m = _retrofit("1 0 0", step=5e-4).model  # plane y-z: the tendon's inverse weight at qpos0 is 0
    tendon = m.tendon(play_tendon_name("pivot", PlayKind.RADIAL)).id
    assert m.tendon_invweight0[tendon] == 0.0
    worlds = randomise_play(m, n_worlds=3, radial=PlayDistribution(size=Uniform(C, 2 * C)), seed=1)
    sizes = [float(w.tendon_range[tendon, 1]) for w in worlds.models]
    np.testing.assert_array_equal(sizes, worlds.size[:, 0])  # what was drawn is what each world holds
    assert len(set(sizes)) == 3 and all(C <= s <= 2 * C for s in sizes)
    with pytest.raises(RetrofitError, match="no inverse weight at qpos0"):
        randomise_play(m, n_worlds=2, radial=PlayDistribution(stiffness=Uniform(1e4, 1e5)))


def test_cli_writes_the_stop_at_the_robot_step_and_refuses_outside(tmp_path, capsys):
    source = tmp_path / "pendulum.xml"
    source.write_text(_pendulum("0 1 0"))
    base = ["retrofit", str(source), "--joint", "pivot:clearance_mm=1", "--no-speed"]
    code, _, err = run_cli([*base, "--out", str(tmp_path / "out"), "--robot-step", "0.5"], capsys)
    assert code == 0, err
    written = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "model.xml"))
    tendon = written.tendon(play_tendon_name("pivot", PlayKind.RADIAL)).id
    assert written.tendon_range[tendon, 1] == C  # 0.001 written and read back: exact in MJCF's text
    assert written.opt.timestep == 5e-4 and written.nplugin == 0 and written.npair == 0
    run = tmp_path / "run"
    code, stdout, err = run_cli(
        ["run", "--model", str(tmp_path / "out"), "--duration-ms", "300", "--out", str(run)], capsys
    )
    assert code == 0, err
    assert "tendon-limit stops at the robot's step" in stdout and "max penetration" in stdout
    code, _, err = run_cli([*base, "--out", str(tmp_path / "refused"), "--robot-step", "2"], capsys)
    assert code == 2 and err.count("\n") == 1 and "give a clearance of at least" in err
    assert not (tmp_path / "refused").exists()


def test_a_run_driven_harder_than_the_sizing_motion_is_told_it_left_the_region(tmp_path, capsys):
    source = tmp_path / "pendulum.xml"
    source.write_text(_pendulum("0 1 0").replace("</mujoco>", _MOTOR + "</mujoco>"))
    out = tmp_path / "out"
    argv = ["retrofit", str(source), "--joint", "pivot:clearance_mm=1", "--robot-step", "0.5", "--no-speed"]
    code, _, err = run_cli([*argv, "--sine-amplitude", "0.005", "--out", str(out)], capsys)  # sized gently
    assert code == 0, err
    run = ["run", "--model", str(out), "--duration-ms", "1500", "--sine-amplitude", "1", "--sine-frequency-hz", "2"]
    code, stdout, err = run_cli([*run, "--out", str(tmp_path / "run")], capsys)
    # measured: the stop sinks 49 % of c (allowed 20 %) and passes its divergence bound (625 against 552 um)
    assert re.search(r"warning: pivot's stop sank \d+% of c \(its region allows 20%\)", stdout), stdout
    assert code == 2 and "a larger clearance or a smaller --robot-step" in err


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_convention_model_takes_the_robot_step_stop(name):
    # the hand-written models load their hinges far faster than a robot's (they are refused at 1 ms, c = 1 mm);
    # at 50 us each stop is inside its region, and the retrofit's own checks (masses, conventions) pass
    plays = {h: RadialPlay.make(C) for h in HINGES[name]}
    r = retrofit(mujoco.MjSpec.from_string(MODELS[name]), plays, RetrofitOptions(robot_step=5e-5, measure_speed=False))
    m = r.model
    for h in HINGES[name]:
        assert m.tendon_range[m.tendon(play_tendon_name(h, PlayKind.RADIAL)).id, 1] == C
        assert r.hinges[h].stop.penetration <= MAX_PENETRATION * C
    d = mujoco.MjData(m)
    for _ in range(1000):  # 50 ms
        mujoco.mj_step(m, d)
    fired = [mujoco.mjtWarning(i).name for i, w in enumerate(d.warning) if w.number]
    assert not fired, fired
