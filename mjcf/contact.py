"""Contact parameters into a compiled model (ring pairs, a slider's corner pairs), and the
effective mass at each bearing.

MuJoCo's direct-mode solref ``(-S, -D)`` with a small constant impedance acts as a plain
spring-damper of physical stiffness S / A_hat and damping D / A_hat per contact row, where
A_hat is the row's approximate inverse inertia (the sum of the two bodies'
``body_invweight0`` translational terms, frozen at qpos0) (docs/mujoco_notes.md, re-measured in
tests/test_mjcf.py). So a physical per-row stiffness k is written as S = k A_hat.

The impedance may rise with each row's penetration r instead (`ContactParameters.impedance_rise`
ε > 0): solimp (d(1 − ε), d, c, 0.5, 1), linear from d(1 − ε) at r = 0 to d at r = c, the
radial clearance. MuJoCo's direct-mode row force is then (d(r)/d)² k r + (d(r)/d) b ṙ, so the
row stiffens with its own penetration (benchmarks/ring_bounded_try.md); k and b are the
values at full impedance, r >= c.
"""

from __future__ import annotations

import mujoco
import numpy as np

from clearance.mjcf.guide import GuideGeometry, corner_pair_name
from clearance.mjcf.spec import BuiltModel
from clearance.options import ContactParameters
from clearance.translational import CORNERS

__all__ = [
    "apply_contact",
    "apply_corner_contact",
    "guide_inverse_weight",
    "row_solimp",
    "row_inverse_weight",
    "effective_masses",
    "initial_velocity",
    "add_initial_keyframe",
]


def _body_id(model: mujoco.MjModel, name: str) -> int:
    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
    return 0 if bid < 0 else bid  # ground -> world


def row_inverse_weight(model: mujoco.MjModel, built: BuiltModel, joint: str) -> float:
    """A_hat of the contact rows of a clearance joint [1/kg]."""
    jb = _body_id(model, built.journal_body[joint])
    bb = _body_id(model, built.bearing_body[joint])
    return float(model.body_invweight0[jb, 0] + model.body_invweight0[bb, 0])


def row_solimp(params: ContactParameters, impedance: float, width: float) -> list[float] | None:
    """The contact rows' solimp for ``params``, or None to keep the constant impedance as built.

    Args:
        params: the per-row contact parameters (``impedance_rise`` ε is used).
        impedance: the full impedance d (`ModelOptions.impedance`) [-].
        width: the penetration at which the impedance reaches d [m]: the radial clearance.

    Returns:
        ``[d(1 − ε), d, width, 0.5, 1]`` (power 1: linear in the row's penetration), or None
        for ε = 0.
    """
    eps = params.impedance_rise
    if eps == 0:
        return None
    return [impedance * (1.0 - eps), impedance, float(width), 0.5, 1.0]


def apply_contact(built: BuiltModel, model: mujoco.MjModel, params: dict[str, ContactParameters]) -> None:
    """Write each clearance joint's per-row stiffness, damping and impedance shape into its pairs.

    solref gets (-k Â, -b Â); with ``impedance_rise`` > 0 solimp gets `row_solimp` (the full
    impedance d read from the pair as built, the width the joint's radial clearance), else
    the pair's solimp is left as built. Updates both the compiled ``model`` (in place) and
    ``built.spec`` (for MJCF output).
    """
    pairs = {p.name: p for p in built.spec.pairs}
    for joint, p in params.items():
        a_hat = row_inverse_weight(model, built, joint)
        solref = [-p.stiffness * a_hat, -p.damping * a_hat]
        for i in range(built.rings[joint].segments):
            name = f"{joint}__pair{i:03d}"
            pid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_PAIR, name)
            model.pair_solref[pid] = solref
            pairs[name].solref = solref
            solimp = row_solimp(p, float(pairs[name].solimp[1]), built.rings[joint].radial_clearance)
            if solimp is not None:
                model.pair_solimp[pid] = solimp
                pairs[name].solimp = solimp


def guide_inverse_weight(model: mujoco.MjModel, geometry: GuideGeometry) -> float:
    """Â of a slider corner's contact rows [1/kg]: the slider's and the guide's translational inverse weights."""
    bodies = (geometry.slider_body, geometry.guide_body)
    ids = [max(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b), 0) for b in bodies]
    return float(sum(model.body_invweight0[i, 0] for i in ids))


def apply_corner_contact(
    spec: mujoco.MjSpec, model: mujoco.MjModel, geometry: GuideGeometry, params: ContactParameters
) -> None:
    """Write a slider's per-corner stiffness and damping into its four pairs, as `apply_contact`
    does a ring's: solref (-k Â, -b Â), Â = `guide_inverse_weight` (the pairs keep their small
    constant impedance, so each row is the spring-damper k [N/m], b [N s/m]).

    Updates the compiled ``model`` in place and ``spec`` (for MJCF output).
    """
    a_hat = guide_inverse_weight(model, geometry)
    solref = [-params.stiffness * a_hat, -params.damping * a_hat]
    pairs = {p.name: p for p in spec.pairs}
    for k in range(len(CORNERS)):
        name = corner_pair_name(geometry.joint, k)
        model.pair_solref[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_PAIR, name)] = solref
        pairs[name].solref = solref


def effective_masses(model: mujoco.MjModel, built: BuiltModel) -> dict[str, float]:
    """Mass seen along the contact normal at each bearing at qpos0 [kg].

    1 / (n^T J M^-1 J^T n) for the relative translation J of journal and bearing centres,
    median over normal directions n. Equality constraints and the drive's actuator are not
    included (the calibration issue measures the mass over a cycle with them).
    """
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    out = {}
    for joint in built.rings:
        jac = np.zeros((2, 3, model.nv))
        for k, site in enumerate((f"{joint}__journal", f"{joint}__bearing")):
            sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
            mujoco.mj_jacSite(model, data, jac[k], None, sid)
        jrel = (jac[0] - jac[1])[:2]
        minv_jt = np.zeros((model.nv, 2))
        for c in range(2):
            x = jrel[c].copy()
            mujoco.mj_solveM(model, data, x.reshape(1, -1), jrel[c].reshape(1, -1))
            minv_jt[:, c] = x
        a = jrel @ minv_jt
        ang = np.linspace(0, np.pi, 36, endpoint=False)
        n = np.stack([np.cos(ang), np.sin(ang)], axis=1)
        inv = np.einsum("ni,ij,nj->n", n, a, n)
        out[joint] = float(np.median(1.0 / inv))
    return out


def initial_velocity(model: mujoco.MjModel, built: BuiltModel) -> np.ndarray:
    """qvel (nv,) that gives every link its ideal-mechanism velocity at qpos0.

    Solves J qvel = (v_x, v_y, omega) of every moving link's frame, stacked (a consistent
    over-determined system; least squares makes it exact to round-off).
    """
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rows, rhs = [], []
    names = [n for n in built.tree.order]
    links_order = built.link_order
    for name in names:
        i = links_order.index(name)
        bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        mujoco.mj_jacBody(model, data, jp, jr, bid)
        rows += [jp[0], jp[1], jr[2]]
        rhs += list(built.qd0[3 * i : 3 * i + 3])
    qvel, *_ = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)
    return qvel


def add_initial_keyframe(built: BuiltModel, model: mujoco.MjModel, ctrl: np.ndarray) -> None:
    """Add keyframe ``initial`` (qpos0, ideal velocities, drive controls) to the spec."""
    built.spec.add_key(
        name="initial",
        qpos=list(model.qpos0),
        qvel=list(initial_velocity(model, built)),
        ctrl=list(ctrl),
    )
