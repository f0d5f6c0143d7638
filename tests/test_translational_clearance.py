"""A slider with play in its guide: the data model, the builders, scenario files and the commands.

The physics (contact cases, the impact, the energy balance) is in test_reference_slider.py.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from cli_runner import run_cli

from clearance.builders import CATALOGUE, load_scenario, slider_crank
from clearance.builders.scenario import dumps_scenario, loads_scenario
from clearance.model import ContactLaw, Drive, DriveKind, Joint, JointType
from clearance.results import SimulationResult
from clearance.translational import SliderContact, TranslationalClearance, classify_contact

SCENARIO = Path(__file__).resolve().parents[1] / "builders" / "scenarios" / "slider_crank_translational_flores2010.toml"


@pytest.mark.parametrize(
    ("field", "value", "expected"),
    [
        ("clearance", 0.0, "clearance must be > 0"),
        ("slider_length", -0.1, "slider_length must be > 0"),
        ("slider_height", float("nan"), "slider_height must be a finite number"),
        ("stiffness", 0.0, "stiffness must be > 0"),
        ("restitution", 0.0, r"restitution must be in \(0, 1\]"),
        ("friction", -0.1, "friction must be >= 0"),
        ("law", "flores", "law must be a ContactLaw"),
        # a block whose diagonal is shorter than the guide's height could turn over
        ("slider_length", 0.01, "slider can turn over in its guide"),
    ],
)
def test_bad_translational_clearance_names_field_value_and_range(field: str, value: object, expected: str) -> None:
    good = {"clearance": 1e-3, "slider_length": 0.1, "slider_height": 0.05}
    with pytest.raises(ValueError, match=expected):
        TranslationalClearance(**{**good, field: value})  # type: ignore[arg-type]


def test_translational_clearance_only_on_prismatic_joints_and_initial_speed_only_on_torque_drives() -> None:
    tc = TranslationalClearance(1e-3, 0.1, 0.05)
    with pytest.raises(ValueError, match="only supported on prismatic joints"):
        Joint("j", JointType.REVOLUTE, "a", "p", "b", "q", translational_clearance=tc)
    with pytest.raises(ValueError, match="initial_speed is for torque drives"):
        Drive("d", "j", DriveKind.CONSTANT_SPEED, speed=1.0, initial_speed=2.0)


def test_largest_tilt_wedges_two_diagonal_corners() -> None:
    tc = TranslationalClearance(1e-3, 0.1, 0.05)
    th = tc.max_tilt
    # corner (+L/2, +H/2) turned by th touches y = H/2 + c while (-L/2, -H/2) touches -(H/2 + c)
    top = 0.05 * np.sin(th) + 0.025 * np.cos(th)
    assert top == pytest.approx(0.025 + 1e-3, rel=1e-12)  # closed form, rounding only


def test_contact_cases_from_corner_penetrations() -> None:
    on, off = 1e-6, -1e-6
    pen = np.array(
        [
            [off, off, off, off],  # free
            [off, off, on, off],  # one corner
            [on, on, off, off],  # upper side
            [off, off, on, on],  # lower side
            [off, on, on, off],  # diagonal
        ]
    )
    expected = [SliderContact.FREE, SliderContact.ONE_CORNER, SliderContact.ONE_SIDE, SliderContact.ONE_SIDE]
    expected.append(SliderContact.DIAGONAL)
    assert list(classify_contact(pen)) == [c.value for c in expected]


def test_every_slider_of_the_catalogue_takes_play_and_its_ideal_twin_drops_it() -> None:
    sliders = {name: e.info.sliders for name, e in CATALOGUE.items() if e.info.sliders}
    assert "slider_crank" in sliders and len(sliders) >= 5  # the catalogue's sliders
    for name, joints in sliders.items():
        for joint in joints:
            mech = CATALOGUE[name].builder(clearance_at=(joint,))
            tc = mech.joint(joint).require_translational()
            assert mech.joint(joint).kind is JointType.PRISMATIC and tc.clearance > 0
            assert mech.ideal_twin().translational_joints == ()
    with pytest.raises(ValueError, match="slider_guide"):  # the message names the sliders too
        slider_crank(clearance_at=("guide",))


def test_scenarios_read_and_write_a_slider_with_play_and_a_free_crank() -> None:
    mech = load_scenario(SCENARIO)
    tc = mech.joint("slider_guide").require_translational()
    # the examples' a = 50 mm, b = 25 mm are half-sizes: a 100 mm by 50 mm block, c = 1 mm
    assert (tc.slider_length, tc.slider_height, tc.clearance) == pytest.approx((0.1, 0.05, 1e-3), rel=1e-12)
    assert (tc.law, tc.restitution, tc.friction) == (ContactLaw.FLORES, 0.4, 0.01)
    (drive,) = mech.drives
    assert drive.kind is DriveKind.TORQUE and drive.torque == 0.0 and drive.initial_speed == 150.0
    assert mech.gravity == (0.0, -9.81)
    assert loads_scenario(dumps_scenario(mech)) == mech  # the full form gives the same mechanism back


def test_a_scenario_key_of_the_guide_table_that_does_not_exist_is_refused_with_its_line() -> None:
    text = dumps_scenario(load_scenario(SCENARIO)).replace("clearance_m = 0.001", "clearance_m = 0.001\ngap_m = 1.0")
    with pytest.raises(ValueError, match=r"line \d+.*gap_m"):
        loads_scenario(text, source="s.toml")


def test_the_ideal_start_turns_the_free_crank_at_its_initial_speed() -> None:
    from clearance.reference import ReferenceSystem

    q, qd = ReferenceSystem(load_scenario(SCENARIO)).initial_state()
    # crank 150 rad/s; at top dead centre the rod turns at -l1/l2 * 150 = -75 rad/s (the examples' start)
    assert qd[2] == pytest.approx(150.0, rel=1e-12) and qd[5] == pytest.approx(-75.0, rel=1e-9)


def test_clearance_reference_runs_the_benchmark_scenario_and_reports_the_slider(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    argv = ["reference", "--scenario", str(SCENARIO), "--duration-ms", "12", "--out", str(out), "--no-progress"]
    code, stdout, err = run_cli(argv, capsys)
    assert code == 0, err
    assert "slider_guide, whole run: free" in stdout
    report = (out / "report.md").read_text()
    assert "## Slider in its guide: slider_guide" in report and (out / "slider_slider_guide.png").exists()
    res = SimulationResult.load(out / "result")
    sr = res.sliders["slider_guide"]
    # the first impact, 2.7 ms after the start (siconos' examples: 2.8 ms), lands the level slider on
    # its two upper corners at once
    first = int(np.argmax(sr.contact_case != SliderContact.FREE.value))
    assert 2.5e-3 < res.times[first] < 2.9e-3  # +-0.2 ms: the examples' 1e-4 s step and our compliance
    assert sr.contact_case[first] == SliderContact.ONE_SIDE.value
    assert np.all(sr.corner_penetration[first, :2] > 0) and np.all(sr.corner_penetration[first, 2:] < 0)


def test_sliders_survive_save_load_slice_and_concatenation(tmp_path: Path) -> None:
    from clearance.reference import run_reference

    mech = dataclasses.replace(load_scenario(SCENARIO), name="flores2010")
    res = run_reference(mech, 4e-3, output_interval=1e-4)
    res.save(tmp_path / "r")
    back = SimulationResult.load(tmp_path / "r")
    joined = SimulationResult.concatenate([res.sliced(slice(0, 20)), res.sliced(slice(20, None))])
    sr = res.sliders["slider_guide"]
    for other in (back.sliders["slider_guide"], joined.sliders["slider_guide"]):
        for f in dataclasses.fields(sr):
            assert np.array_equal(getattr(other, f.name), getattr(sr, f.name))
