"""Ranking a robot's hinges by what their play costs the end effector: ``clearance rank --model``.

gymnasium's reacher, both hinges, radial play (polymer bushing, exact contact) and backlash
(5'), one grid cell (amplitude 0.5, 10 Hz), 0.4 s per run scored after 0.1 s: 4 runs.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from cli_runner import run_cli as _cli
from gym_assets import gym_model

from clearance.analysis.sweeps.robot_ranking import check_grid, per_period_deviation, rank_plays, robot_ranking_markdown
from clearance.cli import main
from clearance.model import Clearance, Material
from clearance.retrofit import Backlash, RadialPlay
from clearance.run.play_candidates import PlayAtHinge, actuated_hinges, end_effector

TINY = ["--amplitudes", "0.5", "--frequencies-hz", "10", "--duration-ms", "400", "--startup-ms", "100"]
POLYMER = ["--youngs-modulus-gpa", "3"]


@pytest.fixture(scope="module")
def ranked(tmp_path_factory):
    """The tiny ranking of the reacher, run once by the command."""
    out = tmp_path_factory.mktemp("rank") / "reacher"
    argv = ["rank", "--model", str(gym_model("reacher")), *TINY, *POLYMER, "--workers", "2", "--no-progress"]
    code = main([*argv, "--out", str(out)])
    return out, argv, code


def _rows(out):
    return [json.loads(p.read_text()) for p in sorted((out / "points").glob("point_*.json"))]


def test_the_reacher_is_ranked_with_both_plays_at_both_hinges(ranked):
    out, _, code = ranked
    assert code == 0
    rows = _rows(out)
    assert sorted((r["point"]["joint"], r["point"]["play"]) for r in rows) == sorted(
        (j, p) for j in ("joint0", "joint1") for p in ("radial", "backlash")
    )
    assert all(r["status"] == "ok" for r in rows)
    # 0.3 s after the start-up window at 10 Hz: 3 whole periods, whatever step each retrofit chose
    assert all(len(r["per_period_mean_deviation"]) == 3 for r in rows)
    text = (out / "ranking.md").read_text()
    for heading in ("All candidates", "Radial play (c = 0.1 mm)", "Backlash play (b = 5 arcmin)", "Per cell"):
        assert heading in text
    assert (out / "ranking.png").stat().st_size > 0


def test_a_score_is_the_end_effectors_mean_distance_from_the_twin(ranked):
    """One point run again in this process gives the row's per-period means: the score is what it says."""
    out, _, _ = ranked
    row = next(r for r in _rows(out) if r["point"]["joint"] == "joint1" and r["point"]["play"] == "radial")
    material = Material(3e9, 0.3)
    runner = PlayAtHinge(
        str(gym_model("reacher")),
        "fingertip",
        0.4,
        RadialPlay(Clearance(1e-4, 0.01, bearing_material=material, journal_material=material)),
        Backlash.from_arcmin(5),
    )
    result, twin = runner(row["point"])
    values = per_period_deviation(result, twin, "fingertip", 10.0, 0.1)
    # the same deterministic runs in another process: equal up to the JSON's round trip of floats
    np.testing.assert_allclose(values, row["per_period_mean_deviation"], rtol=1e-12)
    distance = np.hypot(
        result.outputs["site/fingertip/x"] - twin.outputs["site/fingertip/x"],
        result.outputs["site/fingertip/y"] - twin.outputs["site/fingertip/y"],
    )
    first = (result.times >= 0.1) & (result.times < 0.1 + 1 / 10 - 1e-9)
    # the first period's mean from the two runs' positions directly: rounding of the sum only
    assert values[0] == pytest.approx(distance[first].mean(), rel=1e-9)


def test_the_ranking_is_rank_joints_over_the_rows(ranked):
    out, _, _ = ranked
    ranking = rank_plays(_rows(out), site="fingertip", startup=0.1)
    for kind, size in (("radial", 1e-4), ("backlash", math.radians(5 / 60))):
        r = ranking.by_kind[kind]
        assert [s.joint for s in r.scores] == sorted(
            ("joint0", "joint1"), key=lambda j: -next(c.mean_deviation for c in r.cells if c.joint == j)
        )
        for s in r.scores:  # one cell: the score is its mean deviation over the play, rounding only
            cell = next(c for c in r.cells if c.joint == s.joint)
            assert s.score == pytest.approx(cell.mean_deviation / size, rel=1e-12)
            assert s.ci_low <= s.score <= s.ci_high
    assert len(ranking.overall.scores) == 4
    # the markdown says where the order is not a ranking: every pair whose P(above next) is under 95 %
    text = robot_ranking_markdown(ranking)
    for r in (ranking.overall, *ranking.by_kind.values()):
        apart = [s.confidence_above_next >= 0.95 for s in r.scores if np.isfinite(s.confidence_above_next)]
        assert (f"**Not a ranking:** {apart.count(False)} of {len(apart)} candidates" in text) == (not all(apart))
    assert text.count("**Not a ranking:**") == sum(
        any(s.confidence_above_next < 0.95 for s in r.scores) for r in (ranking.overall, *ranking.by_kind.values())
    )


def test_rerunning_the_command_resumes_without_running_again(ranked, capsys):
    out, argv, _ = ranked
    before = {p.name: p.read_text() for p in (out / "points").glob("point_*.json")}
    table = (out / "ranking.md").read_text()
    code, _, err = _cli([*argv, "--out", str(out)], capsys)
    assert code == 0, err
    assert {p.name: p.read_text() for p in (out / "points").glob("point_*.json")} == before  # no point ran again
    assert (out / "ranking.md").read_text() == table
    code, _, err = _cli([*argv, "--backlash-arcmin", "6", "--out", str(out)], capsys)
    assert code == 2 and "holds a different ranking" in err


def test_defaults_pick_the_actuated_hinges_and_the_deepest_body():
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(gym_model("pusher")))
    hinges = actuated_hinges(model)
    assert len(hinges) == 7 and hinges[0] == "r_shoulder_pan_joint"
    assert end_effector(model, hinges) == "tips_arm"


IDLE = """<mujoco><worldbody><body name="a"><joint name="shoulder" axis="0 0 1"/>
<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/>
<body name="b" pos="0.2 0 0"><joint name="free_pin" axis="0 0 1"/>
<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/></body></body></worldbody>
<actuator><motor joint="shoulder"/></actuator></mujoco>"""
"""A two-link arm whose elbow ``free_pin`` has no actuator."""


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--joints", "free_pin"], "--joints: joint 'free_pin' of"),
        (["--joints", "nosuch"], "is not a joint"),
        (["--joints", "shoulder", "shoulder"], "names 'shoulder' twice"),
        (["--site", "nowhere"], "--site 'nowhere' is neither a site nor a body"),
        (["--frequencies-hz", "1"], "hold 0 whole period(s) of 1 s; the score needs at least 2"),
        (["--startup-ms", "2000"], "shorter than the run"),
        (["--amplitudes", "1.5"], "--amplitudes must be at most 1"),
        (["--frequencies-hz", "0"], "--frequencies-hz must be > 0"),
        (["--backlash-arcmin", "700"], "--backlash-arcmin must be at most 600"),
    ],
)
def test_bad_input_is_refused_before_any_work(tmp_path, capsys, monkeypatch, extra, expected):
    """One error line naming the option, exit 2, and no folder: nothing ran."""
    import clearance.analysis.sweeps.robot_ranking as rr

    monkeypatch.setattr(rr, "run_robot_ranking", lambda *a, **k: pytest.fail("the ranking ran"))
    model = tmp_path / "arm.xml"
    model.write_text(IDLE)
    out = tmp_path / "out"
    code, _, err = _cli(["rank", "--model", str(model), "--out", str(out), "--duration-ms", "1000", *extra], capsys)
    assert code == 2, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 or "usage:" in lines[0], err
    assert expected in err
    assert not out.exists()


def test_unactuated_hinge_is_refused_only_for_backlash(capsys, tmp_path):
    model = tmp_path / "arm.xml"
    model.write_text(IDLE)
    argv = [
        "rank",
        "--model",
        str(model),
        "--joints",
        "free_pin",
        "--duration-ms",
        "1000",
        "--out",
        str(tmp_path / "o"),
    ]
    code, _, err = _cli(argv, capsys)
    assert code == 2 and "no actuator on it" in err and "rank it with radial play alone" in err


def test_grid_check_counts_whole_periods_after_the_start_up_window():
    check_grid([0.5], [2.0], 1.25, 0.25)  # exactly 2 periods of 0.5 s: accepted
    with pytest.raises(ValueError, match="hold 1 whole period"):
        check_grid([0.5], [2.0], 1.2, 0.25)


def test_dask_runs_the_ranking_as_the_process_pool_does(ranked, tmp_path):
    """The same points through a Dask scheduler give the same rows (deterministic runs)."""
    from clearance.analysis.sweeps.robot_ranking import play_points, run_robot_ranking

    distributed = pytest.importorskip("dask.distributed")
    out, _, _ = ranked
    runner = PlayAtHinge(
        str(gym_model("reacher")),
        "fingertip",
        0.4,
        RadialPlay(Clearance(1e-4, 0.01, bearing_material=Material(3e9, 0.3), journal_material=Material(3e9, 0.3))),
        Backlash.from_arcmin(5),
    )
    points = play_points(["joint0", "joint1"], {"backlash": math.radians(5 / 60)}, [0.5], [10.0])
    with distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        ranking = run_robot_ranking(
            runner,
            points,
            site="fingertip",
            startup=0.1,
            out_dir=tmp_path,
            scheduler_address=cluster.scheduler_address,
            progress=False,
        )
    pool = {r["point"]["joint"]: r for r in _rows(out) if r["point"]["play"] == "backlash"}
    for row in _rows(tmp_path):
        assert row["per_period_mean_deviation"] == pool[row["point"]["joint"]]["per_period_mean_deviation"]
    assert [s.joint for s in ranking.by_kind["backlash"].scores] == [
        s.joint for s in rank_plays(_rows(out), site="fingertip", startup=0.1).by_kind["backlash"].scores
    ]


def _run(times, x):
    from clearance.results import SimulationResult

    n = len(times)
    return SimulationResult(
        times=times,
        outputs={"site/tip/x": x, "site/tip/y": np.sin(times), "site/tip/z": np.zeros(n)},
        joints={},
        drive_angle=np.zeros((n, 0)),
        drive_speed=np.zeros((n, 0)),
        drive_torque=np.zeros((n, 0)),
        link_poses=np.zeros((n, 0, 3)),
        closure_violation=np.zeros(n),
        metadata={"timestep": 1e-3},
    )


def _half_broken(point):
    """Runs of joint1 fail; joint0's end effector sits ``size`` x 10 off the twin's in x throughout."""
    if point["joint"] == "joint1":
        raise RuntimeError("this hinge cannot be retrofitted")
    t = np.arange(400) * 1e-3
    return _run(t, np.cos(t) + 10 * point["size"]), _run(t, np.cos(t))


def test_a_failed_run_is_a_row_and_the_ranking_uses_the_others(tmp_path):
    from concurrent.futures import ThreadPoolExecutor

    from clearance.analysis.sweeps.robot_ranking import play_points, run_robot_ranking

    points = play_points(["joint0", "joint1"], {"radial": 1e-4}, [0.5], [10.0])
    with ThreadPoolExecutor(2) as pool:
        ranking = run_robot_ranking(
            _half_broken, points, site="tip", startup=0.1, out_dir=tmp_path, executor=pool, progress=False
        )
    assert [p["joint"] for p, _ in ranking.failed] == ["joint1"]
    assert "this hinge cannot be retrofitted" in ranking.failed[0][1]
    (score,) = ranking.by_kind["radial"].scores
    # a constant 1 mm offset: every period's mean distance is 1 mm, the score 10 (mm per 0.1 mm), rounding only
    assert score.joint == "joint0" and score.score == pytest.approx(10.0, rel=1e-9)
    assert score.se < 1e-9 * score.score  # no scatter between periods but the rounding of (cos t + c') - cos t
