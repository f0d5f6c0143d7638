"""Scenes of the compiled-contact tests: a body free to move in the plane of its bearing; a
prepared mechanism stepped by `mujoco.rollout` and read as a run."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from mujoco import rollout

from clearance.contact_plugin import attributes
from clearance.results import SimulationResult
from clearance.run.preparation import PreparedModel
from clearance.run.readout import read_sensors

PLANAR_DOFS = (("x", "SLIDE", (1, 0, 0)), ("y", "SLIDE", (0, 1, 0)), ("spin", "HINGE", (0, 0, 1)))
"""(suffix, joint type, axis) of a planar body's three dofs."""


def planar_body(
    parent: mujoco.MjsBody, name: str, *, mass: float, inertia: float, prefix: str = "", moving: bool = True
) -> mujoco.MjsBody:
    """A body on slide x, slide y and hinge z (joints ``prefix + suffix``; none, fixed to its
    parent, when not ``moving``), its explicit mass and inertia [kg, kg m²], and a site of its
    own name at its origin."""
    body = parent.add_body(name=name)
    for suffix, kind, axis in PLANAR_DOFS if moving else ():
        body.add_joint(name=f"{prefix}{suffix}", axis=list(axis), type=getattr(mujoco.mjtJoint, f"mjJNT_{kind}"))
    body.explicitinertial = True
    body.mass = mass
    body.inertia = [inertia] * 3
    body.add_site(name=name)
    return body


def add_joint(spec: mujoco.MjSpec, **attrs: Any) -> None:
    """A journal-bearing contact named ``joint`` between the sites ``journal`` and ``bearing``
    (`attributes.add_journal_bearing` with ``attrs``)."""
    attributes.add_journal_bearing(spec, name="joint", journal_site="journal", bearing_site="bearing", **attrs)


def rolled_out(prepared: PreparedModel, data: mujoco.MjData, n: int) -> tuple[SimulationResult, np.ndarray, np.ndarray]:
    """``n`` steps of a prepared model from ``data``'s state at its keyframe's controls, read as a run.

    Returns:
        The run (`read_sensors` of the rollout's rows, row i at t = i h), the raw sensor rows
        (n, nsensordata) and the full-physics state rows (n, state size; row i after step i).
    """
    model = prepared.model
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    start = np.empty(mujoco.mj_stateSize(model, full))
    mujoco.mj_getState(model, data, start, full)
    states, sens = rollout.rollout(model, data, start[None], model.key_ctrl[0][None, None], nstep=n)
    run = read_sensors(prepared, np.arange(n) * model.opt.timestep, sens[0], states[0])
    return run, sens[0], states[0]
