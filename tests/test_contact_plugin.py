"""The compiled journal–bearing contact (`clearance.journal_bearing`) against the slow, obvious one.

The plugin's laws are checked against `contact_calibration.laws` value by value, one impact
against the point-mass reference of `contact_calibration.impact`, chunked and threaded rollouts
against one rollout, the state bookkeeping under RK4 against the sensor record, energy against
its step-halving convergence; then the packaging (entry point in a spawned process, cheap
import), the validation of attributes and the no-compiler path.
"""

from __future__ import annotations

import importlib.metadata
import multiprocessing
import shutil
import subprocess
import sys
import textwrap

import mujoco
import numpy as np
import pytest
from mujoco import rollout
from plugin_scenes import add_joint, planar_body

import clearance.contact_plugin as cp
from clearance.contact_calibration import laws
from clearance.contact_calibration.impact import law_impact
from clearance.contact_plugin import attributes
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw

if not cp.is_available() and shutil.which("cc") is not None:
    pytest.fail(
        "a C compiler is installed but the contact plugin library is missing: reinstall "
        "clearance and read the build log (pip install -v -e .)",
        pytrace=False,
    )
needs_plugin = pytest.mark.skipif(
    not cp.is_available(), reason="installed without a C compiler: no contact plugin library"
)

LN = ContactLaw.LANKARANI_NIKRAVESH
K = 6.61e10  # N/m^1.5: steel, R_B = 10 mm, c = 0.5 mm (docs/references.md: journal-bearing stiffness)
C = 5e-4  # radial clearance [m]
R_J = 9.5e-3  # journal radius [m]
MASS = 0.15  # journal mass [kg], the effective mass of the brief's scenarios
INERTIA = 1e-5  # journal moment of inertia [kg m^2]
V0, V1 = 1e-4, 1e-3  # Ambrósio thresholds [m/s]
IMPACT_C_MAX, IMPACT_D_MAX = 1e4, 1e-5  # N s/m, m (the Adams-style values of docs/references.md, MSC Adams IMPACT)
FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS
# State offsets inside one instance's block.
S = {name: k for k, name in enumerate(attributes.STATE_FIELDS)}
Y = {name: k for k, name in enumerate(attributes.SENSOR_FIELDS)}


def _law_parameters(law: ContactLaw) -> dict[str, float]:
    if law is ContactLaw.IMPACT:
        return {"c_max": IMPACT_C_MAX, "d_max": IMPACT_D_MAX}
    if law is ContactLaw.HERTZ:
        return {}
    return {"restitution": 0.9 if law is LN else 0.7}


def _spec(
    law: ContactLaw = LN,
    *,
    timestep: float = 1e-6,
    friction: float = 0.0,
    integrator: mujoco.mjtIntegrator = mujoco.mjtIntegrator.mjINT_EULER,
    moving_bearing: bool = False,
    frame_quat: tuple[float, ...] = (1, 0, 0, 0),
    **law_kw: float,
) -> mujoco.MjSpec:
    """A journal (slide x, slide y, hinge z) in a bearing, both in one (rotated) frame.

    The bearing is fixed in the frame, or has its own slide x, slide y and hinge z. No gravity,
    no collision geoms: the plugin is the only force.
    """
    spec = mujoco.MjSpec()
    spec.option.timestep = timestep
    spec.option.gravity = [0, 0, 0]
    spec.option.integrator = integrator
    rotated = tuple(frame_quat) != (1, 0, 0, 0)
    frame = spec.worldbody.add_body(name="frame", quat=list(frame_quat)) if rotated else spec.worldbody
    for name in ("bearing", "journal"):
        moving = name == "journal" or moving_bearing
        planar_body(frame, name, mass=MASS, inertia=INERTIA, prefix=f"{name}_", moving=moving)
    parameters = {**_law_parameters(law), **law_kw}
    add_joint(
        spec,
        clearance=C,
        journal_radius=R_J,
        law=law,
        stiffness=K,
        friction=friction,
        v0=V0,
        v1=V1,
        **parameters,
    )
    return spec


def _full_state(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    state = np.empty(mujoco.mj_stateSize(model, FULL))
    mujoco.mj_getState(model, data, state, FULL)
    return state


def _no_warnings(data: mujoco.MjData) -> None:
    fired = {mujoco.mjtWarning(i).name: w.number for i, w in enumerate(data.warning) if w.number}
    assert not fired, f"MuJoCo warnings: {fired}"


# ---------------------------------------------------------------- laws, value by value


@needs_plugin
@pytest.mark.filterwarnings("ignore::clearance.contact_calibration.laws.UnverifiedLawWarning")
@pytest.mark.parametrize("law", [law for law in ContactLaw if law not in CYLINDRICAL_LAWS])  # the point laws
def test_compiled_laws_equal_laws_py(law: ContactLaw) -> None:
    # RK4's states are synchronous: it takes the rates as they are (no in-step treatment, which
    # test_in_step_treatment_equals_its_formula checks), so the law sees the geometric rate
    model = _spec(law, friction=0.3, integrator=mujoco.mjtIntegrator.mjINT_RK4).compile()
    data = mujoco.MjData(model)
    adr = attributes.state_address(model, "joint")
    y = attributes.sensor_address(model, "joint")
    rng = np.random.default_rng(7)
    params = _law_parameters(law)
    for _ in range(60):
        delta = rng.uniform(-5e-6, 4e-5) if law is not ContactLaw.IMPACT else rng.uniform(-5e-6, 2 * IMPACT_D_MAX)
        rate, approach = rng.uniform(-4, 4), rng.uniform(5e-4, 3)  # floor crossed sometimes
        # Sliding (spinning journal) or inside Ambrósio's ramp (no spin: v_t = qvel y).
        spin, vt = rng.choice([(0.0, rng.uniform(-3e-3, 3e-3)), (0.0, 0.0), (rng.uniform(-50, 50), rng.uniform(-2, 2))])
        mujoco.mj_resetData(model, data)
        # Journal on the bearing's x axis: n = x and t = y, so δ̇ = qvel x and v_t = qvel y +
        # spin R_J up to the last bit of MuJoCo's velocity transforms.
        data.qpos[:3] = [C + delta, 0.0, rng.uniform(-3, 3)]
        data.qvel[:3] = [rate, vt - spin * R_J, spin]
        data.plugin_state[adr + S["in_contact"]] = 1.0
        data.plugin_state[adr + S["approach_speed"]] = approach
        mujoco.mj_forward(model, data)
        fn, ft, d, dd, vin = data.sensordata[y : y + 5]
        assert dd == pytest.approx(rate, rel=1e-15)  # a few ulps of the velocity transform
        # one rounding of c + δ (ulp(5e-4) = 1e-19; measured 5.4e-20): 1e-18 leaves 9 ulps for the plugin's hypot
        assert d == pytest.approx(delta, abs=1e-18)
        expected_vin = max(approach, laws.MIN_APPROACH_SPEED) if d > 0 else 0.0
        assert vin == expected_vin  # kept from the state, floored
        expected = laws.normal_force(
            law, d, dd, max(vin, laws.MIN_APPROACH_SPEED), stiffness=K, **{"restitution": 1.0, **params}
        )
        # rtol 1e-12: the same operations in the same order; only pow() may differ in its
        # last bit between the C library and NumPy.
        assert fn == pytest.approx(expected, rel=1e-12, abs=0.0)
        expected_t = laws.ambrosio_friction(fn, vt, friction=0.3, v0=V0, v1=V1)
        # Same operations on the sensed F_n; v_t carries the ulps of the velocity transform,
        # which c_d amplifies by |v_t| / (|v_t| - v0) inside the ramp: still far below 1e-12
        # for these samples (v_t ~ 1e-3 m/s has ulp 2e-19).
        assert ft == pytest.approx(expected_t, rel=1e-12, abs=0.0)


@needs_plugin
@pytest.mark.parametrize("moving_bearing", [False, True])
def test_geometry_and_applied_forces(moving_bearing: bool) -> None:
    # A rotated frame: the joint's plane is the bearing site's x-y plane, not the world's.
    quat = np.array([np.cos(0.3), np.sin(0.3) * 0.6, 0.0, np.sin(0.3) * 0.8])
    # RK4: the rates as they are (see test_compiled_laws_equal_laws_py)
    rk4 = mujoco.mjtIntegrator.mjINT_RK4
    model = _spec(LN, friction=0.2, moving_bearing=moving_bearing, frame_quat=tuple(quat), integrator=rk4).compile()
    data = mujoco.MjData(model)
    y = attributes.sensor_address(model, "joint")
    rng = np.random.default_rng(3)
    nb = 3 if moving_bearing else 0  # bearing dofs come first
    for _ in range(20):
        mujoco.mj_resetData(model, data)
        phi = rng.uniform(-np.pi, np.pi)
        ecc = C + rng.uniform(1e-6, 3e-5)
        qb = rng.uniform(-1e-3, 1e-3, nb)
        data.qpos[:nb] = qb
        data.qpos[nb : nb + 3] = [qb[0] if nb else 0, qb[1] if nb else 0, 0]
        data.qpos[nb : nb + 2] += ecc * np.array([np.cos(phi), np.sin(phi)])
        data.qpos[nb + 2] = rng.uniform(-3, 3)
        data.qvel[:] = rng.uniform(-1, 1, model.nv) * ([1, 1, 40] * (model.nv // 3))
        adr = attributes.state_address(model, "joint")
        data.plugin_state[adr + S["in_contact"]] = 1.0  # inside an impact that began at 5 m/s:
        data.plugin_state[adr + S["approach_speed"]] = 5.0  # the LN force stays > 0
        mujoco.mj_forward(model, data)
        fn, ft, delta, rate, _, _, _, sensed_ecc = data.sensordata[y : y + 8]
        n = np.array([np.cos(phi), np.sin(phi)])
        t = np.array([-n[1], n[0]])
        vj, wj = data.qvel[nb : nb + 2], data.qvel[nb + 2]
        vb, wb = (data.qvel[:2], data.qvel[2]) if nb else (np.zeros(2), 0.0)
        # Tolerances: the plugin works in world coordinates through a rotated frame, so each
        # quantity carries a few roundings of its largest term (1e-16 relative; measured 4e-16
        # relative, 2.2e-19 m and 2.2e-16 m/s at most: 1/20 of the bounds or less).
        assert sensed_ecc == pytest.approx(ecc, rel=1e-14)
        assert delta == pytest.approx(ecc - C, abs=1e-17)
        assert rate == pytest.approx(n @ (vj - vb), abs=1e-14)
        vt = t @ (vj - vb) + wj * R_J - wb * (R_J + C)
        assert fn > 0
        mu_cd = 0.2 * np.clip((abs(vt) - V0) / (V1 - V0), 0, 1)
        assert abs(ft) == pytest.approx(mu_cd * fn, rel=1e-12)  # Ambrósio on the rounded v_t
        if abs(vt) > V1:
            assert np.sign(ft) == -np.sign(vt)
        # Forces in frame coordinates: f = -F_n n + F_t t on the journal at R_J n from its
        # centre (torque R_J F_t), -f on the bearing at (R_J + c) n (torque -(R_J + c) F_t).
        f = -fn * n + ft * t
        scale = abs(fn) + abs(ft)
        assert data.qfrc_passive[nb : nb + 2] == pytest.approx(f, abs=1e-12 * scale)
        assert data.qfrc_passive[nb + 2] == pytest.approx(R_J * ft, abs=1e-12 * scale)
        if nb:
            assert data.qfrc_passive[:2] == pytest.approx(-f, abs=1e-12 * scale)
            assert data.qfrc_passive[2] == pytest.approx(-(R_J + C) * ft, abs=1e-12 * scale)


@needs_plugin
def test_frictionless_force_acts_along_the_line_of_centres() -> None:
    model = _spec(LN, moving_bearing=True).compile()
    data = mujoco.MjData(model)
    data.qpos[3:5] = (C + 2e-5) * np.array([0.6, 0.8])
    data.qvel[:] = [0.1, -0.2, 30, 0.5, 0.3, -20]
    mujoco.mj_forward(model, data)
    fn = data.sensordata[attributes.sensor_offsets(model, "joint")["normal_force"]]
    assert fn > 0
    # No moment about either centre: zero up to the rounding of the Jacobian's moment arm
    # (1e-16 of F_n R_J ~ 56 N m; 1e-12 leaves margin and still catches any real lever arm).
    assert data.qfrc_passive[[2, 5]] == pytest.approx([0, 0], abs=1e-12 * fn * R_J)


# ---------------------------------------------------------------- one impact vs the reference


def _normal_impact(model: mujoco.MjModel, speed: float, phase: float, nstep: int) -> tuple:
    """Journal arriving along x at ``speed``, crossing δ = 0 at ``phase`` of a step."""
    data = mujoco.MjData(model)
    data.qpos[0] = C - speed * model.opt.timestep * phase
    data.qvel[0] = speed
    state, sensors = rollout.rollout(model, data, _full_state(model, data), nstep=nstep)
    _no_warnings(data)
    return state[0], sensors[0]


@needs_plugin
@pytest.mark.parametrize(
    ("law", "timestep", "peak_tol"),
    [
        # 0.5 % at 1 us is the brief's target; measured -0.03..+0.02 % (C file header).
        (LN, 1e-6, 5e-3),
        (ContactLaw.FLORES, 1e-6, 5e-3),
        (ContactLaw.HERTZ, 1e-6, 5e-3),
        # The C file claims first impacts within 1 % up to 3 us; measured -0.43..+0.18 % at 4 m/s.
        (LN, 3e-6, 1e-2),
    ],
)
def test_impact_matches_point_mass_reference(law: ContactLaw, timestep: float, peak_tol: float) -> None:
    speed = 2.0
    params = _law_parameters(law)
    ref = law_impact(law, mass=MASS, speed=speed, stiffness=K, restitution=params.get("restitution", 1.0))
    model = _spec(law, timestep=timestep).compile()
    state, sensors = _normal_impact(model, speed, 0.37, int(1.5 * ref.duration / timestep))
    y = attributes.sensor_offsets(model, "joint")
    assert sensors[:, y["normal_force"]].max() == pytest.approx(ref.peak_force, rel=peak_tol)
    separation = -state[-1, 1 + model.nq]  # qvel x after the impact
    # Restitution: measured 0.00..0.05 % at 1..3 us; 0.2 % is four times the worst.
    assert separation / speed == pytest.approx(ref.restitution, rel=2e-3)
    in_contact = sensors[:, y["penetration"]] > 0
    if law is not ContactLaw.HERTZ:
        # Free flight before the impact: interpolating equal rates at the crossing gives the
        # approach speed to rounding.
        np.testing.assert_allclose(sensors[in_contact, y["approach_speed"]], speed, rtol=1e-14)


# ---------------------------------------------------------------- state through rollouts


def _bouncing(
    integrator: mujoco.mjtIntegrator = mujoco.mjtIntegrator.mjINT_EULER, friction: float = 0.1
) -> tuple[mujoco.MjModel, np.ndarray]:
    """A journal bouncing around its bearing (several impacts in 3 ms), and its start state."""
    model = _spec(LN, friction=friction, integrator=integrator).compile()
    data = mujoco.MjData(model)
    data.qvel[:] = [1.0, 0.35, 50.0]
    return model, _full_state(model, data)


@needs_plugin
def test_chunked_and_threaded_rollouts_are_bitwise_equal() -> None:
    model, start = _bouncing()
    data = mujoco.MjData(model)
    whole, whole_y = rollout.rollout(model, data, start, nstep=3000)
    assert np.count_nonzero(np.diff((whole_y[0, :, Y["penetration"]] > 0).astype(int)) == 1) >= 2
    chunks, chunk_y, state = [], [], start
    for n in (1000, 700, 1300):
        s, y = rollout.rollout(model, data, state, nstep=n)
        chunks.append(s)
        chunk_y.append(y)
        state = s[0, -1]  # the full physics state, plugin state included
    # bitwise by construction: the plugin's state travels in the full physics state, and this model has no
    # constraint rows (nefc = 0: the contact is passive force), so the solver's warm start, which these
    # rollout calls do not carry, plays no part
    np.testing.assert_array_equal(np.concatenate(chunks, axis=1), whole)
    np.testing.assert_array_equal(np.concatenate(chunk_y, axis=1), whole_y)

    # Four different starts on 2 threads equal the same on 1 thread, and the first equals a
    # plain mj_step loop: each run is the same single-threaded mj_step sequence from the same state.
    starts = np.repeat(start[None], 4, axis=0)
    starts[:, 1 + model.nq : 1 + model.nq + 2] *= np.array([1.0, 0.9, 1.1, 1.2])[:, None]
    one, one_y = rollout.rollout(model, data, starts, nstep=1500)
    two, two_y = rollout.rollout(model, [mujoco.MjData(model) for _ in range(2)], starts, nstep=1500)
    np.testing.assert_array_equal(one, two)
    np.testing.assert_array_equal(one_y, two_y)
    mujoco.mj_setState(model, data, start, FULL)
    for _ in range(1500):
        mujoco.mj_step(model, data)
    np.testing.assert_array_equal(_full_state(model, data), one[0, -1])
    _no_warnings(data)


@needs_plugin
@pytest.mark.parametrize(
    "integrator",
    [mujoco.mjtIntegrator.mjINT_EULER, mujoco.mjtIntegrator.mjINT_IMPLICITFAST, mujoco.mjtIntegrator.mjINT_RK4],
)
def test_state_is_updated_once_per_step(integrator: mujoco.mjtIntegrator) -> None:
    model, start = _bouncing(integrator, friction=0.0)
    nstep = 3000
    state, sensors = rollout.rollout(model, mujoco.MjData(model), start, nstep=nstep)
    plugin = state[0, -1, -attributes.state_size(model) :]
    assert plugin[S["steps"]] == nstep  # RK4 calls compute 4 times a step, advance once
    # The dissipated work is the sum of h * (F_n - K δⁿ) δ̇ over the force evaluations made at
    # each step's start state, which are exactly what the sensor recorded. Stage evaluations
    # of RK4 (or a double count) would differ by tens of percent; 1e-9 covers the rounding
    # of pow() and of a sum of 3000 terms.
    y = sensors[0]
    d = np.maximum(y[:, Y["penetration"]], 0.0)
    power = (y[:, Y["normal_force"]] - K * d**1.5) * y[:, Y["penetration_rate"]]
    work = model.opt.timestep * power.sum()
    assert work > 0
    assert plugin[S["dissipated_work"]] == pytest.approx(work, rel=1e-9)
    # The sensor's dissipated work is the state's before each step: non-decreasing.
    assert np.all(np.diff(y[:, Y["dissipated_work"]]) >= 0)


# ---------------------------------------------------------------- energy


def _impact_energy(timestep: float, law: ContactLaw) -> tuple[float, float]:
    """Largest relative drift of kinetic + potential (+ dissipated) energy during an impact,
    and its value after separation, for an oblique frictionless impact at 2 m/s."""
    model = _spec(law, timestep=timestep).compile()
    data = mujoco.MjData(model)
    v_start = np.array([2.0, 0.5, 30.0])
    data.qpos[0] = C - v_start[0] * timestep * 0.37
    data.qvel[:3] = v_start
    state, sensors = rollout.rollout(model, data, _full_state(model, data), nstep=int(1.5e-4 / timestep))
    qvel = np.vstack([v_start, state[0, :, 1 + model.nq : 1 + model.nq + 3]])
    # Semi-implicit Euler's velocities sit half a step off its positions: the velocity at a
    # step's start time is the mean of the velocities before and after that step.
    v = 0.5 * (qvel[:-1] + qvel[1:])
    m = np.array([MASS, MASS, INERTIA])
    e0 = 0.5 * m @ v_start**2
    y = sensors[0]
    # The sensor's dissipated work is the work before the step; at the step's start time half
    # of the step's dissipation h (F_n - K δⁿ) δ̇ has taken place.
    d = np.maximum(y[:, Y["penetration"]], 0.0)
    power = (y[:, Y["normal_force"]] - K * d**1.5) * y[:, Y["penetration_rate"]]
    energy = 0.5 * (v**2) @ m + y[:, Y["potential_energy"]] + y[:, Y["dissipated_work"]] + 0.5 * timestep * power
    assert y[-1, Y["penetration"]] < 0  # separated
    end = 0.5 * m @ qvel[-1] ** 2 + state[0, -1, -attributes.state_size(model) + S["dissipated_work"]]
    return float(np.abs(energy / e0 - 1).max()), float(abs(end / e0 - 1))


@needs_plugin
@pytest.mark.parametrize("law", [ContactLaw.HERTZ, LN])
def test_energy_is_conserved_to_the_step_convergence(law: ContactLaw) -> None:
    # HERTZ is LN at c_e = 1 (χ = 0); for LN the dissipated work closes the balance.
    during_h, end_h = _impact_energy(1e-6, law)
    during_h2, end_h2 = _impact_energy(0.5e-6, law)
    # The residual is discretisation error only if it shrinks with the step: during the impact
    # it converges at second order (measured ratio 0.24 per halving, 0.25 expected), after
    # separation at least at first order (measured 0.03 for HERTZ, 0.34 for LN).
    assert during_h2 < 0.3 * during_h
    assert end_h2 < 0.6 * end_h
    # With that convergence the error at 1 us is about the halving difference times 4/3 (second
    # order) or 2 (first order): measured 3.9e-4..4.1e-4 during, 6e-5..1e-4 after; bounds with
    # margin.
    assert during_h < 2 * (during_h - during_h2)
    assert during_h < 1e-3 and end_h < 3e-4


# ---------------------------------------------------------------- packaging


def test_entry_point_is_registered() -> None:
    eps = importlib.metadata.entry_points(group="mujoco.plugins")
    assert any(ep.value == "clearance.contact_plugin:load" for ep in eps)


def test_import_is_cheap() -> None:
    # `import mujoco` imports this package through the entry point: it must not drag in the
    # heavy parts of clearance, scipy or matplotlib, nor import mujoco itself.
    code = (
        "import sys, clearance.contact_plugin; "
        "print(sorted(m for m in ('scipy', 'matplotlib', 'mujoco', 'numpy', "
        "'clearance.contact_calibration', 'clearance.simulation') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_loading_before_mujoco_is_imported() -> None:
    # load() imports mujoco, whose entry point calls load() again: no deadlock, one load.
    code = (
        "import clearance.contact_plugin as cp; cp.load(); cp.load(); "
        "print(cp.is_available() == (cp.library_path() is not None))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120)
    assert out.stdout.strip() == "True"


_CHILD = textwrap.dedent("""
    import mujoco
    model = mujoco.MjModel.from_xml_string(XML)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data)
    queue.put((model.nplugin, model.nsensordata, list(data.sensordata)))
""")


@needs_plugin
def test_spawned_process_that_only_imports_mujoco_can_compile() -> None:
    xml = _xml()
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    child = ctx.Process(target=exec, args=(_CHILD, {"XML": xml, "queue": queue}))
    child.start()
    child.join(timeout=120)  # the result is a few numbers: the queue's pipe holds it
    assert child.exitcode == 0
    nplugin, nsensordata, sensors = queue.get(timeout=10)
    assert (nplugin, nsensordata) == (1, len(attributes.SENSOR_FIELDS))
    assert sensors[Y["penetration"]] == -C  # journal centred at qpos0


@needs_plugin
def test_spec_round_trips_through_xml() -> None:
    spec = mujoco.MjSpec.from_string(f"<mujoco>{_BODIES}</mujoco>")
    attributes.add_journal_bearing(
        spec,
        name="impact",
        journal_site="journal",
        bearing_site="bearing",
        clearance=C,
        journal_radius=R_J,
        law=ContactLaw.IMPACT,
        stiffness=K,
        c_max=IMPACT_C_MAX,
        d_max=IMPACT_D_MAX,
        friction=0.1,
    )
    model = spec.compile()
    again = mujoco.MjSpec.from_string(spec.to_xml()).compile()
    assert again.plugin_attr.tobytes() == model.plugin_attr.tobytes()
    assert attributes.sensor_offsets(again, "impact") == attributes.sensor_offsets(model, "impact")


# ---------------------------------------------------------------- the C side's own checks


_BODIES = """
  <worldbody>
    <site name="bearing"/>
    <body name="journal"><joint type="slide" axis="1 0 0"/><site name="journal"/>
      <inertial pos="0 0 0" mass="0.15" diaginertia="1e-5 1e-5 1e-5"/></body>
  </worldbody>"""
_XML = (
    """
<mujoco>
  <extension><plugin plugin="clearance.journal_bearing"><instance name="joint">
    {config}
  </instance></plugin></extension>"""
    + _BODIES
    + """
  <sensor><plugin name="joint" instance="joint"/></sensor>
</mujoco>"""
)
_GOOD = {
    "journal_site": "journal",
    "bearing_site": "bearing",
    "clearance": "5e-4",
    "journal_radius": "9.5e-3",
    "law": "lankarani_nikravesh",
    "stiffness": "6.61e10",
    "restitution": "0.9",
}


def _xml(**config: str) -> str:
    items = {**_GOOD, **config}
    return _XML.format(config="".join(f'<config key="{k}" value="{v}"/>' for k, v in items.items() if v is not None))


@needs_plugin
def test_c_defaults_and_law_codes() -> None:
    # Absent min_approach_speed, exponent, friction: the C defaults are laws.py's.
    model = mujoco.MjModel.from_xml_string(_xml(law="1"))  # 1 = lankarani_nikravesh
    data = mujoco.MjData(model)
    data.qpos[0] = C + 1e-5
    data.qvel[0] = 1e-6  # a grazing contact with no history: the floor applies
    mujoco.mj_forward(model, data)
    fn, ft, d, dd, vin = data.sensordata[:5]
    assert vin == laws.MIN_APPROACH_SPEED
    assert ft == 0.0
    assert fn == pytest.approx(
        laws.lankarani_nikravesh(d, dd, vin, stiffness=K, restitution=0.9), rel=1e-12
    )  # same operations, as above


@needs_plugin
@pytest.mark.parametrize(
    "config",
    [
        {"clearance": "-1e-4"},
        {"stiffness": "0"},
        {"law": "bogus"},
        {"law": "7"},
        {"bearing_site": "missing"},
        {"restitution": None},
        {"restitution": "1.5"},
        {"journal_radius": "nan"},
        {"v0": "1e-3", "v1": "1e-4"},
        {"clearance": "5e-4x"},
        {"bearing_site": "journal"},
    ],
)
def test_c_init_refuses_bad_config_safely(config: dict[str, str | None]) -> None:
    # Hand-written XML bypasses the Python checks: the C init refuses, MuJoCo raises.
    with pytest.raises(ValueError, match="plugin->init failed"):
        mujoco.MjModel.from_xml_string(_xml(**config))


# ---------------------------------------------------------------- Python validation


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"clearance": -1e-4}, "'joint': clearance must be > 0 [m] (got -0.0001)"),
        ({"clearance": float("nan")}, "clearance must be a finite number > 0 [m] (got nan)"),
        ({"journal_radius": float("inf")}, "journal_radius must be a finite number > 0 [m] (got inf)"),
        ({"stiffness": -1.0}, "stiffness must be > 0 [N/m^n] (got -1.0)"),
        ({"stiffness": "1e10"}, "stiffness must be a finite number > 0 [N/m^n] (got '1e10')"),
        ({"exponent": 0}, "exponent must be > 0 (got 0)"),
        ({"law": "lankarani_nikravesh"}, "law must be a ContactLaw member (got 'lankarani_nikravesh')"),
        ({"journal_site": "nowhere"}, "journal_site = 'nowhere' is not a site of the spec"),
        ({"bearing_site": "journal"}, "are on the same body 'journal'"),
        ({"restitution": None}, "law LANKARANI_NIKRAVESH needs restitution"),
        ({"restitution": 1.2}, "restitution must be in [0, 1] (got 1.2)"),
        ({"law": ContactLaw.FLORES, "restitution": 0.0}, "restitution must be in (0, 1] (got 0.0)"),
        ({"law": ContactLaw.IMPACT}, "law IMPACT needs c_max [N s/m] and d_max [m]"),
        ({"c_max": 1e4}, "used by law IMPACT only, not LANKARANI_NIKRAVESH"),
        ({"friction": -0.1}, "friction must be >= 0 (got -0.1)"),
        ({"v0": 2e-3}, "v1 must be > v0 = 0.002 [m/s] (got 0.001)"),
        ({"min_approach_speed": 0.0}, "min_approach_speed must be > 0 [m/s] (got 0.0)"),
        ({"friction": True}, "friction must be a finite number >= 0 (got True)"),
    ],
)
def test_bad_attributes_are_refused_in_python(change: dict, message: str) -> None:
    spec = mujoco.MjSpec()
    spec.worldbody.add_body(name="bearing").add_site(name="bearing")
    spec.worldbody.add_body(name="journal").add_site(name="journal")
    kw = {
        "name": "joint",
        "journal_site": "journal",
        "bearing_site": "bearing",
        "clearance": C,
        "journal_radius": R_J,
        "law": LN,
        "stiffness": K,
        "restitution": 0.9,
        **change,
    }
    with pytest.raises(ValueError) as err:
        attributes.add_journal_bearing(spec, **kw)
    assert message in str(err.value)
    assert "journal-bearing contact" in str(err.value)
    assert not spec.plugins  # nothing added


@needs_plugin
def test_duplicate_name_and_sensor_lookup() -> None:
    spec = _spec(LN)
    with pytest.raises(ValueError, match="name 'joint' is already used"):
        add_joint(
            spec,
            clearance=C,
            journal_radius=R_J,
            law=ContactLaw.HERTZ,
            stiffness=K,
        )
    model = spec.compile()
    assert attributes.sensor_offsets(model, "joint") == dict(zip(attributes.SENSOR_FIELDS, range(10)))
    assert attributes.state_address(model, "joint") == 0
    with pytest.raises(ValueError, match="no journal-bearing sensor named 'other'"):
        attributes.sensor_address(model, "other")


@needs_plugin
def test_add_for_clearance_uses_the_joint_parameters() -> None:
    spec = mujoco.MjSpec()
    spec.worldbody.add_body(name="bearing").add_site(name="bearing")
    spec.worldbody.add_body(name="journal").add_site(name="journal")
    cl = Clearance(radial_clearance=C, friction=0.05)
    attributes.add_for_clearance(spec, cl, name="j", journal_site="journal", bearing_site="bearing")
    config = spec.plugins[0].config
    assert float(config["stiffness"]) == laws.bearing_stiffness(cl)  # repr round-trips exactly
    assert float(config["journal_radius"]) == cl.journal_radius
    assert config["law"] == "lankarani_nikravesh" and float(config["friction"]) == 0.05


# ---------------------------------------------------------------- no compiler


def test_without_the_library_the_compiled_mode_is_refused(monkeypatch) -> None:
    monkeypatch.setattr(cp, "LIBRARY_FILE", "libmissing_for_this_test.so")
    assert cp.library_path() is None
    assert not cp.is_available()
    cp.load()  # the entry point: silently nothing
    spec = mujoco.MjSpec()
    spec.worldbody.add_body(name="bearing").add_site(name="bearing")
    spec.worldbody.add_body(name="journal").add_site(name="journal")
    with pytest.raises(cp.PluginUnavailableError) as err:
        add_joint(
            spec,
            clearance=C,
            journal_radius=R_J,
            law=LN,
            stiffness=K,
            restitution=0.9,
        )
    message = str(err.value)
    for part in (
        "installed without a C compiler",
        "install a C compiler",
        "reinstall",
        "`--contact-mode calibrated` works without the plugin",
    ):
        assert part in message
    assert not spec.plugins
