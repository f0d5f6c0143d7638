"""Rerun recordings: read back from the .rrd file, compared with the simulation arrays."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

import clearance
import clearance.builders
from clearance.analysis.recording import rerun_log
from clearance.results import JointResult, SimulationResult

# Points2D / LineStrips2D store float32: a float64 value x comes back as float32(x), whose
# relative rounding error is at most 2**-24 (half an ulp of a 24-bit significand). The tests
# compare with the very float64 x the recording converted (the same product), and |f32(x) - x|
# and 2**-24 |x| are exact in float64, so the bound holds by IEEE rounding on every machine
# (measured up to 0.997 of it).
F32_RTOL = 2.0**-24


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Short MuJoCo runs: one and two clearance joints, and the ideal twin (2 ms each)."""
    one = clearance.builders.slider_crank()
    two = clearance.builders.slider_crank(clearance_at=("crank_rod", "rod_slider"))
    # 2 us divides the recordings' 50 us display rate, so MuJoCo's display times fall on the
    # reference's 1 us output grid (the comparison below needs common times)
    opts = clearance.ModelOptions(timestep=2e-6)
    return {
        "one": (one, clearance.simulate(one, duration=2e-3, options=opts)),
        "two": (two, clearance.simulate(two, duration=2e-3, options=opts)),
        "ideal": (one.ideal_twin(), clearance.simulate(one.ideal_twin(), duration=2e-3, options=opts)),
    }


def _read(path: Path) -> tuple[dict[tuple[str, bool], dict[str, np.ndarray]], list]:
    """Recording store of ``path``: (entity, static) -> column -> values (rows sorted by time),
    and the list of blueprint chunks."""
    reader = rr.chunk.RrdReader(str(path))
    cols: dict[tuple[str, bool], dict[str, list]] = {}
    for chunk in reader.stream():
        rb = chunk.to_record_batch()
        d = cols.setdefault((chunk.entity_path, chunk.is_static), {})
        for name in rb.schema.names:
            if name == "rerun.controls.RowId":
                continue
            col = rb.column(name)
            if name in (rerun_log.TIME_TIMELINE, rerun_log.REV_TIMELINE):
                vals = col.cast("int64").to_numpy()
            else:
                vals = col.to_pylist()
            d.setdefault(name, []).extend(list(vals))
    out: dict[tuple[str, bool], dict[str, np.ndarray]] = {}
    for key, d in cols.items():
        if rerun_log.TIME_TIMELINE in d:
            order = np.argsort(np.asarray(d[rerun_log.TIME_TIMELINE]), kind="stable")
            d = {k: [v[i] for i in order] for k, v in d.items()}
        out[key] = {
            k: np.asarray(v, dtype=object) if k.endswith(("labels", "strips")) else np.asarray(v) for k, v in d.items()
        }
    blueprints = [c for b in reader.blueprints() for c in reader.stream(store=b)]
    return out, blueprints


def _view_names(blueprints: list) -> set[str]:
    names = set()
    for c in blueprints:
        rb = c.to_record_batch()
        if "ViewBlueprint:display_name" in rb.schema.names:
            names.update(v[0] for v in rb.column("ViewBlueprint:display_name").to_pylist())
    return names


def _squeeze(a: np.ndarray) -> np.ndarray:
    """Rows of one-element lists -> the elements."""
    return np.asarray([row[0] for row in a])


def test_single_joint_recording_matches_the_run(runs, tmp_path):
    mech, res = runs["one"]
    _, ideal = runs["ideal"]
    poincare = {"rod_slider": res.joints["rod_slider"].eccentricity[::500]}
    path = rerun_log.record(res, mech, tmp_path / "run.rrd", ideal=ideal, poincare=poincare)
    assert path == tmp_path / "run.rrd" and path.stat().st_size > 0
    assert [p.name for p in tmp_path.iterdir()] == ["run.rrd"]  # atomic: no temporary left
    data, blueprints = _read(path)
    jr = res.joints["rod_slider"]

    orbit = data[("/joints/rod_slider/orbit", False)]
    ns = np.round(res.times * 1e9).astype(np.int64)
    assert np.array_equal(orbit[rerun_log.TIME_TIMELINE], ns)  # exact: nanosecond integers
    rev = np.round(res.drive_angle[:, 0] / (2 * math.pi) * 1e6).astype(np.int64)
    assert np.array_equal(orbit[rerun_log.REV_TIMELINE], rev)
    pos = np.asarray([row[0] for row in orbit["Points2D:positions"]], float)
    np.testing.assert_allclose(pos, jr.eccentricity * 1e6, rtol=F32_RTOL, atol=0)

    # Scalars are float64 in rerun: the series come back bit for bit.
    force = data[("/joints/rod_slider/force/magnitude", False)]
    assert np.array_equal(force[rerun_log.TIME_TIMELINE], ns)
    assert np.array_equal(_squeeze(force["Scalars:scalars"]), jr.force_magnitude)
    assert np.array_equal(
        _squeeze(data[("/joints/rod_slider/force/x", False)]["Scalars:scalars"]), jr.contact_force[:, 0]
    )
    assert np.array_equal(
        _squeeze(data[("/joints/rod_slider/force/y", False)]["Scalars:scalars"]), jr.contact_force[:, 1]
    )
    assert np.array_equal(
        _squeeze(data[("/joints/rod_slider/penetration", False)]["Scalars:scalars"]), jr.penetration * 1e6
    )

    contact = data[("/joints/rod_slider/contact", False)]
    on = jr.penetration > 0
    assert 0 < on.sum() < len(res) and len(contact[rerun_log.TIME_TIMELINE]) == on.sum()
    assert np.array_equal(contact[rerun_log.TIME_TIMELINE], ns[on])

    for kind, suffix in (("displacement", ""), ("velocity", "_vel"), ("acceleration", "_acc")):
        got = _squeeze(data[(f"/outputs/slider_x/{kind}/clearance", False)]["Scalars:scalars"])
        assert np.array_equal(got, res.outputs["slider_x" + suffix])
        got = _squeeze(data[(f"/outputs/slider_x/{kind}/ideal", False)]["Scalars:scalars"])
        assert np.array_equal(got, ideal.outputs["slider_x" + suffix])
    assert np.array_equal(_squeeze(data[("/drives/crank/speed", False)]["Scalars:scalars"]), res.drive_speed[:, 0])

    circle = np.asarray(data[("/joints/rod_slider/clearance_circle", True)]["LineStrips2D:strips"][0][0], float)
    c_um = mech.joint("rod_slider").clearance.radial_clearance * 1e6
    np.testing.assert_allclose(np.hypot(circle[:, 0], circle[:, 1]), c_um, rtol=4 * F32_RTOL)  # cos/sin then float32
    pp = np.asarray(data[("/joints/rod_slider/poincare", True)]["Points2D:positions"][0], float)
    np.testing.assert_allclose(pp, poincare["rod_slider"] * 1e6, rtol=F32_RTOL, atol=0)

    # the mechanism: decimated to the display rate, joints where the links say
    links = data[("/mechanism/links", False)]
    n_disp = len(links[rerun_log.TIME_TIMELINE])
    assert n_disp <= 2e-3 * rerun_log.DEFAULT_MAX_RATE_HZ + 2 and n_disp < len(res)
    joints = data[("/mechanism/joints", False)]
    jp = np.asarray([np.asarray(r, float) for r in joints["Points2D:positions"]])  # (rows, 4 joints, 2) [mm]
    # crank_pivot on ground: the origin; crank pin 50 mm from it (float32 of mm values,
    # plus the ~1e-9 m closure error of the MuJoCo connect constraints -> 1e-5 mm).
    np.testing.assert_allclose(jp[:, 0], 0.0, atol=1e-5)
    np.testing.assert_allclose(np.hypot(jp[:, 1, 0], jp[:, 1, 1]), 50.0, atol=1e-5)
    assert len(data[("/mechanism/links", True)]["LineStrips2D:labels"][0]) == 3

    expected = {
        "/joints/rod_slider/orbit",
        "/joints/rod_slider/contact",
        "/joints/rod_slider/clearance_circle",
        "/joints/rod_slider/poincare",
        "/joints/rod_slider/force/magnitude",
        "/mechanism/links",
        "/mechanism/joints",
        "/mechanism/ground",
        "/drives/crank/speed",
        "/drives/crank/torque",
    }
    assert expected <= {e for e, _ in data}
    assert blueprints, "the file carries a default blueprint"
    assert {
        "mechanism [mm]",
        "orbit rod_slider [µm, bearing frame]",
        "contact force [N]",
        "slider_x displacement",
        "slider_x velocity",
        "slider_x acceleration",
        "drive speed [rad/s]",
    } <= _view_names(blueprints)


def test_two_clearance_joints(runs, tmp_path):
    mech, res = runs["two"]
    path = rerun_log.record(res, mech, tmp_path / "two.rrd", max_rate_hz=None)
    data, blueprints = _read(path)
    for j in ("crank_rod", "rod_slider"):
        pos = np.asarray([row[0] for row in data[(f"/joints/{j}/orbit", False)]["Points2D:positions"]], float)
        np.testing.assert_allclose(pos, res.joints[j].eccentricity * 1e6, rtol=F32_RTOL, atol=0)
        force = _squeeze(data[(f"/joints/{j}/force/magnitude", False)]["Scalars:scalars"])
        assert np.array_equal(force, res.joints[j].force_magnitude)
    assert len(data[("/mechanism/links", False)][rerun_log.TIME_TIMELINE]) == len(res)  # max_rate_hz=None: every row
    assert {"orbit crank_rod [µm, bearing frame]", "orbit rod_slider [µm, bearing frame]"} <= _view_names(blueprints)


def _reference_like(res: SimulationResult, mech) -> SimulationResult:
    """A reference-solver-shaped result: every 10th row, link-frame poses, solver "reference"."""
    r = res.decimated(10)
    poses = r.link_poses.copy()  # link-frame poses, as both solvers store them
    joints = {
        k: JointResult(v.eccentricity, v.eccentricity_rate, v.penetration, v.contact_force) for k, v in r.joints.items()
    }
    meta = {
        "solver": "reference",
        "mechanism": mech.name,
        "clearance_joints": list(joints),
        "links": [lk.name for lk in mech.moving_links],
    }
    return SimulationResult(
        r.times, dict(r.outputs), joints, r.drive_angle, r.drive_speed, r.drive_torque, poses, r.closure_violation, meta
    )


def test_mujoco_and_reference_in_one_recording(runs, tmp_path):
    mech, res = runs["one"]
    ref = _reference_like(res, mech)
    path = rerun_log.record_runs(
        [rerun_log.LoggedRun(res, mech, prefix="mujoco/"), rerun_log.LoggedRun(ref, mech, prefix="reference")],
        tmp_path / "both.rrd",
        max_rate_hz=None,
    )
    data, blueprints = _read(path)
    for prefix, r in (("mujoco", res), ("reference", ref)):
        pos = np.asarray(
            [row[0] for row in data[(f"/{prefix}/joints/rod_slider/orbit", False)]["Points2D:positions"]], float
        )
        np.testing.assert_allclose(pos, r.joints["rod_slider"].eccentricity * 1e6, rtol=F32_RTOL, atol=0)
        force = _squeeze(data[(f"/{prefix}/joints/rod_slider/force/magnitude", False)]["Scalars:scalars"])
        assert np.array_equal(force, r.joints["rod_slider"].force_magnitude)
    # Both results draw the same joints: float32 of mm values (~1e-5 mm at 170 mm).
    jm = np.asarray([np.asarray(x, float) for x in data[("/mujoco/mechanism/joints", False)]["Points2D:positions"]])
    jf = np.asarray([np.asarray(x, float) for x in data[("/reference/mechanism/joints", False)]["Points2D:positions"]])
    np.testing.assert_allclose(jf, jm[::10], atol=1e-4)
    names = _view_names(blueprints)
    assert "orbit rod_slider [µm, bearing frame]" in names
    queries = [
        q
        for c in blueprints
        for rb in [c.to_record_batch()]
        if "ViewContents:query" in rb.schema.names
        for q in rb.column("ViewContents:query").to_pylist()[0]
    ]
    assert "+ /mujoco/joints/rod_slider/force/magnitude" in queries
    assert "+ /reference/joints/rod_slider/force/magnitude" in queries


def test_stream_into_a_given_recording(runs, tmp_path):
    mech, res = runs["one"]
    rec = rr.RecordingStream("clearance-test")
    rec.save(tmp_path / "live.rrd")
    assert rerun_log.stream(res, mech, recording=rec, prefix="live") is rec
    rec.flush()
    rec.disconnect()
    data, blueprints = _read(tmp_path / "live.rrd")
    force = _squeeze(data[("/live/joints/rod_slider/force/magnitude", False)]["Scalars:scalars"])
    assert np.array_equal(force, res.joints["rod_slider"].force_magnitude)
    assert "contact force [N]" in _view_names(blueprints)


def test_bad_arguments_fail_before_writing(runs, tmp_path):
    mech, res = runs["one"]
    two_mech, _ = runs["two"]
    with pytest.raises(ValueError, match="prefix"):
        rerun_log.record(res, mech, tmp_path / "x.rrd", prefix="a b")
    with pytest.raises(ValueError, match="poincare"):
        rerun_log.record(res, mech, tmp_path / "x.rrd", poincare={"crank_rod": np.zeros((3, 2))})
    with pytest.raises(ValueError, match=r"shape \(k, 2\)"):
        rerun_log.record(res, mech, tmp_path / "x.rrd", poincare={"rod_slider": np.zeros(3)})
    with pytest.raises(ValueError, match="max_rate_hz"):
        rerun_log.record(res, mech, tmp_path / "x.rrd", max_rate_hz=0.0)
    with pytest.raises(ValueError, match="distinct prefixes"):
        rerun_log.record_runs([rerun_log.LoggedRun(res, mech), rerun_log.LoggedRun(res, mech)], tmp_path / "x.rrd")
    with pytest.raises(ValueError, match="not clearance joints"):
        rerun_log.record(runs["two"][1], mech, tmp_path / "x.rrd")
    with pytest.raises(TypeError):
        rerun_log.record(res, two_mech, tmp_path / "x.rrd", max_rate=1.0)  # misspelt keyword
    assert list(tmp_path.iterdir()) == []


def test_cli_run_writes_a_recording(tmp_path):
    import os
    import stat

    from clearance.analysis.chaos.poincare import poincare_from_result
    from clearance.cli import main

    rrd = tmp_path / "run.rrd"
    assert (
        main(["run", "--duration-ms", "12.3", "--out", str(tmp_path / "out"), "--no-progress", "--rerun", str(rrd)])
        == 0
    )
    data, blueprints = _read(rrd)
    assert ("/joints/rod_slider/orbit", False) in data and ("/outputs/slider_x/displacement/ideal", False) in data
    assert blueprints
    # the report's Poincaré section: eccentricity at t = kT of the drive after the start-up
    # window (a 12.3 ms run of a 12 ms period has its one point at t = 12 ms, none at t = 0)
    res = SimulationResult.load(tmp_path / "out" / "result.npz")
    ts, expected = poincare_from_result(res, ["rod_slider.ex", "rod_slider.ey"])
    # the drive period from the mean speed: the servo's mean speed error (measured 8.7e-11 s), not rounding
    assert np.allclose(ts, [0.0, 0.012], rtol=0, atol=1e-9)
    pp = np.asarray(data[("/joints/rod_slider/poincare", True)]["Points2D:positions"][0], float)
    np.testing.assert_allclose(pp, expected[1:] * 1e6, rtol=F32_RTOL, atol=0)
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(rrd.stat().st_mode) == 0o666 & ~mask  # a normal output file, not private


def test_orbit_points_are_coloured_by_force(runs, tmp_path):
    mech, res = runs["one"]
    path = rerun_log.record(res, mech, tmp_path / "run.rrd")
    data, _ = _read(path)
    colors = _squeeze(data[("/joints/rod_slider/orbit", False)]["Points2D:colors"]).astype(np.uint32)
    f = res.joints["rod_slider"].force_magnitude
    assert np.array_equal(colors, rerun_log._force_colors(f, f.max()))  # packed RGBA: exact
    # independently of that function: grey without contact, viridis' top colour at the peak force
    assert np.all(colors[f == 0] == 0x9A9A9AFF) and 0 < np.sum(f > 0) < len(f)
    assert colors[np.argmax(f)] == 0xFDE725FF


def test_importing_the_simulation_does_not_load_rerun():
    """rerun is only imported for a recording: simulations and the reference solver do without it."""
    import subprocess
    import sys

    code = (
        "import sys; import clearance; from clearance import simulate; import clearance.reference; "
        "sys.exit('rerun' in sys.modules)"
    )
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_reference_solver_run_records_like_a_mujoco_run(runs, tmp_path):
    from clearance.reference import run_reference

    mech, res = runs["one"]
    ref = run_reference(mech, 4e-4)  # 0.4 ms: through the first impact (about 0.25 ms)
    assert ref.metadata["solver"] == "reference"
    assert ref.joints["rod_slider"].force_magnitude.max() > 1e3  # the recorded forces are not all zero
    path = rerun_log.record_runs(
        [rerun_log.LoggedRun(res, mech, prefix="mujoco"), rerun_log.LoggedRun(ref, mech, prefix="reference")],
        tmp_path / "cmp.rrd",
    )
    data, _ = _read(path)
    pos = np.asarray(
        [row[0] for row in data[("/reference/joints/rod_slider/orbit", False)]["Points2D:positions"]], float
    )
    np.testing.assert_allclose(pos, ref.joints["rod_slider"].eccentricity * 1e6, rtol=F32_RTOL, atol=0)
    force = _squeeze(data[("/reference/joints/rod_slider/force/magnitude", False)]["Scalars:scalars"])
    assert np.array_equal(force, ref.joints["rod_slider"].force_magnitude)
    # Before the first impact (~0.25 ms) both solvers move the ideal mechanism alike (they
    # differ by < 1e-9 m): joints drawn at the same display times agree to float32 of mm
    # values at up to 170 mm (half an ulp ~ 8e-6 mm on each side) -> 2e-5 mm.
    mj, rf = data[("/mujoco/mechanism/joints", False)], data[("/reference/mechanism/joints", False)]
    t_mj, t_rf = mj[rerun_log.TIME_TIMELINE], rf[rerun_log.TIME_TIMELINE]
    common = np.intersect1d(t_mj, t_rf)
    common = common[common < 200_000]  # sim_time in ns: display times before the first impact
    assert len(common) >= 4  # 0, 50, 100, 150 µs at the default display rate

    def pick(d: dict, t: np.ndarray) -> np.ndarray:
        return np.asarray([np.asarray(d["Points2D:positions"][i], float) for i in np.searchsorted(t, common)])

    np.testing.assert_allclose(pick(rf, t_rf), pick(mj, t_mj), atol=2e-5)
