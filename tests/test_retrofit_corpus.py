"""The corpus's fast subset: `clearance.run.retrofit_check` on third-party models copied into the tests.

`benchmarks/retrofit_corpus.py` checks every hinge of fifteen robots over 0.1 s; here two models of
gymnasium-robotics 1.4.2 (tests/corpus/README.md: files unchanged, MIT), chosen for conventions the
hand-written fixtures of tests/retrofit_models.py do not have, over a few hinges and 20 ms: Fetch (a
mobile base on three slides, a mocap body held by a weld, excluded contact pairs, no actuators) and
the Shadow hand (finger joints coupled by fixed tendons held equal, explicit contact pairs, names with
colons). Each check tries every hinge named alone (listed refusals, ineligibility), retrofits the
accepted ones together and checks the invariants, zero play with the chaos check among them.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest

from clearance.retrofit.play import Refusal
from clearance.run.retrofit_check import Operation, check_operation

ASSETS = Path(__file__).parent / "corpus" / "gymnasium_robotics" / "envs" / "assets"
FETCH = ASSETS / "fetch" / "reach.xml"
HAND = ASSETS / "hand" / "reach.xml"

SPAN = 0.02
"""Zero play over 20 ms here (the benchmark's 0.1 s takes minutes on the hand)."""


@pytest.fixture(autouse=True)
def _plugin():
    from clearance.contact_plugin import is_available

    if not is_available():
        pytest.skip("the compiled contact plugin is not built")


def _passes(spec_path: Path, operation: Operation, hinges: list[str] | None):
    check = check_operation(mujoco.MjSpec.from_file(str(spec_path)), operation, duration=SPAN, hinges=hinges)
    assert not check.tracebacks, check.tracebacks
    assert check.broken is None, check.broken
    assert check.passed
    return check


def test_fetch_takes_radial_play_with_its_mobile_base_and_mocap_weld():
    arm = ["robot0:shoulder_pan_joint", "robot0:elbow_flex_joint", "robot0:wrist_roll_joint"]
    check = _passes(FETCH, Operation.RADIAL_EXACT, arm)
    assert check.accepted == arm and not check.refused
    z = check.zero_play
    # the bound: 10 x the geometric play (zero_play's), and the twin far from chaos at this scale
    assert z is not None and z.holds and not z.chaotic


def test_fetch_has_no_hinge_for_backlash_and_says_why():
    check = _passes(FETCH, Operation.BACKLASH_EXACT, None)  # every hinge of the model
    assert len(check.hinges) == 9 and not check.accepted and not check.refused
    assert set(check.ineligible.values()) == {Refusal.NO_ACTUATOR}  # a mocap-driven arm: no motor to separate


def test_the_hand_takes_play_at_a_tendon_coupled_finger_and_backlash_at_its_wrist():
    # FFJ1 is held equal to FFJ0 through a fixed tendon: its equality keeps its softness across the play
    radial = _passes(HAND, Operation.RADIAL_EXACT, ["robot0:WRJ1", "robot0:FFJ1"])
    assert radial.accepted == ["robot0:WRJ1", "robot0:FFJ1"] and radial.zero_play.holds
    backlash = _passes(HAND, Operation.BACKLASH_EXACT, ["robot0:WRJ1", "robot0:FFJ0"])
    assert backlash.accepted == ["robot0:WRJ1"]
    assert backlash.ineligible == {"robot0:FFJ0": Refusal.NO_ACTUATOR}  # moved by its tendon, not by a motor
    assert backlash.zero_play.holds
