"""Speed against error: accuracy measures on known data, the bench pipeline end to end."""

from __future__ import annotations

import functools
import json
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from clearance.analysis.metrics.accuracy import (
    Statistic,
    first_impact,
    first_impact_errors,
    run_statistics,
    separation_time,
    statistic_errors,
)
from clearance.results import JointResult, SimulationResult


def _result(times, ecc, force, penetration, outputs=None) -> SimulationResult:
    n = len(times)
    return SimulationResult(
        times=np.asarray(times, float),
        outputs=outputs or {"y": np.zeros(n)},
        joints={
            "J": JointResult(
                np.asarray(ecc, float),
                np.zeros((n, 2)),
                np.asarray(penetration, float),
                np.column_stack([force, np.zeros(n)]),
            )
        },
        drive_angle=np.zeros((n, 1)),
        drive_speed=np.ones((n, 1)),
        drive_torque=np.zeros((n, 1)),
        link_poses=np.zeros((n, 1, 3)),
        closure_violation=np.zeros(n),
    )


def test_first_impact_of_a_sampled_half_sine() -> None:
    h, i0, n, amp = 1e-6, 50, 40, 1000.0  # pulse over samples i0 .. i0 + n (zero at both ends)
    k = np.arange(200)
    t, t0, dur = k * h, i0 * h, n * h
    inside = (k > i0) & (k < i0 + n)
    f = np.where(inside, amp * np.sin(np.pi * (k - i0) / n), 0.0)
    pen = np.where(inside, 1e-6 * np.sin(np.pi * (k - i0) / n), -1e-6)
    # a second, later contact must not count
    later = (k > 150) & (k < 160)
    f[later], pen[later] = 5 * amp, 1e-6
    fi = first_impact(_result(t, np.zeros((len(t), 2)), f, pen), "J")
    assert fi is not None
    assert fi.onset == pytest.approx(t0 + h, abs=1e-12)  # first sample strictly inside
    assert fi.peak_force == pytest.approx(amp, rel=1e-12)  # the grid hits the crest (t0 + dur/2)
    # trapezoid of a half-sine on 40 intervals: relative error pi^2/(12 * 40^2) = 5.1e-4
    assert fi.impulse == pytest.approx(2 * amp * dur / np.pi, rel=6e-4)
    assert fi.end == pytest.approx(t0 + dur - h, abs=1e-12)


def test_first_impact_errors_and_missing_impacts() -> None:
    from clearance.analysis.metrics.accuracy import FirstImpact

    a = FirstImpact("J", 1.0e-4, 110.0, 2.0e-6, 0.5, 2e-4)
    b = FirstImpact("J", 0.9e-4, 100.0, 2.5e-6, 0.4, 2e-4)
    e = first_impact_errors(a, b)
    assert e["peak_force"] == pytest.approx(0.1, rel=1e-12)
    assert e["max_penetration"] == pytest.approx(-0.2, rel=1e-12)
    assert e["impulse"] == pytest.approx(0.25, rel=1e-12)
    assert e["onset"] == pytest.approx(1e-5, rel=1e-12)
    assert all(np.isnan(v) for v in first_impact_errors(None, b).values())


def test_run_statistics_values_and_batch_scatter() -> None:
    period, h = 0.01, 1e-4
    k = np.arange(1300)  # 13 periods of 100 samples: skip 1, 12 whole revolutions
    t = k * h
    rev, phase = k // 100, k % 100
    contact = phase < np.where(rev % 2 == 0, 50, 25)  # alternate revolutions: 50 % / 25 % contact
    pen = np.where(contact, 1e-6, -1e-6)
    force = np.where(contact, 10.0 * (1 + rev), 0.0)
    ecc = np.column_stack([np.where(contact, 1.0, 0.5), np.zeros(len(t))])
    y = 0.001 * np.sin(2 * np.pi * t / period)
    res = _result(t, ecc, force, pen, outputs={"y": y + 1e-4})
    st = run_statistics(
        res, period=period, skip=period, blocks=4, ideal_output=lambda tt: 0.001 * np.sin(2 * np.pi * tt / period)
    )
    s = st["J"]
    assert s["contact_fraction"].value == pytest.approx(0.375, abs=1e-12)  # 6 revs at 0.5, 6 at 0.25
    assert s["impacts_per_rev"].value == pytest.approx(11 / 12, abs=1e-12)  # onsets at revs 2..12
    assert s["rms_deviation"].value == pytest.approx(1e-4, rel=1e-9)
    # per-revolution peaks 20, 30, ..., 130 N: mean 75 N
    assert s["peak_force"].value == pytest.approx(75.0, rel=1e-12)
    # blocks of 3 revolutions: peaks mean 30, 60, 90, 120 -> std (ddof 1) / sqrt(4)
    assert s["peak_force"].block_values == pytest.approx((30.0, 60.0, 90.0, 120.0), rel=1e-12)
    assert s["peak_force"].scatter == pytest.approx(np.std([30, 60, 90, 120], ddof=1) / 2, rel=1e-12)
    # |e| is 1.0 in contact (37.5 % of the samples) and 0.5 out of it: percentiles of that mix
    assert (s["ecc_p10"].value, s["ecc_p50"].value, s["ecc_p90"].value) == (0.5, 0.5, 1.0)
    # per block of 3 revolutions (2 at 50 %, 1 at 25 % or the reverse) the median is 0.5 or 1.0
    assert s["ecc_p50"].block_values == (0.5,) * 4 and s["ecc_p50"].scatter == 0.0
    with pytest.raises(ValueError, match="whole revolutions"):
        run_statistics(res, period=period, skip=period, blocks=13)


def test_statistic_errors_scales() -> None:
    ref = {
        "J": {
            "p95_force": Statistic(100.0, 2.0, 4),
            "ecc_std": Statistic(1e-8, 1e-9, 4),
            "impacts_per_rev": Statistic(0.0, 0.0, 4),
        }
    }
    run = {
        "J": {
            "p95_force": Statistic(103.0, 1.5, 4),
            "ecc_std": Statistic(2e-8, 1e-9, 4),
            "impacts_per_rev": Statistic(0.5, 0.1, 4),
        }
    }
    e = statistic_errors(run, ref, clearance={"J": 1e-4})["J"]
    assert e["p95_force"]["error"] == pytest.approx(0.03, rel=1e-12)
    assert e["p95_force"]["scatter"] == pytest.approx(np.hypot(2.0, 1.5) / 100, rel=1e-12)
    assert e["p95_force"]["ref_scatter"] == pytest.approx(0.02, rel=1e-12)
    assert e["ecc_std"]["error"] == pytest.approx(1e-8 / 1e-4, rel=1e-12)  # in units of c
    assert e["impacts_per_rev"]["error"] == pytest.approx(0.5, rel=1e-12)  # per revolution
    # a joint the reference never brings into contact: no relative scale; equal is 0, else inf
    zero = {"J": {"p95_force": Statistic(0.0, 0.0, 4)}}
    assert statistic_errors(zero, zero)["J"]["p95_force"]["error"] == 0.0
    assert statistic_errors({"J": {"p95_force": Statistic(5.0, 0.0, 4)}}, zero)["J"]["p95_force"]["error"] == np.inf


def test_separation_time() -> None:
    t = np.arange(0, 1e-3, 1e-6)
    a = np.column_stack([np.zeros_like(t), np.zeros_like(t)])
    b = a.copy()
    b[400:, 0] = 2e-5
    ra, rb = _result(t, a, np.zeros_like(t), -np.ones_like(t)), _result(t, b, np.zeros_like(t), -np.ones_like(t))
    assert separation_time(ra, rb, "J", threshold=1e-5) == t[400]
    assert separation_time(ra, ra, "J", threshold=1e-5) == t[-1]


def test_pareto_front_and_defaults() -> None:
    from clearance.bench.speed_error_report import (
        SettingRow,
        choose_defaults,
        pareto_front,
    )

    def row(key, wall, stat, first):
        return SettingRow(
            "s",
            key,
            key,
            {},
            "ok",
            wall_per_rev=wall,
            cpu_per_rev=wall,
            statistics_error=stat,
            first_impact_error=first,
        )

    rows = [
        row("a", 1.0, 0.20, 0.05),
        row("b", 2.0, 0.04, 0.02),
        row("c", 3.0, 0.06, 0.004),
        row("d", 4.0, 0.01, 0.008),
        SettingRow("s", "e", "e", {}, "error", "boom"),
    ]
    assert [r.key for r in pareto_front(rows, "statistics_error")] == ["a", "b", "d"]
    assert [r.key for r in pareto_front(rows, "first_impact_error")] == ["a", "b", "c"]
    d = choose_defaults(rows)
    assert (d["statistics"].key, d["first_impact"].key, d["both"].key) == ("b", "c", "d")


def test_bench_pipeline_end_to_end_and_resume(tmp_path, monkeypatch) -> None:
    from clearance.bench.scenarios import write_report
    from clearance.bench.speed_error import Scenario, Setting, run_speed_error
    from clearance.bench.speed_error_report import compare_scenario
    from clearance.builders import slider_crank

    monkeypatch.setenv("CLEARANCE_CACHE_DIR", str(tmp_path / "cache"))
    sc = Scenario(
        "sc",
        functools.partial(slider_crank, radial_clearance=0.25e-3),
        3,
        0.25,
        (Setting(5e-6, 36), Setting(2e-6, 36)),
        blocks=2,
        output_interval=2e-6,
    )
    out = tmp_path / "bench"
    with ThreadPoolExecutor(1) as ex:
        run_speed_error([sc], out, executor=ex, progress=False)
    files = sorted(out.rglob("*.json"))
    assert len(files) == 6  # accuracy and timing of the reference and two settings
    stamp = {f: f.stat().st_mtime_ns for f in files}
    with ThreadPoolExecutor(1) as ex:
        run_speed_error([sc], out, executor=ex, progress=False)  # resumes: nothing to do
    assert {f: f.stat().st_mtime_ns for f in files} == stamp
    rows = compare_scenario(sc, out, fixed_per_rev=1.5)
    assert [r.status for r in rows] == ["ok", "ok"]
    for r in rows:
        assert r.speedup > 0 and r.speedup_fixed > 0
        # the first impact is deterministic: the nominal ring is within 15 % of the
        # reference at these coarse settings (benchmarks/stability.md: -4 % at 1 us)
        assert r.first_impact_error < 0.15
        assert set(r.statistics["rod_slider"]) >= {"p95_force", "contact_fraction", "rms_deviation"}
    md = write_report([sc], out, command="test")
    text = md.read_text()
    assert "| nominal, h = 5 µs, N = 36, sphere/sphere |" in text and "Pareto front" in text
    assert (out / "speed_error.png").stat().st_size > 10_000
    rec = json.loads((out / "accuracy" / "sc" / "reference.json").read_text())
    assert rec["status"] == "ok" and rec["metadata"]["solver"] is not None


def test_bench_cli_refuses_bad_arguments(capsys) -> None:
    from clearance.cli import main

    assert main(["bench", "--scenarios", "nope"]) == 2
    assert "unknown scenario" in capsys.readouterr().err
    assert main(["bench", "--workers", "0"]) == 2
    assert "--workers must be >= 1" in capsys.readouterr().err
