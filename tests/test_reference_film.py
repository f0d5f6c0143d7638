"""The reference solver's oil film: the scalar path against the array functions, and a run.

A lubricated slider-crank is run by the reference solver with the film at the crank-rod joint,
where the bearing (on the crank) turns at the crank's 5000 rpm: the force the run applied is
compared with `film_force` evaluated from the run's own eccentricity, its rate seen from the
bearing and the links' spin, which checks the frames and the rate the solver feeds the film.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from clearance.builders import slider_crank
from clearance.builders.scenario import load_scenario
from clearance.contact_calibration.film import film_force, film_parameters, film_scalar, film_torques
from clearance.lubrication import FilmModel, Lubrication
from clearance.options import ContactMode, ModelOptions
from clearance.reference import run_reference
from clearance.run.preparation import prepare

SCENARIO = Path(__file__).resolve().parents[1] / "builders" / "scenarios" / "lubricated_slider_crank.toml"


@pytest.mark.parametrize("film", list(FilmModel))
def test_scalar_film_is_the_array_film(film: FilmModel) -> None:
    lub = Lubrication(0.03, film, 1e-6)
    geometry = dict(journal_radius=0.0099, bearing_length=0.01, clearance=1e-4)
    p = film_parameters(lub, **geometry)
    params = dict(viscosity=0.03, transition_thickness=1e-6, **geometry)
    rng = np.random.default_rng(3)
    for _ in range(20):
        e = rng.uniform(-1e-4, 1e-4, 2)  # some beyond the transition and beyond the wall
        v, w = rng.uniform(-0.05, 0.05, 2), rng.uniform(-600, 600)
        fx, fy, tj, tb = film_scalar(p, e[0], e[1], v[0], v[1], w)
        f = film_force(film, e, v, w, **params)
        t = film_torques(film, e, f, w, **params)
        # the same formulas in another operation order: 1e-12 relative
        assert (fx, fy) == pytest.approx(tuple(f), rel=1e-12, abs=1e-12 * float(np.abs(f).max()))
        assert (tj, tb) == pytest.approx(t, rel=1e-12, abs=1e-12 * max(abs(t[0]), abs(t[1])))


def test_reference_applies_the_film_in_the_bearing_frame() -> None:
    lub = Lubrication(0.03, FilmModel.SHORT, 1e-6)
    mech = slider_crank(clearance_at=["crank_rod"], radial_clearance=1e-5, bearing_length=0.01, lubrication=lub)
    res = run_reference(mech, 0.004)
    joint = mech.joint("crank_rod")
    cl = joint.require_clearance()
    names = [lk.name for lk in mech.moving_links]
    journal = names.index(cl.journal_link)
    bearing = names.index(joint.link_a if cl.journal_link == joint.link_b else joint.link_b)
    theta = np.unwrap(res.link_poses[:, :, 2], axis=0)
    spin = np.gradient(theta[:, journal] - theta[:, bearing], res.times, edge_order=2)
    jr = res.joints["crank_rod"]
    assert np.all(jr.penetration < -1e-6)  # the film holds the journal off the wall: no dry force
    expected = film_force(
        FilmModel.SHORT,
        jr.eccentricity,
        jr.eccentricity_rate,
        spin,
        viscosity=0.03,
        journal_radius=cl.journal_radius,
        bearing_length=0.01,
        clearance=cl.radial_clearance,
        transition_thickness=1e-6,
    )
    inner = slice(2, -2)  # the spin by finite differences of 10 us samples, one-sided at the ends
    scale = float(np.abs(jr.contact_force).max())
    # 1e-3 of the peak: the spin by second-order differences over 10 us samples (measured 2.3e-6;
    # the journal's absolute spin in place of the relative one misses by 1.6)
    assert np.allclose(jr.contact_force[inner], expected[inner], rtol=0.0, atol=1e-3 * scale)


def test_lubricated_scenario_runs_on_the_film() -> None:
    mech = load_scenario(SCENARIO)
    res = run_reference(mech, 0.012)  # a third of a revolution at 5000 rpm (one revolution: 12 ms)
    jr = res.joints["rod_slider"]
    h = -jr.penetration
    assert h.min() > 1e-6  # the oil film carries the slider's inertia: never down to the transition
    assert math.isfinite(float(jr.force_magnitude.max()))


@pytest.mark.parametrize("mode", [ContactMode.NOMINAL, ContactMode.CALIBRATED])
def test_ring_modes_refuse_a_lubricated_joint(mode: ContactMode) -> None:
    # the exact contact carries the film (tests/test_film_compiled.py); a ring cannot
    mech = load_scenario(SCENARIO)
    with pytest.raises(ValueError, match="lubricated") as info:
        prepare(mech, ModelOptions(contact_mode=mode))
    text = str(info.value)
    assert "\n" not in text
    assert "cannot carry the film" in text and "contact_mode 'exact'" in text


@pytest.mark.parametrize(
    ("table", "match"),
    [
        ("viscosity = 0.03", "needs a unit in its name"),
        ("viscosity_pa_s = -1", "must be"),
        ('viscosity_pa_s = 0.03\nfilm = "medium"', "must be one of"),
        ("viscosity_pa_s = 0.03\ntransition_thickness_um = 20", "transition_thickness must be < radial_clearance"),
        ("viscosity_pa_s = 0.03\nthickness_um = 1", "thickness_um"),
    ],
)
def test_bad_lubrication_table_is_refused_in_one_line(table: str, match: str) -> None:
    from clearance.builders.scenario import ScenarioError, loads_scenario

    text = SCENARIO.read_text().split("[mechanism.lubrication]")[0] + "[mechanism.lubrication]\n" + table + "\n"
    with pytest.raises(ScenarioError, match=match) as info:
        loads_scenario(text, source="oil.toml")
    assert "\n" not in str(info.value) and "oil.toml" in str(info.value)
