"""Generated MJCF: golden file, compiles and steps without warnings, contact stiffness mapping."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from clearance.builders import slider_crank
from clearance.mjcf import (
    RingGeometry,
    body_tree,
    choose_segments,
    force_ripple,
    ring_force,
)
from clearance.options import ContactParameters, GeomType, ModelOptions
from clearance.run.preparation import prepare

GOLDEN_DIR = Path(__file__).parent / "golden"
GOLDEN = GOLDEN_DIR / "slider_crank.xml"


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _same_mjcf(xml: str, golden: str) -> bool:
    """The same text, numbers allowed one unit apart in their sixth significant digit.

    MuJoCo writes 6 significant digits. Values through libm (the rings' cos and sin, the contact
    laws' pow) may differ in their last bit between machines and C libraries; that shows in the
    text only for a value within a few ulps of a rounding boundary of its sixth digit (a chance of
    ~1e-9 per number, none seen), and then as one unit of that digit, which this allows.
    """
    if xml == golden:
        return True
    if _NUMBER.split(xml) != _NUMBER.split(golden):
        return False
    for a, b in zip(map(float, _NUMBER.findall(xml)), map(float, _NUMBER.findall(golden)), strict=True):
        if a != b and abs(a - b) > 1.000001 * 10.0 ** (math.floor(math.log10(max(abs(a), abs(b)))) - 5):
            return False
    return True


def _check_golden(xml: str, path: Path) -> None:
    if os.environ.get("CLEARANCE_UPDATE_GOLDEN"):
        path.write_text(xml)
    assert path.exists(), f"no golden file {path.name}: generate it with CLEARANCE_UPDATE_GOLDEN=1"
    assert _same_mjcf(xml, path.read_text()), (
        f"{path.name} differs: regenerate with CLEARANCE_UPDATE_GOLDEN=1 after a deliberate change"
    )


def test_golden_mjcf_for_default_slider_crank(default_mechanism):
    # nominal contact: closed-form parameters, so the file is the same on every machine up to a
    # libm's last bit (see _same_mjcf; a calibrated run's fitted values carry the fit's last
    # digits; their test is elsewhere)
    xml = prepare(default_mechanism, ModelOptions(contact_mode="nominal")).to_xml()
    _check_golden(xml, GOLDEN)


def _catalogue_names() -> list[str]:
    from clearance.builders import CATALOGUE

    return sorted(CATALOGUE)


@pytest.mark.parametrize("name", _catalogue_names())
def test_golden_mjcf_per_builder(name):
    """Every catalogue builder at its defaults gives the same MJCF as its golden file.

    Nominal contact (closed-form parameters: the same on every machine, see _same_mjcf) and 36 segments per
    bearing keep the files small; the segment rule is covered by the default slider-crank's
    golden file above.
    """
    from clearance.builders import CATALOGUE

    xml = prepare(CATALOGUE[name].builder(), ModelOptions(contact_mode="nominal", segments=36)).to_xml()
    _check_golden(xml, GOLDEN_DIR / f"builder_{name}.xml")


def _step_without_warnings(xml: str, steps: int = 2000) -> mujoco.MjData:
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    fired = {
        mujoco.mjtWarning(i).name: data.warning[i].number
        for i in range(mujoco.mjtWarning.mjNWARNING.value)
        if data.warning[i].number
    }
    assert not fired, f"MuJoCo warnings: {fired}"
    return data


@pytest.mark.parametrize("at", [(), ("crank_rod",), ("rod_slider",), ("crank_rod", "rod_slider")])
@pytest.mark.parametrize("pair", [("sphere", "sphere"), ("capsule", "capsule"), ("sphere", "box")])
def test_models_compile_and_step_without_warnings(at, pair):
    mech = slider_crank(clearance_at=at, crank_speed=200 * 2 * np.pi / 60)
    opts = ModelOptions(segments=36, journal_geom=pair[0], segment_geom=pair[1], timestep=2e-6)
    xml = prepare(mech, opts).to_xml()
    _step_without_warnings(xml)


def _cli_geom_pairs() -> list[tuple[str, str]]:
    from clearance.cli.options import JOURNAL_GEOMS, SEGMENT_GEOMS

    return [(j, s) for j in JOURNAL_GEOMS for s in SEGMENT_GEOMS]


@pytest.mark.parametrize("pair", _cli_geom_pairs(), ids=lambda p: f"{p[0]}-{p[1]}")
def test_every_cli_geom_pair_touches_and_steps_without_warnings(pair):
    """Each journal/segment geom pair `clearance run` offers, with its journals started in contact.

    The default pair runs calibrated rows; the others the nominal rows of the same law (what this
    checks is each pair's geometry: that it touches and steps without warnings at ring stiffness;
    calibrating every pair's two joints cost most of this file's time; the calibration itself is
    tested in tests/test_calibration.py).
    """
    from clearance.run.initial_state import offset_journals

    mech = slider_crank(clearance_at=("crank_rod", "rod_slider"), crank_speed=200 * 2 * np.pi / 60)
    default = ModelOptions()
    mode = "calibrated" if pair == (default.journal_geom.value, default.segment_geom.value) else "nominal"
    xml = prepare(
        mech,
        ModelOptions(segments=36, journal_geom=pair[0], segment_geom=pair[1], timestep=2e-6, contact_mode=mode),
    ).to_xml()
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    c = 0.5e-3  # the builder's radial clearance
    # 2 um into each ring, so both are in contact from the first step: one journal towards a
    # segment centre, the other between two segments (36 segments: pitch 10 deg)
    targets = {
        "rod_slider": (c + 2e-6, 0.0),
        "crank_rod": ((c + 2e-6) * np.cos(np.pi / 36), (c + 2e-6) * np.sin(np.pi / 36)),
    }
    data.qpos[:] = offset_journals(
        model, model.key_qpos[0], targets, bearings={k: c for k in targets}, fixed_joints=["crank_pivot"]
    )
    touched = set()
    for _ in range(2000):
        mujoco.mj_step(model, data)
        touched |= {model.geom(data.contact.geom1[k]).name.split("__")[0] for k in range(data.ncon)}
        touched |= {model.geom(data.contact.geom2[k]).name.split("__")[0] for k in range(data.ncon)}
    fired = {
        mujoco.mjtWarning(i).name: data.warning[i].number
        for i in range(mujoco.mjtWarning.mjNWARNING.value)
        if data.warning[i].number
    }
    assert not fired, f"MuJoCo warnings: {fired}"
    assert {"crank_rod", "rod_slider"} <= touched  # both journals met their rings
    assert np.all(np.isfinite(data.qpos))


def test_body_tree_cuts_clearance_joints_first():
    one = body_tree(slider_crank(clearance_at=("rod_slider",)))
    assert [j.name for j in one.cuts] == ["rod_slider"]
    both = body_tree(slider_crank(clearance_at=("crank_rod", "rod_slider")))
    # one loop: one clearance joint is the cut, the other a slide/slide/hinge tree edge
    assert len(both.cuts) == 1 and both.cuts[0].clearance is not None
    ideal = body_tree(slider_crank(clearance_at=()))
    assert [j.name for j in ideal.ideal_cuts] == ["rod_slider"]


def test_physical_row_stiffness_mapping():
    """A journal resting on the ring under a known load sinks as the per-row stiffness says."""
    # re-measures docs/mujoco_notes.md: physical stiffness = S / A_hat with a small impedance
    mech = slider_crank(clearance_at=("rod_slider",), crank_speed=1e-3)
    k = 2.0e7
    prep = prepare(
        mech,
        ModelOptions(segments=72, timestep=1e-6, contact_mode="nominal"),
        contact={"rod_slider": ContactParameters(k, 0.0)},
    )
    model = prep.model
    pid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_PAIR, "rod_slider__pair000")
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    # push the journal 5 um into segment 0 (bearing +x) by shifting the slider in -x
    jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "slider_guide")
    data.qpos[model.jnt_qposadr[jid]] = -(0.5e-3 + 5e-6)
    data.qvel[:] = 0
    mujoco.mj_forward(model, data)
    f = ring_force(RingGeometry.make(0.01, 0.5e-3, 72), np.array([0.5e-3 + 5e-6, 0.0]), stiffness=k)
    total = sum(
        data.efc_force[i]
        for i in range(data.nefc)
        if data.efc_type[i] == mujoco.mjtConstraint.mjCNSTR_CONTACT_FRICTIONLESS
    )
    assert model.pair_solref[pid][0] < 0  # direct mode
    # rows act almost independently at impedance 1e-3 (coupling of order d = 0.1 %), the
    # approximate inverse weight is exact for this pair's bodies: 2 % covers both
    assert total == pytest.approx(np.hypot(*f), rel=0.02)


def test_impedance_rise_reaches_the_pairs_the_mjcf_and_the_row_force():
    """ContactParameters.impedance_rise becomes each pair's solimp, in the model and its MJCF,
    and each row's static force is (d(r)/d)^2 k r (the calibrated mode's ring)."""
    mech = slider_crank(clearance_at=("rod_slider",), crank_speed=1e-3)
    k, eps, c = 2.0e7, 0.4, 0.5e-3
    opts = ModelOptions(segments=72, timestep=1e-6, contact_mode="nominal")  # the ring, parameters given
    d = opts.impedance
    params = {"rod_slider": ContactParameters(k, 0.0, impedance_rise=eps)}
    prep = prepare(mech, opts, contact=params)
    model = prep.model
    pids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_PAIR, f"rod_slider__pair{i:03d}") for i in range(72)]
    shaped = [d * (1 - eps), d, c, 0.5, 1.0]
    np.testing.assert_array_equal(model.pair_solimp[pids], [shaped] * 72)  # the values written, exactly
    # the written MJCF carries it (MuJoCo writes 6 significant digits: 1e-6 relative)
    written = mujoco.MjModel.from_xml_string(prep.to_xml())
    np.testing.assert_allclose(written.pair_solimp[pids], [shaped] * 72, rtol=1e-6)
    # without it (the nominal mode, every caller before it existed) the pairs keep the
    # constant impedance they are built with
    plain = prepare(mech, opts, contact={"rod_slider": ContactParameters(k, 0.0)}).model
    np.testing.assert_array_equal(plain.pair_solimp[pids], [[d, d, 0.001, 0.5, 2.0]] * 72)
    # 50 um deep into segment 0 at rest: every touching row pushes with (d(r)/d)^2 k r,
    # d(r)/d = 1 - eps + eps r/c, r its own penetration
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "slider_guide")
    data.qpos[model.jnt_qposadr[jid]] = -(c + 50e-6)
    data.qvel[:] = 0
    mujoco.mj_forward(model, data)
    rows = [i for i in range(data.nefc) if data.efc_type[i] == mujoco.mjtConstraint.mjCNSTR_CONTACT_FRICTIONLESS]
    assert len(rows) >= 3
    r = -(data.efc_pos[rows] - data.efc_margin[rows])
    expected = (1 - eps + eps * np.minimum(r / c, 1.0)) ** 2 * k * r
    # measured -0.3 to -1.0 % over the 9 rows; 2 %: as the mapping test above (row coupling
    # of order d, Â exact for these bodies)
    np.testing.assert_allclose(data.efc_force[rows], expected, rtol=0.02)
    # and the closed-form ring (what the stability check uses) sums the same rows to the same
    # net force on the journal: measured -0.4 %, 2 % as above
    net = sum(data.efc_force[con.efc_address] * con.frame[:2] for con in data.contact)
    f = ring_force(RingGeometry.make(0.01, c, 72), np.array([c + 50e-6, 0.0]), stiffness=k, impedance_rise=eps)
    assert np.hypot(*net) == pytest.approx(np.hypot(*f), rel=0.02)


def test_ring_is_hertz_like_and_ripple_rule():
    g = RingGeometry.make(0.01, 0.5e-3, 160)
    d = np.array([2e-6, 2e-5])
    f = [np.hypot(*ring_force(g, np.array([0.5e-3 + x, 0.0]))) for x in d]
    # docs/mujoco_notes.md measured exponents 1.46-1.50 for a ring of linear rows
    assert 1.40 < np.log(f[1] / f[0]) / np.log(10) < 1.55
    n = choose_segments(0.01, 0.5e-3, 6e-6)
    assert force_ripple(RingGeometry.make(0.01, 0.5e-3, n), 6e-6) < 0.02
    assert GeomType("box") is GeomType.BOX


def test_default_ring_ripple_measured_in_mujoco(default_prepared):
    """The rule's N keeps the ripple under 2 % in MuJoCo itself, not only in the ring model."""
    from clearance.mjcf.probe import measured_ripple, ring_scene

    p, name = default_prepared, "rod_slider"
    ring, delta = p.built.rings[name], p.sizing[name].typical_penetration
    scene = ring_scene(ring, p.options, p.contact[name])
    # ModelOptions.ripple_limit (2 %) over the band the rule checks, delta/2 .. 2 delta
    # (benchmarks/segments_speed.md measured 1.5 %, 1.1 %, 0.7 % at N = 144)
    for f in (0.5, 1.0, 2.0):
        assert measured_ripple(scene, ring, f * delta) < p.options.ripple_limit


def test_segment_rule_falls_back_with_a_warning_at_light_load():
    # 0.1 um typical penetration (a slow mechanism): no N up to 512 keeps ripple under 2 %
    with pytest.warns(RuntimeWarning, match="using N = "):
        n = choose_segments(0.01, 0.5e-3, 1e-7)
    assert 8 <= n <= 288
