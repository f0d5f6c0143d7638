"""Tolerance allocation: the optimiser on closed forms, bounds and budget, verification, resume, the command."""

from __future__ import annotations

import itertools
import json
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from clearance.analysis.design.allocation import (
    AllocationProblem,
    AllocationSettings,
    BudgetUnreachable,
    allocate,
)
from clearance.analysis.design.ensemble import EnsembleSettings, EnsembleStopped
from clearance.analysis.design.factories import JointClearances
from clearance.analysis.design.surrogate import (
    CostModel,
    cheapest_clearances,
    design_points,
    equal_clearance,
    fit_response_surface,
    quadratic_terms,
)
from clearance.analysis.sweeps.sweep import KeywordFactory
from clearance.builders import watt_six_bar
from clearance.cli.allocate import main_allocate

WEIGHTS = {"A": 3.0, "C": 1.0}
"""Deviation per metre of clearance of each joint in the closed-form evaluator."""


def linear_deviation(mechanism, start, settings):
    """Closed form: D = sum_j w_j c_j, times 1 + 0.3 (u - 0.5) with u in [0, 1] set by the start.

    u is joint A's start offset over its disc radius, so runs scatter by +-15 % around the
    closed form, like an ensemble of start states.
    """
    c = {j.name: j.require_clearance().radial_clearance for j in mechanism.clearance_joints}
    base = sum(WEIGHTS[j] * c[j] for j in c)
    u = math.hypot(*start["A"]) / (settings.spread * c["A"]) if settings.spread else 0.5
    d = base * (1 + 0.3 * (u - 0.5))
    return {"mean_deviation": d, "rms_deviation": d, "peak_deviation": d, "peak_force": 1.0}


FACTORY = JointClearances(KeywordFactory(watt_six_bar, {"clearance_at": ("A", "C")}))


def problem(**kw):
    base = dict(
        joints=("A", "C"),
        lower=(2e-5, 2e-5),
        upper=(4e-4, 4e-4),
        cost=CostModel((0.0, 0.0), (1.0, 1.0)),
        budgets=(4e-4,),
    )
    return AllocationProblem(**{**base, **kw})


def settings(**kw):
    ens = EnsembleSettings(runs=20, spread=0.01, seed=0, evaluate=linear_deviation)
    return AllocationSettings(**{"verification": ens, "design_size": 12, "front_fractions": (0.7, 1.0), **kw})


def test_optimiser_finds_the_closed_form_optimum():
    """min sum b_j / c_j s.t. sum w_j c_j <= B: c_j = sqrt(b_j / w_j) B / sum_k sqrt(b_k w_k) (Lagrange)."""
    w, b, budget = np.array([3.0, 1.0]), np.array([1.0, 2.0]), 4e-4
    expected = np.sqrt(b / w) * budget / np.sum(np.sqrt(b * w))
    got = cheapest_clearances(
        [lambda c: float(w @ c)], [budget], CostModel((0.0, 0.0), tuple(b)), [1e-6] * 2, [1e-3] * 2
    )
    assert got is not None
    # SLSQP ends on the constraint to ftol 1e-12; the rounding to 1 nm moves c by < 1e-9 m
    assert np.allclose(got, expected, rtol=1e-4, atol=2e-9)
    # an active upper bound: c_C = 1e-4 m, then c_A spends the rest of the budget
    got = cheapest_clearances(
        [lambda c: float(w @ c)], [budget], CostModel((0.0, 0.0), tuple(b)), [1e-6] * 2, [1e-3, 1e-4]
    )
    assert got is not None and np.allclose(got, [(budget - 1e-4) / 3.0, 1e-4], rtol=1e-4, atol=2e-9)  # as above


def test_grid_optimum_is_the_cheapest_feasible_cell():
    levels = [2e-5, 5e-5, 1e-4, 1.5e-4, 2e-4, 3e-4]
    w, budget, cost = np.array([3.0, 1.0]), 4e-4, CostModel((0.0, 0.0), (1.0, 1.0))
    got = cheapest_clearances([lambda c: float(w @ c)], [budget], cost, [1e-5] * 2, [1e-3] * 2, levels=levels)
    cells = [np.array(c) for c in itertools.product(levels, levels) if w @ np.array(c) <= budget]
    best = min(cells, key=cost)
    # exact: both are cells of the levels, copied; the one cell on the budget, (1e-4, 1e-4), sums to
    # 4e-4 exactly in w @ c, with or without a fused multiply-add
    assert got is not None and np.array_equal(got, best)
    eq = equal_clearance([lambda c: float(w @ c)], [budget], [1e-5] * 2, [1e-3] * 2, levels=levels)
    assert eq == 1e-4  # 4 * 1e-4 = budget exactly; 1.5e-4 gives 6e-4


def test_response_surface_is_exact_on_a_log_quadratic_and_its_leave_one_out_is_right():
    rng = np.random.default_rng(1)
    c = design_points([1e-5, 1e-5, 1e-5], [1e-3, 1e-3, 1e-3], 25, seed=2)
    coef = rng.normal(size=quadratic_terms(np.zeros((1, 3))).shape[1]) * 0.1
    ref = [1e-4] * 3
    y = np.exp(quadratic_terms(np.log(c / 1e-4)) @ coef)
    s = fit_response_surface(c, y, ref)
    assert np.allclose(s.coefficients, coef, atol=1e-9)  # exact data: least squares recovers it to rounding
    assert s.rms_log_residual < 1e-9
    noisy = y * np.exp(rng.normal(scale=0.05, size=len(y)))
    s = fit_response_surface(c, noisy, ref)
    loo = []
    for i in range(len(y)):
        keep = np.arange(len(y)) != i
        fi = fit_response_surface(c[keep], noisy[keep], ref)
        loo.append(math.log(noisy[i]) - fi.log_predict(c[i])[0])
    assert s.loo_rms_log_residual == pytest.approx(float(np.sqrt(np.mean(np.square(loo)))), rel=1e-9)  # hat identity
    assert (c >= 1e-5 * (1 - 1e-9)).all() and (c <= 1e-3 * (1 + 1e-9)).all()  # design inside the box


def test_allocation_respects_bounds_and_budget(tmp_path):
    with ThreadPoolExecutor(2) as ex:
        a = allocate(FACTORY, problem(upper=(4e-4, 1.2e-4)), settings(), store=tmp_path, executor=ex, progress=False)
    d = a.allocated
    assert d is not None and d.meets
    lo, hi = np.array(a.problem.lower), np.array(a.problem.upper)
    assert np.all(np.array(d.clearances) >= lo) and np.all(np.array(d.clearances) <= hi)
    assert d.predicted[0] <= d.surrogate_budgets[0] * (1 + 1e-8)  # the optimiser's constraint, to its tolerance
    assert d.share[0] >= 0.9 and np.mean(np.array(d.values[0]) <= 4e-4) == d.share[0]
    # C's upper bound 0.12 mm is active: without it the optimum gives C more (w_C is a third of w_A)
    assert d.clearances[1] == pytest.approx(1.2e-4, abs=1.5e-9)  # rounded (down, where needed) to 1 nm
    assert a.equal is not None and a.equal.meets and a.saving > 0
    # the allocation is cheaper than the equal design verified at the same budget
    assert d.cost < a.equal.cost


def test_verification_flags_a_budget_the_allocation_violates(tmp_path):
    """Solved at the budget on the mean, +-15 % start scatter leaves about half the runs above it."""
    with ThreadPoolExecutor(2) as ex:
        one = allocate(FACTORY, problem(), settings(max_iterations=1), store=tmp_path, executor=ex, progress=False)
        more = allocate(FACTORY, problem(), settings(max_iterations=4), store=tmp_path, executor=ex, progress=False)
    first = one.allocated
    assert first is not None and not first.meets and first.share[0] < 0.9
    assert more.allocation_iterations[0] == first  # the same first step, from the same runs
    last = more.allocated
    assert last is not None and last.meets and last.cost > first.cost  # tightened: dearer, within budget
    assert last.surrogate_budgets[0] < first.surrogate_budgets[0]


def test_resume_after_a_stop_gives_the_same_allocation(tmp_path):
    with ThreadPoolExecutor(2) as ex:
        whole = allocate(FACTORY, problem(), settings(), store=tmp_path / "a", executor=ex, progress=False)
        with pytest.raises(EnsembleStopped):
            allocate(FACTORY, problem(), settings(), store=tmp_path / "b", executor=ex, progress=False, stop_after=50)
        stopped_with = len(list((tmp_path / "b").glob("run_*.json")))
        resumed = allocate(FACTORY, problem(), settings(), store=tmp_path / "b", executor=ex, progress=False)
    assert stopped_with == 50 < whole.new_runs  # exactly the runs asked, not everything
    assert resumed.new_runs == whole.new_runs - stopped_with
    # exact: the same runs in index order, either in memory or read back from JSON (which keeps every bit)
    assert resumed.allocation_iterations == whole.allocation_iterations
    assert resumed.equal_iterations == whole.equal_iterations and resumed.front == whole.front


def test_a_budget_the_lower_bounds_miss_is_refused_before_the_design(tmp_path):
    # lower bounds 2e-5 m: D = 4 * 2e-5 = 8e-5 > 5e-5
    with pytest.raises(BudgetUnreachable, match="out of reach"):
        allocate(FACTORY, problem(budgets=(5e-5,)), settings(), store=tmp_path, executor=ThreadPoolExecutor(1),
                 progress=False)  # fmt: skip
    assert len(list(tmp_path.glob("run_*.json"))) == 20  # the lower-bound ensemble only


def test_contradictory_problems_are_refused():
    with pytest.raises(ValueError, match="0 < lower < upper"):
        problem(lower=(2e-4, 2e-5), upper=(1e-4, 4e-4))
    with pytest.raises(ValueError, match="measure"):
        problem(measure="band")
    with pytest.raises(ValueError, match="level"):
        problem(levels=(1e-3,))


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--joints", "A", "Q"], "--joints"),
        (["--output", "nope"], "--output nope"),
        (["--measure", "median"], "--measure median"),
        (["--bounds", "A:0.2:0.1"], "--bounds A:0.2:0.1: joint A's lower bound 0.2 mm must be above 0 and below"),
        (["--bounds", "Z:0.1:0.2"], "'Z'"),
        (["--cost", "A:0:-1"], "cost b"),
        (["--levels-mm", "5"], "level"),
    ],
)
def test_command_refuses_bad_input_in_one_line(tmp_path, capsys, args, words):
    code = main_allocate(
        ["--mechanism", "watt_six_bar", "--budget", "100", "--out", str(tmp_path / "o"), "--no-progress", *args]
    )
    err = capsys.readouterr().err
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o" / "runs").exists()  # before any work


def test_command_refuses_an_unreachable_budget_after_the_lower_bound_runs(tmp_path, capsys):
    out = tmp_path / "o"
    code = main_allocate(
        [
            "--mechanism",
            "watt_six_bar",
            "--joints",
            "B",
            "--budget",
            "1",
            "--runs",
            "2",
            "--periods",
            "2",
            "--workers",
            "1",
            "--out",
            str(out),
            "--no-progress",
        ]  # fmt: skip
    )
    err = capsys.readouterr().err
    assert code == 2 and "out of reach" in err and len(err.strip().splitlines()) == 1
    assert len(list((out / "runs").glob("run_*.json"))) == 2  # only the lower-bound design ran


def test_scenario_cost_table_is_read(tmp_path, capsys):
    scen = tmp_path / "w.toml"
    scen.write_text(
        '[mechanism]\nbuilder = "watt_six_bar"\nclearance_at = ["B"]\n\n[allocation.cost.B]\nb = 3.0\na = 1.5\n'
    )
    code = main_allocate(["--scenario", str(scen), "--joints", "B", "Q", "--budget", "1", "--out", str(tmp_path / "o")])
    assert code == 2 and "--joints" in capsys.readouterr().err  # the file was read past its [allocation] table
    scen.write_text(scen.read_text() + "\n[allocation.cost.Z]\nb = 1\n")
    code = main_allocate(["--scenario", str(scen), "--joints", "B", "--budget", "1", "--out", str(tmp_path / "o")])
    assert code == 2 and "allocation.cost.Z" in capsys.readouterr().err


def test_report_is_written(tmp_path):
    from clearance.analysis.design.allocation_report import budget_shares, write_allocation

    with ThreadPoolExecutor(2) as ex:
        a = allocate(FACTORY, problem(), settings(), store=tmp_path / "runs", executor=ex, progress=False)
    paths = write_allocation(a, tmp_path, title="closed form", unit="µm", scale=1e6, command="clearance allocate ...")
    assert {p.name for p in paths} >= {"allocation.md", "front.png", "allocation.csv", "allocation.json"}
    md = (tmp_path / "allocation.md").read_text()
    assert "Saving against the equal-clearance design" in md and "| A |" in md
    d = json.loads((tmp_path / "allocation.json").read_text())
    assert d["saving"] == pytest.approx(a.saving)
    shares = budget_shares(a)
    # closed form mean D = 1.05 (3 c_A + c_C) (the start factor 1 + 0.3 (u - 0.5) averages 1.05, as E[u] = 2/3
    # for a radius uniform in the disc): A's part 1.05 * 3 (c_A - lo) / B, up to the surrogate's fit error (< 5 %)
    c = a.allocated.clearances
    assert shares[0] == pytest.approx(1.05 * 3 * (c[0] - 2e-5) / 4e-4, rel=0.05)


def speed_deviation(mechanism, start, settings):
    """Closed form at a drive speed w: D = (w / 100 rad/s) * sum_j w_j c_j (no start scatter)."""
    c = {j.name: j.require_clearance().radial_clearance for j in mechanism.clearance_joints}
    d = mechanism.drives[0].speed / 100.0 * sum(WEIGHTS[j] * c[j] for j in c)
    return {"mean_deviation": d, "rms_deviation": d, "peak_deviation": d, "peak_force": 1.0}


def test_several_speeds_each_meet_their_budget(tmp_path):
    """Budgets at 100 and 200 rad/s; the faster one binds (its deviation is twice as large)."""
    make = JointClearances(KeywordFactory(watt_six_bar, {"clearance_at": ("A", "C")}, rename={"speed": "crank_speed"}))
    ops = ({"speed": 100.0}, {"speed": 200.0})
    prob = problem(operating_points=ops, budgets=(6e-4, 6e-4))
    ens = EnsembleSettings(runs=4, evaluate=speed_deviation)
    with ThreadPoolExecutor(2) as ex:
        a = allocate(make, prob, settings(verification=ens), store=tmp_path, executor=ex, progress=False)
    d = a.allocated
    assert d is not None and d.meets and len(d.mean) == 2
    c = np.array(d.clearances)
    assert d.mean[1] == pytest.approx(2 * d.mean[0], rel=1e-12)  # the closed form, to rounding
    # the binding speed sits at its budget up to the surrogate's fit error (< 3 % on a 2-joint linear form)
    assert 0.97 * 6e-4 <= d.mean[1] <= 6e-4
    assert d.mean[1] == pytest.approx(2 * float(np.array([3.0, 1.0]) @ c), rel=1e-12)


def test_factories_set_each_joint_and_the_speed():
    from clearance.analysis.design.factories import FixedMechanism
    from clearance.model import Clearance

    base = FixedMechanism(watt_six_bar(clearance_at=("A",), radial_clearance=2e-4))
    make = JointClearances(base, template=Clearance(radial_clearance=1e-4, friction=0.1))
    m = make({"clearances": {"A": 5e-5, "D": 7e-5}, "speed": 50.0})
    assert m.drives[0].speed == 50.0
    a, d = m.joint("A").require_clearance(), m.joint("D").require_clearance()
    assert a.radial_clearance == 5e-5 and a.friction == 0.0  # A keeps its own record, new clearance
    assert d.radial_clearance == 7e-5 and d.friction == 0.1  # D was ideal: the template's record
    with pytest.raises(KeyError, match="Q"):
        make({"clearances": {"Q": 1e-4}})
    with pytest.raises(ValueError, match="only 'speed'"):
        base({"crank_speed": 1.0})
