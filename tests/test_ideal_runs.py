"""Ideal-twin runs reused within a sweep worker give the rows of fresh runs."""

from __future__ import annotations

import functools

from clearance.analysis.sweeps import ideal_runs
from clearance.analysis.sweeps.sweep import (
    KeywordFactory,
    SweepEvaluation,
    evaluate_point,
)
from clearance.builders import rpm, slider_crank
from clearance.options import ModelOptions
from clearance.run.simulation import default_duration

# 1000 rpm, 2 periods at 5 us and 36 segments: a point takes well under a second
OPTIONS = ModelOptions(timestep=5e-6, segments=36)
MAKE = KeywordFactory(slider_crank, fixed={"crank_speed": rpm(1000.0)})
DURATION = functools.partial(default_duration, revolutions=2.0)


def _row(point):
    row = evaluate_point(0, point, MAKE, DURATION, OPTIONS, SweepEvaluation(), True)
    return row.pop("timing"), row


def test_reused_ideal_run_gives_the_fresh_row():
    ideal_runs.forget_ideal_runs()
    t_first, first = _row({"radial_clearance": 0.2e-3, "clearance_at": ["crank_rod"]})
    # another joint and clearance: same ideal twin (only the builder parameters differ)
    t_reused, reused = _row({"radial_clearance": 0.4e-3, "clearance_at": ["rod_slider"]})
    ideal_runs.forget_ideal_runs()
    t_fresh, fresh = _row({"radial_clearance": 0.4e-3, "clearance_at": ["rod_slider"]})
    assert first["status"] == reused["status"] == "ok"
    assert t_first["ideal_reused"] is False and t_reused["ideal_reused"] is True and t_fresh["ideal_reused"] is False
    assert t_reused["ideal_s"] == 0.0
    # deterministic runs (one MuJoCo thread each): the rows are equal exactly
    assert reused == fresh
    for key in ("simulate_s", "stepping_s", "evaluate_s", "wall_time_s"):
        assert t_fresh[key] > 0


def test_other_speed_is_not_reused():
    ideal_runs.forget_ideal_runs()
    _row({"radial_clearance": 0.2e-3})
    fast = KeywordFactory(slider_crank, fixed={"crank_speed": rpm(1500.0)})
    row = evaluate_point(1, {"radial_clearance": 0.2e-3}, fast, DURATION, OPTIONS, SweepEvaluation(), True)
    assert row["timing"]["ideal_reused"] is False
    ideal_runs.forget_ideal_runs()
