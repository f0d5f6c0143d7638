"""Sweeps: resume after an injected stop, process pool against Dask, row contents, manifest guard."""

from __future__ import annotations

import functools
import json

import pytest

from clearance.analysis.sweeps.sweep import (
    KeywordFactory,
    SweepEvaluation,
    load_rows,
    run_sweep,
)
from clearance.builders import four_bar, rpm, slider_crank
from clearance.options import ModelOptions
from clearance.run.simulation import default_duration

# low speed and a coarse step keep each point under a second (1000 rpm: T = 60 ms)
OPTIONS = ModelOptions(timestep=5e-6, segments=36)
MAKE = KeywordFactory(slider_crank, fixed={"crank_speed": rpm(1000.0)})
POINTS = [{"radial_clearance": c} for c in (0.1e-3, 0.2e-3, 0.35e-3, 0.5e-3)]
DURATION = functools.partial(default_duration, revolutions=2.0)


def _sweep(out, **kw):
    return run_sweep(POINTS, MAKE, out_dir=out, duration=DURATION, options=OPTIONS, progress=False, max_workers=2, **kw)


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    out = tmp_path_factory.mktemp("full")
    return _sweep(out)


def test_rows_hold_statistics_summary_and_poincare(full):
    assert full.complete and full.new == 4
    assert [r["index"] for r in full.rows] == [0, 1, 2, 3]
    r = full.rows[-1]
    assert r["status"] == "ok", r["error"]
    assert r["point"] == POINTS[-1]
    assert set(r["summary"]) == {"rod_slider"}
    # the slider cannot leave the ideal path by more than c plus the penetration (< 0.05 mm)
    assert 0 < r["statistics"]["mean_deviation"] < 0.55e-3
    assert len(r["per_cycle_mean_deviation"]) == 1  # 2 periods minus the skipped one
    assert r["poincare"]["quantities"] == ["slider_x", "slider_x_vel"]
    assert len(r["poincare"]["points"]) == 1  # section at t = T (t = 2T is past the end)
    header = full.csv_path.read_text().splitlines()[0].split(",")
    assert header[:3] == ["index", "point.radial_clearance", "status"]
    assert "statistics.mean_deviation" in header and "summary.rod_slider.peak_force" in header


def test_resumed_sweep_equals_uninterrupted(full, tmp_path):
    # one worker would keep two points in flight; stop_after=1 submits one and stops after it
    part = run_sweep(
        POINTS, MAKE, out_dir=tmp_path, duration=DURATION, options=OPTIONS, progress=False, max_workers=1, stop_after=1
    )
    assert not part.complete and part.new == 1
    assert len(list((tmp_path / "points").glob("*.json"))) == part.new
    rest = _sweep(tmp_path)
    assert rest.complete and rest.new == 4 - part.new
    # bitwise-equal table by construction: each point is one single-threaded MuJoCo run and its
    # NumPy post-processing, from the same inputs on this machine, whichever process or thread ran
    # it; rows in index order; a calibration read back from the cache is JSON, which keeps every bit
    assert rest.csv_path.read_bytes() == full.csv_path.read_bytes()
    # a finished sweep run again computes nothing; the manifest that guards resumption is
    # free of memory addresses, so a new process can resume too
    assert _sweep(tmp_path).new == 0
    assert " at 0x" not in (tmp_path / "sweep.json").read_text()


def test_dask_executor_matches_process_pool(full, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        out = run_sweep(
            POINTS,
            MAKE,
            out_dir=tmp_path,
            duration=DURATION,
            options=OPTIONS,
            progress=False,
            scheduler_address=cluster.scheduler_address,
        )
    assert out.complete
    assert out.csv_path.read_bytes() == full.csv_path.read_bytes()


def test_errors_are_rows_and_other_sweeps_are_refused(tmp_path):
    bad = [{"radial_clearance": 0.5e-3, "rod_length": 0.01}]  # rod shorter than crank
    out = run_sweep(
        bad,
        MAKE,
        out_dir=tmp_path,
        duration=DURATION,
        options=OPTIONS,
        progress=False,
        executor=_Inline(),
        evaluation=SweepEvaluation(ideal=False),
    )
    row = load_rows(tmp_path)[0]
    assert out.complete and row["status"] == "error" and "rod_length" in row["error"]
    assert json.loads((tmp_path / "points" / "point_000000.json").read_text())["index"] == 0
    with pytest.raises(ValueError, match="different sweep"):
        run_sweep(
            POINTS, MAKE, out_dir=tmp_path, duration=DURATION, options=OPTIONS, progress=False, executor=_Inline()
        )
    with pytest.raises(ValueError, match="stop_after"):
        run_sweep(POINTS, MAKE, out_dir=tmp_path / "x", stop_after=0, executor=_Inline())


BAD = [{"radial_clearance": c, "rod_length": 0.01} for c in (0.1e-3, 0.2e-3, 0.3e-3)]  # rod shorter than crank


def test_the_stop_comes_after_exactly_the_points_asked(tmp_path):
    # the inline executor finishes each point as it is submitted: without the cap on what is
    # submitted, all three would run before the first wait; with stop_after=2, two run
    out = run_sweep(
        BAD,
        MAKE,
        out_dir=tmp_path,
        duration=DURATION,
        options=OPTIONS,
        progress=False,
        executor=_Inline(),
        max_workers=3,
        stop_after=2,
        evaluation=SweepEvaluation(ideal=False),
    )
    assert out.new == 2 and not out.complete
    assert [r["index"] for r in load_rows(tmp_path)] == [0, 1]


def test_resume_with_another_mechanism_factory_is_refused(tmp_path):
    kw = dict(
        out_dir=tmp_path,
        duration=DURATION,
        options=OPTIONS,
        progress=False,
        executor=_Inline(),
        evaluation=SweepEvaluation(ideal=False),
    )
    assert run_sweep(BAD, MAKE, **kw).new == 3
    other_builder = KeywordFactory(four_bar, fixed={"crank_speed": rpm(1000.0)})
    other_speed = KeywordFactory(slider_crank, fixed={"crank_speed": rpm(2000.0)})
    for make in (other_builder, other_speed):
        with pytest.raises(ValueError, match="mechanism factory") as err:
            run_sweep(BAD, make, **kw)
        assert "use another out_dir" in str(err.value)
    assert run_sweep(BAD, MAKE, **kw).new == 0  # the same factory resumes
    manifest = json.loads((tmp_path / "sweep.json").read_text())
    assert "slider_crank" in manifest["settings"]["mechanism"] and " at 0x" not in manifest["settings"]["mechanism"]


class _Inline:
    """Minimal executor running each call at submit (for tests without processes)."""

    def submit(self, fn, *args):
        from concurrent.futures import Future

        f = Future()
        f.set_result(fn(*args))
        return f
