"""The mechanism catalogue: registry, topology of each builder, clearance selection, docs."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from clearance.builders import CATALOGUE, build, names
from clearance.builders.catalogue import get
from clearance.kinematics import solve_kinematics
from clearance.model import DriveKind, JointType

NAMES = list(CATALOGUE)
DOCS = Path(__file__).resolve().parents[1] / "docs" / "catalogue"
# links / joints / drives of each mechanism (issue: eight- and ten-bar 1 DOF, the press 2 DOF)
SIZES = {
    "slider_crank": (4, 4, 1),
    "four_bar": (4, 4, 1),
    "eight_bar": (8, 10, 1),
    "ten_bar": (10, 13, 1),
    "seven_bar_press": (7, 8, 2),
}


@pytest.fixture(scope="module")
def built():
    return {n: CATALOGUE[n].builder() for n in NAMES}


def test_registry_lists_the_issue_mechanisms():
    assert names() == tuple(CATALOGUE)
    assert set(names()) == {
        "slider_crank",
        "four_bar",
        "watt_six_bar",
        "watt_six_bar_slider_1",
        "watt_six_bar_slider_2",
        "stephenson_i",
        "stephenson_i_slider",
        "stephenson_ii_1",
        "stephenson_ii_2",
        "eight_bar",
        "ten_bar",
        "seven_bar_press",
    }
    with pytest.raises(KeyError, match="unknown mechanism 'nine_bar'.*catalogue has"):
        get("nine_bar")
    assert build("four_bar", crank_length=0.03).parameters["crank_length"] == 0.03


@pytest.mark.parametrize("name", NAMES)
def test_entry_is_consistent_with_its_mechanism(name, built):
    entry, m = CATALOGUE[name], built[name]
    assert m.name == name
    links, joints, drives = SIZES.get(name, (6, 7, 1))
    assert (len(m.links), len(m.joints), len(m.drives)) == (links, joints, drives)
    assert m.degrees_of_freedom == drives
    info = entry.info
    revolute = {j.name for j in m.joints if j.kind is JointType.REVOLUTE}
    driven = {d.joint for d in m.drives}
    assert set(info.driven) == driven
    assert set(info.clearable) == revolute - driven
    assert set(info.criticality) == set(info.clearable) - {info.output_pivot}
    out_link = m.outputs[0].link
    pivot = m.joint(info.output_pivot)
    assert out_link in (pivot.link_a, pivot.link_b) and m.ground in (pivot.link_a, pivot.link_b)
    for spec in info.transmission:
        assert spec.joint in revolute
    json.dumps(dict(m.parameters))  # parameters are JSON-serialisable metadata
    assert info.provenance


def _adjacent_ternaries(m) -> list[tuple[str, str]]:
    degree = {lk.name: 0 for lk in m.links}
    for j in m.joints:
        degree[j.link_a] += 1
        degree[j.link_b] += 1
    ternary = {n for n, k in degree.items() if k == 3}
    return [(j.link_a, j.link_b) for j in m.joints if j.link_a in ternary and j.link_b in ternary]


@pytest.mark.parametrize("name", ["watt_six_bar", "watt_six_bar_slider_1", "watt_six_bar_slider_2"])
def test_watt_chains_join_their_ternary_links(name, built):
    # Watt's chain: the two ternary links share a joint; Watt II: one of them is the ground
    pairs = _adjacent_ternaries(built[name])
    assert len(pairs) == 1 and built[name].ground in pairs[0]


@pytest.mark.parametrize("name", ["stephenson_i", "stephenson_i_slider", "stephenson_ii_1", "stephenson_ii_2"])
def test_stephenson_chains_separate_their_ternary_links(name, built):
    m = built[name]
    assert _adjacent_ternaries(m) == []
    ground_degree = sum(m.ground in (j.link_a, j.link_b) for j in m.joints)
    # type I fixes a binary link, type II a ternary link
    assert ground_degree == (2 if name.startswith("stephenson_i_") or name == "stephenson_i" else 3)


@pytest.mark.parametrize("name", NAMES)
def test_clearance_at_each_clearable_joint(name):
    entry = CATALOGUE[name]
    for j in entry.info.clearable:
        m = entry.builder(clearance_at=(j,))
        assert [c.name for c in m.clearance_joints] == [j]
    for j in entry.info.driven:
        with pytest.raises(ValueError, match="clearance_at: unknown joint"):
            entry.builder(clearance_at=(j,))
    with pytest.raises(ValueError, match="clearance_at: unknown joint"):
        entry.builder(clearance_at=("nowhere",))
    m = entry.builder(clearance_at=entry.info.clearable, radial_clearance=0.2e-3, friction=0.1)
    assert all(c.clearance.radial_clearance == 0.2e-3 and c.clearance.friction == 0.1 for c in m.clearance_joints)
    assert m.ideal_twin().clearance_joints == ()


@pytest.mark.parametrize("name", [n for n in NAMES if n != "seven_bar_press"])
def test_start_angle_stays_on_the_branch(name):
    builder = CATALOGUE[name].builder
    m0 = builder(clearance_at=())
    w = m0.drives[0].speed
    kin = solve_kinematics(m0, np.linspace(0.0, 2.0 / w, 9))
    m2 = builder(clearance_at=(), start_angle=2.0)
    q2 = np.array([v for lk in m2.moving_links for v in lk.pose_guess])
    # a builder started at 2 rad is the same linkage 2 rad later (Newton tolerances)
    assert np.max(np.abs(q2 - kin.q[-1])) < 1e-9


def test_press_drives_are_configurable():
    from clearance.builders import seven_bar_press
    from clearance.model import MotionLaw

    m = seven_bar_press(crank2_speed=2 * math.pi)
    # the project's choice: the servo's default period equals crank 2's
    assert m.drives[1].period == pytest.approx(m.drives[0].period, rel=1e-15)
    law = MotionLaw(math.pi, harmonics=((0.2, 0.0),))
    m = seven_bar_press(crank7_motion=law, crank2_motion=MotionLaw(math.pi))
    assert [d.kind for d in m.drives] == [DriveKind.MOTION_LAW, DriveKind.MOTION_LAW]
    assert [j.name for j in m.clearance_joints] == ["A", "C"]
    assert m.gravity == (0.0, -9.81)


def test_builders_do_not_import_mujoco():
    code = "import sys, clearance.builders; sys.exit('mujoco' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_docs_describe_every_mechanism():
    text = (DOCS / "catalogue.md").read_text()
    for name in NAMES:
        assert f"### {name}" in text
        assert (DOCS / f"{name}.png").stat().st_size > 10_000


def test_linkage_plot_labels_every_joint_and_link(built):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from clearance.analysis.figures.linkage_plot import plot_linkage

    m = built["ten_bar"]
    ax = plot_linkage(m, trace=False)
    texts = {t.get_text() for t in ax.texts}
    for j in m.joints:
        assert j.name in texts or f"{j.name} (c)" in texts
    for lk in m.moving_links:
        assert lk.name in texts
    assert ax.get_aspect() == 1.0
    plt.close(ax.figure)
