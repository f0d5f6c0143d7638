"""Tools of studies: comparisons across runs, the resumable run store, comparison figures."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from clearance.analysis.metrics.comparisons import (
    joint_distances,
    linear_fit,
    rank_agreement,
    trend,
    velocity_zigzag,
)
from clearance.analysis.sweeps.run_store import RunSpec, run_batch
from clearance.analysis.sweeps.sweep import KeywordFactory
from clearance.builders import rpm, slider_crank, watt_six_bar
from clearance.options import ModelOptions
from clearance.results import JointResult, SimulationResult


def _series(v: np.ndarray, t: np.ndarray) -> SimulationResult:
    n = len(t)
    return SimulationResult(
        times=t,
        outputs={"x": np.cumsum(v) * (t[1] - t[0]), "x_vel": v, "x_acc": np.gradient(v, t)},
        joints={"j": JointResult(np.zeros((n, 2)), np.zeros((n, 2)), np.full(n, -1e-6), np.zeros((n, 2)))},
        drive_angle=(2 * np.pi * t)[:, None],
        drive_speed=np.full((n, 1), 2 * np.pi),
        drive_torque=np.zeros((n, 1)),
        link_poses=np.zeros((n, 1, 3)),
        closure_violation=np.zeros(n),
    )


def test_linear_fit_trend_and_rank_agreement():
    x = np.array([0.02, 0.05, 0.1, 0.5, 1.0])
    f = linear_fit(x, 0.8 * x + 0.01)
    # an exact line: least squares recovers it to rounding (1e-12)
    assert (f.slope, f.intercept, f.r2) == pytest.approx((0.8, 0.01, 1.0), abs=1e-12)
    t = trend(x, [1.0, 2.0, 1.5, 4.0, 8.0])
    assert t.rising_steps == 0.75 and t.ratio == 8.0
    assert t.spearman == pytest.approx(0.9, abs=1e-12)  # ranks 1,3,2,4,5: 1 - 6*2/(5*24) = 0.9
    same = rank_agreement(["B", "A", "C"], ["B", "A", "C", "D"])
    assert same.same_order and same.same_first and same.tau == pytest.approx(1.0, abs=1e-12)
    rev = rank_agreement(["A", "B", "C"], ["C", "B", "A"])
    assert not rev.same_first and rev.tau == pytest.approx(-1.0, abs=1e-12)
    with pytest.raises(ValueError, match="at least 3"):
        linear_fit([1, 2], [1, 2])
    with pytest.raises(ValueError, match="common items"):
        rank_agreement(["A"], ["B"])


def test_velocity_zigzag_of_known_curves():
    t = np.linspace(0.0, 1.0, 200_001)
    smooth = np.sin(2 * np.pi * t)
    ideal = _series(smooth, t)
    # the same curve: ratio 1 to rounding
    assert velocity_zigzag(_series(smooth.copy(), t), ideal, "x") == pytest.approx(1.0, abs=1e-12)
    # a fast ripple eps sin(2 pi k t) whose slope (eps 2 pi k = 126) dwarfs the slow one
    # (2 pi): total variation 4 eps k = 80 against 4, i.e. 20; the slow slope changes the
    # mean |slope| by well under 1 % (second order in 2 pi / 126)
    zig = _series(smooth + 0.1 * np.sin(2 * np.pi * 200 * t), t)
    assert velocity_zigzag(zig, ideal, "x") == pytest.approx(20.0, rel=0.01)


def test_joint_distances_follow_the_links_from_the_crank():
    m = watt_six_bar()
    assert dict(joint_distances(m, ["A", "B", "O4", "C", "D"])) == {"A": 1, "B": 2, "O4": 3, "C": 3, "D": 4}


def test_run_store_digest_resume_and_names(tmp_path):
    make = KeywordFactory(slider_crank)
    point = {"crank_speed": rpm(1000.0), "radial_clearance": 0.3e-3}
    opts = ModelOptions(timestep=5e-6, segments=36)
    spec = RunSpec("sc_1000rpm", make, point, 0.06, opts, keep_every=10)  # one period, 12,000 steps
    with ThreadPoolExecutor(1) as pool:
        store = run_batch([spec], tmp_path, executor=pool, progress=False)
    d = store.digest("sc_1000rpm")
    assert d.status == "ok" and d.steps == 12_000
    kept = store.result("sc_1000rpm")
    assert len(kept) == 1200
    from clearance.run.simulation import simulate

    full = simulate(make(point), duration=0.06, options=opts)
    # the digest comes from every step of the same deterministic run: equal exactly (run_batch made
    # this very call in its worker thread, and its JSON keeps every bit)
    assert d.outputs["slider_x_acc"]["max_abs"] == float(np.abs(full.outputs["slider_x_acc"]).max())
    assert d.joints["rod_slider"]["peak_force"] == float(full.joints["rod_slider"].force_magnitude.max())
    np.testing.assert_array_equal(kept.times, full.times[::10])
    stamp = (tmp_path / "sc_1000rpm.digest.json").stat().st_mtime_ns
    with ThreadPoolExecutor(1) as pool:
        run_batch([spec], tmp_path, executor=pool, progress=False)
    assert (tmp_path / "sc_1000rpm.digest.json").stat().st_mtime_ns == stamp  # resumed: nothing rerun
    with pytest.raises(ValueError, match="letters, digits"):
        RunSpec("c0.1mm", make, point, 0.06)
    with pytest.raises(ValueError, match="unique"):
        run_batch([spec, spec], tmp_path, progress=False)


def test_comparison_figures_write_pngs(tmp_path):
    from clearance.analysis.chaos.poincare import classify_poincare
    from clearance.analysis.figures.comparison_figures import (
        OrbitPanel,
        PoincarePanel,
        TrendPanel,
        plot_orbit_phase_panels,
        plot_output_overlay,
        plot_poincare_panels,
        plot_trends,
    )

    t = np.linspace(0, 1, 500)
    r = _series(np.sin(2 * np.pi * t), t)
    plot_trends(
        [
            TrendPanel(
                {"a": ([1, 2, 3], [1, 4, 9], [0.1, 0.2, 0.3])},
                "x [mm]",
                "y [N]",
                reference={"paper": ([2], [5])},
                logx=True,
            )
        ],
        title="t",
        path=tmp_path / "trend.png",
    )
    plot_output_overlay({"ideal": r, "other": r}, "x", window=(0.2, 0.8), path=tmp_path / "overlay.png")
    plot_orbit_phase_panels(
        [OrbitPanel(r, "j", 1e-4, "one", period=0.5), OrbitPanel(r, "j", 1e-4, "two", period=0.5)],
        path=tmp_path / "orbits.png",
    )
    with pytest.raises(ValueError, match="period"):
        plot_orbit_phase_panels([OrbitPanel(r, "j", 1e-4, "no period")])
    pts = np.column_stack([np.cos(np.arange(30) * 0.7), np.sin(np.arange(30) * 0.7)]) * 1e-5
    plot_poincare_panels(
        [PoincarePanel(pts, ("j.ex", "j.ey"), classify_poincare(pts), label="c = 0.1 mm")],
        path=tmp_path / "poincare.png",
    )
    for name in ("trend", "overlay", "orbits", "poincare"):
        assert (tmp_path / f"{name}.png").read_bytes()[:4] == b"\x89PNG"
