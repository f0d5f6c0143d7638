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

from clearance.retrofit import Backlash, RadialPlay, RetrofitOptions, SineControl, add_backlash, retrofit
from clearance.retrofit.output import backlash_manifest_of, manifest_of
from clearance.run.backlash_readout import add_backlash_sensors
from clearance.run.play_candidates import end_effector
from clearance.run.retrofitted import Retrofitted, retrofitted
from clearance.run.zero_play import ZERO_BAND, ZERO_CLEARANCE, ZERO_RING_CLEARANCE, zero_play

DURATION = 0.1
"""The check's span [s]."""

ROWS = 1e-4
"""Rows the drift is read on [s]: a hundredth of the shortest motion here (the 1 Hz sinusoid's)."""


def _needs_plugin(kind: str) -> None:
    from clearance.contact_plugin import is_available

    if kind.endswith("exact") and not is_available():
        pytest.skip("the compiled contact plugin is not built")


def _radial(spec: mujoco.MjSpec, joints, mode: str) -> Retrofitted:
    c = ZERO_CLEARANCE if mode == "exact" else ZERO_RING_CLEARANCE
    options = RetrofitOptions(
        contact_mode=mode,
        segments=None if mode == "exact" else 64,
        sizing_duration=0.3,
        measure_speed=False,
        accept_inaccurate=True,  # this checks where the model moves, not the ring's accuracy
    )
    r = retrofit(spec, {j: RadialPlay.make(c) for j in joints}, options)
    return retrofitted(".", manifest_of(r), r.model, r.twin)


def _backlash(spec: mujoco.MjSpec, joints, stop: str) -> Retrofitted:
    edit = add_backlash(spec, {j: Backlash(ZERO_BAND, stop=stop) for j in joints})
    manifest = backlash_manifest_of(edit)
    work = edit.spec.copy()
    add_backlash_sensors(work, manifest.backlash)
    return retrofitted(".", manifest, work.compile(), edit.twin)


def _check(loaded: Retrofitted, site: str) -> None:
    z = zero_play(loaded, SineControl(), DURATION, site, output_interval=ROWS)
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
    play, mode = kind.split("-")
    loaded = _radial(spec, HINGES[name], mode) if play == "radial" else _backlash(spec, MOTORS[name], mode)
    _check(loaded, "tip")


@pytest.mark.parametrize("kind", ["radial-exact", "backlash-calibrated"])
def test_zero_play_reproduces_the_twin_on_the_reacher(kind):
    _needs_plugin(kind)
    spec = mujoco.MjSpec.from_file(str(gym_model("reacher")))
    play, mode = kind.split("-")
    loaded = (
        _radial(spec, ("joint0", "joint1"), mode) if play == "radial" else _backlash(spec, ("joint0", "joint1"), mode)
    )
    _check(loaded, end_effector(loaded.twin, ["joint0", "joint1"]))
