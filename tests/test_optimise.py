"""Design optimisation (`clearance optimise`): the search, the design space, the pipeline, the command."""

from __future__ import annotations

import json
import math
import pickle
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from clearance.analysis.design.ensemble import MEASURES, EnsembleSettings
from clearance.analysis.design.optimise import optimise_design
from clearance.analysis.design.optimise_search import Estimate, SearchSettings, minimise
from clearance.analysis.design.optimise_space import (
    DesignFactory,
    DesignVariable,
    InfeasibleSpaceError,
    StrokeLimits,
    check_design,
    scan_bounds,
)
from clearance.builders import four_bar, seven_bar_press, slider_crank
from clearance.cli import main
from clearance.cli.optimise import _OBJECTIVES

# --- the search on closed-form objectives -------------------------------------------------


def _bowl(centre: tuple[float, float], calls: list[int]):
    def objective(designs: np.ndarray) -> list[Estimate]:
        calls.append(len(designs))
        return [Estimate(float((x[0] - centre[0]) ** 2 + 4 * (x[1] - centre[1]) ** 2), 0.0, True) for x in designs]

    return objective


def test_search_finds_the_minimum_of_a_bowl():
    calls: list[int] = []
    found = minimise(_bowl((0.3, -0.1), calls), [0.0, -1.0], [1.0, 1.0], [0.9, 0.8], SearchSettings(budget=40))
    # the simplex shrinks to xatol = 1 % of each range before or at the budget; 0.02 of a range leaves it room
    assert found.best.x == pytest.approx((0.3, -0.1), abs=0.02 * 2.0)
    # the first batch is the start design alone, then the 8 samples at once (the executor runs them together)
    assert calls[:2] == [1, 8]
    assert found.evaluations <= 40  # the budget is never exceeded
    assert len({t.x for t in found.trials}) == len(found.trials)  # no design is evaluated twice


def test_search_keeps_to_the_feasible_side_of_a_constraint():
    """The unconstrained minimum (0.3, -0.1) is infeasible (x0 > 0.5 required): the best feasible lies on x0 = 0.5."""
    calls: list[int] = []
    bowl = _bowl((0.3, -0.1), calls)

    def objective(designs: np.ndarray) -> list[Estimate]:
        ok = [x for x in designs if x[0] > 0.5]
        values = iter(bowl(np.array(ok))) if ok else iter(())
        return [next(values) if x[0] > 0.5 else Estimate(math.nan, math.nan, False, "x0 too small") for x in designs]

    found = minimise(objective, [0.0, -1.0], [1.0, 1.0], [0.9, 0.8], SearchSettings(budget=40))
    assert found.best.x[0] > 0.5
    # the constrained minimum is (0.5, -0.1); 5 % of the range covers a simplex stopped by the budget at the wall
    assert found.best.x == pytest.approx((0.5, -0.1), abs=0.05)
    assert any(not t.estimate.feasible for t in found.trials)  # the search did meet the constraint


def test_search_refuses_a_start_outside_its_bounds():
    with pytest.raises(ValueError, match="outside the bounds"):
        minimise(_bowl((0, 0), []), [0.0], [1.0], [2.0])


# --- the design space ----------------------------------------------------------------------


def test_factory_sets_one_component_of_a_pivot_and_pickles():
    f = DesignFactory(seven_bar_press, {}, ("crank7_pivot[1]",))
    mech = f({"crank7_pivot[1]": 0.01})
    assert mech.parameters["crank7_pivot"] == [0.35, 0.01]  # x kept at the builder's default 0.35 m
    assert f.start_value("crank7_pivot[1]") == 0.0
    assert pickle.loads(pickle.dumps(f))({"crank7_pivot[1]": 0.01}) == mech
    with pytest.raises(ValueError, match="takes no such keyword"):
        f.start_value("crank9_length")


def test_bounds_are_checked():
    with pytest.raises(ValueError, match="contradictory bounds"):
        DesignVariable("rod_length", 0.2, 0.1)
    with pytest.raises(ValueError, match="contradictory stroke limits"):
        StrokeLimits(0.2, 0.1)


def test_designs_that_do_not_assemble_over_their_cycle_are_infeasible():
    # a rod shorter than the crank: the builder refuses it (no loop at the start angle)
    sc = DesignFactory(slider_crank)
    short = check_design(sc, {"rod_length": 0.04})
    assert not short.feasible and "assemble" in short.reason
    # a four-bar crank of 110 mm assembles at 90 deg but not at 0 deg (0.02 m between A and O4 < 0.13 - 0.10)
    fb = DesignFactory(four_bar, {"start_angle": math.pi / 2})
    fb({"crank_length": 0.11})  # the start position exists
    mid = check_design(fb, {"crank_length": 0.11})
    assert not mid.feasible and "assemble over its cycle" in mid.reason
    assert check_design(fb, {"crank_length": 0.04}).feasible


def test_stroke_limits_are_kept():
    sc = DesignFactory(slider_crank)
    ok = check_design(sc, {"crank_length": 0.05}, stroke=StrokeLimits(0.095, 0.105))
    # an in-line slider-crank's stroke is twice its crank: 0.1 m (to the kinematics' 1e-12 tolerance, and the
    # 181 samples include both dead centres at 0 and 180 deg)
    assert ok.feasible and ok.stroke == pytest.approx(0.1, abs=1e-9)
    long = check_design(sc, {"crank_length": 0.06}, stroke=StrokeLimits(0.095, 0.105))
    assert not long.feasible and "above its upper limit" in long.reason


def test_bounds_where_nothing_assembles_are_refused():
    with pytest.raises(InfeasibleSpaceError, match="no design within the bounds"):
        scan_bounds(DesignFactory(slider_crank), [DesignVariable("rod_length", 0.02, 0.045)])


# --- the pipeline with a closed-form run evaluator ----------------------------------------

_EVALUATED: list[int] = []
_LOCK = threading.Lock()


def _closed_form_run(mechanism, start, settings) -> dict[str, float]:
    """A 'run' without simulation: a bowl in rod length and slider mass, minimum at (0.15 m, 0.1 kg), plus a
    start-state term of up to 1e-6 (the journals start within 1 % of c = 0.5 mm, so |e| / c <= 0.01)."""
    with _LOCK:
        _EVALUATED.append(1)
    p = mechanism.parameters
    c = mechanism.clearance_joints[0].require_clearance().radial_clearance
    e = max((math.hypot(*v) for v in start.values()), default=0.0) / c
    value = (p["rod_length"] - 0.15) ** 2 + 0.01 * (p["slider_mass"] - 0.1) ** 2 + 1e-4 * e
    return dict.fromkeys(MEASURES, value)


def test_optimisation_pipeline_finds_confirms_and_resumes(tmp_path):
    factory = DesignFactory(slider_crank, {}, ("rod_length", "slider_mass"))
    variables = [DesignVariable("rod_length", 0.10, 0.20), DesignVariable("slider_mass", 0.05, 0.40)]
    ensemble = EnsembleSettings(runs=20, evaluate=_closed_form_run)

    def run() -> object:
        with ThreadPoolExecutor(2) as pool:
            return optimise_design(
                factory,
                variables,
                ensemble=ensemble,
                search=SearchSettings(samples=6, budget=30),
                stroke=StrokeLimits(0.09, 0.11),
                store=tmp_path / "runs",
                executor=pool,
            )

    _EVALUATED.clear()
    first = run()
    simulated = len(_EVALUATED)
    # the known optimum (0.15 m, 0.1 kg); the mass term is 100x flatter, so its tolerance is 10x wider
    assert first.optimum["rod_length"] == pytest.approx(0.15, abs=0.01)
    assert first.optimum["slider_mass"] == pytest.approx(0.1, abs=0.1)
    c = first.confirmation
    assert c.seed == 1 and c.significant  # start (0.12 m): 9e-4 above the optimum, s.e. ~3e-7
    assert c.optimum.runs == c.start.runs == 20
    # every design simulated ran 20 runs, plus 2 x 20 confirmation runs
    assert simulated == 20 * first.search.evaluations + 40
    _EVALUATED.clear()
    again = run()
    assert not _EVALUATED  # every run was read back from the store
    assert again.optimum == first.optimum and again.confirmation == first.confirmation
    # an optimisation stopped part-way kept only some runs: drop a third of them, as a stop would have
    files = sorted((tmp_path / "runs").iterdir())
    for f in files[::3]:
        f.unlink()
    _EVALUATED.clear()
    resumed = run()
    assert len(_EVALUATED) == len(files[::3])  # only the missing runs ran again
    assert resumed.optimum == first.optimum and resumed.search.trials == first.search.trials
    for a, b in ((resumed.confirmation.start, c.start), (resumed.confirmation.optimum, c.optimum)):
        assert (a.value, a.se) == (b.value, b.se)  # the runs are deterministic: equal (only wall times differ)


# --- the command ---------------------------------------------------------------------------


def test_objectives_are_the_ensemble_measures():
    assert set(_OBJECTIVES) == set(MEASURES)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--vary", "rod_lenght_mm=100:200"], "unknown design variable"),
        (["--vary", "rod_length=100:200"], "give its unit in the name"),
        (["--vary", "rod_length_mm=200:100"], "contradictory bounds"),
        (["--vary", "rod_length_mm=130:200"], "lies outside its bounds"),
        (["--vary", "rod_length_mm=100:200", "--output", "slider_y"], "--output slider_y: unknown output"),
        (["--vary", "rod_length_mm=100:200", "--objective", "noise"], "--objective noise: unknown output measure"),
        (["--vary", "rod_length_mm=100:200", "--stroke", "120:90"], "contradictory limits"),
        (["--vary", "rod_length_mm=100:200", "--stroke", "150:200"], "no design within the bounds"),
        (["--vary", "rod_length_mm=20:45:30"], "no design within the bounds"),
        (["--vary", "rod_length_mm=100:200", "--mechanism", "nine_bar"], "--mechanism: unknown mechanism"),
        (["--vary", "rod_length_mm=100:200", "--runs", "x"], "--runs must be a whole number"),
    ],
)
def test_bad_input_is_refused_before_any_work(tmp_path, capsys, argv, message):
    out = tmp_path / "out"
    assert main(["optimise", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    # a refusal of the parser names the command too: "clearance optimise: error: ..."
    assert message in err and err.startswith(("error:", "clearance optimise: error:")) and err.count("\n") == 1
    assert not out.exists()  # nothing was written


def test_command_end_to_end(tmp_path, capsys):
    """A tiny real optimisation: 2 designs of 2 runs searched, confirmed, reported (resuming is tested above)."""
    out = tmp_path / "opt"
    argv = [
        "optimise",
        "--vary",
        "slider_mass_kg=0.05:0.4",
        "--runs",
        "2",
        "--periods",
        "2",
        "--samples",
        "0",
        "--budget",
        "2",
        "--workers",
        "1",
        "--out",
        str(out),
        "--no-progress",
    ]
    assert main(argv) == 0
    data = json.loads((out / "optimise.json").read_text())
    assert len(data["search"]["trials"]) == 2 and data["confirmation"]["seed"] == 1
    md = (out / "optimise.md").read_text()
    for name in ("convergence.png", "start/report.md", "optimum/report.md"):
        assert name in md and (out / name).is_file()
    stored = sorted(p.name for p in (out / "runs").iterdir())
    # 2 designs x 2 runs, and 2 runs (a new seed) at the start and at the optimum (once if they are one design)
    assert len(stored) == 2 * 2 + 2 * len({data["start"]["slider_mass"], data["optimum"]["slider_mass"]})


_SCENARIO = """# slider-crank sized for a low fluctuation of the slider
[mechanism]
builder = "slider_crank"
clearance_mm = 0.1
crank_speed_rpm = 2000

[optimise]
objective = "peak_force"
stroke = [95, 105]
runs = 3
budget = 12

[optimise.vary]
slider_mass_kg = [0.05, 0.4]
"crank_length_mm" = [45, 60, 50]
"""


def test_scenario_section_sets_the_optimisation(tmp_path):
    from clearance.cli.optimise import _plan, optimise_parser

    path = tmp_path / "design.toml"
    path.write_text(_SCENARIO)
    args = optimise_parser().parse_args(["--scenario", str(path), "--runs", "4", "--out", str(tmp_path / "o")])
    plan = _plan(args)
    assert [v.name for v in plan.variables] == ["slider_mass", "crank_length"]
    assert plan.variables[1].low == pytest.approx(0.045, rel=1e-12)  # 45 mm in m, to rounding
    assert plan.start == {"slider_mass": 0.14, "crank_length": pytest.approx(0.05, rel=1e-12)}
    assert plan.ensemble.runs == 4  # the command line wins over the file's 3
    assert args.objective == "peak_force" and args.budget == 12 and args.samples == 8  # file, file, default
    assert plan.factory.fixed["radial_clearance"] == pytest.approx(1e-4, rel=1e-12)
    assert plan.stroke.low == pytest.approx(0.095, rel=1e-12)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("budget = 12", "budgt = 12"), "[optimise] has unknown key(s) ['budgt']"),
        (("runs = 3", "runs = 1"), "[optimise] runs: runs must be at least 2"),
        (("crank_speed_rpm", "crank_sped_rpm"), "line 5: [mechanism]: key 'crank_sped_rpm'"),
        (("[45, 60, 50]", "[45, 60, 70]"), "START 70 lies outside"),
    ],
)
def test_bad_scenario_is_refused_before_any_work(tmp_path, capsys, edit, message):
    path = tmp_path / "design.toml"
    path.write_text(_SCENARIO.replace(*edit))
    out = tmp_path / "out"
    assert main(["optimise", "--scenario", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not out.exists()
