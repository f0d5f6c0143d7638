"""Radial impacts of a journal on its ring in the one-bearing MuJoCo scene.

The scene (`impact_scene`) is `clearance.mjcf.probe.ring_scene`: the bearing ring fixed to
the world and a journal of mass m on slide x / slide y, with the joint's geoms, segment
count, time step and per-row contact parameters, the impedance shape included (the rows'
solimp as `clearance.mjcf.contact.apply_contact` writes it into a run's model). A journal
starts two steps before first contact with normal speed v along a direction ψ (toward a
segment, ψ = 0, or between two segments, ψ = π/N) and is stepped with `mujoco.rollout`
until well after separation.

Measured quantities, chosen to be the ones a clearance run reports:
  * penetration δ = |e| − c (exact circle geometry, as in `SimulationResult`); its maximum
    is refined by a parabola through the three samples around the largest one;
  * force: the radial net contact force, from the journal's momentum change
    F_k = m (v_{k+1} − v_k)/h, exact for this scene (implicitfast with no passive,
    actuator or gravity force: the only acceleration is the constraint's); its peak is
    refined like δ;
  * duration: from the first to the last instant the ring's actual geometry (the segment
    circles) touches the journal, both crossing times interpolated linearly within a step;
  * restitution: the journal's radial speed after separation over v.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import mujoco.rollout
import numpy as np

from clearance.mjcf.bearing import RingGeometry, segment_centres
from clearance.mjcf.contact import row_solimp
from clearance.mjcf.probe import ring_scene
from clearance.options import ContactParameters, ModelOptions

__all__ = [
    "SceneImpact",
    "impact_scene",
    "ring_gap",
    "onset_radius",
    "scene_impacts",
    "measure_impact",
    "DEFAULT_DIRECTIONS",
]

DEFAULT_DIRECTIONS = (0.0, 0.5)
"""Impact directions as fractions of the segment pitch 2π/N: at a segment, between two."""

_LEAD_STEPS = 2  # free-flight steps before first contact


@dataclass(frozen=True)
class SceneImpact:
    """One MuJoCo impact of the journal on its ring.

    Attributes:
        speed: approach speed v [m/s].
        direction: impact direction ψ [rad] in the bearing frame.
        times: (n,) array [s], 0 at the first contact instant.
        penetration: (n,) array δ = |e| − c [m].
        force: (n,) array radial contact force on the journal [N] (>= 0 pushes it back).
        peak_force: refined maximum force [N].
        max_penetration: refined maximum δ [m].
        duration: contact duration [s] (actual ring geometry).
        restitution: separation speed / approach speed [-].
    """

    speed: float
    direction: float
    times: np.ndarray
    penetration: np.ndarray
    force: np.ndarray
    peak_force: float
    max_penetration: float
    duration: float
    restitution: float


def impact_scene(
    ring: RingGeometry,
    options: ModelOptions,
    params: ContactParameters,
    *,
    mass: float,
    friction: float = 0.0,
) -> mujoco.MjModel:
    """The compiled one-bearing scene with ``params`` as a run's model gets them.

    `clearance.mjcf.probe.ring_scene` (solref (−k Â, −b Â)) with the rows' solimp of
    `clearance.mjcf.contact.row_solimp` when ``params.impedance_rise`` > 0 (full impedance
    d = ``options.impedance``, width the ring's radial clearance), as `apply_contact` writes
    them into a run's pairs: the fit measures what the run does.

    Args:
        ring: ring geometry.
        options: model options (geoms, time step, impedance).
        params: per-row contact parameters.
        mass: journal mass [kg].
        friction: the clearance's friction coefficient [-].
    """
    model = ring_scene(ring, options, params, mass=mass, friction=friction)
    solimp = row_solimp(params, options.impedance, ring.radial_clearance)
    if solimp is not None:
        model.pair_solimp[:] = solimp
    return model


def ring_gap(ring: RingGeometry, position: np.ndarray) -> np.ndarray:
    """Signed distance [m] between journal and nearest segment (< 0: touching).

    Args:
        ring: ring geometry.
        position: (..., 2) journal centre in the bearing frame [m].

    Returns:
        (...) array: min over segments of |e − s_i| − (R_J + r_s).
    """
    s = segment_centres(ring)
    d = np.linalg.norm(np.asarray(position, dtype=float)[..., None, :] - s, axis=-1)
    return d.min(axis=-1) - (ring.journal_radius + ring.segment_radius)


def onset_radius(ring: RingGeometry, direction: float) -> float:
    """Journal-centre radius [m] at which first contact occurs along ``direction`` [rad].

    In closed form: the journal centre r u touches segment i (centre s_i, |s_i| = rho) when
    |r u - s_i| = a = R_J + r_s, first at r_i = s_i.u - sqrt(a^2 - (s_i x u)^2); the onset is the
    smallest r_i over the segments the line meets in front of the centre (c along a segment's
    own direction, where s_i.u = rho and rho - a = c).
    """
    s = segment_centres(ring)
    u = np.array([math.cos(direction), math.sin(direction)])
    along = s @ u
    across = s[:, 0] * u[1] - s[:, 1] * u[0]
    a = ring.journal_radius + ring.segment_radius
    disc = a * a - across * across
    met = (disc >= 0.0) & (along > 0.0)
    return float(np.min(along[met] - np.sqrt(disc[met])))


def _peak(values: np.ndarray) -> tuple[float, int]:
    """Maximum of uniformly sampled values, refined by a parabola through 3 samples."""
    i = int(np.argmax(values))
    if 0 < i < len(values) - 1:
        a, b, c = values[i - 1], values[i], values[i + 1]
        den = a - 2 * b + c
        if den < 0:
            return float(b - 0.25 * (a - c) ** 2 / den), i
    return float(values[i]), i


def _crossing(g0: float, g1: float) -> float:
    """Fraction of a step at which a linear gap g0 -> g1 crosses zero."""
    return g0 / (g0 - g1) if g0 != g1 else 0.0


def _initial_states(
    model: mujoco.MjModel, ring: RingGeometry, speeds: np.ndarray, directions: np.ndarray
) -> np.ndarray:
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    size = mujoco.mj_stateSize(model, spec)
    h = model.opt.timestep
    out = np.zeros((len(speeds) * len(directions), size))
    k = 0
    for v in speeds:
        for psi in directions:
            u = np.array([math.cos(psi), math.sin(psi)])
            r0 = onset_radius(ring, psi) - _LEAD_STEPS * v * h
            mujoco.mj_resetData(model, data)
            data.qpos[:2] = r0 * u
            data.qvel[:2] = v * u
            mujoco.mj_getState(model, data, out[k], spec)
            k += 1
    return out


def scene_impacts(
    model: mujoco.MjModel,
    ring: RingGeometry,
    *,
    mass: float,
    speeds: np.ndarray,
    directions: np.ndarray,
    nstep: int,
) -> list[list[SceneImpact]]:
    """Run radial impacts in a compiled `ring_scene` model, one batched rollout.

    Args:
        model: the scene (journal of ``mass`` on slide x / y, ring on the world).
        ring: the ring geometry the scene was built with.
        mass: journal mass m [kg] (the scene's body mass).
        speeds: (n_v,) approach speeds [m/s] > 0.
        directions: (n_d,) impact directions ψ [rad].
        nstep: steps per impact; must cover the whole contact (checked).

    Returns:
        ``out[i][j]``: the impact at ``speeds[i]`` along ``directions[j]``.

    Raises:
        RuntimeError: an impact did not separate within ``nstep`` steps, or MuJoCo warned
            (a diverged contact).
    """
    speeds = np.asarray(speeds, dtype=float)
    directions = np.asarray(directions, dtype=float)
    h = float(model.opt.timestep)
    init = _initial_states(model, ring, speeds, directions)
    data = mujoco.MjData(model)
    state, _ = mujoco.rollout.rollout(model, data, init, nstep=nstep)
    state = np.concatenate([init[:, None, :], state], axis=1)  # (batch, nstep + 1, nstate)
    qpos, qvel = state[..., 1:3], state[..., 3:5]
    if not np.all(np.isfinite(state)) or int(data.warning.number.sum()) > 0:
        raise RuntimeError(
            "the MuJoCo impact diverged (non-finite state or MuJoCo warning): the contact "
            "parameters are unstable at this time step"
        )
    out: list[list[SceneImpact]] = []
    k = 0
    for v in speeds:
        row = []
        for psi in directions:
            row.append(_measure(qpos[k], qvel[k], ring, mass, h, float(v), float(psi)))
            k += 1
        out.append(row)
    return out


def _measure(
    q: np.ndarray, qd: np.ndarray, ring: RingGeometry, mass: float, h: float, v: float, psi: float
) -> SceneImpact:
    u = np.array([math.cos(psi), math.sin(psi)])
    delta = np.linalg.norm(q, axis=1) - ring.radial_clearance
    return measure_impact(ring_gap(ring, q), delta, qd @ u, mass=mass, h=h, speed=v, direction=psi)


def measure_impact(
    gap: np.ndarray,
    delta: np.ndarray,
    rate: np.ndarray,
    *,
    mass: float,
    h: float,
    speed: float,
    direction: float = 0.0,
) -> SceneImpact:
    """Measure one impact of a stepped scene (the quantities of the module docstring).

    Args:
        gap: (n,) signed distance of the actual geoms at each state [m] (< 0: touching).
        delta: (n,) the penetration a run reports at each state [m].
        rate: (n,) the impacting body's velocity along the approach direction [m/s] (> 0
            approaching): the force during step k is -m (rate[k+1] - rate[k]) / h.
        mass: the impacting mass [kg].
        h: the time step [s].
        speed: the approach speed v [m/s].
        direction: the impact's direction [rad], recorded.

    Raises:
        RuntimeError: no contact, or no separation before the last two states.
    """
    v, psi = speed, direction
    touching = np.flatnonzero(gap < 0)
    if len(touching) == 0:
        raise RuntimeError(f"no contact in the impact at v = {v:g} m/s (direction {psi:.4f} rad)")
    first = int(touching[0])
    after = np.flatnonzero(gap[first:] >= 0)
    if len(after) == 0 or first + int(after[0]) >= len(gap) - 2:
        raise RuntimeError(
            f"the impact at v = {v:g} m/s did not separate within {len(gap) - 1} steps; "
            "the contact parameters are far off (or raise nstep)"
        )
    last = first + int(after[0]) - 1
    t_on = (first - 1 + _crossing(gap[first - 1], gap[first])) * h
    t_off = (last + _crossing(gap[last], gap[last + 1])) * h
    force = -mass * np.diff(rate) / h  # force during step k, from state k
    lo, hi = max(first - 1, 0), min(last + 2, len(force))
    fpk, _ = _peak(force[lo:hi])
    dpk, _ = _peak(delta[lo : hi + 1])
    t = np.arange(len(force)) * h - t_on
    return SceneImpact(
        speed=v,
        direction=psi,
        times=t[lo:hi],
        penetration=delta[lo:hi],
        force=force[lo:hi],
        peak_force=fpk,
        max_penetration=dpk,
        duration=t_off - t_on,
        restitution=-float(rate[last + 2]) / v,
    )
