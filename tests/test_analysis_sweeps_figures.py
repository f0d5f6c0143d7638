"""Bifurcation and criticality sweeps, figures, the Markdown report and the CLI entry points."""

from __future__ import annotations

from concurrent.futures import Future

import numpy as np
import pytest

from clearance.analysis.sweeps.bifurcation import (
    BifurcationDiagram,
    bifurcation_from_rows,
    run_bifurcation,
)
from clearance.analysis.sweeps.criticality import (
    ClearanceAtJoint,
    criticality_candidates,
    rank_joints,
    ranking_markdown,
    run_criticality,
)
from clearance.analysis.sweeps.sweep import KeywordFactory
from clearance.builders import rpm, slider_crank
from clearance.cli.rank import main_rank
from clearance.cli.sweep import main_sweep
from clearance.model import OutputKind
from clearance.options import ModelOptions

# low speed and a coarse step keep each run well under a second (1000 rpm: T = 60 ms)
OPTIONS = ModelOptions(timestep=5e-6, segments=36)


class _Inline:
    """Executor running each call at submit (no process start-up in these tests)."""

    def submit(self, fn, *args):
        f = Future()
        f.set_result(fn(*args))
        return f


def test_bifurcation_sweep_and_figure(tmp_path):
    make = KeywordFactory(slider_crank, fixed={"crank_speed": rpm(1000.0)})
    values = [0.1e-3, 0.5e-3]
    d = run_bifurcation(
        values,
        make,
        out_dir=tmp_path,
        quantity="rod_slider.ex",
        periods=4,
        sampled=2,
        options=OPTIONS,
        executor=_Inline(),
        progress=False,
    )
    np.testing.assert_array_equal(d.values, values)  # the points' values, copied
    assert d.quantity == "rod_slider.ex" and d.errors == ("", "")
    # sections at t = 2T and 3T: the run ends one step before 4T
    assert [len(s) for s in d.samples] == [2, 2]
    # the journal stays within its clearance circle plus penetration (< 0.1 mm here)
    assert all(np.all(np.abs(s) < c + 0.1e-3) for s, c in zip(d.samples, values))
    from clearance.analysis.figures.analysis_figures import plot_bifurcation

    png = tmp_path / "bif.png"
    plot_bifurcation(d, path=png)
    assert png.stat().st_size > 5000
    with pytest.raises(ValueError, match="sampled"):
        run_bifurcation(values, make, out_dir=tmp_path / "x", periods=4, sampled=4, executor=_Inline())


def test_bifurcation_from_rows_marks_failed_points():
    rows = [
        {
            "index": 0,
            "point": {"c": 1.0},
            "status": "ok",
            "error": "",
            "poincare": {"quantities": ["q"], "points": [[1.0], [2.0]], "regime": "periodic"},
        },
        {"index": 1, "point": {"c": 2.0}, "status": "error", "error": "TimeStepError: x"},
    ]
    d = bifurcation_from_rows(rows, "c")
    assert d.regimes == ("periodic", "error") and d.quantity == "q"
    x, y = d.scatter()  # the rows' numbers, copied: exact
    np.testing.assert_array_equal(x, [1.0, 1.0])
    np.testing.assert_array_equal(y, [1.0, 2.0])


def test_criticality_candidates_and_sweep(tmp_path):
    assert criticality_candidates(slider_crank(clearance_at=())) == ["crank_rod", "rod_slider"]
    r = run_criticality(
        ClearanceAtJoint(slider_crank),
        clearances=[0.5e-3],
        speeds=[rpm(1000.0)],
        periods=3,
        out_dir=tmp_path,
        options=OPTIONS,
        executor=_Inline(),
        progress=False,
    )
    assert {s.joint for s in r.scores} == {"crank_rod", "rod_slider"}
    assert [s.rank for s in r.scores] == [1, 2]
    for s in r.scores:
        # the output moves at most by c plus penetration relative to ideal: ratio <= ~1.1
        assert 0 < s.score < 1.1
        assert s.ci_low <= s.score <= s.ci_high
    assert len(r.cells) == 2 and all(c.cycles == 2 for c in r.cells)
    # the slider's x position is measured: deviation [m] / clearance [m] is dimensionless
    assert (r.output, r.output_kind, r.score_unit) == ("slider_x", OutputKind.POSITION_X, "-")
    md = ranking_markdown(r)
    assert "| 1 |" in md and "rod_slider" in md and "[-]" in md and "[µm]" in md
    from clearance.analysis.figures.analysis_figures import plot_criticality

    fig = plot_criticality(r, path=tmp_path / "crit.png")
    assert fig.axes[0].get_ylabel() == "mean deviation of slider_x / radial clearance [-]"
    assert (tmp_path / "crit.png").stat().st_size > 5000
    with pytest.raises(ValueError, match="output must be one of .*slider_x"):
        run_criticality(
            ClearanceAtJoint(slider_crank),
            clearances=[0.5e-3],
            speeds=[rpm(1000.0)],
            periods=3,
            output="crank_angle",
            out_dir=tmp_path / "x",
            executor=_Inline(),
            progress=False,
        )


def test_score_unit_follows_the_output_kind():
    from clearance.analysis.figures.analysis_figures import plot_criticality

    rows = [_row(0, "a", 1e-4, [0.5e-4, 0.6e-4]), _row(1, "b", 1e-4, [0.2e-4, 0.3e-4])]
    angle = rank_joints(rows, output="rocker_angle", output_kind=OutputKind.ANGLE)
    assert angle.score_unit == "rad/m"  # deviation [rad] / clearance [m]
    assert "[rad/m]" in ranking_markdown(angle) and "[µrad]" in ranking_markdown(angle)
    assert plot_criticality(angle).axes[0].get_ylabel().endswith("[rad/m]")
    assert rank_joints(rows, output_kind=OutputKind.POSITION_Y).score_unit == "-"
    unknown = rank_joints(rows)  # rows alone do not say what was measured
    assert unknown.output_kind is None and "[-]" not in plot_criticality(unknown).axes[0].get_ylabel()


def _row(i, joint, c, cycles):
    return {
        "index": i,
        "status": "ok",
        "error": "",
        "point": {"joint": joint, "clearance": c, "speed": 100.0},
        "per_cycle_mean_deviation": cycles,
    }


def test_rank_joints_scores_and_confidence():
    rows = [
        _row(0, "a", 1e-4, [0.5e-4, 0.5e-4, 0.5e-4]),  # ratio 0.5, no scatter
        _row(1, "a", 2e-4, [1.0e-4, 1.2e-4, 0.8e-4]),  # ratio 0.5 +- 0.058 (s.e.)
        _row(2, "b", 1e-4, [0.2e-4, 0.3e-4, 0.1e-4]),  # ratio 0.2 +- 0.058
        _row(3, "b", 2e-4, [0.4e-4, 0.4e-4, 0.4e-4]),  # ratio 0.2
        {"index": 4, "status": "error", "error": "boom", "point": {"joint": "c", "clearance": 1e-4, "speed": 100.0}},
    ]
    r = rank_joints(rows)
    a, b = r.scores
    assert (a.joint, b.joint) == ("a", "b")
    # means of the per-cell ratios; identical arithmetic: 1e-12 relative
    assert a.score == pytest.approx(0.5, rel=1e-12) and b.score == pytest.approx(0.2, rel=1e-12)
    se = np.std([0.5, 0.6, 0.4], ddof=1) / np.sqrt(3) / 2  # one cell with scatter, averaged over 2 cells
    assert a.se == pytest.approx(se, rel=1e-12)
    assert a.confidence_above_next > 0.99  # 0.3 apart with s.e. ~0.04 each
    assert np.isnan(b.confidence_above_next)
    assert r.failed and r.failed[0][1] == "boom"
    with pytest.raises(ValueError, match="1 failed; first error: boom"):
        rank_joints(rows[4:])


def test_report_writes_markdown_and_figures(tmp_path):
    from clearance import simulate
    from clearance.analysis.figures.report import write_report

    m = slider_crank(crank_speed=rpm(1000.0))
    res, ideal = simulate(m, options=OPTIONS), simulate(m.ideal_twin(), options=OPTIONS)
    diag = BifurcationDiagram(
        "radial_clearance",
        "rod_slider.ex",
        np.array([1e-4, 2e-4]),
        (np.array([1e-5, 2e-5]), np.zeros(0)),
        ("periodic", "error"),
        ("", "boom"),
    )
    ranking = rank_joints([_row(0, "a", 1e-4, [0.5e-4, 0.6e-4]), _row(1, "b", 1e-4, [0.2e-4, 0.3e-4])])
    # figures of an earlier report into the same folder (a mechanism with more joints)
    for stale in ("phase_4.png", "poincare_2.png"):
        (tmp_path / stale).write_bytes(b"")
    path = write_report(tmp_path, res, ideal, bifurcation=diag, ranking=ranking)
    text = path.read_text()
    for heading in (
        "Response against the ideal",
        "Deviation statistics",
        "Contact at the clearance joints",
        "Poincaré sections",
        "Bifurcation diagram",
        "Joint criticality",
    ):
        assert heading in text
    for png in (
        "response_vs_ideal",
        "deviation",
        "contact_force",
        "contact_modes",
        "orbit_rod_slider",
        "phase_0",
        "bifurcation",
        "criticality",
    ):
        assert (tmp_path / f"{png}.png").exists() and f"({png}.png)" in text
    # 3 periods: no Poincaré section (the output's phase portrait only), nothing older linked
    assert "No Poincaré section" in text and "poincare_1.png" not in text
    assert "phase_4.png" not in text and "poincare_2.png" not in text


def test_cli_sweep_and_rank(tmp_path, capsys):
    common = ["--rpm", "1000", "--timestep-us", "5", "--workers", "1", "--no-progress"]
    rc = main_sweep(
        [
            "--points",
            "2",
            "--start",
            "0.2",
            "--stop",
            "0.5",
            "--periods",
            "3",
            "--sampled",
            "1",
            "--out",
            str(tmp_path / "s"),
            *common,
        ]
    )
    assert rc == 0 and (tmp_path / "s" / "bifurcation.png").exists() and (tmp_path / "s" / "sweep.csv").exists()
    rc = main_rank(
        ["--clearances-mm", "0.5", "--joints", "rod_slider", "--periods", "3", "--out", str(tmp_path / "r"), *common]
    )
    assert rc == 0 and "rod_slider" in (tmp_path / "r" / "ranking.md").read_text()
    assert "rod_slider" in capsys.readouterr().out
    # over drive speed: 1000 and 2000 rpm given in rpm, stored in rad/s (SI inside)
    rc = main_sweep(
        [
            "--parameter",
            "speed",
            "--points",
            "2",
            "--start",
            "1000",
            "--stop",
            "2000",
            "--periods",
            "3",
            "--sampled",
            "1",
            "--out",
            str(tmp_path / "v"),
            *common[2:],
        ]
    )
    assert rc == 0 and (tmp_path / "v" / "bifurcation.png").exists()
    from clearance.analysis.sweeps.sweep import load_rows

    speeds = sorted(r["point"]["crank_speed"] for r in load_rows(tmp_path / "v"))
    assert speeds == pytest.approx([1000 * np.pi / 30, 2000 * np.pi / 30], rel=1e-12)  # exact unit conversion
    with pytest.raises(SystemExit):
        main_sweep(["--mechanism", "no_such", "--out", str(tmp_path / "x")])


def test_cli_refuses_unknown_quantity_and_reports_failed_points(tmp_path, capsys):
    common = ["--workers", "1", "--no-progress", "--periods", "2", "--sampled", "1"]
    assert main_sweep(["--quantity", "no_such", "--out", str(tmp_path / "q"), *common]) == 2
    err = capsys.readouterr().err
    assert "--quantity 'no_such'" in err and "'rod_slider.ex'" in err and "'slider_x_vel'" in err
    assert not (tmp_path / "q").exists()  # refused before any point was launched
    # a 1 ms step is far above the contact's stability limit (about 10 us here): every
    # point fails at its time-step check, in milliseconds
    rc = main_sweep(["--timestep-us", "1000", "--points", "2", "--out", str(tmp_path / "f"), *common])
    err = capsys.readouterr().err
    assert rc == 1 and "2 of 2 points failed" in err and "TimeStepError" in err and "sweep.csv" in err
    rc = main_rank(
        [
            "--timestep-us",
            "1000",
            "--clearances-mm",
            "0.5",
            "--rpm",
            "1000",
            "--joints",
            "rod_slider",
            "--periods",
            "3",
            "--workers",
            "1",
            "--no-progress",
            "--out",
            str(tmp_path / "r"),
        ]
    )
    assert rc == 1 and "1 of 1 points failed" in capsys.readouterr().err
    assert main_rank(["--joints", "no_such", "--out", str(tmp_path / "j")]) == 2
    assert "['crank_rod', 'rod_slider', 'slider_guide']" in capsys.readouterr().err  # a slider ranks too


def test_cli_sweeps_and_ranks_the_press(tmp_path, monkeypatch, capsys):
    """The press's speed keyword is crank2_speed; one short point each (about 4 s)."""
    monkeypatch.chdir(tmp_path)
    # 90 rpm = 3 pi rad/s (T = 0.67 s), the top of the press's speed range; 10 us steps
    common = [
        "--mechanism",
        "seven_bar_press",
        "--rpm",
        "90",
        "--timestep-us",
        "10",
        "--workers",
        "1",
        "--no-progress",
    ]
    rc = main_sweep(["--points", "1", "--start", "0.5", "--stop", "0.5", "--periods", "2", "--sampled", "1", *common])
    out = tmp_path / "clearance-sweep-seven_bar_press"  # default folder named after the mechanism
    assert rc == 0 and (out / "bifurcation.png").exists(), capsys.readouterr().err
    rc = main_rank(["--clearances-mm", "0.5", "--joints", "A", "--periods", "3", *common])
    ranking = (tmp_path / "clearance-rank-seven_bar_press" / "ranking.md").read_text()
    assert rc == 0 and "| 1 | A |" in ranking and "[-]" in ranking  # slider_y: a position output
    assert main_sweep(["--clearance-at", "Z", *common]) == 2
    assert "unknown joint" in capsys.readouterr().err


def _analysis_and_cli_modules() -> list[str]:
    import pkgutil

    import clearance.analysis
    import clearance.cli

    return [
        m.name
        for pkg in (clearance.analysis, clearance.cli)
        for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + ".")
        if not m.ispkg and not m.name.endswith("__main__")
    ]  # __main__ runs the command on import


@pytest.mark.parametrize("module", _analysis_and_cli_modules())
def test_every_public_argument_is_documented(module):
    import importlib
    import inspect

    mod = importlib.import_module(module)
    for name in getattr(mod, "__all__", ()):
        obj = getattr(mod, name)
        if not inspect.isfunction(obj):
            continue
        doc = inspect.getdoc(obj) or ""
        assert doc, f"{module}.{name} has no docstring"
        missing = [p for p in inspect.signature(obj).parameters if p not in doc]
        # short helpers may describe their arguments in the summary line; require the
        # Args section only where a function takes more than two arguments
        if len(inspect.signature(obj).parameters) > 2:
            assert not missing, f"{module}.{name}: undocumented {missing}"


def test_catalogue_speed_keyword_sets_the_first_drive_speed():
    """The CLI passes each entry's speed keyword to its builder: every builder must take it."""
    from clearance.builders import CATALOGUE

    for name, entry in CATALOGUE.items():
        low, high = entry.speed_range
        m = entry.builder(**{entry.speed_keyword: high})
        # the value is stored as given: exact
        assert m.drives[0].speed == high and 0 < low < high, name
