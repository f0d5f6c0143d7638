"""Reference solver contact: scalar laws against `contact_calibration.laws` (the definition),
circle-in-circle geometry by hand, and the `SimulationResult` frames and signs.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from clearance.builders import slider_crank
from clearance.contact_calibration import laws
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw
from clearance.reference import run_reference
from clearance.reference.contact import (
    evaluate_contact,
    friction_scalar,
    normal_force_scalar,
)
from clearance.reference.examples import journal_in_bearing

ULPS = 1e-12  # rel. tolerance: the same formula evaluated in floats vs NumPy (rounding; measured 6.2e-16 at most)
IMPACT = dict(c_max=2e5, d_max=1e-5)


def _joint(law: ContactLaw, restitution: float = 0.8, friction: float = 0.0):
    cl = Clearance(radial_clearance=0.5e-3, restitution=restitution, friction=friction, law=law)
    system, _, _ = journal_in_bearing(
        cl, mass=0.2, speed=1.0, impact_c_max=IMPACT["c_max"], impact_d_max=IMPACT["d_max"]
    )
    return cl, system.contacts[0]


@pytest.mark.parametrize("law", sorted(set(ContactLaw) - CYLINDRICAL_LAWS, key=list(ContactLaw).index))
def test_scalar_normal_force_equals_contact_laws(law: ContactLaw) -> None:
    # the cylindrical laws: tests/test_cylindrical_laws.py
    cl, cj = _joint(law)
    assert cj.stiffness == laws.bearing_stiffness(cl)
    for d, dd, v in itertools.product(
        (-1e-6, 0.0, 1e-7, 5e-6, 3e-5, 2e-5 + 1e-9), (-3.0, -0.5, 0.0, 0.7, 2.0), (0.5, 2.0)
    ):
        ref = laws.normal_force(law, d, dd, v, stiffness=cj.stiffness, restitution=cl.restitution, **IMPACT)
        assert normal_force_scalar(cj, d, dd, v) == pytest.approx(ref, rel=ULPS, abs=0.0)


def test_scalar_friction_equals_ambrosio() -> None:
    _, cj = _joint(ContactLaw.LANKARANI_NIKRAVESH, friction=0.12)
    for fn, vt in itertools.product((0.0, 150.0), (-1e-2, -5e-4, -1e-4, 0.0, 5e-5, 3e-4, 2e-3)):
        ref = laws.ambrosio_friction(fn, vt, friction=0.12, v0=cj.v0, v1=cj.v1)
        assert friction_scalar(cj, fn, vt) == pytest.approx(ref, rel=ULPS, abs=0.0)


def test_circle_in_circle_geometry_by_hand() -> None:
    cl, cj = _joint(ContactLaw.HUNT_CROSSLEY, friction=0.1)
    ex, ey = 0.4e-3, 0.45e-3  # |e| = 0.602 mm: 0.102 mm beyond c = 0.5 mm
    vx, vy, w = 0.3, -0.2, 50.0
    r = evaluate_contact(cj, [ex, ey, 0.7], [vx, vy, w], 1.5)
    d = math.hypot(ex, ey)
    nx, ny = ex / d, ey / d
    delta, ddot = d - 0.5e-3, nx * vx + ny * vy
    vt = -ny * vx + nx * vy + w * cl.journal_radius  # journal surface point, bearing fixed
    fn = laws.hunt_crossley(delta, ddot, 1.5, stiffness=cj.stiffness, restitution=cl.restitution)
    ft = laws.ambrosio_friction(fn, vt, friction=0.1)
    fx, fy = -fn * nx - ft * ny, -fn * ny + ft * nx
    # moments about the centres of mass: journal R_J F_T; bearing (ground here) -R_B F_T
    expected = (ex, ey, vx, vy, delta, ddot, vt, fx, fy, cl.journal_radius * ft, -cl.bearing_radius * ft, fn, ft)
    # abs 1e-18: lets exact zeros compare with rounding-level values (quantities >= 1e-6)
    assert r == pytest.approx(expected, rel=ULPS, abs=1e-18)
    # free mode (approach speed 0): geometry but no force
    assert evaluate_contact(cj, [ex, ey, 0.7], [vx, vy, w], 0.0)[7:] == (0.0,) * 6


@pytest.fixture(scope="module")
def crank_rod_run():
    """Clearance at the crank-rod joint: the bearing is on the rotating crank."""
    mech = slider_crank(clearance_at=("crank_rod",), friction=0.1)
    return mech, run_reference(mech, 1.5e-3, output_interval=1e-6)


def test_result_frames_follow_the_conventions(crank_rod_run) -> None:
    mech, res = crank_rod_run
    jr = res.joints["crank_rod"]
    assert mech.joint("crank_rod").clearance.journal_link == "rod"
    crank, rod = res.link_poses[:, 0], res.link_poses[:, 1]
    c, s = np.cos(crank[:, 2]), np.sin(crank[:, 2])
    pin = crank[:, :2] + 0.05 * np.stack([c, s], axis=1)  # bearing centre: crank point (r, 0)
    ew = rod[:, :2] - pin  # journal centre: rod frame origin
    e = np.stack([c * ew[:, 0] + s * ew[:, 1], -s * ew[:, 0] + c * ew[:, 1]], axis=1)
    # same arithmetic (measured equal); 1e-15 m: over 100 ulps of the 0.05 m positions the difference cancels
    assert np.allclose(jr.eccentricity, e, rtol=0, atol=1e-15)
    assert np.allclose(jr.penetration, np.hypot(e[:, 0], e[:, 1]) - 0.5e-3, rtol=0, atol=1e-15)  # idem
    # rate = time derivative of the frame-expressed vector; central differences at 1 us are
    # accurate to ~h^2 e''' / 6 ~ 1e-3 of max|rate| through the impacts (measured 4e-4)
    fd = np.gradient(jr.eccentricity, res.times, axis=0)
    assert np.max(np.abs(fd - jr.eccentricity_rate)[1:-1]) < 1e-2 * np.max(np.abs(jr.eccentricity_rate))
    # force on the journal pushes it back toward the bearing centre; friction is bounded
    on = jr.penetration > 0
    assert on.sum() > 10 and np.all(jr.force_magnitude[~on] == 0.0)
    n = jr.eccentricity[on] / np.linalg.norm(jr.eccentricity[on], axis=1)[:, None]
    f = jr.contact_force[on]
    fn = -(f * n).sum(axis=1)
    ft = np.abs(f[:, 0] * -n[:, 1] + f[:, 1] * n[:, 0])
    assert np.all(fn >= 0.0)
    assert np.all(ft <= 0.1 * fn * (1 + 1e-12))  # mu = 0.1, Ambrosio's c_d <= 1
    assert np.any(ft > 0.05 * fn)  # friction did act


def test_drive_torque_sign_and_work_on_the_ideal_mechanism() -> None:
    res = run_reference(slider_crank(clearance_at=()), 3e-3, output_interval=1e-6, track_work=True)
    kin = np.array(res.metadata["energy"]["kinetic"])
    work = np.array(res.metadata["drive_work"])[:, 0]
    # no gravity, no contact: the drive's work is the change of kinetic energy (at rtol 1e-9
    # measured 2e-8 of max T, scaling with rtol; bound x5)
    assert np.allclose(work, kin - kin[0], rtol=0, atol=1e-7 * kin.max())
    # and the reported torque is the one doing it: tau * omega = dT/dt (central differences)
    power = res.drive_torque[:, 0] * res.drive_speed[:, 0]
    dkin = np.gradient(kin, res.times)
    assert np.max(np.abs(power - dkin)[1:-1]) < 1e-4 * np.max(np.abs(power))


def test_friction_only_dissipates() -> None:
    res = run_reference(slider_crank(restitution=1.0, friction=0.1), 2e-3, track_work=True)
    e = res.metadata["energy"]
    kin, pot = np.array(e["kinetic"]), np.array(e["contact_potential"])
    balance = (kin + pot - kin[0] - pot[0] - np.array(res.metadata["drive_work"])[:, 0]) / kin.max()
    assert balance.max() < 1e-7  # never gains energy (integration error ~1e-8 at rtol 1e-9)
    assert balance[-1] < -1e-3  # and friction took some (measured -8e-3 of max T)


def test_impact_law_needs_its_parameters() -> None:
    mech = slider_crank(law=ContactLaw.IMPACT)
    with pytest.raises(ValueError, match="impact_c_max"):
        run_reference(mech, 1e-4)
    res = run_reference(mech, 0.4e-3, impact_c_max=1e5, impact_d_max=1e-5)
    assert res.metadata["impact_c_max"] == 1e5
    assert res.joints["rod_slider"].force_magnitude.max() > 1e3  # the first impact happened
