"""The compiled contact's in-step treatment (journal_bearing.c: "In-step treatment", "Friction near rest").

The treatment is checked against its formula computed the slow, obvious way (Jacobians and M⁻¹
from MuJoCo in Python), then on what it is for: a mechanism whose penetration rate has a large
kinematic part (the slider-crank, not a point mass) gets its first impact's approach speed from
the reference solver; the c = 0.1 mm slider-crank's error over 0–14.9 ms shrinks with the step
at an observed order ≥ 0.8; a grazing contact at the 1 mm/s floor of the approach speed under a
2 kN load and friction near rest stay stable at 3 µs, where the explicit treatment chattered.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.optimize import brentq
from test_contact_plugin import R_J, C, S, _spec, needs_plugin

from clearance import ModelOptions
from clearance.builders import slider_crank
from clearance.contact_calibration import laws
from clearance.contact_plugin import attributes
from clearance.model import ContactLaw
from clearance.reference import run_reference
from clearance.run.preparation import exact_contact_name, prepare
from clearance.run.simulation import simulate_prepared, start_data

LN = ContactLaw.LANKARANI_NIKRAVESH
EULER = mujoco.mjtIntegrator.mjINT_EULER
K = 6.61e10  # N/m^1.5, as test_contact_plugin's scene
MU, V0, V1 = 0.3, 1e-4, 1e-3


def _rows(model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(n, t, J_n, J_t): the contact normal and tangent and the rows of the normal rate (site
    centres) and of the tangential velocity (contact points) over the dofs."""
    pj, pb = data.site("journal").xpos, data.site("bearing").xpos
    e = pj - pb
    e[2] = 0.0
    n = e / np.linalg.norm(e)
    t = np.cross([0.0, 0.0, 1.0], n)

    def jac(point: np.ndarray, body: str) -> np.ndarray:
        jp = np.zeros((3, model.nv))
        mujoco.mj_jac(model, data, jp, None, point, model.body(body).id)
        return jp

    jn = n @ (jac(pj, "journal") - jac(pb, "bearing"))
    jt = t @ (jac(pj + R_J * n, "journal") - jac(pb + (R_J + C) * n, "bearing"))
    return n, t, jn, jt


def _response(model: mujoco.MjModel, data: mujoco.MjData, row: np.ndarray) -> np.ndarray:
    """M^-1 row' with the equality rows acting as the solver solves them alone:
    u - Y (J_c Y' + R)^-1 J_c u, Y = M^-1 J_c' (dense from the model's equality rows)."""
    u = np.zeros((1, model.nv))
    mujoco.mj_solveM(model, data, u, row[None])
    eq = np.flatnonzero(data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    if not len(eq):
        return u[0]
    jc = data.efc_J[: data.nefc * model.nv].reshape(data.nefc, model.nv)[eq]  # dense: nv < 60
    y = np.zeros((len(eq), model.nv))
    mujoco.mj_solveM(model, data, y, jc)
    a = jc @ y.T + np.diag(data.efc_R[eq])
    return u[0] - y.T @ np.linalg.solve(a, jc @ u[0])


@needs_plugin
@pytest.mark.parametrize(
    ("integrator", "connect"),
    [(mujoco.mjtIntegrator.mjINT_EULER, False), (mujoco.mjtIntegrator.mjINT_IMPLICITFAST, False), (None, True)],
    ids=["euler", "implicitfast", "bearing held by a connect"],
)
def test_in_step_treatment_equals_its_formula(integrator: mujoco.mjtIntegrator | None, connect: bool) -> None:
    h = 2e-6
    spec = _spec(LN, friction=MU, moving_bearing=True, timestep=h, integrator=integrator or EULER)
    if connect:  # the bearing pinned to the world 30 mm from its centre: it can only swing
        anchor = [0.03, 0.0, 0.0] + [0.0] * 9
        spec.add_equality(
            type=mujoco.mjtEq.mjEQ_CONNECT, name1="bearing", objtype=mujoco.mjtObj.mjOBJ_BODY, data=anchor
        )
    model = spec.compile()
    data = mujoco.MjData(model)
    adr = attributes.state_address(model, "joint")
    y = attributes.sensor_offsets(model, "joint")
    other = adr + len(attributes.STATE_FIELDS)
    rng = np.random.default_rng(11)
    for _ in range(40):
        mujoco.mj_resetData(model, data)
        phi, delta = rng.uniform(-np.pi, np.pi), rng.uniform(1e-7, 2e-5)
        data.qpos[3:5] = (C + delta) * np.array([np.cos(phi), np.sin(phi)])
        data.qpos[[2, 5]] = rng.uniform(-3, 3, 2)
        data.qvel[:] = rng.uniform(-1, 1, 6) * [0.3, 0.3, 10, 1, 1, 40]
        data.time = 5 * h
        state = data.plugin_state
        state[adr + S["sample_time"]] = 4 * h  # a sample one step back: its history counts
        state[adr + S["has_sample"]] = 1.0
        state[adr + S["in_contact"]] = 1.0
        state[adr + S["approach_speed"]] = vin = rng.uniform(1e-3, 2.0)
        state[adr + S["sample_friction_force"]] = ft_last = rng.uniform(-50, 50)
        state[other : other + 6] = dv = rng.uniform(-1, 1, 6) * 1e-4
        state[other + 6 : other + 12] = dv_all = dv + rng.uniform(-1, 1, 6) * 1e-4
        state[adr + S["sample_geometric_rate"]] = rate0 = rng.uniform(-1, 1)
        mujoco.mj_forward(model, data)
        fields = ("normal_force", "tangential_force", "penetration", "penetration_rate")
        fn, ft, d, rate = (data.sensordata[y[k]] for k in fields)

        n, t, jn, jt = _rows(model, data)
        un, ut = _response(model, data, jn), _response(model, data, jt)
        w_nn, w_nt, w_tt = jn @ un, jn @ ut, jt @ ut
        fel = K * d**1.5
        g = h * w_nn * fel * laws.hysteresis_factor(LN, 0.9) / vin
        phi1, psi = -np.expm1(-g) / g, (g + np.expm1(-g)) / g**2
        # the geometry's own change of the sampled rate over the last step (h J_dot v): the rate's
        # change less the whole velocity change along the row; it forces the step's rate
        r0 = jn @ data.qvel
        kin = r0 - rate0 - jn @ dv_all
        expected_rate = (r0 - kin / 2) * phi1 + (jn @ dv + kin - h * w_nn * fel + h * w_nt * ft_last) * psi
        # the same operations in another order (and the series below g = 1e-3 in C): 1e-9 of the
        # rate's largest term, |jn . qvel| ~ 1 m/s, bounds the rounding of psi's cancellation
        assert rate == pytest.approx(expected_rate, abs=1e-9)
        assert fn == pytest.approx(laws.normal_force(LN, d, rate, vin, stiffness=K, restitution=0.9), rel=1e-12)
        # friction at the tangential velocity it leaves at the step's end: the root of
        # v - v_free - h w_tt F_t(v), found by bracketing (the slow, obvious way)
        v_free = jt @ data.qvel + jt @ dv - h * w_nt * fn

        def residual(v: float, fn: float = fn, v_free: float = v_free, w_tt: float = w_tt) -> float:
            return v - v_free - h * w_tt * laws.ambrosio_friction(fn, v, friction=MU, v0=V0, v1=V1)

        v_end = brentq(residual, v_free - 10.0, v_free + 10.0, xtol=1e-15, rtol=1e-15)
        expected_ft = laws.ambrosio_friction(fn, v_end, friction=MU, v0=V0, v1=V1)
        # brentq's root to 1e-15 m/s moves F_t by mu F_n / (v1 - v0) * 1e-15 ~ 3e-10 of F_n in the ramp
        assert ft == pytest.approx(expected_ft, abs=1e-9 * fn)


def _first_onset(mech, h: float) -> tuple[float, float]:
    """(onset time [s], approach speed [m/s]) of the first impact of the exact contact's run."""
    prepared = prepare(mech, ModelOptions(contact_mode="exact", timestep=h))
    model = prepared.model
    data = start_data(model)  # the run's own start (velocities at -h/2)
    o = attributes.sensor_offsets(model, exact_contact_name(mech.clearance_joints[0].name))
    before = 0.0
    for k in range(int(0.5e-3 / h)):
        mujoco.mj_forward(model, data)  # the sensors at t_k, as a run's row k
        delta = data.sensordata[o["penetration"]]
        if delta > 0:
            return (k - 1 + before / (before - delta)) * h, float(data.sensordata[o["approach_speed"]])
        before = delta
        mujoco.mj_step(model, data)
    raise AssertionError("no impact in 0.5 ms")


@needs_plugin
def test_first_impact_approach_speed_on_a_mechanism_matches_the_reference() -> None:
    # the default slider-crank: the journal's penetration rate changes by omega^2 l ~ 1.4e4 m/s^2
    # through its kinematic part alone, which a half-step advance of the whole rate biased by
    # h delta_ddot / 2 (+0.49 % per us); measured now -1.6e-5 at 3 us, -2.0e-6 at 1 us
    mech = slider_crank()
    ref = run_reference(mech, 0.3e-3, output_interval=1e-6, rtol=1e-11)
    t_ref, v_ref = ref.metadata["contact_onsets"]["rod_slider"][0]
    for h in (1e-6, 3e-6):
        onset, speed = _first_onset(mech, h)
        assert speed == pytest.approx(v_ref, rel=1e-4), h  # the bound
        assert onset == pytest.approx(t_ref, abs=0.01 * h), h  # the crossing located inside its step


@needs_plugin
def test_the_c01_window_error_shrinks_with_the_step_at_order_above_08() -> None:
    # c = 0.1 mm at the rod-slider joint, 5000 rpm, 0-14.9 ms: regular before the grazing lift-off
    # at 14.97 ms, so a pointwise comparison (max |x - x_ref|); the order is the least-squares
    # slope of log error against log step over 2, 1, 0.5 us (measured 1.98 on this window)
    mech = slider_crank(radial_clearance=0.1e-3)
    window = 14.9e-3
    ref = run_reference(mech, window, output_interval=1e-6, rtol=1e-11)
    steps, errors = np.array([2e-6, 1e-6, 0.5e-6]), []
    for h in steps:
        # one step more than the window: the run's rows then cover every reference time (a row
        # held past the run's end would read the slider's 26 m/s times h as an error)
        run = simulate_prepared(prepare(mech, ModelOptions(contact_mode="exact", timestep=h)), duration=window + h)
        assert run.times[-1] >= ref.times[-1]
        x = np.interp(ref.times, run.times, run.outputs["slider_x"])
        errors.append(np.max(np.abs(x - ref.outputs["slider_x"])))
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert order >= 0.8, (errors, order)  # the bound
    # and the errors lie well above the reference's own floor (its rtol 1e-9 against 1e-11
    # difference, about 1e-9 m here), so the slope is the scheme's
    assert min(errors) > 1e-8


def _loaded_contact(h: float, *, normal: float, tangential: float, friction: float) -> dict[str, np.ndarray]:
    """The journal barely touching its bearing at 0.1 mm/s (the approach speed floors at 1 mm/s),
    then loaded along the normal (and along the tangent, with the couple that keeps it from
    rolling) by forces ramped up over 2 ms; 10 ms of sensor rows at step h."""
    model = _spec(LN, timestep=h, friction=friction, integrator=mujoco.mjtIntegrator.mjINT_IMPLICITFAST).compile()
    data = mujoco.MjData(model)
    data.qpos[0], data.qvel[0] = C - 1e-10, 1e-4
    y = attributes.sensor_offsets(model, "joint")
    body = model.body("journal").id
    n = int(0.01 / h)
    out = {k: np.empty(n) for k in ("normal_force", "tangential_force", "approach_speed", "vt")}
    for i in range(n):
        ramp = min(1.0, i * h / 2e-3)
        data.xfrc_applied[body] = [normal * ramp, tangential * ramp, 0, 0, 0, tangential * ramp * R_J]
        mujoco.mj_step(model, data)
        for k in ("normal_force", "tangential_force", "approach_speed"):
            out[k][i] = data.sensordata[y[k]]
        e = data.qpos[:2] / np.linalg.norm(data.qpos[:2])
        out["vt"][i] = np.array([-e[1], e[0]]) @ data.qvel[:2] + data.qvel[2] * R_J
    assert not any(w.number for w in data.warning), "MuJoCo warnings"
    return out


@needs_plugin
def test_a_grazing_contact_at_the_floor_approach_speed_is_stable_at_3us() -> None:
    # damping chi F_el / v_in at v_in = 1 mm/s under 2 kN gives h w_nn C ~ 4 at 3 us: the explicit
    # treatment chattered between 0 and 4 kN there; the exponential one settles on the load
    run = _loaded_contact(3e-6, normal=2000.0, tangential=0.0, friction=0.0)
    assert run["approach_speed"].max() == laws.MIN_APPROACH_SPEED  # the floor binds
    held = run["normal_force"][len(run["normal_force"]) // 2 :]
    # measured within 5.3e-6 of the load; 1e-3 is the static balance with margin, far below chatter
    np.testing.assert_allclose(held, 2000.0, rtol=1e-3)


@needs_plugin
def test_friction_near_rest_does_not_chatter_at_the_default_step() -> None:
    # 2 kN normal, 100 N tangential (below mu F_n = 200 N) at 3 us: the journal sticks inside
    # Ambrosio's ramp; the explicit friction changed the sign of v_t on 709 of 1666 steps here
    mu = 0.1
    run = _loaded_contact(3e-6, normal=2000.0, tangential=100.0, friction=mu)
    half = slice(len(run["vt"]) // 2, None)
    below = np.abs(run["tangential_force"][half]) < mu * run["normal_force"][half]
    flips = np.count_nonzero(np.diff(np.sign(run["vt"][half])) != 0)
    assert below.all()  # it sticks: the friction force stays below mu F_n
    assert flips <= len(run["vt"][half]) / 10  # the definition of chatter (measured 0)
    # the friction holds the tangential load (measured within 2.5 %)
    np.testing.assert_allclose(run["tangential_force"][half], -100.0, rtol=0.05)
