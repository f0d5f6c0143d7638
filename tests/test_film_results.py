"""A lubricated joint's result series: film thickness, eccentricity ratio and the film force.

The film thickness is c − |e| and ε = |e|/c with c the joint's clearance; the film force of a
reference run is the film at the run's states (the film formula of
`contact_calibration.film.film_force`, evaluated independently from the run's eccentricity, its
rate and the links' spin), and the part of the contact force the dry law did not give; a MuJoCo
run's is its compiled contact's sensor, and agrees with the reference's. The series survive
save/load, slicing and joining; a result saved without them still loads; the report's section
and the console line say whether the film carried the load.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from plugin_scenes import rolled_out
from test_contact_plugin import needs_plugin

from clearance import ModelOptions, simulate
from clearance.analysis.figures.film_figures import film_section, plot_film
from clearance.analysis.figures.report_sections import Window
from clearance.analysis.metrics.film import film_summaries, film_summary
from clearance.builders.scenario import load_scenario, loads_scenario
from clearance.cli.outputs import console_lines
from clearance.contact_calibration.film import film_force
from clearance.contact_plugin.attributes import sensor_offsets
from clearance.joint_result import JOINT_FIELDS
from clearance.reference import run_reference
from clearance.results import JointResult, SimulationResult
from clearance.run.preparation import exact_contact_name, prepare
from clearance.run.simulation import start_data

SCENARIO = Path(__file__).resolve().parents[1] / "builders" / "scenarios" / "lubricated_slider_crank.toml"
JOINT = "rod_slider"


@pytest.fixture(scope="module")
def mechanism():
    return load_scenario(SCENARIO)


@pytest.fixture(scope="module")
def reference(mechanism) -> SimulationResult:
    return run_reference(mechanism, 0.004)  # a third of a revolution: the film's first load peak


def _unit(e: np.ndarray) -> np.ndarray:
    """n = e/|e|, the bearing's x axis where e = 0 (as the compiled contact takes it)."""
    d = np.hypot(e[:, 0], e[:, 1])
    return np.where(d[:, None] > 0, e / np.where(d > 0, d, 1.0)[:, None], [1.0, 0.0])


def test_film_thickness_and_eccentricity_ratio(mechanism, reference) -> None:
    c = mechanism.joint(JOINT).require_clearance().radial_clearance
    jr = reference.joints[JOINT]
    d = np.hypot(*jr.eccentricity.T)
    # the penetration |e| - c rounded once: a few ulps of c
    np.testing.assert_allclose(jr.film_thickness, c - d, rtol=0, atol=1e-12 * c)
    np.testing.assert_allclose(jr.eccentricity_ratio, d / c, rtol=1e-12, atol=1e-15)
    s = film_summary(reference, JOINT)
    assert s.min_film_thickness == pytest.approx(float((c - d).min()), rel=1e-12)  # the same numbers
    assert s.max_eccentricity_ratio == pytest.approx(float(d.max() / c), rel=1e-12)
    assert s.clearance == pytest.approx(c, rel=1e-12)
    assert s.film_carried_the_load and s.dry_fraction == 0.0


def test_reference_film_force_is_the_film_at_the_run_states(mechanism, reference) -> None:
    joint = mechanism.joint(JOINT)
    cl = joint.require_clearance()
    oil = cl.lubrication
    assert oil is not None and cl.bearing_length is not None
    names = [lk.name for lk in mechanism.moving_links]
    bearing = joint.link_a if cl.journal_link == joint.link_b else joint.link_b
    theta = np.unwrap(reference.link_poses[:, :, 2], axis=0)
    spin = theta[:, names.index(cl.journal_link)] - (theta[:, names.index(bearing)] if bearing in names else 0.0)
    spin = np.gradient(spin, reference.times, edge_order=2)
    jr = reference.joints[JOINT]
    assert jr.film_force is not None
    expected = film_force(
        oil.film,
        jr.eccentricity,
        jr.eccentricity_rate,
        spin,
        viscosity=oil.viscosity,
        journal_radius=cl.journal_radius,
        bearing_length=cl.bearing_length,
        clearance=cl.radial_clearance,
        transition_thickness=oil.transition_thickness,
    )
    inner = slice(2, -2)  # the spin by second-order differences of 10 us samples, one-sided at the ends
    scale = float(np.abs(jr.film_force).max())
    # 1e-4 of the peak: the spin's finite differences (measured 6.0e-7 of the peak)
    np.testing.assert_allclose(jr.film_force[inner], expected[inner], rtol=0, atol=1e-4 * scale)
    # no dry contact here: the contact force is the film's alone (the dry law adds exactly 0)
    assert jr.penetration.max() < 0
    np.testing.assert_array_equal(jr.contact_force, jr.film_force)


def test_the_dry_part_of_a_ruptured_film_is_the_dry_law() -> None:
    # a tenth of the oil at the crank-rod joint: through the transition into dry contact at 3.0 ms
    text = SCENARIO.read_text().replace("viscosity_pa_s = 0.03", "viscosity_pa_s = 0.003")
    mech = loads_scenario(text.replace('clearance_at = ["rod_slider"]', 'clearance_at = ["crank_rod"]'))
    res = run_reference(mech, 0.0033)
    jr = res.joints["crank_rod"]
    assert jr.film_force is not None
    dry = jr.contact_force - jr.film_force
    on = jr.penetration > 0
    assert on.any() and not on.all()
    np.testing.assert_array_equal(dry[~on], 0.0)  # no dry force in the film: contact force = film force
    # frictionless LN: the rest is along -n; a film left in it would push across n (its F_t)
    n = _unit(jr.eccentricity[on])
    cross = n[:, 0] * dry[on, 1] - n[:, 1] * dry[on, 0]
    size = np.hypot(*dry[on].T)
    assert np.all(np.sum(n * dry[on], axis=1) < 0)
    assert np.abs(cross).max() <= 1e-12 * size.max()  # rounding of the rotation (measured 5e-16)
    s = film_summary(res, "crank_rod")
    assert not s.film_carried_the_load and s.dry_fraction == pytest.approx(float(on.mean()))
    assert s.max_eccentricity_ratio > 1


@needs_plugin
def test_mujoco_film_force_is_the_sensor_s(mechanism) -> None:
    prepared = prepare(mechanism, ModelOptions(contact_mode="exact"))
    model = prepared.model
    res, raw, _ = rolled_out(prepared, start_data(model), 400)
    jr = res.joints[JOINT]
    at = sensor_offsets(model, exact_contact_name(JOINT))
    e = jr.eccentricity
    u = _unit(e)
    t = np.stack([-u[:, 1], u[:, 0]], axis=1)
    film = raw[:, [at["film_normal_force"]]] * u + raw[:, [at["film_tangential_force"]]] * t
    dry = -raw[:, [at["normal_force"]]] * u + raw[:, [at["tangential_force"]]] * t
    assert jr.film_force is not None
    scale = float(np.abs(film).max())
    assert scale > 100.0  # the film carries the slider's load (kN)
    # the same products summed in another order: rounding of the largest term
    np.testing.assert_allclose(jr.film_force, film, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(jr.contact_force - jr.film_force, dry, rtol=0, atol=1e-12 * scale)
    # |e| from the sensor's own eccentricity slot: c - |e| is the film thickness
    np.testing.assert_allclose(jr.film_thickness, -raw[:, at["penetration"]], rtol=0, atol=1e-15)


@needs_plugin
def test_mujoco_film_force_follows_the_reference_s(mechanism, reference) -> None:
    run = simulate(mechanism, duration=0.004, options=ModelOptions(contact_mode="exact"))
    a, b = run.joints[JOINT].film_force, reference.joints[JOINT].film_force
    assert a is not None and b is not None
    on_run = np.stack([np.interp(run.times, reference.times, b[:, i]) for i in range(2)], axis=1)
    # after the film's first microseconds: the journal starts centred and the film's damping
    # (a relaxation time m/D of 0.3 us) sets its force within the first step, whose mean the
    # compiled contact gives at row 0 where the reference gives the state's 0
    late = run.times >= 5 * run.metadata["time_step"]
    scale = float(np.abs(b).max())
    # 5e-3 of the peak: measured 7.9e-4 at the default 3 us (2.4e-5 at 1 us against the reference
    # sampled every 1 us: the error falls faster than the step)
    np.testing.assert_allclose(a[late], on_run[late], rtol=0, atol=5e-3 * scale)


def _synthetic(film: bool) -> SimulationResult:
    n = 50
    t = np.linspace(0.0, 0.049, n)
    phi = 2 * np.pi * t / 0.01
    e = 6e-6 * np.stack([np.cos(phi), np.sin(phi)], axis=1)
    f = 1e3 * np.stack([np.cos(phi), np.zeros(n)], axis=1)
    jr = JointResult(e, np.gradient(e, t, axis=0), np.hypot(*e.T) - 1e-5, -f, -f if film else None)
    z = np.zeros((n, 1))
    return SimulationResult(t, {"x": t.copy()}, {"j": jr}, z, z, z, np.zeros((n, 1, 3)), np.zeros(n))


def test_film_series_survive_save_load_slicing_and_joining(tmp_path) -> None:
    res = _synthetic(film=True)
    res.save(tmp_path / "oil")
    back = SimulationResult.load(tmp_path / "oil")
    assert back.joints["j"].film_force is not None
    np.testing.assert_array_equal(back.joints["j"].film_force, res.joints["j"].film_force)  # a file round trip
    np.testing.assert_array_equal(res.sliced(slice(3, 9)).joints["j"].film_force, res.joints["j"].film_force[3:9])
    joined = SimulationResult.concatenate([res.sliced(slice(0, 20)), res.sliced(slice(20, None))])
    np.testing.assert_array_equal(joined.joints["j"].film_force, res.joints["j"].film_force)
    dry = _synthetic(film=False)
    assert not any("film" in k for k in dry.arrays())  # a dry joint saves as before the field existed
    dry.save(tmp_path / "dry")
    assert SimulationResult.load(tmp_path / "dry").joints["j"].film_force is None
    assert film_summaries(dry) == []
    with pytest.raises(ValueError, match="carries no film force"):
        film_summary(dry, "j")


def test_a_file_saved_before_the_film_series_existed_still_loads(tmp_path) -> None:
    # a run saved before film_force existed: the .npz holds each joint's four series only
    # (joint/<j>/eccentricity, eccentricity_rate, penetration, contact_force), the .json the same
    res = _synthetic(film=True)
    npz, _ = res.save(tmp_path / "old")
    with np.load(npz) as z:
        arrays = {k: z[k] for k in z.files if not k.endswith("/film_force")}
    assert {k for k in arrays if k.startswith("joint/j/")} == {f"joint/j/{f}" for f in JOINT_FIELDS}
    np.savez(npz, **arrays)
    back = SimulationResult.load(tmp_path / "old")
    jr, was = back.joints["j"], res.joints["j"]
    assert jr.film_force is None and not jr.lubricated
    for f in JOINT_FIELDS:
        np.testing.assert_array_equal(getattr(jr, f), getattr(was, f))  # the file's own numbers
    np.testing.assert_array_equal(jr.film_thickness, -was.penetration)  # h and ε need no film series
    assert film_summaries(back) == [] and film_section(back, Window(0.0, 0.01, 0.049), tmp_path) == []


def test_report_section_and_console_line_say_the_film_carried_the_load(mechanism, tmp_path) -> None:
    res = _synthetic(film=True)
    lines = film_section(res, Window(0.0, 0.01, float(res.times[-1])), tmp_path)
    text = "\n".join(lines)
    assert "## Oil film at the lubricated joints" in text and "film_j.png" in text
    assert "the oil film carried the load" in text and "4 µm" in text  # h = 10 - 6 um throughout
    assert (tmp_path / "film_j.png").exists()
    assert film_section(_synthetic(film=False), Window(0.0, 0.01, 0.049), tmp_path) == []
    # a run no longer than its start-up window has no steady-state scale to speak of
    titles = [t.get_text() for t in plot_film(res, "j", startup=1.0).texts]
    assert any(t.endswith("the whole run is its start-up window") for t in titles)
    # the console: the minimum film thickness and the largest eccentricity ratio, not "no contact"
    from clearance.analysis.metrics.summary import summarise

    rows = [r for r in summarise(res) if r.joint == "j"]
    line = console_lines(mechanism, rows, [], films=film_summaries(res))[0]
    assert "the oil film carried the load" in line and "no contact" not in line
    assert "minimum film thickness 4 µm" in line and "eccentricity ratio 0.6" in line
