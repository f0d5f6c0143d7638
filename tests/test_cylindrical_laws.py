"""The cylindrical (conformal) laws of a pin in a hole (`contact_calibration.cylindrical_laws`).

Checked against an implementation we did not write: ladisk/DyS's
``MBD_system/contact_model/contact_model_cylinder.py`` (commit 5e6a54d), its formulas
transcribed by hand into a scratch script (not in the repository) and its implicit ones
solved there with scipy's brentq to rtol 9e-16; the forces it gave are written below.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad

from clearance.contact_calibration import cylindrical_laws as cyl_laws
from clearance.contact_calibration import laws
from clearance.contact_calibration.cylindrical_laws import (
    bearing_length,
    cylinder_law,
    cylindrical_force,
    elastic,
    elastic_energy,
    elastic_force,
    penetration,
)
from clearance.contact_calibration.impact import clearance_impact, cylinder_impact
from clearance.contact_calibration.laws import UnverifiedLawWarning
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw
from clearance.reference import simulate_system
from clearance.reference.contact import evaluate_contact
from clearance.reference.examples import journal_in_bearing

pytestmark = pytest.mark.filterwarnings("ignore::clearance.contact_calibration.laws.UnverifiedLawWarning")

EPS = 2.0**-52
PENETRATIONS = (1e-7, 1e-6, 1e-5)  # the check: 0.1, 1 and 10 um at c = 0.1 mm, L = 20 mm, steel
LOGARITHMIC = (
    ContactLaw.JOHNSON,
    ContactLaw.RADZIMOVSKY,
    ContactLaw.GOLDSMITH,
    ContactLaw.DUBOWSKY_FREUDENSTEIN,
    ContactLaw.ESDU_78035,
)
RECALLED = (ContactLaw.GOLDSMITH, ContactLaw.DUBOWSKY_FREUDENSTEIN, ContactLaw.ESDU_78035, ContactLaw.PERSSON)

# DyS's force [N] at PENETRATIONS (c = 0.1 mm, R_B = 10 mm, L = 20 mm, E = 207 GPa, nu = 0.3)
DYS = {
    ContactLaw.JOHNSON: (74.8247795836832, 1031.67189199491, 17430.6540098567),
    ContactLaw.RADZIMOVSKY: (67.2555429802933, 888.318801729282, 13406.2102534688),
    ContactLaw.LIU: (7.98576992224173, 251.40455695877, 7617.93898232274),
    ContactLaw.PEREIRA: (61.782512104509, 1008.7202462436, 16469.3292733154),
}
DYS_DUBOWSKY_FREUDENSTEIN = (19.3270890173628, 246.629701032819, 3455.19370932418)  # sigma = (1 - nu^2)/E
DYS_PERSSON = (178.701147117815, 1791.00936409986, 18292.0917130833)  # marked not implemented by DyS


def _law(law: ContactLaw, c: float = 1e-4, length: float | None = 0.02, radius: float = 0.01):
    return cylinder_law(Clearance(c, radius, law=law, bearing_length=length))


def test_new_laws_are_appended_so_compiled_codes_stay() -> None:
    old = ["hertz", "lankarani_nikravesh", "hunt_crossley", "flores", "gonthier", "hu_guo", "impact"]
    assert [m.value for m in ContactLaw][:7] == old  # codes 0..6 of the compiled contact
    assert set(list(ContactLaw)[7:]) == CYLINDRICAL_LAWS and len(CYLINDRICAL_LAWS) == 8


@pytest.mark.parametrize("law", list(DYS))
def test_checked_laws_equal_dys_by_hand(law: ContactLaw) -> None:
    cyl = _law(law)
    # the goal: 1e-6 relative (measured 1e-15: the same formulas, rearranged)
    np.testing.assert_allclose([elastic(cyl, d) for d in PENETRATIONS], DYS[law], rtol=1e-6, atol=0)


def test_recalled_laws_differ_from_dys_as_their_docstrings_say() -> None:
    # Dubowsky-Freudenstein with the compliance 1/(pi E* L) is exactly pi times DyS's (which takes
    # sigma = (1 - nu^2)/E): F_ours(delta) = pi F_DyS(delta) since delta(pi F) under ours is
    # delta(F) under DyS's. Rounding only: 1e-12.
    got = [elastic(_law(ContactLaw.DUBOWSKY_FREUDENSTEIN), d) for d in PENETRATIONS]
    np.testing.assert_allclose(got, math.pi * np.array(DYS_DUBOWSKY_FREUDENSTEIN), rtol=1e-12, atol=0)
    # Goldsmith with L^3 is Dubowsky-Freudenstein's law for a pin in a hole (R = R_B R_J / c)
    gold = [elastic(_law(ContactLaw.GOLDSMITH), d) for d in PENETRATIONS]
    np.testing.assert_allclose(gold, got, rtol=1e-12, atol=0)
    # Persson is DyS's expression written with s = tan^2(eps/2) = delta/(2c + delta): DyS's
    # arccos/tan loses digits at 0.1 um (7e-14), so 1e-12
    pers = [elastic(_law(ContactLaw.PERSSON), d) for d in PENETRATIONS]
    np.testing.assert_allclose(pers, DYS_PERSSON, rtol=1e-12, atol=0)


@pytest.mark.parametrize("law", sorted(CYLINDRICAL_LAWS, key=list(ContactLaw).index))
def test_recalled_laws_warn_once_and_checked_ones_do_not(law: ContactLaw, monkeypatch) -> None:
    monkeypatch.setattr(cyl_laws, "_warned", set())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _law(law)
        _law(law)
    unverified = [w for w in caught if issubclass(w.category, UnverifiedLawWarning)]
    assert len(unverified) == (1 if law in RECALLED else 0)
    if unverified:
        assert law.value in str(unverified[0].message)


@pytest.mark.parametrize("law", LOGARITHMIC)
@pytest.mark.parametrize("c", [1e-5, 1e-4, 5e-4])
def test_newton_solves_the_logarithmic_laws_to_rounding(law: ContactLaw, c: float) -> None:
    cyl = _law(law, c=c)
    for d in cyl.max_penetration * np.geomspace(1e-12, 1 - 1e-9, 300):
        f = elastic_force(cyl, float(d))
        u = math.log(f / cyl.reference_force)
        # residual of the law as its paper writes it, delta(F) - delta: rounding of the solve
        # (its last step below 4 ulps of |u|) and of evaluating delta(F) (log, products), so a
        # few ulps of (1 + |u|) relative to delta; measured <= 1.9
        assert abs(penetration(cyl, f) - d) <= 8 * EPS * (1 + abs(u)) * d


@pytest.mark.parametrize("law", LOGARITHMIC)
def test_beyond_the_deepest_penetration_the_law_is_refused(law: ContactLaw) -> None:
    cyl = _law(law, c=1e-5)
    top = cyl.reference_force * math.exp(cyl.offset - 1)
    # delta(F) peaks at F* = F0 e^(beta - 1) with delta* = k F* (rounding: 1e-12)
    assert penetration(cyl, top) == pytest.approx(cyl.max_penetration, rel=1e-12)
    assert penetration(cyl, 0.999 * top) < cyl.max_penetration > penetration(cyl, 1.001 * top)
    assert elastic(cyl, cyl.max_penetration) == pytest.approx(top, rel=1e-12)
    with pytest.raises(ValueError, match=r"beyond the deepest .* the law is refused there"):
        elastic(cyl, cyl.max_penetration * (1 + 1e-9))
    assert elastic_force(cyl, cyl.max_penetration * (1 + 1e-9)) == math.inf  # the integrators' wall
    # the reference solver stops there: its divergence limit is at most delta*
    system, _, _ = journal_in_bearing(Clearance(1e-5, 0.01, law=law, bearing_length=0.02), mass=0.1, speed=0.1)
    assert system.contacts[0].penetration_limit == cyl.max_penetration


def test_persson_force_grows_without_bound_at_its_deepest_penetration() -> None:
    cyl = _law(ContactLaw.PERSSON)
    near = [elastic(cyl, cyl.max_penetration * (1 - x)) for x in (1e-3, 1e-6, 1e-9)]
    assert near[0] < near[1] < near[2] and near[2] > 1e5 * elastic(cyl, cyl.clearance)
    with pytest.raises(ValueError, match="refused"):
        elastic(cyl, 1.01 * cyl.max_penetration)


def test_pereira_is_refused_outside_its_fitted_clearances() -> None:
    with pytest.raises(ValueError, match=r"0\.005-10 mm \(got 0\.004 mm\)"):
        _law(ContactLaw.PEREIRA, c=0.004e-3)
    with pytest.raises(ValueError, match=r"got 11 mm"):
        _law(ContactLaw.PEREIRA, c=11e-3, radius=0.05)
    assert _law(ContactLaw.PEREIRA, c=10e-3, radius=0.05).exponent > 0
    # its exponent's two branches meet at 0.34954 mm when the second takes c in mm (DyS takes
    # metres there): continuous to the fit's printed digits, 1e-4
    lo, hi = (_law(ContactLaw.PEREIRA, c=x * 1e-3) for x in (0.349539, 0.349541))
    assert hi.exponent == pytest.approx(lo.exponent, rel=1e-4)


@pytest.mark.parametrize("law", sorted(CYLINDRICAL_LAWS, key=list(ContactLaw).index))
def test_hysteresis_is_lankarani_nikravesh(law: ContactLaw) -> None:
    cyl, e = _law(law), 0.7
    d, dd, v = np.array([2e-6, 2e-6, 2e-6, -1e-6]), np.array([1.0, -0.5, -5.0, 1.0]), 2.0
    want = np.maximum(elastic(cyl, d) * (1 + 0.75 * (1 - e * e) * dd / v), 0.0)
    # the same factor, its products in another order: a few roundings, 1e-14
    np.testing.assert_allclose(cylindrical_force(cyl, d, dd, v, restitution=e), want, rtol=1e-14, atol=0)
    assert laws.hysteresis_factor(law, e) == laws.hysteresis_factor(ContactLaw.LANKARANI_NIKRAVESH, e)


@pytest.mark.parametrize("law", sorted(CYLINDRICAL_LAWS, key=list(ContactLaw).index))
def test_reference_solver_evaluates_the_same_law(law: ContactLaw) -> None:
    cl = Clearance(1e-4, 0.01, law=law, restitution=0.8, bearing_length=0.02)
    system, _, _ = journal_in_bearing(cl, mass=0.2, speed=1.0)
    cj = system.contacts[0]
    assert cj.cylinder == cylinder_law(cl)
    for d, dd in ((3e-6, 0.4), (2e-5, -0.2), (-1e-6, 1.0)):
        z, zd = [cl.radial_clearance + d, 0.0, 0.0], [dd, 0.0, 0.0]  # journal on the x axis
        fn = evaluate_contact(cj, z, zd, 1.5)[11]
        # the same floats through the same function: rounding of e - c only, 1e-9
        assert fn == pytest.approx(cylindrical_force(cj.cylinder, d, dd, 1.5, restitution=0.8), rel=1e-9, abs=0)


@pytest.mark.parametrize("law", sorted(CYLINDRICAL_LAWS, key=list(ContactLaw).index))
def test_elastic_energy_is_the_work_of_the_force(law: ContactLaw) -> None:
    cyl = _law(law)
    for d in (1e-7, 3e-6, 4e-5):
        work, err = quad(lambda x: elastic_force(cyl, x), 0.0, d, epsabs=0.0, epsrel=1e-12, limit=200)
        # quad's own estimate is ~1e-13; 1e-10 covers it and the Gauss-Legendre rule of Persson
        assert elastic_energy(cyl, d) == pytest.approx(work, rel=1e-10)


def test_bearing_length_defaults_to_the_bore_and_scales_the_force() -> None:
    cl = Clearance(1e-4, 0.012, law=ContactLaw.LIU)
    assert bearing_length(cl) == 0.024  # L = 2 R_B
    assert bearing_length(Clearance(1e-4, 0.012, law=ContactLaw.LIU, bearing_length=0.03)) == 0.03
    # a line contact: LIU's force is proportional to L (rounding only)
    one, two = (elastic(_law(ContactLaw.LIU, length=x), 3e-6) for x in (0.01, 0.02))
    assert two == pytest.approx(2 * one, rel=1e-14)


def test_scenario_key_bearing_length_mm_reaches_the_law() -> None:
    from clearance.builders.scenario import loads_scenario

    mech = loads_scenario(
        '[mechanism]\nbuilder = "slider_crank"\nclearance_mm = 0.1\nbearing_length_mm = 15.0\nlaw = "johnson"\n'
    )
    (joint,) = mech.clearance_joints
    assert joint.require_clearance().law is ContactLaw.JOHNSON
    assert bearing_length(joint.require_clearance()) == pytest.approx(0.015, rel=1e-15)


@pytest.mark.parametrize("law", sorted(CYLINDRICAL_LAWS, key=list(ContactLaw).index))
def test_single_impact_matches_the_impact_reference(law: ContactLaw) -> None:
    clearance = Clearance(radial_clearance=0.5e-3, restitution=0.9, law=law, bearing_length=0.02)
    mass, speed = 0.14, 2.0
    system, q0, qd0 = journal_in_bearing(clearance, mass=mass, speed=speed)
    ref = clearance_impact(clearance, mass=mass, speed=speed)
    res = simulate_system(system, q0, qd0, 0.25e-3 + 2 * ref.duration, output_interval=1e-8)
    jr = res.joints["pin"]
    onset = res.metadata["contact_onsets"]["pin"][0][0]
    end = res.metadata["contact_ends"]["pin"][0]
    # the goal: within 0.5 % (sampling every 1e-8 s over a contact of >= 4e-5 s costs < 1e-6)
    assert jr.force_magnitude.max() == pytest.approx(ref.peak_force, rel=0.005)
    assert jr.penetration.max() == pytest.approx(ref.max_penetration, rel=0.005)
    assert -jr.eccentricity_rate[-1, 0] / speed == pytest.approx(ref.restitution, rel=0.005)
    assert end - onset == pytest.approx(ref.duration, rel=0.005)


def test_impacts_that_would_pass_the_deepest_penetration_are_refused() -> None:
    cyl = _law(ContactLaw.JOHNSON, c=1e-5)
    capacity = elastic_energy(cyl, cyl.max_penetration)
    speed = math.sqrt(2 * capacity / 0.1) * 1.01
    with pytest.raises(ValueError, match="would reach the 'johnson' law's deepest penetration"):
        cylinder_impact(cyl, restitution=0.9, mass=0.1, speed=speed)
    with pytest.raises(ValueError, match="do not apply to the cylindrical law"):
        clearance_impact(Clearance(1e-4, law=ContactLaw.JOHNSON), mass=0.1, speed=1.0, exponent=1.5)


def test_point_law_entry_refuses_a_cylindrical_law() -> None:
    with pytest.raises(ValueError, match="cylindrical law: its force needs the joint's radii"):
        laws.normal_force(ContactLaw.JOHNSON, 1e-6, 0.0, 1.0, stiffness=1e10, restitution=0.9)


def test_retrofit_play_takes_the_bearing_length() -> None:
    from clearance.cli import build_parser
    from clearance.cli.retrofit import plays_from_args
    from clearance.retrofit import RadialPlay

    play = RadialPlay.make(1e-4, law=ContactLaw.RADZIMOVSKY, bearing_length=0.012)
    assert bearing_length(play.clearance) == 0.012
    args = build_parser().parse_args(
        [
            "retrofit",
            "m.xml",
            "--out",
            "x",
            "--law",
            "johnson",
            "--joint",
            "elbow:clearance_mm=0.2,bearing_length_mm=12",
        ]
    )
    assert plays_from_args(args)["elbow"].clearance.bearing_length == pytest.approx(0.012, rel=1e-15)
