"""Start-state ensembles: draws inside the disc, measures as the criticality study defines them, resume."""

from __future__ import annotations

import functools
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from clearance.analysis.design.ensemble import (
    MEASURES,
    EnsembleSettings,
    EnsembleStopped,
    draw_start_states,
    run_ensemble,
    run_ensembles,
)
from clearance.analysis.sweeps.sweep import KeywordFactory, SweepEvaluation, run_sweep
from clearance.builders import watt_six_bar

JOINTS = ("A", "B", "O4", "C", "D")
WATT = KeywordFactory(watt_six_bar, {"clearance_at": JOINTS})


def fake_measures(mechanism, start, settings):
    """Closed-form measures: the clearances' sum plus the start offsets' sum (no simulation)."""
    c = sum(j.require_clearance().radial_clearance for j in mechanism.clearance_joints)
    e = sum(math.hypot(*v) for v in start.values())
    return {"mean_deviation": c + e, "rms_deviation": 2 * c, "peak_deviation": 3 * c, "peak_force": 1.0}


def failing_measures(mechanism, start, settings):
    """Fails on odd x offsets of joint A, so about half the runs fail."""
    if start["A"][0] > 0:
        raise RuntimeError("diverged")
    return fake_measures(mechanism, start, settings)


def test_start_states_lie_in_the_disc_are_reproducible_and_shared_across_designs():
    small, large = WATT({"radial_clearance": 1e-4}), WATT({"radial_clearance": 2e-4})
    a = draw_start_states(small, 400, 0.01, seed=3)
    assert a == draw_start_states(small, 400, 0.01, seed=3)
    assert a != draw_start_states(small, 400, 0.01, seed=4)
    r = np.array([[math.hypot(*s[j]) for j in JOINTS] for s in a])
    assert r.max() <= 0.01 * 1e-4 * (1 + 1e-12)  # inside spread * c up to rounding
    # uniform in the disc: P(r < R/sqrt(2)) = 1/2; 2000 draws give a binomial s.e. of 0.011, 4 s.e. allowed
    assert abs(np.mean(r < 1e-6 / math.sqrt(2)) - 0.5) < 0.045
    b = draw_start_states(large, 400, 0.01, seed=3)
    # common random numbers: run k starts at the same relative offset whatever the clearance
    assert np.allclose([b[k]["C"] for k in range(400)], [2 * np.array(a[k]["C"]) for k in range(400)], rtol=1e-12)


def test_summary_share_and_store_resume(tmp_path):
    settings = EnsembleSettings(runs=6, spread=0.01, seed=1, evaluate=fake_measures)
    pts = [{"radial_clearance": 1e-4}, {"radial_clearance": 2e-4}]
    with ThreadPoolExecutor(2) as ex:
        with pytest.raises(EnsembleStopped):
            run_ensembles(WATT, pts, settings, store=tmp_path, executor=ex, progress=False, stop_after=3)
        kept = len(list(tmp_path.glob("run_*.json")))
        assert kept == 3  # exactly the runs asked: none started beyond them
        first = run_ensembles(WATT, pts, settings, store=tmp_path, executor=ex, progress=False)
    assert len(list(tmp_path.glob("run_*.json"))) == 12
    again = run_ensembles(WATT, pts, settings, store=tmp_path, executor=None, progress=False)  # all from the store
    assert [e.runs for e in again] == [e.runs for e in first]
    s = first[1].summary("mean_deviation")
    v = first[1].values("mean_deviation")
    assert s.n == 6 and s.mean == pytest.approx(v.mean(), rel=1e-12)  # the definition, to rounding
    assert s.sem == pytest.approx(v.std(ddof=1) / math.sqrt(6), rel=1e-12)
    # five joints at 0.2 mm plus five offsets of at most 1 % of 0.2 mm each
    assert 5 * 2e-4 <= s.min <= s.max <= 5 * 2e-4 * 1.01
    assert first[1].share_within("mean_deviation", s.max) == 1.0
    assert first[1].share_within("mean_deviation", s.min) == pytest.approx(1 / 6)  # only the smallest run


def test_failed_runs_are_recorded_and_count_outside_the_budget():
    settings = EnsembleSettings(runs=8, seed=0, evaluate=failing_measures)
    with ThreadPoolExecutor(1) as ex:
        e = run_ensemble(WATT, {"radial_clearance": 1e-4}, settings, executor=ex, progress=False)
    bad = [r for r in e.runs if r.start["A"][0] > 0]
    assert 0 < len(bad) < 8 and [r.index for r in e.failed] == [r.index for r in bad]
    assert all("RuntimeError: diverged" in r.error for r in e.failed)
    assert e.summary("peak_force").n == 8 - len(bad)
    assert e.share_within("peak_force", 1.0) == pytest.approx((8 - len(bad)) / 8)  # failed runs are outside


def test_bad_settings_are_refused():
    for kw, word in [({"runs": 0}, "runs"), ({"spread": 1.0}, "spread"), ({"periods": 1}, "periods")]:
        with pytest.raises(ValueError, match=word):
            EnsembleSettings(**kw)
    with pytest.raises(KeyError, match="measure"):
        run_ensemble(
            WATT,
            {"radial_clearance": 1e-4},
            EnsembleSettings(runs=1, evaluate=fake_measures),
            progress=False,
            executor=ThreadPoolExecutor(1),
        ).values("band")


def test_simulated_mean_deviation_is_the_criticality_definition(tmp_path):
    """With no spread, an ensemble run is the sweep's run: equal per-cycle mean deviations."""
    factory = KeywordFactory(watt_six_bar, {"clearance_at": ("B",), "radial_clearance": 2e-4})
    with ThreadPoolExecutor(1) as ex:
        e = run_ensemble(factory, {}, EnsembleSettings(runs=1, spread=0.0, periods=3), executor=ex, progress=False)
        sweep = run_sweep(
            [{}],
            factory,
            out_dir=tmp_path,
            duration=functools.partial(_periods, n=3),
            executor=ex,
            progress=False,
            evaluation=SweepEvaluation(ideal=True),
        )
    row = sweep.rows[0]
    assert e.failed == () and set(MEASURES) <= set(e.runs[0].values)
    # same runs, same definition: equal to rounding
    assert e.values("mean_deviation")[0] == pytest.approx(np.mean(row["per_cycle_mean_deviation"]), rel=1e-9)
    assert e.values("rms_deviation")[0] == pytest.approx(row["statistics"]["rms_deviation"], rel=1e-9)
    assert e.values("peak_force")[0] == pytest.approx(e.runs[0].values["peak_force_by_joint"]["B"], rel=1e-12)
    assert e.values("peak_force")[0] > 0  # a 0.2 mm joint at 1000 rpm makes contact


def _periods(mechanism, n):
    return n * mechanism.drive_period
