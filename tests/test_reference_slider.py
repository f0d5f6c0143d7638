"""The reference solver's slider with play: the four contact cases, one corner's impact, the energy.

A free block in a ground-fixed guide (`clearance.reference.slider_in_guide`) meets each contact
case of Flores, Ambrósio, Claro and Lankarani (2008) by its start alone; the slider-crank of
Flores, Leine and Glocker (2010) closes the energy balance. Short horizons: the file runs in
seconds.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from clearance.builders import load_scenario
from clearance.contact_calibration import laws
from clearance.contact_calibration.impact import law_impact
from clearance.model import ContactLaw
from clearance.reference import run_reference, simulate_system, slider_in_guide
from clearance.reference.corner_contact import CornerContact, corner_gap, corner_gaps_many, evaluate_corner
from clearance.translational import SliderContact, TranslationalClearance

SCENARIO = Path(__file__).resolve().parents[1] / "builders" / "scenarios" / "slider_crank_translational_flores2010.toml"
GUIDE = TranslationalClearance(1e-3, 0.1, 0.05, stiffness=1e10, restitution=0.4, law=ContactLaw.FLORES)
MASS = 0.076  # the benchmark's slider [kg]
INERTIA = MASS * (0.1**2 + 0.05**2) / 12  # a uniform 100 mm x 50 mm block [kg m^2]


def _run(guide: TranslationalClearance, duration: float, **start: object):
    system, q0, qd0 = slider_in_guide(guide, mass=MASS, inertia=INERTIA, **start)  # type: ignore[arg-type]
    return system, simulate_system(system, q0, qd0, duration, output_interval=1e-6)


def _cases(res) -> set[SliderContact]:
    return set(res.sliders["guide"].cases())


def test_free_flight_along_the_guide_touches_nothing() -> None:
    _, res = _run(GUIDE, 5e-3, velocity=(1.0, 0.0))
    sr = res.sliders["guide"]
    assert _cases(res) == {SliderContact.FREE} and res.metadata["impacts"]["guide"] == 0
    # uniform motion along the axis; rtol 1e-9 of 5 mm
    assert np.max(np.abs(sr.position[:, 0] - res.times)) < 1e-11


def test_a_tilted_slider_lands_on_one_corner() -> None:
    _, res = _run(GUIDE, 0.6e-3, tilt=0.5 * GUIDE.max_tilt, velocity=(0.0, -1.0))
    t, v, corner = res.metadata["corner_onsets"]["guide"][0]
    assert corner == 2  # the lower corner behind the centre: (-L/2, -H/2) turned by a positive tilt
    assert SliderContact.ONE_CORNER in _cases(res) and SliderContact.ONE_SIDE not in _cases(res)


def test_a_level_slider_lands_flat_on_two_corners_at_once() -> None:
    _, res = _run(GUIDE, 2e-3, velocity=(0.5, -1.0))
    onsets = res.metadata["corner_onsets"]["guide"]
    # both lower corners start their impact at c / v = 1 ms (rtol 1e-9), together: in one switch, or in
    # the next step's root search (to 1e-16 s) where rounding left the second corner 1e-19 m short
    assert sorted(o[2] for o in onsets[:2]) == [2, 3] and abs(onsets[0][0] - onsets[1][0]) < 1e-12
    assert onsets[0][0] == pytest.approx(1e-3, rel=1e-8)
    assert SliderContact.ONE_SIDE in _cases(res) and SliderContact.ONE_CORNER not in _cases(res)
    # without friction the two corners' forces balance: the tilt stays at the rounding level
    # (1e-9 of the largest tilt allows any asymmetry of two onsets located to 1e-16 s)
    assert np.max(np.abs(res.sliders["guide"].tilt)) < 1e-9 * GUIDE.max_tilt


def test_a_spinning_slider_wedges_on_two_diagonal_corners() -> None:
    _, res = _run(GUIDE, 5e-3, spin=5.0)
    onsets = res.metadata["corner_onsets"]["guide"]
    assert sorted(o[2] for o in onsets[:2]) == [1, 2]  # (+L/2, +H/2) and (-L/2, -H/2)
    assert SliderContact.DIAGONAL in _cases(res)
    # it rotates to the largest tilt the guide allows, no further (its corners' penetration aside:
    # 1 % of the largest tilt is ~10 um of corner travel, the penetrations here are under 5 um)
    assert np.max(np.abs(res.sliders["guide"].tilt)) < 1.01 * GUIDE.max_tilt


@pytest.mark.parametrize(("law", "restitution"), [(ContactLaw.FLORES, 0.4), (ContactLaw.LANKARANI_NIKRAVESH, 0.9)])
def test_one_corners_impact_matches_the_impact_reference(law: ContactLaw, restitution: float) -> None:
    guide = dataclasses.replace(GUIDE, law=law, restitution=restitution)
    tilt, v = 0.5 * guide.max_tilt, 1.0
    system, res = _run(guide, 0.75e-3, tilt=tilt, velocity=(0.0, -v))
    t_on, v_in, corner = res.metadata["corner_onsets"]["guide"][0]
    t_end = res.metadata["corner_ends"]["guide"][0][0]
    # the corner's effective mass along the guide's normal: 1 / (1/m + r_x^2 / J), r_x its lever arm
    rx = -0.05 * math.cos(tilt) + 0.025 * math.sin(tilt)
    meff = 1.0 / (1.0 / MASS + rx * rx / INERTIA)
    ref = law_impact(law, mass=meff, speed=v, stiffness=guide.stiffness, restitution=restitution)
    sr = res.sliders["guide"]
    i = int(np.searchsorted(res.times, t_end))  # the first sample after separation
    k = next(n for n, cp in enumerate(system.contacts) if isinstance(cp, CornerContact) and cp.corner == corner)
    pose, vel = res.link_poses[i, 0], [*sr.velocity[i], sr.tilt_rate[i]]
    rebound = -corner_gap(system.contacts[k], pose.tolist(), vel)[1]  # type: ignore[arg-type]
    # issue goal: within 0.5 % (measured: 3e-4 at most; sampling every 1e-8 s of a 1e-4 s contact
    # costs < 1e-4, the block's turn during the contact moves the lever arm by < 1e-3)
    assert sr.corner_force[:, corner].max() == pytest.approx(ref.peak_force, rel=0.005)
    assert sr.corner_penetration[:, corner].max() == pytest.approx(ref.max_penetration, rel=0.005)
    assert t_end - t_on == pytest.approx(ref.duration, rel=0.005)
    assert rebound / v == pytest.approx(ref.restitution, rel=0.005)
    assert v_in == pytest.approx(v, rel=1e-8)  # no rotation before the impact: the centre's speed


def test_corner_forces_are_the_contact_laws() -> None:
    """The reference's scalar corner force against `laws` (the single source of the laws)."""
    guide = dataclasses.replace(GUIDE, friction=0.2)
    system, q0, _ = slider_in_guide(guide, mass=MASS, inertia=INERTIA)
    cp = system.contacts[3]  # corner (+L/2, -H/2)
    z = [0.0, -1e-3 - 5e-6, 0.0]  # 5 um below the lower line
    zd = [0.3, -0.2, 0.0]  # sliding along +x while approaching
    r = evaluate_corner(cp, z, zd, 0.5)  # type: ignore[arg-type]
    fn = laws.normal_force(guide.law, 5e-6, 0.2, 0.5, stiffness=guide.stiffness, restitution=guide.restitution)
    ft = laws.ambrosio_friction(fn, 0.3, friction=0.2)
    # 1e-9: the penetration is a difference of lengths of 26 mm (rounding ~1e-12 of 5 um)
    assert r[4] == pytest.approx(5e-6, rel=1e-9) and r[5] == pytest.approx(0.2, rel=1e-12)
    assert r[11] == pytest.approx(fn, rel=1e-9) and r[12] == pytest.approx(ft, rel=1e-9)
    assert (r[7], r[8]) == pytest.approx((ft, fn), rel=1e-9)  # friction along -x, the normal force up
    # the vectorised gap used by the event search gives the scalar one
    ys = np.array([*z, *zd])[:, None]
    delta, ddot, _ = corner_gaps_many(cp, 3, ys)  # type: ignore[arg-type]
    assert (delta[0], ddot[0]) == pytest.approx(r[4:6], rel=1e-12, abs=1e-18)


def test_energy_balance_closes_with_elastic_frictionless_corners() -> None:
    mech = load_scenario(SCENARIO)
    tc = dataclasses.replace(mech.joint("slider_guide").require_translational(), restitution=1.0, friction=0.0)
    joints = tuple(
        dataclasses.replace(j, translational_clearance=tc) if j.name == "slider_guide" else j for j in mech.joints
    )
    res = run_reference(dataclasses.replace(mech, joints=joints), 0.06, track_work=True)
    e = res.energy
    total = e["kinetic"] + e["gravity_potential"] + e["contact_potential"] - e["drive_work"]
    assert res.metadata["impacts"]["slider_guide"] >= 10  # impacts and contacts on both lines were crossed
    # measured 1.5e-8 of the largest kinetic energy at rtol 1e-9; the bound is 1000 rtol, ten times
    # tighter than the revolute joint's check in test_reference.py
    assert np.max(np.abs(total - total[0])) / e["kinetic"].max() < 1e-6
