"""Chunked, thinned and swept runs equal one long lone run bit for bit, by construction.

`clearance.run.simulation.model_stepper` starts each `mujoco.rollout` chunk from the full-physics
state (plugin state included) and the constraint solver's warm start that the chunk before it
ended with, so a chunk boundary changes no input of any step: the equality asserted here is one
the code guarantees, not one machine's rounding. Each family is tried with constraint rows (a
``connect`` loop closure, ring contact rows) and without (the compiled contact alone); the
retrofit families (radial play, backlash) are tried in their own test modules with the same
helper.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from chunking import assert_chunking_is_invisible

import clearance.contact_plugin as cp
from clearance.analysis.sweeps.sweep import KeywordFactory, SweepEvaluation, evaluate_point, run_sweep
from clearance.builders import slider_crank, watt_six_bar
from clearance.model import Mechanism
from clearance.options import ModelOptions
from clearance.run.preparation import prepare
from clearance.run.simulation import simulate_prepared

needs_plugin = pytest.mark.skipif(not cp.is_available(), reason="installed without a C compiler: no contact plugin")


def _watt(**kw: float) -> Mechanism:
    return watt_six_bar(crank_speed=5000 * np.pi / 30, **kw)  # 12 ms a turn: contact events early


FAMILIES = {
    # (mechanism, mode, step [s], steps); each window holds contact events of its journal
    "exact, a connect closure": (_watt, "exact", 3e-6, 3000),
    "exact, no constraint rows": (slider_crank, "exact", 3e-6, 1500),
    "ring, contact rows and a connect closure": (_watt, "nominal", 2e-6, 3000),
}


@needs_plugin
@pytest.mark.parametrize("family", list(FAMILIES))
def test_chunked_and_thinned_runs_are_the_one_long_run_bitwise(family):
    make, mode, h, nstep = FAMILIES[family]
    prepared = prepare(make(), ModelOptions(contact_mode=mode, timestep=h))
    whole = simulate_prepared(prepared, duration=nstep * h)
    # the window is not contact-free: the journal met its bearing (else the rows carry nothing)
    assert max(float(j.force_magnitude.max()) for j in whole.joints.values()) > 0, family
    if "connect" in family:
        assert prepared.model.neq > 0  # the family has its constraint rows
    assert_chunking_is_invisible(lambda **kw: simulate_prepared(prepared, **kw), h, nstep)


@needs_plugin
def test_a_sweep_worker_running_several_points_gives_each_the_bits_of_a_lone_run(tmp_path):
    # one worker runs three points in turn; the last point's row equals that point run alone in
    # this process (no state of an earlier point reaches a later one)
    points = [{"radial_clearance": c} for c in (1e-4, 2e-4, 3e-4)]
    factory = KeywordFactory(_watt)
    options = ModelOptions(contact_mode="exact")
    duration = 0.03  # 2.5 turns at 5000 rpm: statistics after the first turn
    out = run_sweep(
        points, factory, out_dir=tmp_path / "s", duration=duration, options=options, max_workers=1, progress=False
    )
    assert out.complete and all(r["status"] == "ok" for r in out.rows), [r["error"] for r in out.rows]
    assert len({r["timing"]["pid"] for r in out.rows}) == 1  # one worker ran all three
    lone = evaluate_point(2, points[2], factory, duration, options, SweepEvaluation(), True)

    def bits(row: dict) -> str:
        return json.dumps({k: v for k, v in row.items() if k != "timing"}, sort_keys=True)

    assert bits(out.rows[2]) == bits(lone)
