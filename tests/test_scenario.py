"""TOML scenarios: round trip of every builder, builder form with units, clear errors."""

from __future__ import annotations

import math
import os
import re
from importlib import resources

import pytest

from clearance.builders import (
    CATALOGUE,
    ScenarioError,
    dump_scenario,
    four_bar,
    load_scenario,
    slider_crank,
)
from clearance.builders.scenario import dumps_scenario, loads_scenario
from clearance.model import ContactLaw, Material, MotionLaw


@pytest.mark.parametrize("name", list(CATALOGUE))
def test_round_trip_every_builder(name, tmp_path):
    entry = CATALOGUE[name]
    for m in (entry.builder(), entry.builder(clearance_at=entry.info.clearable, law=ContactLaw.FLORES)):
        path = tmp_path / f"{name}.toml"
        dump_scenario(m, path)
        assert load_scenario(path) == m


def test_round_trip_press_with_servo_laws(tmp_path):
    from clearance.builders import seven_bar_press

    m = seven_bar_press(
        crank2_motion=MotionLaw(math.pi),
        crank7_motion=MotionLaw(math.pi, harmonics=((0.2, 0.1), (0.05, 0.0)), period=2.0),
    )
    dump_scenario(m, tmp_path / "p.toml")
    assert load_scenario(tmp_path / "p.toml") == m


def test_default_scenario_is_the_classic_slider_crank():
    path = resources.files("clearance.builders") / "scenarios" / "slider_crank.toml"
    assert load_scenario(path) == slider_crank()


def test_builder_form_converts_units():
    m = loads_scenario(
        '[mechanism]\nbuilder = "four_bar"\ncrank_length_mm = 35\ncrank_speed_rpm = 600\n'
        'start_angle_deg = 90\nclearance_mm = 0.25\nclearance_at = ["A", "B"]\nlaw = "hertz"\n'
        'material = { youngs_modulus_gpa = 200, poisson_ratio = 0.29 }\nname = "mine"\n'
    )
    ref = four_bar(
        crank_length=0.035,
        crank_speed=600 * 2 * math.pi / 60,
        start_angle=math.pi / 2,
        radial_clearance=0.25e-3,
        clearance_at=("A", "B"),
        law=ContactLaw.HERTZ,
        material=Material(200e9, 0.29),
        name="mine",
    )
    # unit factors applied once: equal to the last bit or within one rounding
    assert m.parameters["crank_length"] == pytest.approx(0.035, rel=1e-15)
    assert m.drives[0].speed == pytest.approx(ref.drives[0].speed, rel=1e-15)
    assert m.clearance_joints[0].clearance == ref.clearance_joints[0].clearance
    assert m.name == "mine"


def test_builder_form_with_motion_law_and_pairs():
    m = loads_scenario(
        '[mechanism]\nbuilder = "seven_bar_press"\ncrank7_pivot_mm = [360, 0]\n'
        "crank7_motion = { speed_rad_per_s = 3.14, harmonics_rad = [[0.2, 0.0]], period_s = 2.0 }\n"
    )
    assert m.parameters["crank7_pivot"] == pytest.approx([0.36, 0.0], rel=1e-15)  # mm -> m
    assert m.drives[1].motion == MotionLaw(3.14, ((0.2, 0.0),), 2.0)


BASE = dumps_scenario(four_bar())

MALFORMED = [
    (
        "unknown link",
        ('link_b = "rocker4"\npoint_b = "B"', 'link_b = "rocker9"\npoint_b = "B"'),
        r"line \d+: \[\[joints\]\] #3 'B': key 'link_b': unknown link 'rocker9'",
    ),
    (
        "missing joint",
        ('joint = "O2"', 'joint = "O9"'),
        r"line \d+: \[\[drives\]\] #1 'crank': key 'joint': unknown joint 'O9'",
    ),
    (
        "bad unit",
        ("mass_kg = 0.2041", "mass_lb = 0.2041"),
        r"line \d+: \[\[links\]\] #3 'coupler3': key 'mass_lb': bad unit 'lb'",
    ),
    (
        "no unit",
        ("mass_kg = 0.2041", "mass = 0.2041"),
        r"key 'mass': needs a unit in its name \(mass is a mass: use mass_kg",
    ),
    (
        "unclosable loop",
        ("O4 = [0.13, 0.0]", "O4 = [0.5, 0.0]"),
        r"line \d+: \[\[joints\]\] #3 'B': the loops cannot be closed at t = 0: .* the largest is at joint 'B'",
    ),
    (
        "unknown key",
        ('kind = "revolute"', 'kind = "revolute"\nclearence = 1'),
        r"key 'clearence': unknown key; expected one of",
    ),
    ("missing key", ('name = "A"\n', ""), r"line \d+: \[\[joints\]\] #2: missing key 'name'"),
    ("bad choice", ('kind = "revolute"', 'kind = "hinge"'), r"key 'kind': must be one of \['revolute', 'prismatic'\]"),
    ("missing point", ('point_b = "B"', 'point_b = "Q"'), r"key 'point_b': link 'rocker4' has no point 'Q'"),
    ("not TOML", ('name = "A"', 'name = "A'), r"not valid TOML: .*line \d+"),
    (
        "model rejects",
        ("radial_clearance_m = 0.0001", "radial_clearance_mm = 20"),
        r"\[clearance\]: radial_clearance must be > 0 and < bearing_radius",
    ),
]


@pytest.mark.parametrize("case,edit,pattern", MALFORMED, ids=[c[0] for c in MALFORMED])
def test_malformed_full_scenarios_name_the_key(case, edit, pattern):
    old, new = edit
    assert old in BASE
    with pytest.raises(ScenarioError, match=pattern) as err:
        loads_scenario(BASE.replace(old, new, 1), source="bad.toml")
    assert str(err.value).startswith("bad.toml")


def test_unclosable_loop_names_the_joint_entry_and_its_line():
    text = BASE.replace("O4 = [0.13, 0.0]", "O4 = [0.5, 0.0]", 1)  # ground 0.5 m: longer than the other three
    with pytest.raises(ScenarioError) as info:
        loads_scenario(text, source="bad.toml")
    err = info.value
    lines = text.splitlines()
    # the [[joints]] header of B: the joint whose two sides Newton leaves farthest apart
    header = next(i for i, ln in enumerate(lines) if ln == "[[joints]]" and lines[i + 1] == 'name = "B"') + 1
    assert err.key == "joints.2" and err.line == header
    # its gap is the residual quoted; the loop is 0.5 - (0.04 + 0.13 + 0.1) = 0.23 m short, and
    # Newton ends with about that gap at B (0.249 m measured): between 0.1 and 0.5 m
    gap = float(re.search(r"two sides stay ([0-9.e+-]+) m apart", str(err)).group(1))
    assert 0.1 < gap < 0.5


BUILDER_CASES = [
    ("crank_speed = 300", r"line 3: \[mechanism\]: key 'crank_speed': needs a unit in its name"),
    (
        "crank_speed_mm = 3",
        r"key 'crank_speed_mm': bad unit 'mm' \(crank_speed is an angular speed: use crank_speed_rad_per_s",
    ),
    (
        "crank_sped_rpm = 3",
        r"key 'crank_sped_rpm': 'four_bar' has no such argument; expected one of: crank_length_<m\|mm",
    ),
    (
        'clearance_at = ["O2"]',
        r"line 3: \[mechanism\]: key 'clearance_at': builder 'four_bar': clearance_at: unknown joint",
    ),
    ("ground_length_mm = 500", r"builder 'four_bar': coupler 3 / rocker 4 cannot be assembled"),
    ('law = "soft"', r"key 'law': must be one of \['hertz'"),
    ('restitution = "high"', r"builder 'four_bar': restitution must be a finite number"),
]


@pytest.mark.parametrize("line,pattern", BUILDER_CASES, ids=[c[0].split(" =")[0] for c in BUILDER_CASES])
def test_malformed_builder_scenarios_name_the_key(line, pattern):
    with pytest.raises(ScenarioError, match=pattern):
        loads_scenario(f'[mechanism]\nbuilder = "four_bar"\n{line}\n', source="s.toml")


def test_unknown_builder_and_mixed_forms():
    with pytest.raises(ScenarioError, match=r"unknown builder 'nine_bar' \(the catalogue has: slider_crank"):
        loads_scenario('[mechanism]\nbuilder = "nine_bar"\n')
    with pytest.raises(ScenarioError, match="cannot also define links"):
        loads_scenario('[mechanism]\nbuilder = "four_bar"\n[[links]]\nname = "x"\n')
    with pytest.raises(ScenarioError, match="missing table 'mechanism'"):
        loads_scenario('[[links]]\nname = "x"\n')


def test_dump_is_atomic(tmp_path):
    path = tmp_path / "m.toml"
    dump_scenario(four_bar(), path)
    before = path.read_text()
    bad = four_bar()
    object.__setattr__(bad, "parameters", {"x": None})  # None cannot be written to TOML
    with pytest.raises(ValueError, match="cannot be written as TOML"):
        dump_scenario(bad, path)
    assert path.read_text() == before
    assert os.listdir(tmp_path) == ["m.toml"]  # no temporary file left behind
