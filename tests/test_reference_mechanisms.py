"""Reference solver on closed loops, two drives (constant speed and motion law), torque
drives and the builders' catalogue; its constraint rows against `clearance.kinematics`.

The fixtures below are small linkages with the project's own test dimensions (a Grashof
crank-rocker and a symmetric five-bar), independent of the catalogue.
"""

from __future__ import annotations

import dataclasses
import inspect
import math

import numpy as np
import pytest

from clearance.builders import rpm, slider_crank
from clearance.kinematics import ConstraintSystem, solve_kinematics
from clearance.model import (
    Clearance,
    Drive,
    DriveKind,
    Joint,
    JointType,
    Link,
    Mechanism,
    MotionLaw,
    Output,
    OutputKind,
)
from clearance.reference import ReferenceSystem, run_reference


def _bar(name: str, p: tuple[float, float], q: tuple[float, float], pa: str, pb: str, mass: float) -> Link:
    length = math.dist(p, q)
    th = math.atan2(q[1] - p[1], q[0] - p[0])
    return Link(
        name,
        mass,
        mass * length**2 / 12,
        com=(length / 2, 0.0),
        points={pa: (0.0, 0.0), pb: (length, 0.0)},
        pose_guess=(p[0], p[1], th),
    )


def _meet(p: tuple[float, float], r1: float, q: tuple[float, float], r2: float) -> tuple[float, float]:
    """Upper intersection of circles (p, r1) and (q, r2)."""
    d = math.dist(p, q)
    a = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h = math.sqrt(r1 * r1 - a * a)
    ux, uy = (q[0] - p[0]) / d, (q[1] - p[1]) / d
    return (p[0] + a * ux - h * uy, p[1] + a * uy + h * ux)


def _clearance(on: bool, restitution: float = 0.9) -> Clearance | None:
    return Clearance(radial_clearance=0.2e-3, restitution=restitution) if on else None


def four_bar(clearance: bool = False, *, speed: float = rpm(1500), restitution: float = 0.9) -> Mechanism:
    """Crank 40 mm, coupler 130 mm, rocker 100 mm, ground 120 mm; clearance at B."""
    o2, o4 = (0.0, 0.0), (0.12, 0.0)
    a = (0.04, 0.0)
    b = _meet(a, 0.13, o4, 0.10)
    links = (
        Link("ground", 0.0, 0.0, points={"o2": o2, "o4": o4}),
        _bar("crank", o2, a, "o", "a", 0.1),
        _bar("coupler", a, b, "a", "b", 0.3),
        _bar("rocker", o4, b, "o", "b", 0.25),
    )
    joints = (
        Joint("O2", JointType.REVOLUTE, "ground", "o2", "crank", "o"),
        Joint("A", JointType.REVOLUTE, "crank", "a", "coupler", "a"),
        Joint("B", JointType.REVOLUTE, "coupler", "b", "rocker", "b", clearance=_clearance(clearance, restitution)),
        Joint("O4", JointType.REVOLUTE, "ground", "o4", "rocker", "o"),
    )
    drives = (Drive("crank", "O2", DriveKind.CONSTANT_SPEED, speed=speed),)
    outputs = (Output("rocker_angle", "rocker", OutputKind.ANGLE),)
    return Mechanism("four_bar_test", links, joints, drives, outputs)


def five_bar(clearance: bool = False, *, restitution: float = 0.9) -> Mechanism:
    """Two 30 mm cranks 80 mm apart, two 100 mm couplers meeting at P (clearance at P).

    Crank 1: constant 1000 rpm; crank 2: a motion law (mean 1000 rpm plus a harmonic).
    """
    o1, o2 = (0.0, 0.0), (0.08, 0.0)
    a1, a2 = (0.03, 0.0), (0.05, 0.0)
    p = _meet(a1, 0.1, a2, 0.1)
    links = (
        Link("ground", 0.0, 0.0, points={"o1": o1, "o2": o2}),
        _bar("crank1", o1, a1, "o", "a", 0.1),
        _bar("crank2", o2, a2, "o", "a", 0.1),
        _bar("coupler1", a1, p, "a", "p", 0.2),
        _bar("coupler2", a2, p, "a", "p", 0.2),
    )
    joints = (
        Joint("O1", JointType.REVOLUTE, "ground", "o1", "crank1", "o"),
        Joint("O2", JointType.REVOLUTE, "ground", "o2", "crank2", "o"),
        Joint("A1", JointType.REVOLUTE, "crank1", "a", "coupler1", "a"),
        Joint("A2", JointType.REVOLUTE, "crank2", "a", "coupler2", "a"),
        Joint("P", JointType.REVOLUTE, "coupler1", "p", "coupler2", "p", clearance=_clearance(clearance, restitution)),
    )
    w = rpm(1000)
    drives = (
        Drive("d1", "O1", DriveKind.CONSTANT_SPEED, speed=w),
        Drive(
            "d2", "O2", DriveKind.MOTION_LAW, start_angle=math.pi, motion=MotionLaw(speed=w, harmonics=((0.2, 0.3),))
        ),
    )
    outputs = (
        Output("p_x", "coupler1", OutputKind.POSITION_X, point="p"),
        Output("p_y", "coupler1", OutputKind.POSITION_Y, point="p"),
    )
    return Mechanism("five_bar_test", links, joints, drives, outputs)


def _compare_ideal(mech: Mechanism, duration: float) -> None:
    res = run_reference(mech, duration, output_interval=duration / 200)
    kin = solve_kinematics(mech, res.times)
    q = res.link_poses.reshape(len(res.times), -1)
    # issue goal for ideal kinematics: 1e-6 relative (max|err| / max|value|)
    assert np.max(np.abs(q - kin.q)) / np.max(np.abs(kin.q)) < 1e-6
    for name, ref in kin.outputs.items():
        assert np.max(np.abs(res.outputs[name] - ref)) / np.max(np.abs(ref)) < 1e-6, name
    for k, d in enumerate(mech.drives):
        # the drive follows its law to the same level
        assert np.max(np.abs(res.drive_angle[:, k] - d.angle(res.times))) < 1e-6 * (2 * math.pi)
        assert np.max(np.abs(res.drive_speed[:, k] - d.rate(res.times))) < 1e-6 * abs(d.rate(0.0))


def test_ideal_four_bar_matches_kinematics() -> None:
    _compare_ideal(four_bar(), 2 * math.pi / rpm(1500))


def test_ideal_five_bar_with_two_drives_matches_kinematics() -> None:
    _compare_ideal(five_bar(), 2 * math.pi / rpm(1000))


def _energy_residual(res) -> float:
    e = res.metadata["energy"]
    kin, pot = np.array(e["kinetic"]), np.array(e["contact_potential"])
    grav = np.array(e["gravity_potential"])
    work = np.array(res.metadata["drive_work"]).sum(axis=1)
    return float(np.max(np.abs(kin + pot - kin[0] - pot[0] - work + grav - grav[0])) / kin.max())


@pytest.mark.parametrize(
    "mech", [four_bar(True, restitution=1.0), five_bar(True, restitution=1.0)], ids=["four_bar", "five_bar"]
)
def test_closed_loops_with_elastic_clearance_conserve_energy(mech: Mechanism) -> None:
    res = run_reference(mech, 8e-3, track_work=True)
    assert sum(res.metadata["impacts"].values()) >= 1  # the journal did hit its bearing
    assert _energy_residual(res) < 1e-5  # issue goal (energy conservation, c_e = 1, mu = 0)
    assert res.closure_violation.max() < 1e-8  # rtol 1e-9 on ~0.1 m coordinates, x10


def test_torque_drive_applies_its_torque() -> None:
    base = slider_crank(restitution=1.0, gravity=9.81)
    tau = 0.5  # well above the crank weight torque m g r / 2 = 0.07 N m at the start
    drive = dataclasses.replace(base.drives[0], kind=DriveKind.TORQUE, torque=tau, speed=0.0)
    mech = dataclasses.replace(base, drives=(drive,))
    res = run_reference(mech, 20e-3, track_work=True)
    # starts at rest, the torque turns the crank forward
    assert res.drive_speed[0, 0] == 0.0
    assert res.drive_angle[-1, 0] > 0.01
    assert np.all(res.drive_torque == tau)
    # work of a constant torque is tau times the angle turned (rtol 1e-9 integration, x1e3)
    work = np.array(res.metadata["drive_work"])[:, 0]
    assert np.allclose(work, tau * (res.drive_angle[:, 0] - res.drive_angle[0, 0]), rtol=1e-6, atol=1e-12)
    assert _energy_residual(res) < 1e-5  # issue goal (energy conservation)


@pytest.mark.parametrize(
    "mech", [slider_crank(), four_bar(True), five_bar(True)], ids=["slider_crank", "four_bar", "five_bar"]
)
def test_constraint_rows_match_kinematics_constraint_system(mech: Mechanism) -> None:
    system = ReferenceSystem(mech, baumgarte=(0.0, 0.0))
    cs = ConstraintSystem(mech, include_clearance=False)
    rng = np.random.default_rng(1)
    q0, _ = system.initial_state()
    for _ in range(3):
        q = q0 + rng.normal(scale=0.01, size=q0.shape)
        qd = rng.normal(scale=1.0, size=q0.shape)
        t = float(rng.uniform(0, 0.01))
        z, zd = system.to_com(q, qd)
        phi, gam, phit = system.rows.evaluate(t, z.tolist(), zd.tolist())
        # the same residuals in either coordinates (rounding only: measured 6.9e-18, 1/140 of the bound)
        assert np.allclose(phi, cs.phi(q, t), rtol=0, atol=1e-15)
        assert np.allclose(phit, cs.phi_t(t), rtol=0, atol=1e-12)  # rates ~100 rad/s, rounding
        g = system.rows.G.copy()
        # G against central differences of phi (step 1e-6: truncation ~1e-12, rounding ~1e-10)
        h = 1e-6
        fd = np.empty_like(g)
        for j in range(len(z)):
            dz = np.zeros_like(z)
            dz[j] = h
            fd[:, j] = (
                np.array(system.rows.evaluate(t, (z + dz).tolist())[0])
                - np.array(system.rows.evaluate(t, (z - dz).tolist())[0])
            ) / (2 * h)
        assert np.allclose(g, fd, rtol=0, atol=1e-8)
        # gamma = -(d^2/ds^2) phi(z + s zd) at fixed t for the joint rows (second differences,
        # step 1e-4: truncation ~1e-8 relative to |zd|^2 = O(10))
        s = 1e-4
        second = (
            np.array(system.rows.evaluate(t, (z + s * zd).tolist())[0])
            - 2 * np.array(phi)
            + np.array(system.rows.evaluate(t, (z - s * zd).tolist())[0])
        ) / s**2
        npairs = 2 * len(system.rows.pairs)
        assert np.allclose(np.array(gam)[:npairs], -second[:npairs], rtol=0, atol=1e-5)


def _catalogue():
    """Every catalogue mechanism (by `builders.names`), or the exported builders before it."""
    import clearance.builders as builders

    if hasattr(builders, "names") and hasattr(builders, "build"):
        return [pytest.param(lambda n=name: builders.build(n), id=name) for name in builders.names()]
    return [
        pytest.param(getattr(builders, name), id=name)
        for name in getattr(builders, "__all__", [])
        if inspect.isfunction(getattr(builders, name)) and name != "rpm"
    ]


@pytest.mark.parametrize("builder", _catalogue())
def test_every_catalogue_mechanism_runs(builder) -> None:
    try:
        mech = builder()
    except TypeError:
        pytest.skip("builder needs arguments")
    if not isinstance(mech, Mechanism):
        pytest.skip("not a mechanism builder")
    period = min([d.period for d in mech.drives if d.kind is not DriveKind.TORQUE] or [0.01])
    ideal = mech.ideal_twin()
    res = run_reference(ideal, period / 8, output_interval=period / 800)
    kin = solve_kinematics(ideal, res.times)
    q = res.link_poses.reshape(len(res.times), -1)
    assert np.max(np.abs(q - kin.q)) / np.max(np.abs(kin.q)) < 1e-6  # issue goal
    # with its clearances: a short run (covers the first impacts of the fast mechanisms)
    clear = run_reference(mech, min(period / 8, 2e-3))
    assert set(clear.joints) == {j.name for j in mech.clearance_joints}
    for jr in clear.joints.values():
        assert np.all(np.isfinite(jr.contact_force))
    assert clear.closure_violation.max() < 1e-8  # projection bound ~2e-9 m, x5
