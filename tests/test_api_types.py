"""The public Python API refuses an argument of the wrong type at its boundary: a TypeError naming it.

A file name where a model is wanted, a dict where an options record is, a string where a
number is: each is refused before any work with a `TypeError` (also a `ValueError`, so code
that catches either keeps working) whose message names the argument and the type expected,
never an AttributeError or a NumPy message from deep inside.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import mujoco
import pytest

from clearance import ModelOptions, simulate
from clearance.builders import four_bar, rpm, slider_crank
from clearance.retrofit import Backlash, RadialPlay, add_backlash, retrofit
from clearance.run.preparation import prepare

ARM = (
    '<mujoco><worldbody><body name="arm"><joint name="elbow" axis="0 0 1"/>'
    '<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/></body></worldbody>'
    '<actuator><motor joint="elbow"/></actuator></mujoco>'
)


def _arm() -> mujoco.MjSpec:
    return mujoco.MjSpec.from_string(ARM)


CASES = [
    ("simulate-a-name", lambda: simulate("slider_crank", duration=1e-3), "mechanism must be a Mechanism"),
    ("simulate-options-dict", lambda: simulate(slider_crank(), options={"timestep": 1e-6}), "options must be a"),
    ("simulate-duration-text", lambda: simulate(slider_crank(), duration="0.001"), "duration must be a finite"),
    ("prepare-a-name", lambda: prepare("slider_crank"), "mechanism must be a Mechanism"),
    ("prepare-options-dict", lambda: prepare(slider_crank(), {"timestep": 1e-6}), "options must be a ModelOptions"),
    ("options-timestep-text", lambda: ModelOptions(timestep="1e-6"), "timestep must be a finite number"),
    ("options-segments-float", lambda: ModelOptions(segments=36.5), "segments must be an integer"),
    ("options-contact-mode-number", lambda: ModelOptions(contact_mode=3), "contact_mode must be a ContactMode"),
    ("options-geom-none", lambda: ModelOptions(journal_geom=None), "journal_geom must be a GeomType"),
    ("rpm-text", lambda: rpm("3000"), "rpm must be a finite number"),
    ("builder-clearance-text", lambda: slider_crank(radial_clearance="0.1"), "radial_clearance must be a finite"),
    ("builder-length-text", lambda: four_bar(crank_length="0.04"), "crank_length must be a finite number"),
    ("retrofit-a-path", lambda: retrofit("arm.xml", {"elbow": RadialPlay()}), "spec must be a mujoco.MjSpec"),
    ("retrofit-joints-list", lambda: retrofit(_arm(), ["elbow"]), "joints must be a mapping"),
    ("retrofit-play-number", lambda: retrofit(_arm(), {"elbow": 1e-4}), "must be a RadialPlay"),
    ("backlash-a-path", lambda: add_backlash("arm.xml", {"elbow": Backlash(1e-3)}), "spec must be a mujoco.MjSpec"),
    ("backlash-joints-list", lambda: add_backlash(_arm(), ["elbow"]), "joints must be a mapping"),
    ("backlash-a-number", lambda: add_backlash(_arm(), {"elbow": 1e-3}), "must be a Backlash"),
]


@pytest.mark.parametrize("call,words", [pytest.param(c, w, id=i) for i, c, w in CASES])
def test_a_wrong_type_is_a_type_error_naming_the_argument(call, words):
    with pytest.raises(TypeError) as info:
        call()
    assert words in str(info.value)
    assert isinstance(info.value, ValueError)  # code that caught ValueError before still does


def test_every_run_failing_says_the_runs_own_error_once():
    """A batch where no run finished raises the first run's error, not statistics of nothing."""
    from clearance.analysis.design.ensemble import EnsembleSettings, EveryRunFailed, require_some_run, run_ensemble
    from clearance.analysis.design.factories import FixedMechanism

    def failing(mechanism, start, settings):
        raise RuntimeError("time step 0.001 s is too large")

    settings = EnsembleSettings(runs=3, seed=0, evaluate=failing)
    with ThreadPoolExecutor(1) as ex:
        e = run_ensemble(FixedMechanism(slider_crank()), {}, settings, executor=ex, progress=False)
    with pytest.raises(EveryRunFailed, match=r"every one of the 3 runs failed; the first: .*time step 0\.001 s"):
        require_some_run([e])
