"""Play randomised per world (`clearance.retrofit.randomised_play`, `clearance.run.world_batch`).

A two-link arm with backlash at both hinges (MuJoCo's default stop, the recipe: no fit, so the
test is fast) is copied into worlds whose bands and stops are drawn; the worlds must hold what
was drawn, step together as they would alone, and behave differently (a wider band lets the
load lag further). Ranges that would make a stop unstable at the step are refused before any
draw; a world that blows up is named.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from clearance.retrofit import Backlash, RetrofitError, add_backlash
from clearance.retrofit.motion import control_signal
from clearance.retrofit.play import SineControl
from clearance.retrofit.randomised_play import (
    STABLE_BOUND,
    PlayDistribution,
    PlayKind,
    Uniform,
    randomise_play,
    stop_bound,
    stop_spring,
)
from clearance.run.world_batch import WorldFailure, initial_states, step_worlds

ARM = """<mujoco model="arm"><option timestep="0.002" gravity="0 0 -9.81"/>
<worldbody><body name="upper"><joint name="shoulder" type="hinge" axis="0 1 0" armature="0.01"/>
<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/>
<body name="fore" pos="0.3 0 0"><joint name="elbow" type="hinge" axis="0 1 0" armature="0.005"/>
<geom type="capsule" fromto="0 0 0 0.25 0 0" size="0.025" mass="0.5"/></body></body></worldbody>
<actuator><motor joint="shoulder" ctrlrange="-2 2"/><motor joint="elbow" ctrlrange="-1 1"/></actuator></mujoco>"""

ARCMIN = math.radians(1 / 60)
N_WORLDS = 6


@pytest.fixture(scope="module")
def arm():
    spec = mujoco.MjSpec.from_string(ARM)
    return add_backlash(spec, {h: Backlash(5 * ARCMIN, stop="recipe") for h in ("shoulder", "elbow")}).model


def _band(model: mujoco.MjModel, hinge: str) -> np.ndarray:
    return model.tendon_range[model.tendon(f"clr_{hinge}__backlash").id]


def test_worlds_hold_what_was_drawn_and_differ(arm):
    sizes, stiff, damp = Uniform(1 * ARCMIN, 20 * ARCMIN), Uniform(10.0, 100.0, log=True), Uniform(0.1, 1.0)
    worlds = randomise_play(
        arm, n_worlds=N_WORLDS, backlash=PlayDistribution(size=sizes, stiffness=stiff, damping=damp), seed=3
    )
    assert [t.hinge for t in worlds.tendons] == ["shoulder", "elbow"]
    assert all(t.kind is PlayKind.BACKLASH for t in worlds.tendons)
    for values, u in ((worlds.size, sizes), (worlds.stiffness, stiff), (worlds.damping, damp)):
        assert values.shape == (N_WORLDS, 2)
        assert ((values >= u.low) & (values <= u.high)).all()
        assert len(np.unique(values)) == values.size  # every world and band drew its own
    for k, model in enumerate(worlds.models):
        for i, t in enumerate(worlds.tendons):
            # written as drawn: the copy's arrays hold the values themselves (no arithmetic on the band)
            assert tuple(model.tendon_range[t.tendon]) == (-worlds.size[k, i], worlds.size[k, i])
            k_b = stop_spring(model, t.tendon)
            # K and B read back through -solref/Â: one multiplication and one division, rel 1e-12 (measured 2e-16)
            assert k_b == pytest.approx((worlds.stiffness[k, i], worlds.damping[k, i]), rel=1e-12)
    # the model itself is untouched; the same seed draws the same worlds
    assert tuple(_band(arm, "elbow")) == (-5 * ARCMIN, 5 * ARCMIN)
    again = randomise_play(
        arm, n_worlds=N_WORLDS, backlash=PlayDistribution(size=sizes, stiffness=stiff, damping=damp), seed=3
    )
    np.testing.assert_array_equal(again.size, worlds.size)


def test_a_stop_left_alone_keeps_its_force(arm):
    """Worlds that randomise only the band keep the recipe's stop; written back as (K, B) it is the same stop."""
    worlds = randomise_play(arm, n_worlds=2, backlash=PlayDistribution(size=Uniform(2 * ARCMIN, 3 * ARCMIN)))
    np.testing.assert_array_equal(worlds.models[1].tendon_solref_lim, arm.tendon_solref_lim)
    rewritten = randomise_play(
        arm,
        n_worlds=1,
        backlash={
            "elbow": PlayDistribution(
                stiffness=Uniform(*[stop_spring(arm, arm.tendon("clr_elbow__backlash").id)[0]] * 2),
                damping=Uniform(*[stop_spring(arm, arm.tendon("clr_elbow__backlash").id)[1]] * 2),
            )
        },
    ).models[0]
    kbip = []
    for model in (arm, rewritten):
        data = mujoco.MjData(model)
        data.qpos[model.joint("elbow").qposadr[0]] = 6 * ARCMIN  # 1' past the band's end
        mujoco.mj_forward(model, data)
        rows = [i for i in range(data.nefc) if data.efc_id[i] == model.tendon("clr_elbow__backlash").id]
        kbip.append(data.efc_KBIP[rows[0], :2])
    # MuJoCo's K, B from the time-constant form and from the direct form: rounding of a few operations (measured 3e-16)
    np.testing.assert_allclose(kbip[1], kbip[0], rtol=1e-12)


def _firm_stops(model: mujoco.MjModel, size: Uniform) -> dict[str, PlayDistribution]:
    """Each band drawn from ``size`` with a firm stop: h omega = 0.5 and damping ratio 0.5 at the reference pose."""
    out = {}
    h = float(model.opt.timestep)
    for hinge in ("shoulder", "elbow"):
        j = 1.0 / float(model.tendon_invweight0[model.tendon(f"clr_{hinge}__backlash").id])
        k = (0.5 / h) ** 2 * j
        b = math.sqrt(k * j)  # 2 zeta sqrt(K J) at zeta = 0.5
        out[hinge] = PlayDistribution(size=size, stiffness=Uniform(k, k), damping=Uniform(b, b))
    return out


def test_batch_steps_each_world_as_it_would_alone_and_wider_bands_lag_more(arm):
    worlds = randomise_play(arm, n_worlds=4, backlash=_firm_stops(arm, Uniform(1 * ARCMIN, 30 * ARCMIN)), seed=7)
    steps = 400  # 0.8 s at 2 ms
    ctrl = control_signal(arm, SineControl(), np.arange(steps) * arm.opt.timestep)[None]
    batch = step_worlds(worlds.models, control=ctrl, nthread=2)
    assert batch.state.shape[:2] == (4, steps)
    start = initial_states(worlds.models)
    for k in (0, 3):
        alone = step_worlds([worlds.models[k]], control=ctrl, initial_state=start[k : k + 1], nthread=1)
        # the same computation: rollout sets each world's state and zero warm start before its first step
        np.testing.assert_array_equal(alone.state[0], batch.state[k])
    qpos = batch.qpos(arm)
    for i, t in enumerate(worlds.tendons):
        load, motor = arm.joint(t.hinge).qposadr[0], arm.joint(f"{t.hinge}__motor").qposadr[0]
        widest = np.abs(qpos[:, :, load] - qpos[:, :, motor]).max(axis=1)
        b = worlds.size[:, i]
        # each world's load swings across its own band and is caught there: the firm stop lets it 1.29-1.55 b
        # deep at most (measured over these worlds; the soft recipe stop let it 29 b), so 2 b bounds it
        assert ((widest > b) & (widest < 2 * b)).all(), (t.hinge, b, widest / b)
        order = np.argsort(b)
        assert np.all(np.diff(widest[order]) > 0), (t.hinge, b[order], widest[order])


def test_unstable_stop_ranges_are_refused_before_any_draw(arm):
    t = arm.tendon("clr_shoulder__backlash").id
    k0, _ = stop_spring(arm, t)
    with pytest.raises(RetrofitError, match=r"backlash stop of hinge 'shoulder'.*unstable at the step 0.002 s"):
        randomise_play(arm, n_worlds=3, backlash={"shoulder": PlayDistribution(stiffness=Uniform(k0, 1e4 * k0))})
    # the bound itself: a spring alone at the reference pose is stable below h omega = 2
    j = 1.0 / float(arm.tendon_invweight0[t])
    for h_omega, stable in ((1.9, True), (2.1, False)):
        k = (h_omega / 0.002) ** 2 * j
        a = 1.0 / j
        bound = stop_bound(stiffness=k, damping=0.0, invweight=a, lightest=a, impedance=0.95, h=0.002)
        assert (bound < STABLE_BOUND) is stable
    with pytest.raises(RetrofitError, match="radial: the model has no limited radial tendon"):
        randomise_play(arm, n_worlds=2, radial=PlayDistribution(size=Uniform(1e-5, 2e-5)))
    with pytest.raises(RetrofitError, match=r"hinge 'wrist' has no backlash tendon"):
        randomise_play(arm, n_worlds=2, backlash={"wrist": PlayDistribution()})
    with pytest.raises(RetrofitError, match="n_worlds must be an integer >= 1"):
        randomise_play(arm, n_worlds=0)
    with pytest.raises(ValueError, match="0 < low <= high"):
        Uniform(2.0, 1.0)


def test_a_world_that_blows_up_is_named(arm):
    worlds = randomise_play(arm, n_worlds=3)
    model = worlds.models[1]  # a stop made absurdly stiff by hand (randomise_play refuses such a range)
    t = model.tendon("clr_elbow__backlash").id
    model.tendon_solref_lim[t] = (-1e9 * model.tendon_invweight0[t], 0.0)
    ctrl = control_signal(arm, SineControl(), np.arange(300) * arm.opt.timestep)[None]
    with pytest.raises(WorldFailure, match=r"1 of 3 worlds stopped.*worlds 1 \(t = ") as caught:
        step_worlds(worlds.models, control=ctrl, nthread=1)
    assert caught.value.worlds == (1,)
    assert 0 < caught.value.times[0] < 300 * arm.opt.timestep
    with pytest.raises(ValueError, match=r"control must have shape \(3 or 1, n_steps >= 1, 2\)"):
        step_worlds(worlds.models, control=np.zeros((2, 10, 2)))
