"""The ideal cycle a run is sized from (clearance.run.cycle) and its cache (clearance.run.cycle_cache).

A cached cycle is bitwise the one computed (from memory, from its file, through `prepare`); the
cycle's loads and bearing masses agree with the solvers they replace (`joint_reaction_vectors`
over the cycle, `cycle_effective_mass` on the compiled model) on every catalogue mechanism with
every clearable joint given play; the loads of one constant-speed drive scale with its speed
squared; the key ignores what the shape does not depend on; a corrupt file is reported, ignored
and rewritten. The sizing's median is np.median's, bitwise, and a preparation does not import numpy.ma.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

from clearance.builders import CATALOGUE, rpm, slider_crank
from clearance.contact_calibration.effective_mass import cycle_effective_mass
from clearance.loads import joint_reaction_vectors
from clearance.mjcf import build_spec
from clearance.model import Mechanism
from clearance.options import ContactMode, ModelOptions
from clearance.run import cycle_cache
from clearance.run.cycle import CYCLE_TIMES, IdealCycle, cycle_shape, scale_cycle
from clearance.run.cycle_cache import CycleCacheWarning, clear_memory, cycle_key, cycle_path, ideal_cycle

# Both sides solve the ideal kinematics to the same Newton tolerance (1e-12 on the closures) and
# `cycle_effective_mass` accepts its poses mapped onto the model's coordinates to a residual of
# 1e-8 (its RuntimeError bound): the two agree to 1e-8 relative (measured: 8e-11 at most on the
# catalogue), far tighter than any load or mass a sizing uses differs between speeds or joints.
AGREE = 1e-8


def _same_cycle(a: IdealCycle, b: IdealCycle) -> None:
    """Bitwise equality of two cycles."""
    assert np.array_equal(a.times, b.times)
    assert a.loads.keys() == b.loads.keys() and a.masses.keys() == b.masses.keys()
    for k in a.loads:
        assert np.array_equal(a.loads[k], b.loads[k]), k
    for k in a.masses:
        ma, mb = a.masses[k], b.masses[k]
        assert (ma.median, ma.minimum, ma.maximum) == (mb.median, mb.minimum, mb.maximum), k
        assert np.array_equal(ma.times, mb.times) and np.array_equal(ma.values, mb.values), k


def test_cached_cycle_equals_fresh_bitwise(tmp_path):
    m = slider_crank()
    fresh = scale_cycle(cycle_shape(m), m)
    clear_memory()
    first = ideal_cycle(m, directory=tmp_path)  # a miss: computed and stored
    assert cycle_path(cycle_key(m), tmp_path).is_file()
    memory = ideal_cycle(m, directory=tmp_path)  # a hit in the process
    clear_memory()
    disk = ideal_cycle(m, directory=tmp_path)  # a hit from the file
    for cached in (first, memory, disk):
        _same_cycle(fresh, cached)


def test_prepare_sizes_the_same_on_a_hit(tmp_path, monkeypatch):
    from clearance.run.preparation import prepare

    monkeypatch.setenv("CLEARANCE_CACHE_DIR", str(tmp_path))
    m = slider_crank()
    clear_memory()
    miss = prepare(m)
    clear_memory()
    disk = prepare(m)
    memory = prepare(m)
    assert miss.sizing == disk.sizing == memory.sizing  # dataclass equality: every float bitwise
    assert miss.to_xml() == disk.to_xml() == memory.to_xml()


def _matches_the_solvers_it_replaces(m: Mechanism) -> None:
    cycle = scale_cycle(cycle_shape(m), m)
    loads = joint_reaction_vectors(m, np.linspace(0.0, m.drive_period or 1.0, CYCLE_TIMES))[0]
    assert loads.keys() == cycle.loads.keys()
    for k, v in loads.items():
        peak = float(np.max(np.hypot(v[:, 0], v[:, 1])))
        assert np.max(np.abs(cycle.loads[k] - v)) <= AGREE * peak, k
    built = build_spec(m, ModelOptions(contact_mode=ContactMode.EXACT), {j.name: 0 for j in m.clearance_joints})
    masses = cycle_effective_mass(built.spec.compile(), built, m)
    assert set(cycle.masses) == {j.name for j in m.clearance_joints}
    for k, mass in cycle.masses.items():
        assert np.allclose(mass.values, masses[k].values, rtol=AGREE, atol=0.0), k
        # the same times from two np.linspace grids (every fifth of 181, and 36 without the end): ulps apart
        assert np.allclose(mass.times, masses[k].times, rtol=1e-14, atol=0.0), k


@pytest.mark.parametrize("name", list(CATALOGUE))
def test_cycle_matches_the_solvers_it_replaces(name):
    entry = CATALOGUE[name]
    _matches_the_solvers_it_replaces(entry.builder(clearance_at=entry.info.clearable))


@pytest.mark.parametrize("case", ["torque drive", "slider with play"])
def test_cycle_matches_them_with_free_rows(case):
    # a torque drive's joint and a slider's rows are left free in the mobility, as the model leaves them
    if case == "torque drive":
        m = slider_crank(free_crank=True)
    else:
        m = slider_crank(clearance_at=("crank_rod", "rod_slider", "slider_guide"))
    _matches_the_solvers_it_replaces(m)


def test_loads_scale_with_speed_squared():
    slow, fast = slider_crank(crank_speed=rpm(1000)), slider_crank(crank_speed=rpm(5000))
    assert cycle_key(slow) == cycle_key(fast)
    shape = cycle_shape(fast)
    cycle = scale_cycle(shape, slow)
    loads = joint_reaction_vectors(slow, np.linspace(0.0, slow.drive_period, CYCLE_TIMES))[0]
    for k, v in loads.items():
        peak = float(np.max(np.hypot(v[:, 0], v[:, 1])))
        assert np.max(np.abs(cycle.loads[k] - v)) <= AGREE * peak, k  # AGREE: as above
    assert np.allclose(cycle.times, np.linspace(0.0, slow.drive_period, CYCLE_TIMES), rtol=1e-15, atol=0.0)


def test_key_follows_what_the_shape_depends_on():
    m = slider_crank()
    joint = m.clearance_joints[0]
    wider = dataclasses.replace(joint, clearance=dataclasses.replace(joint.require_clearance(), radial_clearance=1e-4))
    assert cycle_key(dataclasses.replace(m, joints=tuple(wider if j is joint else j for j in m.joints))) == cycle_key(m)
    link = m.moving_links[0]
    heavier = dataclasses.replace(link, mass=2 * link.mass)
    assert cycle_key(dataclasses.replace(m, links=tuple(heavier if lk is link else lk for lk in m.links))) != cycle_key(
        m
    )


def test_a_corrupt_file_is_reported_and_rewritten(tmp_path):
    m = slider_crank()
    clear_memory()
    good = ideal_cycle(m, directory=tmp_path)
    path = cycle_path(cycle_key(m), tmp_path)
    path.write_text('{"key": {}, "shape": {}}')
    clear_memory()
    with pytest.warns(CycleCacheWarning, match=str(path.name)):
        again = ideal_cycle(m, directory=tmp_path)
    _same_cycle(good, again)
    clear_memory()
    with warnings.catch_warnings():
        warnings.simplefilter("error", CycleCacheWarning)  # rewritten: read back without a warning
        _same_cycle(good, ideal_cycle(m, directory=tmp_path))


def test_memory_keeps_a_bounded_number_of_shapes(tmp_path, monkeypatch):
    monkeypatch.setattr(cycle_cache, "MEMORY_ENTRIES", 2)
    clear_memory()
    for rpm_ in (1000, 2000, 3000):  # one key: a speed sweep shares its shape
        ideal_cycle(slider_crank(crank_speed=rpm(rpm_)), directory=tmp_path)
    assert len(cycle_cache._MEMORY) == 1
    for scale in (2.0, 3.0, 4.0):  # three keys: two kept
        m = slider_crank()
        link = m.moving_links[0]
        heavier = dataclasses.replace(link, mass=scale * link.mass)
        ideal_cycle(
            dataclasses.replace(m, links=tuple(heavier if lk is link else lk for lk in m.links)), directory=tmp_path
        )
    assert len(cycle_cache._MEMORY) == 2


@pytest.mark.parametrize("shape", [(181,), (36,), (7, 36), (5, 35)])
def test_median_is_numpys(shape):
    from clearance.run.sizing import median

    values = np.random.default_rng(len(shape) * 1000 + shape[-1]).lognormal(size=shape)
    # bitwise: the same middle elements, and for an even count the one sum and halving np.median's mean makes
    assert np.array_equal(median(values, axis=-1), np.median(values, axis=-1))
    assert np.array_equal(median(values.T, axis=0), np.median(values.T, axis=0))


def test_a_preparation_does_not_import_numpy_ma(tmp_path):
    code = (
        "import sys; from clearance.builders import slider_crank; from clearance.run.preparation import prepare; "
        "prepare(slider_crank()); print('numpy.ma' in sys.modules)"
    )
    env = {**os.environ, "CLEARANCE_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    # numpy.ma's import is 10 ms of a fresh process's first preparation: np.median imports it (use sizing.median)
    assert out.stdout.strip() == "False", "a preparation imported numpy.ma"
