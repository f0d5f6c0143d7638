"""Data model validation: bad input fails before any simulation, naming field and value."""

from __future__ import annotations

import dataclasses

import pytest

from clearance.builders import slider_crank
from clearance.kinematics import AssemblyError, assemble
from clearance.model import Clearance, Drive, Link, Mechanism
from clearance.options import ModelOptions


@pytest.mark.parametrize("c", [0.0, -1e-4])
def test_clearance_must_be_positive(c):
    with pytest.raises(ValueError, match=r"radial_clearance must be > 0 .*got"):
        Clearance(radial_clearance=c)


def test_journal_larger_than_bearing():
    # a clearance as large as the bearing radius leaves no journal
    with pytest.raises(ValueError, match="radial_clearance must be > 0 and < bearing_radius"):
        Clearance(radial_clearance=0.012, bearing_radius=0.010)


def test_builder_rejects_bad_clearance_before_work():
    with pytest.raises(ValueError, match="radial_clearance"):
        slider_crank(radial_clearance=-0.5e-3)


@pytest.mark.parametrize("n", [0, 7, 4.5])
def test_segments_at_least_8(n):
    with pytest.raises(ValueError, match=r"segments must be an integer >= 8 \(got"):
        ModelOptions(segments=n)


def test_non_assemblable_lengths():
    with pytest.raises(ValueError, match="rod_length must be > crank_length"):
        slider_crank(crank_length=0.2, rod_length=0.1)


def test_unclosable_loop_is_reported_by_assembly():
    mech = slider_crank()
    # move the slider guide 0.3 m off the line: the 0.12 m rod cannot reach it
    ground = mech.link("ground")
    moved = dataclasses.replace(ground, points={"crank_pivot": (0.0, 0.0), "guide": (0.0, 0.3)})
    bad = dataclasses.replace(mech, links=(moved,) + mech.links[1:])
    with pytest.raises(AssemblyError, match="cannot be assembled"):
        assemble(bad)


def test_unknown_option_is_a_type_error():
    # a misspelt option must never be silently ignored
    with pytest.raises(TypeError):
        slider_crank(radial_clearence=1e-3)
    with pytest.raises(TypeError):
        ModelOptions(segment=36)


def test_unknown_clearance_joint():
    with pytest.raises(ValueError, match=r"clearance_at: unknown joint"):
        slider_crank(clearance_at=("crank_pivot",))


def test_drive_needs_one_per_dof():
    mech = slider_crank()
    with pytest.raises(ValueError, match="degree"):
        dataclasses.replace(mech, drives=())


def test_drive_on_clearance_joint_rejected():
    mech = slider_crank(clearance_at=("crank_rod",))
    with pytest.raises(ValueError, match="ideal revolute"):
        dataclasses.replace(mech, drives=(Drive("d", "crank_rod", speed=1.0),))


def test_link_validation_names_the_link():
    with pytest.raises(ValueError, match="link 'bar'"):
        Link("bar", -1.0, 1e-3)


def test_ideal_twin_removes_clearances_and_journal_side_resolved():
    mech = slider_crank(clearance_at=("crank_rod", "rod_slider"))
    # journal on the link farther from ground: rod (depth 2) at both joints
    assert mech.joint("rod_slider").clearance.journal_link == "rod"
    assert mech.joint("crank_rod").clearance.journal_link == "rod"
    twin = mech.ideal_twin()
    assert not twin.clearance_joints
    assert isinstance(twin, Mechanism)
