"""A minimal MuJoCo scene of one bearing: a journal body free in the plane inside a fixed ring.

Used to measure what the ring does in MuJoCo itself (static force against penetration and
direction, force ripple) and by `clearance.contact_calibration` to run single impacts with
the same geoms, segment count, time step and contact parameters as a full model.
"""

from __future__ import annotations

import mujoco
import numpy as np

from clearance.mjcf.bearing import RingGeometry
from clearance.mjcf.bearing_geoms import Placement, add_journal_and_bearing
from clearance.options import ContactParameters, ModelOptions

__all__ = ["probe_spec", "ring_scene", "static_ring_force", "measured_ripple"]


def probe_spec(
    name: str, body_name: str, timestep: float, *, mass: float, axes: tuple[str, ...]
) -> tuple[mujoco.MjSpec, mujoco.MjsBody]:
    """An empty probe scene and its one body: implicitfast at ``timestep`` [s], no gravity,
    elliptic cones, no auto-reset; the body of ``mass`` [kg] (a tiny explicit inertia) slides
    along each of ``axes`` (of "x", "y"), a slide joint named like its axis.

    Returns:
        (the spec, the body).
    """
    spec = mujoco.MjSpec()
    spec.modelname = name
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = [0, 0, 0]
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
    body = spec.worldbody.add_body(name=body_name)
    body.mass = mass
    body.inertia = [1e-6, 1e-6, 1e-6]
    body.explicitinertial = True
    for axis in axes:
        body.add_joint(name=axis, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[float(axis == "x"), float(axis == "y"), 0])
    return spec, body


def ring_scene(
    ring: RingGeometry,
    options: ModelOptions,
    params: ContactParameters,
    *,
    mass: float = 1.0,
    friction: float = 0.0,
) -> mujoco.MjModel:
    """Compile a scene: bearing ring on the world, journal of ``mass`` [kg] on slide x / y.

    The contact pairs get ``params`` in physical units (S = k A_hat, D = b A_hat).
    """
    spec, body = probe_spec("ring_probe", "journal", options.timestep, mass=mass, axes=("x", "y"))
    centre = Placement((0.0, 0.0, 0.0))
    add_journal_and_bearing(spec, body, spec.worldbody, "ring", centre, centre, ring, options, friction)
    model = spec.compile()
    a_hat = float(model.body_invweight0[1, 0])
    model.pair_solref[:] = [-params.stiffness * a_hat, -params.damping * a_hat]
    return model


def static_ring_force(model: mujoco.MjModel, eccentricity: np.ndarray) -> np.ndarray:
    """Net contact force on the journal [N] at journal positions (n, 2) [m], zero velocity."""
    data = mujoco.MjData(model)
    out = np.zeros((len(eccentricity), 2))
    for i, e in enumerate(np.asarray(eccentricity, dtype=float)):
        data.qpos[:2] = e
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        # the net force on the journal = qfrc_constraint on its two slide dofs
        out[i] = data.qfrc_constraint[:2]
    return out


def measured_ripple(model: mujoco.MjModel, ring: RingGeometry, delta: float, *, n_dir: int = 64) -> float:
    """(max - min) / mean of the radial force over one segment pitch of journal direction."""
    psi = np.linspace(0.0, 2 * np.pi / ring.segments, n_dir, endpoint=False)
    u = np.stack([np.cos(psi), np.sin(psi)], axis=1)
    f = static_ring_force(model, (ring.radial_clearance + delta) * u)
    radial = -(f * u).sum(axis=1)
    return float((radial.max() - radial.min()) / radial.mean())
