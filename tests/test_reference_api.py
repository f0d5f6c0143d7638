"""Reference solver API: argument validation, output grid, metadata, failures with partial
results, progress reporting, stabilisation choices and systems built from parts.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import clearance
from clearance.builders import slider_crank
from clearance.model import Clearance, Joint, JointType, Link
from clearance.reference import (
    METHODS,
    ReferenceSolverError,
    ReferenceSystem,
    Stabilisation,
    run_reference,
    simulate_system,
)
from clearance.results import SimulationResult


@pytest.fixture(scope="module")
def mech():
    return slider_crank()


@pytest.mark.parametrize(
    ("kwargs", "exc", "match"),
    [
        (dict(duration=0.0), ValueError, "duration must be > 0"),
        (dict(duration=-1e-3), ValueError, "duration must be > 0"),
        (dict(duration=math.nan), ValueError, "duration must be a finite number"),
        (dict(duration="1"), TypeError, "duration must be a finite number"),
        (dict(duration=1e-4, output_interval=1e-3), ValueError, "must not exceed duration"),
        (dict(duration=1e-4, output_interval=0.0), ValueError, "output_interval must be > 0"),
        (dict(duration=1e-4, rtol=1e-2), ValueError, r"rtol must be in \[1e-13, 1e-3\]"),
        (dict(duration=1e-4, method="Euler"), ValueError, "method must be one of"),
        (dict(duration=1e-4, stabilisation="magic"), ValueError, "stabilisation must be one of"),
        (dict(duration=1e-4, atol=-1.0), ValueError, "atol must be positive"),
        (dict(duration=1e-4, progress="yes"), TypeError, "progress must be a bool or a callable"),
        (dict(duration=1e-4, min_approach_speed=0.0), ValueError, "min_approach_speed"),
        (dict(duration=1e-4, baumgarte=(-1.0, 5.0)), ValueError, "baumgarte"),
        (dict(duration=1e-4, friction_v0=1e-2, friction_v1=1e-3), ValueError, "v0 < v1"),
        (dict(duration=1e-4, max_penetration=0.0), ValueError, "max_penetration must be > 0"),
    ],
)
def test_bad_arguments_fail_before_integrating(mech, kwargs, exc, match) -> None:
    duration = kwargs.pop("duration")
    with pytest.raises(exc, match=match):
        run_reference(mech, duration, **kwargs)


def test_unknown_keyword_is_a_type_error(mech) -> None:
    with pytest.raises(TypeError):
        run_reference(mech, 1e-4, rtoll=1e-9)
    with pytest.raises(TypeError):
        ReferenceSystem(mech, alpha=5.0)


def test_result_shapes_grid_and_metadata(mech, tmp_path) -> None:
    res = run_reference(mech, 1.05e-4, output_interval=1e-5)
    n = 11  # samples at 0, 1e-5, ..., 1e-4 (the grid never passes the duration)
    assert isinstance(res, SimulationResult)
    assert np.array_equal(res.times, 1e-5 * np.arange(n))  # the grid is output_interval * arange: the same products
    assert res.link_poses.shape == (n, 3, 3)
    assert res.drive_angle.shape == res.drive_speed.shape == res.drive_torque.shape == (n, 1)
    assert set(res.outputs) == {"slider_x", "slider_x_vel", "slider_x_acc"}
    assert list(res.joints) == ["rod_slider"]
    jr = res.joints["rod_slider"]
    assert jr.eccentricity.shape == jr.eccentricity_rate.shape == jr.contact_force.shape == (n, 2)
    # journals start centred with the ideal velocities
    assert np.all(jr.eccentricity[0] == 0.0) and jr.penetration[0] == -0.5e-3
    md = res.metadata
    for key, value in dict(
        solver="reference",
        method="LSODA",
        rtol=1e-9,
        mechanism=mech.name,
        stabilisation="projection",
        mujoco_version=None,
        time_step=None,
        segments=None,
        package_version=clearance.__version__,
    ).items():
        assert md[key] == value, key
    assert md["parameters"] == dict(mech.parameters)
    assert md["contact_law"] == {"rod_slider": "lankarani_nikravesh"}
    assert md["stiffness"]["rod_slider"] == pytest.approx(6.61e10, rel=5e-3)  # REFERENCES s.1
    assert md["n_rhs"] > 0 and md["wall_time_s"] > 0 and len(md["atol"]) == 18
    res.save(tmp_path / "ref")  # metadata is JSON-serialisable and round-trips
    back = SimulationResult.load(tmp_path / "ref")
    assert back.metadata["stiffness"] == md["stiffness"]
    assert np.array_equal(back.joints["rod_slider"].contact_force, jr.contact_force)


def test_divergence_raises_with_partial_result(mech) -> None:
    with pytest.raises(ReferenceSolverError) as info:
        run_reference(mech, 1e-3, max_penetration=1e-6)
    err = info.value
    assert err.joint == "rod_slider"
    assert 0.2e-3 < err.time < 0.3e-3  # during the first impact (docs/references.md, "The default scenario, measured")
    msg = str(err)
    assert "rod_slider" in msg and "Remedy" in msg and f"{err.time:.9g}" in msg
    part = err.partial
    assert isinstance(part, SimulationResult)
    assert 0 < len(part.times) and part.times[-1] <= err.time
    assert part.joints["rod_slider"].penetration.max() <= 1e-6  # the limit, by construction


def test_progress_callable_and_bar(mech, capsys, monkeypatch) -> None:
    calls: list[tuple[float, float]] = []
    res = run_reference(mech, 2e-4, progress=lambda t, d: calls.append((t, d)))
    ts = [c[0] for c in calls]
    assert ts == sorted(ts) and ts[-1] == res.times[-1] and all(c[1] == 2e-4 for c in calls)
    # pytest's stderr is no terminal: the display is a line per interval, here every update
    monkeypatch.setenv("CLEARANCE_PROGRESS_EVERY_S", "0")
    run_reference(mech, 1e-4, progress=True)
    assert "reference slider_crank: " in capsys.readouterr().err


@pytest.mark.parametrize("stab", list(Stabilisation) + ["projection"])
def test_every_stabilisation_keeps_the_loop_closed(mech, stab) -> None:
    res = run_reference(mech, 1e-3, stabilisation=stab)
    assert res.metadata["stabilisation"] == Stabilisation(stab).value
    # rtol 1e-9 on coordinates of ~0.1 m bounds the error at ~1e-10 m; measured 2e-11 m
    assert res.closure_violation.max() < 1e-9


@pytest.mark.parametrize("method", [m for m in METHODS if m not in ("LSODA", "RK23")])
def test_other_scipy_methods_agree_on_the_first_impact(mech, method) -> None:
    ref = run_reference(mech, 0.4e-3, output_interval=1e-6)
    res = run_reference(mech, 0.4e-3, output_interval=1e-6, method=method)
    f0, f1 = (r.joints["rod_slider"].force_magnitude.max() for r in (ref, res))
    assert f1 == pytest.approx(f0, rel=1e-4)  # each at rtol 1e-9; measured <= 1e-7 apart


def test_from_parts_validation() -> None:
    links = (Link("ground", 0.0, 0.0, points={"b": (0.0, 0.0)}), Link("body", 0.1, 1e-5, points={"j": (0.0, 0.0)}))
    cl = Clearance(radial_clearance=1e-4)
    no_side = (Joint("pin", JointType.REVOLUTE, "ground", "b", "body", "j", clearance=cl),)
    with pytest.raises(ValueError, match="journal_link"):
        ReferenceSystem.from_parts(links, no_side)
    bad_link = (Joint("pin", JointType.REVOLUTE, "ground", "b", "nobody", "j"),)
    with pytest.raises(ValueError, match="nobody"):
        ReferenceSystem.from_parts(links, bad_link)
    with pytest.raises(TypeError):
        ReferenceSystem.from_parts(links, (), frobnicate=1)
    system = ReferenceSystem.from_parts(links, ())  # a free body: no constraints at all
    with pytest.raises(ValueError, match="give q0 and qd0"):
        system.initial_state()
    with pytest.raises(ValueError, match="shape"):
        simulate_system(system, np.zeros(2), np.zeros(3), 1e-3)
    # a free body under no force keeps its velocity: the integrator is exact on a straight
    # line up to rounding (1e-12 relative: a few ulps per step over a few steps)
    res = simulate_system(system, np.zeros(3), np.array([1.0, 2.0, 3.0]), 1e-3, output_interval=1e-4)
    assert np.allclose(res.link_poses[-1, 0], [1e-3, 2e-3, 3e-3], rtol=1e-12, atol=0)
