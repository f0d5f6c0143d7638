"""The generic kinematics solver on every catalogue mechanism, and against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearance.builders import CATALOGUE, four_bar, rpm, seven_bar_press, slider_crank
from clearance.kinematics import (
    AssemblyError,
    ConstraintSystem,
    SingularPositionError,
    TransmissionAngle,
    assemble,
    solve_kinematics,
    transmission_angle,
)
from clearance.model import MotionLaw

NAMES = list(CATALOGUE)


@pytest.fixture(scope="module")
def mechanisms():
    return {n: CATALOGUE[n].builder() for n in NAMES}


@pytest.fixture(scope="module")
def cycles(mechanisms):
    out = {}
    for n, m in mechanisms.items():
        period = max(d.period for d in m.drives)
        out[n] = solve_kinematics(m, np.linspace(0.0, period, 721))
    return out


@pytest.mark.parametrize("name", NAMES)
def test_jacobian_and_gamma_match_finite_differences(name, mechanisms):
    m = mechanisms[name]
    cs = ConstraintSystem(m)
    rng = np.random.default_rng(1)
    q = np.array([v for lk in m.moving_links for v in lk.pose_guess]) + 0.01 * rng.normal(size=cs.nq)
    qd = rng.normal(size=cs.nq)
    h = 1e-6
    num = np.stack([(cs.phi(q + h * e, 0.1) - cs.phi(q - h * e, 0.1)) / (2 * h) for e in np.eye(cs.nq)], axis=1)
    # central differences: truncation ~h^2 |Phi'''| ~ 1e-12, rounding ~1e-16 / h ~ 1e-10
    assert np.max(np.abs(num - cs.jacobian(q))) < 1e-8
    s = 1e-4
    second = (cs.phi(q + s * qd, 0.1) - 2 * cs.phi(q, 0.1) + cs.phi(q - s * qd, 0.1)) / s**2
    npairs = 2 * len(cs.pairs)
    # gamma = -d^2/ds^2 Phi(q + s qd) for the (scleronomic) joint rows; truncation ~s^2 |qd|^4 ~ 1e-6
    assert np.max(np.abs(cs.gamma(q, qd, 0.1)[:npairs] + second[:npairs])) < 1e-5


def test_batched_evaluation_equals_single(mechanisms):
    m = mechanisms["ten_bar"]
    cs = ConstraintSystem(m)
    rng = np.random.default_rng(2)
    q = rng.normal(size=(3, 4, cs.nq))
    qd = rng.normal(size=(3, 4, cs.nq))
    t = rng.random((3, 4))
    for i in range(3):
        for k in range(4):
            # the same elementwise operations in both paths (sums only over length-2 axes, np.cos and
            # np.sin element by element whatever the shape): measured equal; 1e-14 is below an ulp of the
            # largest entries (65), so this asserts that sameness, not a tolerance
            assert np.allclose(cs.phi(q, t)[i, k], cs.phi(q[i, k], t[i, k]), rtol=0, atol=1e-14)
            assert np.allclose(cs.jacobian(q)[i, k], cs.jacobian(q[i, k]), rtol=0, atol=1e-14)
            assert np.allclose(cs.gamma(q, qd, t)[i, k], cs.gamma(q[i, k], qd[i, k], t[i, k]), rtol=0, atol=1e-14)


@pytest.mark.parametrize("name", NAMES)
def test_every_mechanism_closes_over_a_cycle(name, mechanisms, cycles):
    m, kin = mechanisms[name], cycles[name]
    cs = ConstraintSystem(m)
    # Newton tolerance is 1e-12 m / rad on max |Phi|
    assert np.max(np.abs(cs.phi(kin.q, kin.times))) < 1e-11
    # velocities and accelerations consistent with positions: central differences on the
    # 721-point grid, error ~ dt^2 |q'''| / 6, below 1e-3 of the peak rate for these drives
    dt = kin.times[1] - kin.times[0]
    dq = (kin.q[2:] - kin.q[:-2]) / (2 * dt)
    assert np.max(np.abs(dq - kin.qd[1:-1])) < 1e-3 * np.max(np.abs(kin.qd))
    dqd = (kin.qd[2:] - kin.qd[:-2]) / (2 * dt)
    assert np.max(np.abs(dqd - kin.qdd[1:-1])) < 5e-3 * np.max(np.abs(kin.qdd))
    # one cycle later the linkage is back where it started (same assembly branch): Newton tol
    ang = kin.q[-1] - kin.q[0]
    ang[2::3] = (ang[2::3] + math.pi) % (2 * math.pi) - math.pi
    assert np.max(np.abs(ang)) < 1e-9


@pytest.mark.parametrize("name", NAMES)
def test_no_singular_position_and_transmission_range(name, mechanisms, cycles):
    m, kin, info = mechanisms[name], cycles[name], CATALOGUE[name].info
    # singularity measure = 1/cond of the scaled Jacobian; healthy linkages here stay above 0.02
    # (catalogue.md lists 0.023-0.175); 0.01 leaves margin and is 1e5 times the error threshold
    assert kin.singularity.min() > 0.01
    for spec in info.transmission:
        mu = np.degrees(transmission_angle(m, kin.q, spec))
        # the usual design rule keeps transmission angles within 40-140 deg (catalogue.md)
        assert np.all((mu > 40.0) & (mu < 140.0)), (spec.joint, mu.min(), mu.max())


def test_slider_crank_against_closed_form():
    m = slider_crank(crank_speed=rpm(1000), clearance_at=())
    t = np.linspace(0.0, 2 * math.pi / rpm(1000), 3601)
    kin = solve_kinematics(m, t)
    th = rpm(1000) * t
    x = 0.05 * np.cos(th) + np.sqrt(0.12**2 - (0.05 * np.sin(th)) ** 2)
    # Newton tolerance 1e-12 m
    assert np.max(np.abs(kin.outputs["slider_x"] - x)) < 1e-11
    # docs/references.md, "The classic slider-crank, ideal" [derived]: -777 / +388 m/s^2 at 1000 rpm, quoted to 3 digits
    assert kin.outputs["slider_x_acc"].min() == pytest.approx(-777, abs=0.5)
    assert kin.outputs["slider_x_acc"].max() == pytest.approx(388, abs=0.5)


def test_four_bar_against_freudenstein_and_transmission_formula():
    a, b, c, d = 0.04, 0.13, 0.10, 0.13
    m = four_bar(clearance_at=())
    th = np.linspace(0.0, 2 * math.pi, 361)
    kin = solve_kinematics(m, th / m.drives[0].speed)
    # closed form: B on the circle of radius c about O4, at distance b from A (upper branch)
    ax_, ay = a * np.cos(th), a * np.sin(th)
    dx, dy = d - ax_, -ay
    f = np.hypot(dx, dy)
    gamma = np.arccos((f**2 + c**2 - b**2) / (2 * f * c))
    phi = np.arctan2(-dy, -dx) - gamma  # angle of O4 -> B
    rocker = np.unwrap(np.where(phi < 0, phi + 2 * math.pi, phi))
    # Newton tolerance 1e-12 rad, plus rounding of the closed form
    assert np.max(np.abs(kin.outputs["rocker_angle"] - rocker)) < 1e-9
    mu = transmission_angle(m, kin.q, TransmissionAngle("B", ("coupler3", "A"), follower=("rocker4", "O4")))
    mu_ref = np.arccos((b**2 + c**2 - f**2) / (2 * b * c))
    assert np.max(np.abs(mu - mu_ref)) < 1e-9  # same geometry, rounding only


def test_coarse_time_grid_follows_the_same_branch(mechanisms, cycles):
    for name in ("stephenson_ii_2", "ten_bar"):
        m, fine = mechanisms[name], cycles[name]
        coarse = solve_kinematics(m, fine.times[::90])  # 8 samples per cycle, 45 deg apart
        # continuation between samples: same branch, same Newton tolerance
        assert np.max(np.abs(coarse.q - fine.q[::90])) < 1e-9


def test_dead_point_is_reported_with_time_and_drive_angle():
    # crank 110 mm > rocker 100 mm (non-Grashof for a crank input): the 'crank' cannot turn
    # fully; starting at 90 deg, coupler and rocker become collinear (a dead point) on the way
    m = four_bar(crank_length=0.11, start_angle=math.pi / 2, clearance_at=())
    t = np.linspace(0.0, m.drives[0].period, 361)
    with pytest.raises(SingularPositionError, match=r"t = .* s \(crank = .* deg\).*dead point") as err:
        solve_kinematics(m, t)
    assert 0 < err.value.time < m.drives[0].period
    assert isinstance(err.value, AssemblyError)


def test_unclosable_start_is_an_assembly_error():
    with pytest.raises(ValueError, match="cannot be assembled"):
        four_bar(ground_length=0.5)


def test_two_drive_press_with_servo_law():
    law = MotionLaw(math.pi, harmonics=((0.3, 0.0), (0.05, 1.0)))
    m = seven_bar_press(crank7_motion=law, clearance_at=())
    t = np.linspace(0.0, 2.0, 801)
    kin = solve_kinematics(m, t)
    cs = ConstraintSystem(m)
    assert np.max(np.abs(cs.phi(kin.q, t))) < 1e-11  # Newton tolerance
    i7 = [lk.name for lk in m.moving_links].index("crank7")
    # the servo crank follows its law exactly (a constraint row): rounding only
    assert np.max(np.abs(kin.q[:, 3 * i7 + 2] - law.offset(t))) < 1e-11
    assert np.max(np.abs(kin.qdd[:, 3 * i7 + 2] - law.acceleration(t))) < 1e-8


def test_assemble_uses_pose_guess_branch(mechanisms):
    for m in mechanisms.values():
        q = assemble(m)
        guess = np.array([v for lk in m.moving_links for v in lk.pose_guess])
        # builders store the exact assembled pose as pose_guess (Newton tolerance)
        assert np.max(np.abs(q - guess)) < 1e-10
