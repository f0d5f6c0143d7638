"""Every catalogue mechanism in MuJoCo: ideal twin against the kinematics solver, and every
mechanism x {no clearance, each single clearance, all clearances} compiles, runs one drive
cycle without a MuJoCo warning and keeps its ideal loop closures tight.

The matrix runs at low speed and a coarse time step: the crank at the
catalogue's default 1000 rpm (the press at 3 pi rad/s, the top of the press paper's range), 8
bearing segments, and one set of contact parameters (the nominal ones of the four-bar's joint
B) for every joint, so that the matrix fits the test budget; accuracy is measured elsewhere.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from clearance import ModelOptions, simulate
from clearance.builders import CATALOGUE, four_bar, rpm
from clearance.kinematics import solve_kinematics

SEGMENTS = 8
RING = "nominal"  # the matrix checks the ring model; the exact contact's matrix is below
# 6 us: below the contact stability limit at 1000 rpm (8.7 us for the four-bar's joint A by
# the simulator's omega*h < 2 sizing), six times coarser than the 1 us default
STEP = 6e-6
PRESS_STEP = 1e-5  # limit 1.7e-5 s at the press's joint E


def _setup(name: str) -> tuple[dict, ModelOptions]:
    if name == "seven_bar_press":
        # two speed-driven cranks close one loop: default closures hold it (drive armature)
        return {"crank2_speed": 3 * math.pi}, ModelOptions(timestep=PRESS_STEP, segments=SEGMENTS, contact_mode=RING)
    return {"crank_speed": rpm(1000)}, ModelOptions(timestep=STEP, segments=SEGMENTS, contact_mode=RING)


@functools.cache
def _contact():
    from clearance.run.preparation import prepare

    p = prepare(
        four_bar(crank_speed=rpm(1000), clearance_at=("B",)),
        ModelOptions(timestep=STEP, segments=SEGMENTS, contact_mode=RING),
    )
    return p.contact["B"]


@functools.cache
def _run(name: str, clearance_at: tuple[str, ...]):
    kwargs, options = _setup(name)
    m = CATALOGUE[name].builder(clearance_at=clearance_at, **kwargs)
    period = max(d.period for d in m.drives)
    # simulate raises SimulationError on any MuJoCo warning or non-finite state, so a
    # returned result ran the whole cycle without one
    return m, simulate(m, duration=period, options=options, contact={j: _contact() for j in clearance_at})


@pytest.mark.parametrize("name", list(CATALOGUE))
def test_ideal_twin_matches_kinematics(name):
    m, r = _run(name, ())
    kin = solve_kinematics(m, r.times)
    for o in m.outputs:
        err = np.max(np.abs(r.outputs[o.name] - kin.outputs[o.name]))
        span = np.ptp(kin.outputs[o.name])
        # measured 2e-7 to 1.7e-6 of the output range (soft loop closures with a 2 h time
        # constant, velocity servo error)
        tol = 1e-5
        assert err < tol * span, (o.name, err, span)
        verr = np.max(np.abs(r.outputs[o.name + "_vel"] - kin.outputs[o.name + "_vel"]))
        vspan = np.ptp(kin.outputs[o.name + "_vel"])
        # the sampled velocity of a MuJoCo step may lag the exact one by up to one step
        # (measured ~h/2 * |a|): h * max|a| plus the position bound's relative error
        h = r.metadata["time_step"]
        bound = h * np.max(np.abs(kin.outputs[o.name + "_acc"])) + tol * vspan
        assert verr < bound, (o.name, verr, bound)


def _sets(name: str) -> list[tuple[str, ...]]:
    clearable = CATALOGUE[name].info.clearable
    return [(j,) for j in clearable] + [tuple(clearable)]


@pytest.mark.parametrize(
    "name,clearance_at",
    [(n, s) for n in CATALOGUE for s in [()] + _sets(n)],
    ids=lambda v: v if isinstance(v, str) else ("+".join(v) or "ideal"),
)
def test_runs_one_cycle_without_warnings(name, clearance_at):
    m, r = _run(name, clearance_at)
    period = max(d.period for d in m.drives)
    assert r.times[-1] == pytest.approx(period, abs=2 * _setup(name)[1].timestep)
    assert set(r.joints) == set(clearance_at)
    for jr in r.joints.values():
        assert np.all(np.isfinite(jr.contact_force)) and np.all(np.isfinite(jr.eccentricity))
    # ideal loop closures (connect equalities at a 2 h time constant): measured up to 4e-7 m
    # across the matrix; 5 um bound
    assert np.max(r.closure_violation) < 5e-6


@pytest.mark.parametrize("name", list(CATALOGUE))
def test_exact_contact_runs_one_cycle_with_every_joint_in_clearance(name):
    # the compiled exact contact at every clearable joint at once, one drive cycle at the
    # matrix's speeds and steps: simulate raises on any MuJoCo warning or non-finite state
    kwargs, options = _setup(name)
    m = CATALOGUE[name].builder(clearance_at=CATALOGUE[name].info.clearable, **kwargs)
    exact = ModelOptions(timestep=options.timestep, contact_mode="exact")
    r = simulate(m, duration=max(d.period for d in m.drives), options=exact)
    assert r.metadata["contact_mode"] == "exact"
    for name_j, jr in r.joints.items():
        assert np.all(np.isfinite(jr.contact_force)), name_j
        # journals stay near their clearance circle: penetration under 50 um (c = 0.1 mm)
        assert jr.penetration.max() < 50e-6, name_j
    assert np.max(r.closure_violation) < 5e-6  # the same closure bound as the ring matrix
