"""Joint reactions: MuJoCo and reference runs against inverse dynamics, against each other and
against Newton's law body by body; the drive torque against the energy meter; statistics,
report, figure, recording and files."""

from __future__ import annotations

import csv
import math

import mujoco
import numpy as np
import pytest
import rerun as rr
from plugin_scenes import rolled_out

import clearance.contact_plugin as cp
from clearance import ModelOptions, simulate
from clearance.analysis.figures.reaction_figures import plot_reactions, reaction_section
from clearance.analysis.metrics.reactions import (
    reaction_in_frame,
    reaction_statistics,
    summarise_reactions,
    write_reactions_csv,
)
from clearance.analysis.recording import rerun_log
from clearance.builders import build, slider_crank
from clearance.loads import joint_reaction_forces
from clearance.mjcf.spec import drive_armature
from clearance.reference import run_reference
from clearance.results import SimulationResult
from clearance.run.preparation import prepare
from clearance.run.reactions import reaction_layout

needs_plugin = pytest.mark.skipif(
    not cp.is_available(), reason="installed without a C compiler: no contact plugin library"
)

REQUIRED = 1e-3
"""The requirement: max over the cycle of |F - F_inv| / max |F_inv| <= 0.1 %."""


def _relative_error(f: np.ndarray, f_inv: np.ndarray) -> float:
    """max |f - f_inv| / max |f_inv| over rows; vectors (n, 2) or scalars (n,)."""
    if f.ndim == 1:
        return float(np.max(np.abs(f - f_inv)) / np.max(np.abs(f_inv)))
    return float(np.max(np.hypot(*(f - f_inv).T)) / np.max(np.hypot(*f_inv.T)))


@pytest.fixture(scope="module")
def ideal_mech():
    """The ideal twin of the default slider-crank (5000 rpm)."""
    return slider_crank().ideal_twin()


def test_inverse_dynamics_of_the_stated_case(ideal_mech):
    """The case the requirement names: rod-slider pin 434-2,719 N and drive torque +-138.5 N m."""
    t = np.linspace(0.0, ideal_mech.drive_period, 4001)
    forces, drives = joint_reaction_forces(ideal_mech, t)
    pin = np.hypot(*forces["rod_slider"].T)
    # the stated figures are rounded to their last digit: 0.5 N, 0.5 N, 0.05 N m
    assert pin.min() == pytest.approx(434.0, abs=0.5)
    assert pin.max() == pytest.approx(2719.0, abs=0.5)
    assert drives["crank"].max() == pytest.approx(138.5, abs=0.05)
    assert drives["crank"].min() == pytest.approx(-138.5, abs=0.05)
    # at top dead centre the slider decelerates at r w^2 (1 + r/l): the rod pulls it back (-x)
    r, rod, w, m = 0.05, 0.12, ideal_mech.drives[0].speed, ideal_mech.link("slider").mass
    assert forces["rod_slider"][0, 0] == pytest.approx(-m * r * w**2 * (1 + r / rod), rel=1e-9)  # exact kinematics
    assert forces["slider_guide"][0] == pytest.approx([0.0, 0.0], abs=1e-6)  # no side load in line


@needs_plugin
@pytest.mark.parametrize("mode", ["exact", "nominal"])
def test_mujoco_ideal_twin_reactions_match_inverse_dynamics(ideal_mech, mode):
    """Every joint and the drive torque within 0.1 % over the steady cycle, at the mode's default step.

    Measured (exact, 3 us): rod_slider 9.7e-6, drive torque 1.7e-4, every joint below 1e-4.
    The first ~50 us differ more (11 % at t = 0): MuJoCo's soft loop closure starts from zero
    violation and settles to its working violation (0.27 um) in 17 steps, about 8 of its time
    constants 2h; the comparison takes the cycle after the start-up window (the first drive
    period), the window every steady-state statistic uses, and checks separately that only
    those first steps are off.
    """
    period = ideal_mech.drive_period
    run = simulate(ideal_mech, duration=2 * period, options=ModelOptions(contact_mode=mode))
    forces, drives = joint_reaction_forces(ideal_mech, run.times)
    steady = run.times >= period - 1e-12
    assert list(run.joint_reactions) == [j.name for j in ideal_mech.joints]
    for name, f_inv in forces.items():
        assert _relative_error(run.joint_reactions[name][steady], f_inv[steady]) <= REQUIRED, name
    assert _relative_error(run.drive_torque[steady, 0], drives["crank"][steady]) <= REQUIRED
    # the closure's settling: 0.1 ms is over 15 of its time constants (2h <= 6 us)
    settled = run.times >= 1e-4
    pin = _relative_error(run.joint_reactions["rod_slider"][settled], forces["rod_slider"][settled])
    assert pin <= REQUIRED


def test_reference_ideal_twin_reactions_match_inverse_dynamics(ideal_mech):
    """Lagrange multipliers of the reference: measured 1.4e-8 (pin) and 1.4e-8 (torque) at rtol 1e-9."""
    run = run_reference(ideal_mech, ideal_mech.drive_period, output_interval=1e-5)
    forces, drives = joint_reaction_forces(ideal_mech, run.times)
    for name, f_inv in forces.items():
        assert _relative_error(run.joint_reactions[name], f_inv) <= REQUIRED, name
    assert _relative_error(run.drive_torque[:, 0], drives["crank"]) <= REQUIRED


@needs_plugin
def test_first_impact_reactions_agree_with_the_reference():
    """Every joint's first-impact peak: the exact contact against the reference solver.

    The exact contact's first impacts are within 1 % of the reference at the default step
    (measured +0.13 to +0.15 % for the three revolute joints, -0.05 % for the guide): the
    reactions, read from different quantities in each solver, agree as closely.
    """
    mech = slider_crank()
    ref = run_reference(mech, 0.4e-3, output_interval=1e-6)
    run = simulate(mech, duration=0.4e-3)
    for name in ref.joint_reactions:
        a = np.hypot(*ref.joint_reactions[name].T)
        b = np.hypot(*run.joint_reactions[name].T)
        assert b.max() == pytest.approx(a.max(), rel=0.01), name
        assert run.times[np.argmax(b)] == pytest.approx(ref.times[np.argmax(a)], abs=5e-6)  # one step, 3 us
        # before the impact (free flight) the same forces: the drive alone moves the linkage
        early = ref.times < 0.2e-3
        assert np.max(np.abs(np.interp(ref.times[early], run.times, b) - a[early])) <= 1.0  # N, of up to 8 kN


@needs_plugin
@pytest.mark.parametrize(
    ("mech", "mode"),
    [
        (build("watt_six_bar"), "exact"),  # an ideal cut (O4) and a clearance joint (D)
        (build("watt_six_bar"), "nominal"),  # the same with a ring: contacts in cfrc_ext
        (slider_crank(clearance_at=("crank_rod", "rod_slider")), "exact"),  # a clearance tree edge
    ],
    ids=["watt-exact", "watt-ring", "two-clearances-exact"],
)
def test_every_body_obeys_newton(mech, mode):
    """Sum of the joint reactions on each link = m a_com (minus gravity), at sampled rows with impacts.

    The reactions come from the readout of a rollout; a_com from MuJoCo's own acceleration of
    the body at the row's state (`mj_objectAcceleration` after `mj_forward`), so the balance is
    exact up to rounding (measured 4e-11 N on loads of 70 kN): the bound, 1e-9 of the largest
    reaction, leaves room for rounding only. The replay's solver starts from another warm start
    than the rollout's; measured, a cold start at every row changes the balance by < 1e-14 N, as
    the solver converges to rounding level on these rows. Covers tree joints (FORCE sensors, with a compiled
    contact's passive force added), cuts (the bodies' equations) and clearance joints, cut or
    tree edges, with the compiled contact and with a ring.
    """
    prepared = prepare(mech, ModelOptions(contact_mode=mode))
    model = prepared.model
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    n = 3000
    res, _, states = rolled_out(prepared, data, n)
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    loads = np.stack([np.hypot(*f.T) for f in res.joint_reactions.values()])
    rows = np.union1d(np.arange(1, n, 37), [max(1, int(np.argmax(loads.max(axis=0))))])  # the hardest impact too
    scale = loads.max()
    acc = np.zeros(6)
    for i in rows:
        mujoco.mj_setState(model, data, states[i - 1], full)  # state row i - 1 is sensor row i's state
        data.ctrl[:] = model.key_ctrl[0]
        mujoco.mj_forward(model, data)
        for lk in mech.moving_links:
            net = np.zeros(2)
            for j in mech.joints:
                net += (j.link_b == lk.name) * res.joint_reactions[j.name][i]
                net -= (j.link_a == lk.name) * res.joint_reactions[j.name][i]
            mujoco.mj_objectAcceleration(model, data, mujoco.mjtObj.mjOBJ_BODY, model.body(lk.name).id, acc, 0)
            # MuJoCo's body acceleration is a - g (as an accelerometer reads it)
            assert np.hypot(*(net - lk.mass * acc[3:5])) <= 1e-9 * scale, (lk.name, i)
    assert scale > 1e3  # impacts happened: kN loads


@needs_plugin
def test_slider_newton_and_drive_torque_against_the_energy_meter():
    """The slider's Newton equation, and the drive torque integrating to the drive's work.

    Slider: guide force + pin force = m a (the output's acceleration sensor), exact to
    rounding (1e-9 of the peak; measured 0). Drive: the torque passed to the mechanism plus the
    armature's share, times the step's mean speed, summed, is the work the energy meter (compiled,
    its own implementation) integrates: equal to rounding (measured 5e-13 J; a 4000-term sum of up
    to 117 J rounds by ~4000 eps 117 J = 1e-10 J at most, so 1e-9 J; the step-start force that
    was reported before differed by up to 144 N m at impacts).
    """
    mech = slider_crank()
    run = simulate(mech, duration=mech.drive_period)
    f = run.joint_reactions
    m = mech.link("slider").mass
    net = f["rod_slider"] + f["slider_guide"]
    scale = np.hypot(*f["rod_slider"].T).max()
    assert np.max(np.abs(net[:, 0] - m * run.outputs["slider_x_acc"])) <= 1e-9 * scale
    assert np.max(np.abs(net[:, 1])) <= 1e-9 * scale
    tau, w = run.drive_torque[:, 0], run.drive_speed[:, 0]
    h = run.times[1] - run.times[0]
    applied = tau[:-1] + drive_armature(mech) * np.diff(w) / h
    work = np.cumsum(h * applied * 0.5 * (w[:-1] + w[1:]))
    meter = run.energy["drive_work"][1:] - run.energy["drive_work"][0]
    assert np.max(np.abs(work - meter)) <= 1e-9


def test_undetermined_cuts_are_found():
    """Cuts closing a cycle through the ground cannot be told apart by the bodies' equations."""
    mech = slider_crank().ideal_twin()
    parents = {"crank": ("ground", "crank_pivot"), "rod": ("crank", "crank_rod"), "slider": ("ground", "slider_guide")}
    forest = reaction_layout(mech, parents, ("rod_slider", "crank_rod"), exact_contact=False)
    assert forest.determined.all()
    cycle = reaction_layout(
        mech, parents, ("crank_pivot", "crank_rod", "rod_slider", "slider_guide"), exact_contact=False
    )
    assert not cycle.determined.any()


# -- statistics, files, report, figure, recording ---------------------------------------------
def test_statistics_of_a_known_series():
    """Peaks, steady state and cycle peaks of a series built to have them."""
    period, h = 0.01, 1e-4
    t = np.arange(0, 3 * period, h)  # rows of a 3-period run
    m = 1.0 + np.sin(2 * np.pi * t / period) ** 2 * (1 + t / period)  # grows each period
    m[5] = 50.0  # a start-up spike
    s = reaction_statistics(t, m, name="pin", startup=period)
    assert (s.peak, s.peak_time) == (50.0, pytest.approx(5 * h))
    steady = t >= period - 1e-12
    assert s.steady_peak == pytest.approx(m[steady].max())  # the same samples
    assert s.steady_peak_time == pytest.approx(t[steady][np.argmax(m[steady])])
    assert s.cycles == 2
    first = m[(t >= period - 1e-12) & (t < 2 * period - 1e-12)].max()
    second = m[t >= 2 * period - 1e-12].max()
    assert (s.cycle_peak_min, s.cycle_peak_max) == (pytest.approx(first), pytest.approx(second))
    assert s.cycle_peak_mean == pytest.approx(0.5 * (first + second))
    short = reaction_statistics(t[t < period], m[t < period], startup=period)
    assert not short.has_steady_state and short.cycles == 0 and math.isnan(short.steady_p95)
    with pytest.raises(ValueError, match="kind must be"):
        reaction_statistics(t, m, kind="pin")


def _toy(n: int = 200, scale: float = 1.0) -> SimulationResult:
    t = np.arange(n) * 1e-4
    f = np.stack([scale * np.cos(t * 300), scale * np.sin(t * 300)], axis=1)
    poses = np.zeros((n, 1, 3))
    poses[:, 0, 2] = t * 300  # the link turns with the force: constant in its frame
    return SimulationResult(
        times=t,
        outputs={},
        joints={},
        drive_angle=np.zeros((n, 1)),
        drive_speed=np.zeros((n, 1)),
        drive_torque=np.full((n, 1), -2.0 * scale),
        link_poses=poses,
        closure_violation=np.zeros(n),
        metadata={"links": ["arm"], "drives": ["motor"], "mechanism": "toy"},
        joint_reactions={"pivot": f},
    )


def test_summary_csv_ideal_ratio_frame_and_round_trip(tmp_path):
    run, ideal = _toy(scale=3.0), _toy()
    rows = summarise_reactions(run, ideal, startup=0.005)
    assert [(r.name, r.kind, r.unit) for r in rows] == [("pivot", "joint", "N"), ("motor", "drive", "N m")]
    assert rows[0].steady_peak == pytest.approx(3.0) and rows[0].ideal_steady_peak == pytest.approx(1.0)
    assert rows[0].steady_peak_ratio == pytest.approx(3.0)  # 1e-15 of rounding in cos^2 + sin^2
    assert rows[1].peak == 6.0  # |torque|
    written = list(csv.DictReader(open(write_reactions_csv(rows, tmp_path / "reactions.csv"))))
    assert written[0]["name"] == "pivot" and float(written[0]["steady_peak_ratio"]) == pytest.approx(3.0, rel=1e-5)
    in_arm = reaction_in_frame(run, "pivot", "arm")
    assert np.allclose(in_arm, [3.0, 0.0], atol=1e-12)  # rounding of the rotation
    run.save(tmp_path / "r.npz")
    back = SimulationResult.load(tmp_path / "r.npz")
    assert np.array_equal(back.joint_reactions["pivot"], run.joint_reactions["pivot"])
    assert list(back.sliced(slice(0, 5)).joint_reactions["pivot"].shape) == [5, 2]


@needs_plugin
def test_report_section_figure_and_recording(tmp_path):
    mech = slider_crank()
    period = mech.drive_period
    run = simulate(mech, duration=1.5 * period)
    ideal = simulate(mech.ideal_twin(), duration=1.5 * period)
    lines = reaction_section(run, ideal, startup=period, figure="reactions.png")
    text = "\n".join(lines)
    for j in mech.joints:
        assert f"| {j.name} |" in text
    assert "crank (drive torque)" in text and "steady / ideal" in text and "(reactions.png)" in text
    assert "no longer than the start-up window" in "\n".join(reaction_section(run, ideal, startup=10 * period))
    fig = plot_reactions(run, ideal, startup=period, path=tmp_path / "reactions.png")
    assert {ax.get_label() for ax in fig.axes} >= {j.name for j in mech.joints} | {"crank"}
    assert (tmp_path / "reactions.png").stat().st_size > 10_000
    # the recording: each joint's magnitude, read back, is the result's
    path = rerun_log.record(run, mech, tmp_path / "run.rrd", ideal=ideal)
    got: dict[str, list[float]] = {}
    for chunk in rr.chunk.RrdReader(str(path)).stream():
        if (
            chunk.entity_path.startswith("/reactions/")
            and chunk.entity_path.endswith("/magnitude")
            and not chunk.is_static
        ):
            rb = chunk.to_record_batch()
            got.setdefault(chunk.entity_path.split("/")[2], []).extend(
                v[0] for v in rb.column("Scalars:scalars").to_pylist()
            )
    assert set(got) == {j.name for j in mech.joints}
    for name, values in got.items():
        assert np.allclose(np.sort(values), np.sort(np.hypot(*run.joint_reactions[name].T)))  # float64 scalars
