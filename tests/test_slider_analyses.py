"""A slider with play in its guide through the analyses: sweeps, ranking, allocation, the report, rerun.

The catalogue slider-crank with play at ``slider_guide`` (a translational clearance joint) is a
candidate joint like a hinge with radial play: each analysis takes it and reads its numbers
from the slider's own series (`SimulationResult.sliders`).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict

import numpy as np
import pytest

import clearance
from clearance.analysis.chaos.poincare import SLIDER_PARTS, poincare_section, quantity_series
from clearance.analysis.design.factories import JointClearances, with_clearances
from clearance.analysis.metrics.response import ContactMode, contact_modes
from clearance.analysis.metrics.summary import contact_series, joint_summary, summarise
from clearance.analysis.sweeps.sweep import KeywordFactory
from clearance.builders import slider_crank
from clearance.cli.allocate import main_allocate
from clearance.cli.rank import main_rank
from clearance.cli.sweep import main_sweep
from clearance.model import Clearance

JOINT = "slider_guide"
COMMON = ["--workers", "1", "--no-progress", "--timestep-us", "5", "--periods", "3"]


@pytest.fixture(scope="module")
def run():
    """4 ms of the catalogue slider-crank with play in its guide (its first impacts come at 0.9 ms)."""
    mech = slider_crank(clearance_at=(JOINT,))
    return mech, clearance.simulate(mech, duration=4e-3)


def test_quantities_of_a_slider_are_its_own_series(run):
    _, res = run
    sr = res.sliders[JOINT]
    assert np.array_equal(quantity_series(res, f"{JOINT}.n"), sr.position[:, 1])
    assert np.array_equal(quantity_series(res, f"{JOINT}.vn"), sr.velocity[:, 1])
    assert np.array_equal(quantity_series(res, f"{JOINT}.tilt"), sr.tilt)
    force = quantity_series(res, f"{JOINT}.force")
    assert np.array_equal(force, np.hypot(sr.contact_force[:, 0], sr.contact_force[:, 1]))
    assert force.max() > 0  # the run has impacts: the force series is not all zeros
    with pytest.raises(KeyError, match=r"'<slider>\.<n\|vn\|tilt\|force>' with slider in \['slider_guide'\]"):
        quantity_series(res, f"{JOINT}.ex")
    assert SLIDER_PARTS == ("n", "vn", "tilt", "force")
    from clearance.analysis.figures.analysis_figures import quantity_label

    # a bifurcation diagram's axis: the slider across its guide in µm, not the default mm
    assert quantity_label(f"{JOINT}.n") == (f"{JOINT} across the guide", "µm", 1e6)
    assert quantity_label(f"{JOINT}.tilt")[1:] == ("µrad", 1e6)


def test_sweep_samples_the_slider_across_its_guide(tmp_path):
    out = tmp_path / "s"
    rc = main_sweep(
        ["--clearance-at", JOINT, "--points", "1", "--start", "0.1", "--rpm", "3000", "--sampled", "2"]
        + ["--out", str(out), *COMMON]
    )
    assert rc == 0 and (out / "bifurcation.png").exists()
    row = next(json.loads(p.read_text()) for p in (out / "points").glob("point_*.json"))
    assert row["status"] == "ok" and row["poincare"]["quantities"] == [f"{JOINT}.n"]  # the slider's default
    # the sweep's section is the slider's own across position, sampled once per revolution: the
    # same run simulated here gives the same points. Same model and options, but not bit for
    # bit: measured 2e-8 c apart (rounding grown by 3 revolutions of impacts); 1e-4 c is 5000
    # times that and still 500 times below the 5 % by which the two section points differ
    c = 1e-4
    mech = slider_crank(clearance_at=(JOINT,), radial_clearance=c, crank_speed=3000 * math.pi / 30)
    res = clearance.simulate(mech, duration=3 * mech.drive_period, options=clearance.ModelOptions(timestep=5e-6))
    _, points = poincare_section(res.times, quantity_series(res, f"{JOINT}.n"), mech.drive_period, last=2)
    np.testing.assert_allclose(np.ravel(row["poincare"]["points"]), np.ravel(points), rtol=0, atol=1e-4 * c)


def test_rank_takes_a_slider_as_a_candidate_joint(tmp_path, capsys):
    from clearance.analysis.sweeps.criticality import criticality_candidates

    # a candidate when asked for (clearance rank asks); the published rule is revolute joints alone
    assert criticality_candidates(slider_crank(), sliders=True) == ["crank_rod", "rod_slider", JOINT]
    assert criticality_candidates(slider_crank()) == ["crank_rod", "rod_slider"]
    out = tmp_path / "r"
    rc = main_rank(["--clearances-mm", "0.1", "--rpm", "1000", "--out", str(out), *COMMON])  # default joints
    assert rc == 0
    table = (out / "ranking.md").read_text()
    ranked = [line.split("|")[2].strip() for line in table.splitlines() if line.startswith(("| 1 |", "| 2 |", "| 3 |"))]
    # benchmarks/revolute_vs_translational.md: at 0.1 mm and 1000 rpm the pin's play costs the
    # slider's position 4.2 times the guide's (3 us and 1.5 us alike): the guide ranks last
    assert sorted(ranked) == ["crank_rod", "rod_slider", JOINT] and ranked[-1] == JOINT
    assert JOINT in capsys.readouterr().out
    # each point's row carries the played joint's contact summary, the slider's too
    rows = [json.loads(p.read_text()) for p in (out / "points").glob("point_*.json")]
    slider_row = next(r for r in rows if r["point"]["joint"] == JOINT)
    assert list(slider_row["summary"]) == [JOINT] and slider_row["summary"][JOINT]["impacts"] > 0


def test_allocation_gives_a_slider_its_own_play(tmp_path, capsys):
    base = KeywordFactory(slider_crank, {"clearance_at": ("rod_slider", JOINT)})
    m = JointClearances(base)({"clearances": {"rod_slider": 5e-5, JOINT: 7e-5}})
    assert m.joint(JOINT).translational_clearance.clearance == 7e-5
    assert m.joint("rod_slider").require_clearance().radial_clearance == 5e-5
    # a slider the base leaves without play is refused, naming it
    with pytest.raises(ValueError, match="'slider_guide' is a slider without play in its guide"):
        with_clearances(slider_crank(), {JOINT: 1e-4}, Clearance(radial_clearance=1e-4))
    out = tmp_path / "a"
    rc = main_allocate(
        ["--joints", "rod_slider", JOINT, "--budget", "50", "--runs", "2", "--design-size", "4", "--stop-after", "1"]
        + ["--out", str(out), *COMMON]
    )
    err = capsys.readouterr().err
    assert rc == 3, err  # stopped after its first simulated run: the slider's design ran
    assert "--joints" not in err


def test_summary_and_contact_modes_read_a_slider(run):
    _, res = run
    sr = res.sliders[JOINT]
    penetration, force = contact_series(res, JOINT)
    assert np.array_equal(penetration, sr.corner_penetration.max(axis=1))
    (row,) = summarise(res)
    np.testing.assert_equal(asdict(row), asdict(joint_summary(res, JOINT)))  # NaN where no ideal run
    assert row.impacts > 0 and row.max_penetration == penetration.max()
    modes = contact_modes(res, JOINT)
    # every sample is in one of the three modes; in contact exactly where a corner is
    assert sum(modes.fractions.values()) == pytest.approx(1.0, abs=1e-12)  # a sum of n ratios k_i / n
    in_contact = 1 - modes.fractions[ContactMode.FREE_FLIGHT]
    assert in_contact == pytest.approx(np.mean(penetration > 0), abs=1e-12)  # the same count over n
    with pytest.raises(KeyError, match="no clearance joint or slider with play 'nosuch'"):
        contact_series(res, "nosuch")


def test_report_lists_the_slider_in_its_contact_table(run, tmp_path):
    from clearance.analysis.figures.report import write_report

    mech, res = run
    ideal = clearance.simulate(mech.ideal_twin(), duration=4e-3)
    write_report(tmp_path, res, ideal)
    text = (tmp_path / "report.md").read_text()
    section = text[text.index("## Contact at the clearance joints") :]
    assert f"| statistic | {JOINT}," in section  # the slider's column
    assert "deepest corner" in section and "contact_force.png" not in section  # no journal, no journal figure
    assert (tmp_path / "contact_modes.png").exists()


def test_rerun_draws_the_slider_in_its_guide_with_its_contact_case(run, tmp_path):
    from test_rerun import F32_RTOL, _read, _squeeze, _view_names

    from clearance.analysis.recording import rerun_log
    from clearance.analysis.recording.slider_rerun import SLIDER_CASE_COLORS
    from clearance.translational import CORNERS, SliderContact

    mech, res = run
    sr, play = res.sliders[JOINT], mech.joint(JOINT).translational_clearance
    data, blueprints = _read(rerun_log.record(res, mech, tmp_path / "s.rrd", max_rate_hz=None))
    base = f"/sliders/{JOINT}"
    # the guide's two lines at +-(H/2 + c) [mm]
    guide = [np.asarray(s, float) for s in data[(f"{base}/guide", True)]["LineStrips2D:strips"][0]]
    y = (play.slider_height / 2 + play.clearance) * 1e3
    np.testing.assert_allclose([g[:, 1] for g in guide], [[y, y], [-y, -y]], rtol=F32_RTOL)
    # the block: every row (no display decimation here), its corners where the slider's
    # across position and tilt put them; float32 of mm values (F32_RTOL of the largest, 20 mm)
    block = data[(f"{base}/block", False)]
    strips = np.asarray([np.asarray(r[0], float) for r in block["LineStrips2D:strips"]])  # (n, 5, 2) [mm]
    assert strips.shape == (len(res), 5, 2)
    th = sr.tilt[:, None]
    local = np.array(CORNERS)[[0, 1, 3, 2, 0]] * (play.slider_length, play.slider_height)
    want_n = sr.position[:, 1:2] + np.sin(th) * local[:, 0] + np.cos(th) * local[:, 1]
    np.testing.assert_allclose(strips[:, :, 1], want_n * 1e3, rtol=0, atol=F32_RTOL * 20.0)
    # and the drawn corners reach into the guide lines by the contact's own penetrations (the
    # readout's, from the plugin: independent of the drawing; same float32 bound)
    drawn = strips[:, [0, 1, 3, 2], 1] * 1e-3  # corners 0-3 [m]
    reach = np.where(np.array(CORNERS)[:, 1] > 0, drawn, -drawn) - y * 1e-3
    np.testing.assert_allclose(reach, sr.corner_penetration, rtol=0, atol=F32_RTOL * 20e-3)
    # coloured and labelled by its contact case, row by row
    cases = [list(SliderContact)[k] for k in sr.contact_case]
    assert len(set(cases)) > 1  # the run has free flight and contact
    assert np.array_equal(_squeeze(block["LineStrips2D:colors"]), [SLIDER_CASE_COLORS[k] for k in cases])
    assert [r[0] for r in block["LineStrips2D:labels"]] == [k.name.lower().replace("_", " ") for k in cases]
    # the corners in contact, and the series at full rate (float64 scalars: bit for bit)
    touching = sr.corner_penetration > 0
    assert len(data[(f"{base}/contact", False)][rerun_log.TIME_TIMELINE]) == touching.any(axis=1).sum()
    assert np.array_equal(_squeeze(data[(f"{base}/across", False)]["Scalars:scalars"]), sr.position[:, 1] * 1e6)
    assert np.array_equal(_squeeze(data[(f"{base}/contact_case", False)]["Scalars:scalars"]), sr.contact_case)
    assert {f"{JOINT} in its guide [mm, guide frame]", "contact force [N]"} <= _view_names(blueprints)


def test_run_digest_keeps_the_slider(run):
    from clearance.analysis.sweeps.run_store import digest_result

    _, res = run
    d = digest_result("s", res, 2e-3).joints[JOINT]
    _, force = contact_series(res, JOINT)
    assert d["steady_peak_force"] == force[res.times >= 2e-3].max() > 0  # the same samples, the same max
    assert d["impacts"] == joint_summary(res, JOINT).impacts


def test_ensemble_measures_count_the_slider_s_force():
    from clearance.analysis.design.ensemble import EnsembleSettings, draw_start_states, simulated_measures

    mech = slider_crank(clearance_at=(JOINT,), radial_clearance=1e-4)
    assert draw_start_states(mech, 2, 0.01, 0) == [{}, {}]  # a slider starts centred in its guide
    m = simulated_measures(mech, {}, EnsembleSettings(runs=1, periods=2))
    res = clearance.simulate(mech, duration=2 * mech.drive_period)
    _, force = contact_series(res, JOINT)
    steady = force[res.times >= res.times[0] + mech.drive_period]
    # the same model and duration: the same run up to rounding grown over two revolutions of
    # impacts (2e-8 c in the sweep test above); 1e-6 relative is far above that, far below a change
    assert m["peak_force_by_joint"] == {JOINT: pytest.approx(steady.max(), rel=1e-6)}
    assert m["peak_force"] == m["peak_force_by_joint"][JOINT] > 0
