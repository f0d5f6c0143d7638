"""Zero play reproduces the twin (`clearance.run.zero_play`): with a 1 µm clearance (exact contact),
10 µm (a calibrated ring) or a 0.1' band at every play, the end effector over 0.1 s stays within
10 times the geometric play of the unmodified model's. One check that catches a locked joint, a
wrong reference angle, an open loop or a wrong frame, on models the retrofit was not built
around: the hand-written ones (tests/retrofit_models.py) and gymnasium's reacher.

This is the suite's fast subset; benchmarks/retrofit_invariants.md runs every model (the pusher
too) with radial play and backlash, calibrated and exact.
"""

from __future__ import annotations

import mujoco
import pytest
from gym_assets import gym_model
from retrofit_models import HINGES, MODELS, MOTORS

from clearance.options import ContactMode
from clearance.retrofit import SineControl
from clearance.run.play_candidates import end_effector
from clearance.run.retrofitted import Retrofitted
from clearance.run.zero_play import backlash_at_zero, radial_at_zero, zero_play

DURATION = 0.1
"""The check's span [s]."""

ROWS = 1e-4
"""Rows the drift is read on [s]: a hundredth of the shortest motion here (the 1 Hz sinusoid's)."""


def _needs_plugin(kind: str) -> None:
    from clearance.contact_plugin import is_available

    if kind.endswith("exact") and not is_available():
        pytest.skip("the compiled contact plugin is not built")


def _edit(spec: mujoco.MjSpec, kind: str, radial, backlash) -> Retrofitted:
    play, mode = kind.split("-")
    if play == "radial":
        return radial_at_zero(spec, radial, ContactMode(mode))
    return backlash_at_zero(spec, backlash, mode)


def _check(loaded: Retrofitted, site: str) -> None:
    z = zero_play(loaded, SineControl(), DURATION, site, output_interval=ROWS)
    # the bound: 10 x the geometric play, the sum of c or of b x the hinge-to-point distance (zero_play's docstring)
    assert z.deviation <= z.bound, (
        f"{site} drifted {z.deviation * 1e6:.3g} um from the twin (bound {z.bound * 1e6:.3g} um)"
    )


CASES = [
    *[(name, "radial-exact") for name in MODELS],
    *[(name, "backlash-exact") for name in MODELS],
    ("degree_arm", "backlash-calibrated"),
    ("four_bar", "backlash-calibrated"),
    ("far_bearing", "radial-calibrated"),
]


@pytest.mark.parametrize(("name", "kind"), CASES)
@pytest.mark.filterwarnings("ignore:compiler attribute 'settotalmass' is deprecated")  # the model's own choice
def test_zero_play_reproduces_the_twin_on_hand_written_models(name, kind):
    _needs_plugin(kind)
    spec = mujoco.MjSpec.from_string(MODELS[name])
    _check(_edit(spec, kind, HINGES[name], MOTORS[name]), "tip")


@pytest.mark.parametrize("kind", ["radial-exact", "backlash-calibrated"])
def test_zero_play_reproduces_the_twin_on_the_reacher(kind):
    _needs_plugin(kind)
    spec = mujoco.MjSpec.from_file(str(gym_model("reacher")))
    hinges = ("joint0", "joint1")
    loaded = _edit(spec, kind, hinges, hinges)
    _check(loaded, end_effector(loaded.twin, list(hinges)))


@pytest.mark.parametrize("kind", ["radial-exact", "backlash-exact"])
def test_zero_play_reproduces_the_twin_in_a_fluid(kind):
    """Gymnasium's swimmer moves in a fluid (density 4000, viscosity 0.1): MuJoCo drags every body with mass by
    the box its inertia implies, so a backlash motor body must be one the fluid barely sees (a motor of 1e-12 kg
    and 1e-12 kg m^2 was a 2.4 m box that moved the tail 1.5 mm from the twin, 5x the bound)."""
    _needs_plugin(kind)
    spec = mujoco.MjSpec.from_file(str(gym_model("swimmer")))
    hinges = ("motor1_rot", "motor2_rot")  # its actuated hinges (the third turns the planar base)
    loaded = _edit(spec, kind, hinges, hinges)
    assert loaded.twin.opt.density > 0 and loaded.twin.opt.viscosity > 0
    _check(loaded, end_effector(loaded.twin, list(hinges)))
