"""A lubricated journal in the compiled contact (journal_bearing.c, "Oil film") against the Python
film (`contact_calibration.film`) and against the reference solver.

The film force and torques at a state equal `film_scalar`'s; the committed lubricated
slider-crank (builders/scenarios/lubricated_slider_crank.toml, regular:
benchmarks/lubricated_regularity.md) gives the reference's minimum film thickness and peak force
at the default step; a thinner oil drives the crank–rod journal through the film's transition into
dry contact, stable at the default step.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from plugin_scenes import add_joint, planar_body
from test_contact_plugin import LN, K, needs_plugin

from clearance import ModelOptions, simulate
from clearance.builders.scenario import load_scenario, loads_scenario
from clearance.contact_calibration.film import film_parameters, film_scalar
from clearance.contact_plugin import attributes
from clearance.lubrication import FilmModel, Lubrication
from clearance.reference import run_reference

SCENARIO = Path(__file__).resolve().parents[1] / "builders" / "scenarios" / "lubricated_slider_crank.toml"
C, R_J, L = 10e-6, 0.01 - 10e-6, 0.01  # the scenario's bearing: c, journal radius, length [m]


def _free_pair(film: FilmModel) -> mujoco.MjModel:
    """A journal and a bearing, each on slide x, slide y and hinge z, with an oiled contact (RK4:
    the rates as they are, so the force is the film's at the state)."""
    spec = mujoco.MjSpec()
    spec.option.timestep = 1e-6
    spec.option.gravity = [0, 0, 0]
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    for name in ("bearing", "journal"):
        planar_body(spec.worldbody, name, mass=0.15, inertia=1e-5, prefix=f"{name}_")
    add_joint(
        spec,
        clearance=C,
        journal_radius=R_J,
        law=LN,
        stiffness=K,
        restitution=0.9,
        lubrication=Lubrication(viscosity=0.03, film=film),
        bearing_length=L,
    )
    return spec.compile()


@needs_plugin
@pytest.mark.parametrize("film", list(FilmModel))
def test_compiled_film_equals_film_scalar(film: FilmModel) -> None:
    model = _free_pair(film)
    data = mujoco.MjData(model)
    params = film_parameters(Lubrication(viscosity=0.03, film=film), journal_radius=R_J, bearing_length=L, clearance=C)
    y = attributes.sensor_offsets(model, "joint")
    rng = np.random.default_rng(5)
    for ratio in (0.0, 0.2, 0.5, 0.8, 0.95, 0.999):  # 0.95 and 0.999 beyond the transition at 0.9
        mujoco.mj_resetData(model, data)
        phi = rng.uniform(-np.pi, np.pi)
        data.qpos[:3] = [1e-3, -2e-3, 0.3]
        data.qpos[3:5] = data.qpos[:2] + ratio * C * np.array([np.cos(phi), np.sin(phi)])
        data.qpos[5] = 0.7
        data.qvel[:] = rng.uniform(-1, 1, 6) * [0.1, 0.1, 300, 0.1, 0.1, 300]
        mujoco.mj_forward(model, data)
        # e and its rate seen from the bearing, in the bearing's axes (its x axis is the film's n
        # at e = 0, where the long film is not isotropic)
        rot = data.site("bearing").xmat.reshape(3, 3)[:2, :2]
        wb = data.qvel[2]
        e_w = data.qpos[3:5] - data.qpos[:2]
        v_w = data.qvel[3:5] - data.qvel[:2] - wb * np.array([-e_w[1], e_w[0]])  # v_J - v_B - w_B x e
        (ex, ey), (vx, vy) = rot.T @ e_w, rot.T @ v_w
        fbx, fby, tj, tb = film_scalar(params, ex, ey, vx, vy, data.qvel[5] - data.qvel[2])
        fx, fy = rot @ [fbx, fby]
        d = np.hypot(ex, ey)
        n = rot @ (np.array([ex, ey]) / d if d > 0 else np.array([1.0, 0.0]))
        t = np.array([-n[1], n[0]])
        scale = np.hypot(fx, fy)
        # rtol 1e-12: the operations of film_scalar in another order (sqrt for s**0.5, the force
        # through n and t); a few ulps of the largest term
        assert data.sensordata[y["film_normal_force"]] == pytest.approx(np.dot([fx, fy], n), abs=1e-12 * scale)
        assert data.sensordata[y["film_tangential_force"]] == pytest.approx(np.dot([fx, fy], t), abs=1e-12 * scale)
        # applied at the centres with the shear torques: the hinges' passive forces are the torques
        # (no dry contact inside the clearance), the slides' the force
        np.testing.assert_allclose(data.qfrc_passive[3:5], [fx, fy], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(data.qfrc_passive[[5, 2]], [tj, tb], rtol=0, atol=1e-12 * max(abs(tj), abs(tb)))


@needs_plugin
def test_lubricated_slider_crank_matches_the_reference_at_the_default_step() -> None:
    mech = load_scenario(SCENARIO)
    duration = 3 * (mech.drive_period or 0.0)
    ref = run_reference(mech, duration, output_interval=1e-6, rtol=1e-9)
    run = simulate(mech, duration=duration, options=ModelOptions(contact_mode="exact"))
    assert run.metadata["time_step"] == pytest.approx(3e-6)  # the default step

    def film_and_peak(r):
        jr = r.joints["rod_slider"]
        return C - float(np.hypot(*jr.eccentricity.T).max()), float(jr.force_magnitude.max())

    (h_ref, f_ref), (h, f) = film_and_peak(ref), film_and_peak(run)
    assert h_ref > 1e-6  # the film carries the load: no dry contact (measured 4.11 um)
    # the 2 %; measured -0.30 % and 0.000 %
    assert h == pytest.approx(h_ref, rel=0.02)
    assert f == pytest.approx(f_ref, rel=0.02)


@needs_plugin
def test_a_journal_driven_through_the_film_into_dry_contact_is_stable_at_the_default_step() -> None:
    # a tenth of the oil's viscosity at the crank-rod joint: the journal closes the film at
    # increasing speed, through the transition (1 um) into the dry law (5.4 um of penetration)
    text = SCENARIO.read_text()
    text = text.replace("viscosity_pa_s = 0.03", "viscosity_pa_s = 0.003")
    mech = loads_scenario(text.replace('clearance_at = ["rod_slider"]', 'clearance_at = ["crank_rod"]'))
    duration = mech.drive_period or 0.0
    ref = run_reference(mech, duration, output_interval=1e-6, rtol=1e-9)
    run = simulate(mech, duration=duration, options=ModelOptions(contact_mode="exact", timestep=3e-6))
    a, b = run.joints["crank_rod"], ref.joints["crank_rod"]
    assert b.penetration.max() > 4e-6  # the reference goes through into dry contact
    # measured: penetration 5.361 against 5.364 um, peak force +0.05 %; 2 % as the bound
    assert a.penetration.max() == pytest.approx(b.penetration.max(), rel=0.02)
    assert a.force_magnitude.max() == pytest.approx(b.force_magnitude.max(), rel=0.02)


def test_two_lubricated_joints_are_refused_in_the_exact_contact_before_any_work() -> None:
    # benchmarks/lubricated_bearing.md ("Two lubricated joints"): both rod joints oiled diverge within
    # 0.09 ms at any step down to 0.5 us, so the run is refused, naming the joints and the remedy
    text = SCENARIO.read_text()
    mech = loads_scenario(text.replace('clearance_at = ["rod_slider"]', 'clearance_at = ["crank_rod", "rod_slider"]'))
    with pytest.raises(ValueError, match=r"\['crank_rod', 'rod_slider'\] are all lubricated.*clearance reference"):
        simulate(mech, duration=1e-4, options=ModelOptions())
