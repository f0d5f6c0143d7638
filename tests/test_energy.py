"""Energy balance of a run, every term measured on its own (`clearance.run.energy`, `clearance.work`).

The compiled work meter is checked against the slow, obvious computation (a Python step loop
and the mass matrix), then the balance of whole runs against step halving: with an elastic
compiled contact (Hertz, no friction) in a two-loop mechanism (a connect closure, a speed drive
with its armature, gravity), with a dissipative one, and in a ring mode. Then persistence, the
chunked and thinned runs, and the report's section.
"""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest

import clearance.contact_plugin as cp
from clearance.analysis.figures.report import energy_section
from clearance.builders import slider_crank, watt_six_bar
from clearance.contact_plugin.energy import WORK_FIELDS, WORK_SENSOR, add_energy_meter
from clearance.model import ContactLaw, Mechanism
from clearance.options import ModelOptions
from clearance.results import ENERGY_TERMS, SimulationResult, energy_residual
from clearance.run.initial_state import offset_journals
from clearance.run.preparation import prepare
from clearance.run.simulation import simulate_prepared

pytestmark = pytest.mark.skipif(
    not cp.is_available(), reason="installed without a C compiler: no contact plugin library"
)

STEPS = (4e-6, 2e-6, 1e-6)  # h, h/2, h/4 [s]
HERTZ = dict(law=ContactLaw.HERTZ, friction=0.0, gravity=9.81)  # elastic (c_e = 1 in effect), mu = 0, g along -y


def _six_bar() -> Mechanism:
    # two loops: the clearance joint D is one cut (the compiled contact), the other a connect equality
    return watt_six_bar(**HERTZ)


def _run(mech: Mechanism, h: float, duration: float, mode: str = "exact") -> SimulationResult:
    prepared = prepare(mech, ModelOptions(contact_mode=mode, timestep=h))  # every prepared run carries the meter
    return simulate_prepared(prepared, duration=duration)


def _worst(results: dict[float, SimulationResult]) -> list[float]:
    out = []
    for h in STEPS:
        res = results[h].energy_residual
        assert res is not None
        out.append(float(np.max(np.abs(res))))
    return out


@pytest.fixture(scope="module")
def six_bar_runs() -> dict[float, SimulationResult]:
    mech = _six_bar()
    return {h: _run(mech, h, 0.02) for h in STEPS}  # 20 ms: 23 contact events of journal D at 1 us


def test_meter_adds_up_to_the_kinetic_energy_change_of_every_step():
    """Python step loop: the six works of a step add up to v_mid' M_k dv + h qfrc_bias . v_mid exactly.

    With implicitfast, (M - h D) dv = h f exactly; the meter's actuator term carries D dv (the
    speed drive's implicit damping), so the sum of the works must match the kinetic-energy change
    measured in the step's own metric M_k, bias forces (Coriolis, gravity) included, to rounding.
    The journal starts 2 um into its bearing, so the compiled contact pushes from the first step.
    """
    mech = _six_bar()
    prepared = prepare(mech, ModelOptions(contact_mode="exact", timestep=2e-6))
    spec = prepared.built.spec.copy()
    add_energy_meter(spec)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    c = mech.joint("D").require_clearance().radial_clearance
    data.qpos[:] = offset_journals(
        model, model.key_qpos[0], {"D": (c + 2e-6, 0.0)}, bearings={"D": c}, fixed_joints=[mech.drives[0].joint]
    )
    adr = int(model.plugin_stateadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_PLUGIN, WORK_SENSOR)])
    eq_rows = mujoco.mjtConstraint.mjCNSTR_EQUALITY
    h = model.opt.timestep
    mv = np.empty(model.nv)
    feq = np.empty(model.nv)
    bodies = range(1, model.nbody)
    potential = model.sensor("D__contact").adr[0] + 5  # its contact sensor's potential_energy
    for k in range(300):
        mujoco.mj_forward(model, data)
        if k == 0:
            stored = data.sensordata[potential]
        v0, bias = data.qvel.copy(), data.qfrc_bias.copy()
        efc = np.where(data.efc_type == eq_rows, data.efc_force, 0.0)
        mujoco.mj_mulJacTVec(model, data, feq, efc)
        # kinetic energy: links and armature, from the bodies' own velocities
        kin = 0.5 * float(np.sum(model.dof_armature * v0**2))
        for b in bodies:
            vel = np.empty(6)
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, vel, 0)
            rot = data.ximat[b].reshape(3, 3)
            inertia = rot @ np.diag(model.body_inertia[b]) @ rot.T
            kin += 0.5 * model.body_mass[b] * vel[3:] @ vel[3:] + 0.5 * vel[:3] @ inertia @ vel[:3]
        before = data.plugin_state[adr : adr + 7].copy()
        mujoco.mj_step(model, data)  # its forward repeats the one above (same warm start)
        sensor = data.sensordata[model.sensor_adr[model.sensor(WORK_SENSOR).id] :][: len(WORK_FIELDS)]
        step = data.plugin_state[adr : adr + 7] - before
        dv, vmid = data.qvel - v0, 0.5 * (data.qvel + v0)
        mujoco.mj_mulM(model, data, mv, dv)  # qM is still the step's start M_k (no forward since)
        expected = vmid @ mv + h * bias @ vmid
        mujoco.mj_mulM(model, data, mv, vmid)
        # rounding: a change of ½ v'Mv taken from velocities of size |v| carries a few eps v'Mv
        # (measured up to 3.3 eps v'Mv over these steps); bound 50 eps v'Mv
        assert abs(step[:6].sum() - expected) <= 50 * np.finfo(float).eps * (vmid @ mv)
        # the equality rows' share, h J_eq' f_eq . v_mid: the same products summed in another
        # order, so rounding of a few eps of the sum of their magnitudes; bound 50 eps
        assert abs(step[1] - h * feq @ vmid) <= 50 * np.finfo(float).eps * h * np.sum(np.abs(feq * vmid))
        assert step[6] == 1.0  # one step recorded per mj_step
        # the energy sensor is MuJoCo's ½ v'Mv with armature: equal to the bodies' sum to rounding
        assert data.sensordata[model.sensor("energy__kinetic").adr[0]] == pytest.approx(kin, rel=1e-12)
    assert sensor[7] == 299  # sensordata of the last step: the works of the 299 steps before it
    mujoco.mj_forward(model, data)
    released = stored - data.sensordata[potential]
    assert released > 0.5 * stored  # the pressed journal came (mostly) out of its bearing
    # and the compiled contact's work is the elastic energy it released (Hertz: nothing dissipated),
    # to the explicit force's first-order error: measured +0.62 % at 2 us; bound 2 %
    assert data.plugin_state[adr + 5] == pytest.approx(released, rel=0.02)


def test_elastic_compiled_contact_conserves_energy_at_first_order(six_bar_runs):
    """Hertz, mu = 0, exact mode, a connect closure, a speed drive, gravity: residual ~ h.

    Measured (20 ms, 23 contact events): max |residual| 5.50e-4 / 2.52e-4 / 1.25e-4 J at 4 / 2 / 1 us
    (orders 1.13, 1.01; 1.01 again down to 0.5 us) against 3.71 J exchanged: the semi-implicit
    integrators' energy error, first order, which oscillates over each contact (about omega h of
    the contact's energy) and does not drift.
    """
    worst = _worst(six_bar_runs)
    orders = np.log2(np.array(worst[:-1]) / np.array(worst[1:]))
    # first-order integrator: measured orders 1.13 and 1.01; the band allows the first level's
    # pre-asymptotic 0.13 twice over
    assert np.all((orders > 0.75) & (orders < 1.35)), orders
    # conservation: the residual extrapolated to h -> 0 from the two finest steps (2 r(h/4) - r(h/2))
    # vanishes: measured 1.6 % of r(h/4); a missing term of fixed size would stay as a floor
    assert abs(2 * worst[2] - worst[1]) < 0.1 * worst[2]
    fine = six_bar_runs[STEPS[-1]]
    balance = fine.energy_balance()
    assert balance is not None and balance["missing"] == []
    # measured 3.4e-5 at 1 us: bound 2x that
    assert balance["residual_relative"] < 7e-5
    e = fine.energy
    assert np.ptp(e["equality_work"]) > 0  # the connect closure's soft rows did (a little) work
    assert np.all(e["dissipated_work"] == 0)  # Hertz: nothing to dissipate
    assert e["contact_potential"].max() > 0  # the journal touched
    # the compiled contact's own bookkeeping: its force's work is -(potential change) to the step's
    # error; measured max 8.9e-5 J at 1 us, below the residual it is part of
    check = e["compiled_contact_work"] + e["contact_potential"] - e["contact_potential"][0] + e["dissipated_work"]
    assert np.max(np.abs(check)) <= worst[2]


def test_dissipative_compiled_contact_balance_closes_with_the_dissipated_work():
    """Lankarani-Nikravesh, c_e = 0.9: the dissipated work enters the balance; it converges at order 1.

    Measured (slider-crank, 10 ms, clearance at crank_rod and the 5000 rpm drive): max |residual|
    0.160 / 0.079 J at 2 / 1 us (order 1.02), dissipated 3.04 / 3.07 J, 129 J exchanged.
    """
    mech = slider_crank(clearance_at=("crank_rod",), law=ContactLaw.LANKARANI_NIKRAVESH, restitution=0.9, gravity=9.81)
    runs = {h: _run(mech, h, 0.01) for h in STEPS[1:]}
    worst = []
    for r in runs.values():
        res = r.energy_residual
        assert res is not None
        worst.append(float(np.max(np.abs(res))))
        dissipated = r.energy["dissipated_work"]
        assert np.all(np.diff(dissipated) >= 0) and dissipated[-1] > 0  # heat only grows
        # the residual is an integration error, far below the energy it accounts for: measured 0.05x
        assert worst[-1] < 0.2 * dissipated[-1]
    # first order: measured ratio 2.02 (order 1.02); band as in the elastic test
    assert 2**0.75 < worst[0] / worst[1] < 2**1.35


def test_ring_mode_balance_closes_through_the_contact_rows_work():
    """Ring of constraint rows (nominal contact, LN 0.9): no contact potential, the rows' work instead.

    The ring's stored and dissipated energy are both in contact_work (the work of the contact
    rows, which MuJoCo's soft constraints make elastic and damped at once). Measured (default
    slider-crank, 10 ms): max |residual| 0.066 / 0.033 / 0.0166 J at 4 / 2 / 1 us (orders 1.00,
    1.00) against 114 J exchanged; contact_work at the end -1.25 J.
    """
    mech = slider_crank(gravity=9.81)
    runs = {h: _run(mech, h, 0.01, mode="nominal") for h in STEPS}
    worst = _worst(runs)
    orders = np.log2(np.array(worst[:-1]) / np.array(worst[1:]))
    # measured 1.00 and 1.00: band as in the elastic test
    assert np.all((orders > 0.75) & (orders < 1.35)), orders
    # the extrapolated residual vanishes (measured 0.09 % of r(h/4)): bound as in the elastic test
    assert abs(2 * worst[2] - worst[1]) < 0.1 * worst[2]
    e = runs[STEPS[-1]].energy
    assert set(e) == set(ENERGY_TERMS)
    assert np.all(e["contact_potential"] == 0) and np.all(e["dissipated_work"] == 0)
    assert e["contact_work"][-1] < 0  # damped rows: the ring took energy out
    assert e["contact_work"].min() < e["contact_work"][-1]  # and gave some back (elastic rows)


def test_chunked_and_thinned_runs_carry_the_same_energy(six_bar_runs):
    """The works live in the plugin state and chunks carry the solver's warm start, so chunk
    boundaries and output thinning change no bit (tests/test_chunked_runs.py says why)."""
    h = STEPS[0]
    whole = six_bar_runs[h]
    prepared = prepare(_six_bar(), ModelOptions(contact_mode="exact", timestep=h))
    chunked = simulate_prepared(prepared, duration=0.02, chunk_steps=777)
    thinned = simulate_prepared(prepared, duration=0.02, output_interval=3 * h, chunk_steps=1000)
    for k, v in whole.energy.items():
        np.testing.assert_array_equal(chunked.energy[k], v, err_msg=k)
        np.testing.assert_array_equal(thinned.energy[k], v[::3], err_msg=k)


def test_energy_series_save_and_load_losslessly(tmp_path, six_bar_runs):
    r = six_bar_runs[STEPS[0]]
    npz, js = r.save(tmp_path / "run")
    back = SimulationResult.load(npz)
    assert set(back.energy) == set(r.energy)
    for k, v in r.energy.items():
        assert np.array_equal(back.energy[k], v), k
    summary = json.loads(js.read_text())["energy_balance"]
    assert summary == back.metadata["energy_balance"] == r.energy_balance()
    # a file written before energy series existed (no energy_names) loads with none
    meta = json.loads(js.read_text())
    del meta["energy_names"], meta["energy_balance"]
    js.write_text(json.dumps(meta))
    assert SimulationResult.load(npz).energy == {}


def test_residual_needs_every_term_and_the_report_says_so(six_bar_runs):
    r = six_bar_runs[STEPS[0]]
    lines = "\n".join(energy_section(r))
    assert "## Energy balance" in lines and "**residual**" in lines
    # a reference-like result: the terms it integrates, no constraint or dissipated work
    partial = {k: r.energy[k] for k in ("kinetic", "gravity_potential", "contact_potential", "drive_work")}
    assert energy_residual(partial) is None
    r2 = r.sliced(slice(None))
    r2.energy = partial
    text = "\n".join(energy_section(r2))
    assert "No residual" in text and "dissipated_work" in text
    r2.energy = {}
    assert "no energy series" in "\n".join(energy_section(r2))


def test_reference_reports_the_terms_it_integrates_and_no_residual():
    """The reference solver integrates kinetic, potential and drive work, but no constraint or heat work."""
    from clearance.reference import run_reference

    res = run_reference(slider_crank(clearance_at=()), 1e-3, track_work=True)
    assert set(res.energy) == {"kinetic", "gravity_potential", "contact_potential", "drive_work"}
    balance = res.metadata["energy_balance"]
    assert balance["residual_J"] is None and "dissipated_work" in balance["missing"]
    assert run_reference(slider_crank(clearance_at=()), 1e-3).energy == {}  # not tracked: none
