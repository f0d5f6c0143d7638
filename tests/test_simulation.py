"""MuJoCo runs of the default slider-crank: ideal twin vs analytic, clearance runs, halving."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearance import ModelOptions, simulate
from clearance.builders import rpm, slider_crank
from clearance.run.simulation import SimulationError


@pytest.fixture(scope="module")
def ideal_run():
    mech = slider_crank().ideal_twin()
    period = 2 * math.pi / rpm(5000)
    return simulate(mech, duration=period, options=ModelOptions(timestep=1e-6))


def test_ideal_twin_matches_analytic_kinematics(ideal_run):
    r = ideal_run
    acc = r.outputs["slider_x_acc"]
    vel = r.outputs["slider_x_vel"]
    # docs/references.md, "The classic slider-crank, ideal" (derived): -19,419 / +9,696 m/s^2,
    # 28.41 m/s; the goal is 0.5 %
    assert acc.min() == pytest.approx(-19419, rel=5e-3)
    assert acc.max() == pytest.approx(9696, rel=5e-3)
    assert np.abs(vel).max() == pytest.approx(28.41, rel=5e-3)
    # position against the closed form x = r cos(th) + sqrt(l^2 - r^2 sin^2(th))
    th = r.drive_angle[:, 0]
    x = 0.05 * np.cos(th) + np.sqrt(0.12**2 - (0.05 * np.sin(th)) ** 2)
    # 1 um: the soft loop closure and drive servo errors measured are below 0.1 um
    assert np.max(np.abs(r.outputs["slider_x"] - x)) < 1e-6


def test_drive_speed_within_0p1_percent(ideal_run):
    w = rpm(5000)
    # the bound: 0.1 % of 5000 rpm
    assert np.max(np.abs(ideal_run.drive_speed[:, 0] - w)) < 1e-3 * w


def test_ideal_run_has_no_contact_or_closure_error(ideal_run):
    assert ideal_run.joints == {}
    # the ideal twin closes its loop with a connect equality (time constant 2 h); docs/mujoco_notes.md
    # measured 0.34 um with a 1e-5 s time constant at 5000 rpm: 1 um bounds it
    assert 0 < np.max(ideal_run.closure_violation) < 1e-6


@pytest.fixture(scope="module")
def clearance_run(default_prepared):
    from clearance.run.simulation import simulate_prepared

    # one revolution at 5000 rpm = 12 ms
    return simulate_prepared(default_prepared, duration=0.012)


def test_journal_stays_inside_clearance_plus_bound(clearance_run, default_prepared):
    jr = clearance_run.joints["rod_slider"]
    bound = default_prepared.sizing["rod_slider"].penetration_limit
    # the bound is 4x the Hertz penetration of an impact at the speed gained crossing the
    # clearance under the ideal peak joint load (preparation.JointSizing); c = 0.5 mm
    assert np.max(np.hypot(*jr.eccentricity.T)) < 0.5e-3 + bound
    assert bound < 0.5e-3  # and the bound itself is a fraction of the clearance here


def test_deepest_penetration_is_the_ln_impact_of_the_fastest_approach(clearance_run, default_prepared):
    """The deepest penetration against a point-mass LN impact at the same speed and mass.

    The bound above is loose by design (4x, to catch divergence); this is the physical check.
    """
    import mujoco

    from clearance.contact_calibration import clearance_impact
    from clearance.contact_calibration.effective_mass import normal_effective_mass
    from clearance.mjcf import ring_force

    p, name = default_prepared, "rod_slider"
    jr = clearance_run.joints[name]
    on = jr.penetration > 0
    onsets = np.nonzero(on[1:] & ~on[:-1])[0] + 1
    e = jr.eccentricity
    eo = e[onsets]
    approach = np.sum(eo * jr.eccentricity_rate[onsets], axis=1) / np.hypot(*eo.T)  # d|e|/dt [m/s]
    i = int(onsets[np.argmax(approach)])  # the fastest approach of the run (the first impact)
    v = float(approach.max())
    depth = float(jr.penetration[i : i + int(np.argmax(~on[i:]))].max())
    assert depth == jr.penetration.max()  # that impact is also the deepest
    # the mass it meets along its normal: replay the run to row i (sensor row i is at i h)
    data = mujoco.MjData(p.model)
    mujoco.mj_resetDataKeyframe(p.model, data, 0)
    for _ in range(i):
        mujoco.mj_step(p.model, data)
    mujoco.mj_forward(p.model, data)
    sites = [data.site(f"{name}__{s}").xpos[:2] for s in ("journal", "bearing")]
    normal = sites[0] - sites[1]
    # the replay steps like the rollout but from the keyframe's velocities (the run starts from
    # start_data's, qvel up to 8e-13 apart here) and reads |e| from the sites, not the sensors:
    # measured 2.2e-19 m apart (one ulp); 1e-12 m covers the start's drift (< 1e-15 m over the
    # 114 steps) and is 1e-7 of the 8.8e-6 m |e| moves in one step here, so a wrong row still fails
    assert np.hypot(*normal) == pytest.approx(np.hypot(*e[i]), abs=1e-12)
    m = normal_effective_mass(p.model, data, p.mechanism, name, normal)
    clearance = p.mechanism.joint(name).clearance
    ln = clearance_impact(clearance, mass=m, speed=v).max_penetration
    ratio = depth / ln
    # Two effects make the ring go deeper than the point-mass LN impact, both computed here:
    # (1) the ring of linear rows softens as delta/c grows (benchmarks/calibration_accuracy.md):
    #     its static radial force at this depth is s K delta^1.5 (mean over the segment pitch);
    #     for the same energy a Hertz-type contact goes deeper by s^-0.4;
    ring, sizing = p.built.rings[name], p.sizing[name]
    psi = np.linspace(0, 2 * np.pi / ring.segments, 16, endpoint=False)
    at = (clearance.radial_clearance + depth) * np.column_stack([np.cos(psi), np.sin(psi)])
    f = ring_force(ring, at, stiffness=p.contact[name].stiffness, impedance_rise=p.contact[name].impedance_rise)
    s = float(np.mean(-np.sum(f * at, axis=1) / np.hypot(*at.T))) / (sizing.stiffness * depth**1.5)
    # (2) the rest of the mechanism keeps pushing during the impact, with at most the ideal
    #     joint's peak load P: at most P delta of work on top of the impact energy m v^2 / 2.
    energy = 0.5 * m * v**2
    low, high = s**-0.4, s**-0.4 * (1 + sizing.peak_load * depth / energy) ** 0.4
    # measured (calibrated ring with its fitted impedance rise, h = 2 us): s = 1.032, load up to
    # 6 % deeper, ratio 1.035 within its bounds; 2 % either side: the ring's force ripple
    # limit (ModelOptions.ripple_limit) and the calibrated damping, which matches LN's restitution
    # within 0.022 at 5 m/s (benchmarks/calibration_accuracy.md), not exactly
    assert low * 0.98 < ratio < high * 1.02
    assert ratio < 1.15  # within 15 % of the LN impact's penetration
    # the sizing's mass is taken along the ideal joint's load (cycle median 0.145 kg): this
    # impact, along the slider axis, meets 0.140 kg, inside the cycle's range
    lo, hi = sizing.effective_mass_range
    assert lo <= m <= hi


def test_contacts_occur(clearance_run):
    jr = clearance_run.joints["rod_slider"]
    assert np.any(jr.penetration > 0)
    assert np.max(jr.force_magnitude) > 1e3  # Flores and Ambrósio 2004, docs/references.md: forces of order 1e4 N
    # first impact about 0.25 ms after start (docs/references.md, "The default scenario, measured"); 0.05 ms tolerance
    # because the ring's stiffness and the effective mass shift it slightly
    t_first = clearance_run.times[np.argmax(jr.penetration > 0)]
    assert abs(t_first - 0.25e-3) < 0.05e-3


def test_contact_force_follows_the_stiffness(clearance_run, default_prepared):
    jr = clearance_run.joints["rod_slider"]
    K = default_prepared.sizing["rod_slider"].stiffness
    on = jr.penetration > 5e-6
    e = jr.eccentricity[on]
    fn = -(jr.contact_force[on] * e).sum(1) / np.hypot(*e.T)
    ratio = fn / (K * jr.penetration[on] ** 1.5)
    # the ring is sized to K within its fit (about 3 %) and damping adds or subtracts during
    # an impact; the median over the run stays within 10 % of the Hertz-type law
    assert abs(np.median(ratio) - 1) < 0.10


def test_time_step_halving_first_impact_peak(default_prepared):
    from clearance.run.preparation import prepare

    mech = default_prepared.mechanism
    # fixed, uncalibrated parameters: nominal contact, the same at both steps
    params = prepare(mech, ModelOptions(contact_mode="nominal", segments=144)).contact
    assert params["rod_slider"].source == "nominal"
    peaks = []
    for h in (1e-6, 0.5e-6):
        r = simulate(
            mech,
            duration=0.5e-3,
            options=ModelOptions(timestep=h, segments=144, contact_mode="nominal"),
            contact=params,
        )
        peaks.append(r.joints["rod_slider"].force_magnitude.max())
    # the first impact lasts ~30 us; sampling its peak at 1 us costs up to ~0.5 % and the
    # integrator error at omega*h ~ 0.1 is smaller (measured 0.07 %)
    assert peaks[1] == pytest.approx(peaks[0], rel=5e-3)


def test_time_step_too_large_is_explained():
    from clearance.run.preparation import TimeStepError

    with pytest.raises(TimeStepError, match=r"largest stable"):
        simulate(slider_crank(), duration=1e-3, options=ModelOptions(timestep=1e-4))


def test_divergence_names_time_joint_and_keeps_partial():
    # contact 1000x softer than the bearing: the journal sinks beyond the bound at once
    from clearance.options import ContactParameters

    soft = {"rod_slider": ContactParameters(stiffness=1e3, damping=0.0)}
    with pytest.raises(SimulationError) as info:
        simulate(slider_crank(), duration=3e-3, contact=soft, options=ModelOptions(segments=36, contact_mode="nominal"))
    err = info.value
    assert err.joint == "rod_slider" and err.time is not None
    assert "Remedy" in str(err)
    assert err.partial is not None and len(err.partial.times) > 0
    assert err.partial.times[-1] < err.time + 1e-12


@pytest.mark.parametrize(
    "stiffness, reason",
    [
        # per-row stiffness far beyond any bearing's (it passes validation: finite and > 0)
        (1e300, "the state became non-finite"),  # the first contact step overflows to Inf/NaN
        (1e100, "MuJoCo raised warnings ['mjWARN_BADQACC']"),  # a huge but finite acceleration
    ],
)
def test_non_finite_or_warning_stops_at_the_first_bad_step(stiffness, reason):
    from clearance.options import ContactParameters

    h, duration = 1e-6, 0.5e-3
    absurd = {"rod_slider": ContactParameters(stiffness=stiffness, damping=0.0)}
    with pytest.raises(SimulationError) as info:
        # one chunk of 500 steps: the bad step lies inside it, not at its end
        simulate(
            slider_crank(),
            duration=duration,
            contact=absurd,
            options=ModelOptions(segments=36, timestep=h, contact_mode="nominal"),
        )
    err = info.value
    assert reason in str(err) and "Remedy: use a smaller time step" in str(err)
    assert f"diverged at t = {err.time:.6g} s:" in str(err)
    # the cause is the model's state, not one joint's penetration: no joint is named
    assert err.joint is None and "at joint" not in str(err)
    # it happens at the first contact (about 0.23 ms: docs/references.md, "The default scenario,
    # measured", gives the first
    # impact at about 0.25 ms), well before the chunk ends at 0.5 ms
    assert 0.2e-3 < err.time < 0.3e-3
    p = err.partial
    assert p is not None and len(p.times) == round(err.time / h)  # every row before the bad step
    assert p.times[-1] == pytest.approx(err.time - h, abs=1e-12)  # 1e-12 s: rounding of k h
    for series in (p.outputs["slider_x_acc"], p.joints["rod_slider"].contact_force, p.drive_torque, p.link_poses):
        assert np.all(np.isfinite(series))


def test_exact_ln_step_failure_carries_the_steps_before_it():
    import copy

    import mujoco

    from clearance.contact_calibration.exact_ln import (
        ExactLNContact,
        ExactLNStepError,
        step_exact_ln,
    )
    from clearance.run.preparation import prepare

    p = prepare(slider_crank(), ModelOptions(segments=36, contact_mode="nominal"))  # the ring the step loop drives
    model = copy.copy(p.model)
    j = p.mechanism.clearance_joints[0]
    contact = ExactLNContact(
        model, j.clearance, p.built.rings[j.name], journal_geom=f"{j.name}__journal", bearing_site=f"{j.name}__bearing"
    )
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    ctrl = np.tile(data.ctrl, (6, 1))
    ctrl[3] = np.nan  # a bad control at step 3: MuJoCo warns (and zeroes it)
    with pytest.raises(ExactLNStepError) as info:
        step_exact_ln(model, data, [contact], 6, ctrl=ctrl)
    err = info.value
    assert err.step == 3 and "mjWARN_BADCTRL" in err.reason and "at step 3" in str(err)
    assert len(err.partial.qpos) == 3 and np.all(np.isfinite(err.partial.qvel))  # the three good steps


def test_bad_arguments_fail_before_work():
    with pytest.raises(ValueError, match="duration must be a positive"):
        simulate(slider_crank(), duration=-1.0)
    with pytest.raises(TypeError):
        simulate(slider_crank(), duraton=1.0)


def test_link_poses_are_link_frames(ideal_run):
    """link_poses hold each link frame's origin (not its centre of mass): compare with kinematics."""
    from clearance.kinematics import assemble

    mech = slider_crank().ideal_twin()
    q0 = assemble(mech, 0.0).reshape(-1, 3)
    # the first row is the keyframe pose, written from the same assembly: round-off only
    assert np.allclose(ideal_run.link_poses[0], q0, atol=1e-12)


def test_exact_mode_under_its_earlier_name_runs_the_whole_mechanism():
    # first impact of the default scenario in the exact mode, asked for by its earlier name
    # 'exact_ln', against the reference solver: the goal is 1 % on peak force (measured 0.04 %)
    from clearance.reference import run_reference

    mech = slider_crank()
    ref = run_reference(mech, 0.4e-3, output_interval=1e-6)
    r = simulate(mech, duration=0.4e-3, options=ModelOptions(contact_mode="exact_ln"))
    f, fr = r.joints["rod_slider"].force_magnitude, ref.joints["rod_slider"].force_magnitude
    assert f.max() == pytest.approx(fr.max(), rel=0.01)
    assert r.metadata["contact_mode"] == "exact"  # one mode, recorded under its name


def test_torque_drive_starts_at_rest_in_its_start_pose():
    import dataclasses

    from clearance import Drive, DriveKind

    base = slider_crank(clearance_at=())
    mech = dataclasses.replace(
        base, drives=(Drive("crank", "crank_pivot", DriveKind.TORQUE, torque=2.0, start_angle=0.5),)
    )
    r = simulate(mech, duration=0.01, options=ModelOptions(timestep=1e-5))
    assert r.drive_angle[0, 0] == pytest.approx(0.5, abs=1e-12)  # assembled at the start angle
    # at rest: the velocity carried into the first step is the one half a step before t = 0
    # (clearance.run.simulation.start_data), about -(h/2) alpha_0, where the first step adds
    # h alpha_0: measured 2.9 % less, the share the loop closure's rows take out of the shift
    gain = r.drive_speed[1, 0] - r.drive_speed[0, 0]
    assert gain > 0
    assert r.drive_speed[0, 0] == pytest.approx(-0.5 * gain, rel=0.05)
    assert np.all(r.drive_torque[:, 0] == 2.0)  # a motor passes its control unchanged
    assert r.drive_speed[-1, 0] > 1.0  # and a positive torque spins the crank up
