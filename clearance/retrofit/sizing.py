"""Sizing each bearing from the model itself: loads, effective masses, segments, time step.

The same rules as a mechanism's run (`clearance.run.preparation`), with the loads and masses
measured on the user's model instead of the ideal mechanism's inverse dynamics:

* loads: the in-plane force each hinge carries over the unmodified model's motion
  (`clearance.retrofit.motion`); the median gives the typical Hertz penetration
  (median / K)^(2/3) that the segment rule (`clearance.mjcf.choose_segments`) works at, the
  peak the impact speed sqrt(2 F_peak c / m) (the speed gained crossing the clearance under
  the peak load) and the divergence bound 4 max(δ_impact, (F_peak / K)^(2/3)), δ_impact the
  Hertz penetration of an impact at that speed;
* effective mass: 1 / (nᵀ A n) with A = J W Jᵀ, J the relative in-plane translation of
  journal and bearing centres in the retrofitted model, W its inverse mass matrix with the
  model's equality constraints held, n the load's direction (the direction median where the
  load is below `LIGHT_LOAD` of its peak), at up to `MASS_POSES` poses of the motion: the
  median is what the contact is calibrated at, min and max the range it is valid for;
* time step: the run's stability rule ω h < 2 at the divergence bound, ω = sqrt(k_t / m),
  k_t = 1.5 K sqrt(δ_lim); a retrofit takes ω h <= `STEP_OMEGA_H`, the margin the default
  scenario's 2 µs step has (ω h = 0.22), rounded down to 1, 2 or 5 x 10^k s and never above
  the model's own step.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.contact_calibration.effective_mass import LIGHT_LOAD
from clearance.contact_calibration.laws import bearing_stiffness, contact_omega
from clearance.contact_calibration.torsional_stop import MIN_TIMESTEP
from clearance.mjcf.bearing import RingGeometry, band_ripple, choose_segments
from clearance.model import Clearance
from clearance.retrofit.coordinates import CoordinateMap
from clearance.retrofit.frames import BearingFrame
from clearance.retrofit.motion import Motion
from clearance.retrofit.play import Refusal, RetrofitError
from clearance.retrofit.selection import Hinge

__all__ = [
    "MASS_POSES",
    "STEP_OMEGA_H",
    "PlayMass",
    "PlaySizing",
    "effective_masses",
    "size_play",
    "choose_time_step",
    "check_time_step",
]

MASS_POSES = 36
"""Poses of the motion at which the effective mass is measured."""

STEP_OMEGA_H = 0.2
"""ω h of a chosen time step: the margin of the default scenario's 2 µs step (ω h = 0.22 at its
rod-slider bearing, benchmarks/speed_error.md), a tenth of the stability limit 2."""


@dataclass(frozen=True)
class PlayMass:
    """Effective mass of one bearing over the motion.

    Attributes:
        median, minimum, maximum: over the poses [kg].
        values: (n,) at each pose [kg].
    """

    median: float
    minimum: float
    maximum: float
    values: np.ndarray


@dataclass(frozen=True)
class PlaySizing:
    """Loads and sizes of one retrofitted bearing (what `clearance.contact_calibration` reads).

    Attributes:
        stiffness: journal-bearing stiffness K [N/m^1.5].
        median_load, peak_load: in-plane hinge load over the motion [N].
        typical_penetration: (median_load / K)^(2/3) [m].
        impact_speed: sqrt(2 peak_load c / m_eff) [m/s].
        effective_mass: median over the motion [kg].
        effective_mass_range: (min, max) over the motion [kg].
        penetration_limit: divergence bound [m].
        segments: ring segment count N.
        omega: contact frequency sqrt(k_t / m) at the divergence bound [rad/s].
        ripple: the ring's force ripple over half to twice the typical penetration [-]
            (`clearance.mjcf.bearing.band_ripple`); NaN without a ring (the exact contact).
    """

    stiffness: float
    median_load: float
    peak_load: float
    typical_penetration: float
    impact_speed: float
    effective_mass: float
    effective_mass_range: tuple[float, float]
    penetration_limit: float
    segments: int
    omega: float
    ripple: float = math.nan


def _equality_rows(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    eq = data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    if not np.any(eq):
        return np.zeros((0, model.nv))
    if mujoco.mj_isSparse(model):
        jac = np.zeros((data.nefc, model.nv))
        mujoco.mju_sparse2dense(jac, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind)
    else:
        jac = data.efc_J[: data.nefc * model.nv].reshape(data.nefc, model.nv)
    return np.asarray(jac[eq])


def _mobility(model: mujoco.MjModel, data: mujoco.MjData, hinge: Hinge, frame: BearingFrame) -> np.ndarray:
    """A = J W Jᵀ (2, 2) [1/kg] of the journal centre against the bearing centre, bearing-frame x-y."""
    nv = model.nv
    minv = np.zeros((nv, nv))
    mujoco.mj_solveM(model, data, minv, np.eye(nv))
    g = _equality_rows(model, data)
    w = minv
    if len(g):
        gm = g @ minv
        w = minv - gm.T @ np.linalg.pinv(gm @ g.T, rcond=1e-10) @ gm
    jac = np.zeros((2, 3, nv))
    for k, (body, local) in enumerate(
        ((hinge.child_id, frame.journal.origin), (hinge.parent_id, frame.bearing.origin))
    ):
        rot = data.xmat[body].reshape(3, 3)
        point = data.xpos[body] + rot @ np.asarray(local, dtype=float)
        mujoco.mj_jac(model, data, jac[k], None, point, body)
    axes = data.xmat[hinge.parent_id].reshape(3, 3) @ frame.axes_in_parent
    jrel = axes[:, :2].T @ (jac[0] - jac[1])
    return np.asarray(jrel @ w @ jrel.T)


def effective_masses(
    model: mujoco.MjModel,
    cmap: CoordinateMap,
    hinges: Sequence[Hinge],
    frames: Mapping[str, BearingFrame],
    motion: Motion,
    *,
    n_poses: int = MASS_POSES,
    n_dir: int = 36,
) -> dict[str, PlayMass]:
    """Effective mass at each bearing along its load over the motion (see the module docstring).

    Args:
        model: the retrofitted model (slides in place; the ring is not needed).
        cmap: the unmodified model's coordinates in it.
        hinges: the retrofitted hinges (body ids are the same in both models).
        frames: their bearing frames.
        motion: the unmodified model's motion and loads.
        n_poses: poses, evenly spread over the motion.
        n_dir: directions of the direction median.
    """
    picks = np.unique(np.linspace(0, len(motion.times) - 1, min(n_poses, len(motion.times))).round().astype(int))
    data = mujoco.MjData(model)
    ang = np.linspace(0, np.pi, n_dir, endpoint=False)
    dirs = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    sizes = {h.name: motion.load_size(h.name) for h in hinges}
    out = {h.name: np.zeros(len(picks)) for h in hinges}
    for i, k in enumerate(picks):
        data.qpos[:] = cmap.model_qpos(motion.qpos[k])
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        for h in hinges:
            a = _mobility(model, data, h, frames[h.name])
            size, peak = sizes[h.name][k], float(np.max(sizes[h.name], initial=0.0))
            if peak > 0 and size > LIGHT_LOAD * peak:
                n = motion.loads[h.name][k] / size
                out[h.name][i] = 1.0 / max(float(n @ a @ n), 1e-300)
            else:
                inv = np.einsum("ni,ij,nj->n", dirs, a, dirs)
                out[h.name][i] = float(np.median(1.0 / np.maximum(inv, 1e-300)))
    return {n: PlayMass(float(np.median(v)), float(v.min()), float(v.max()), v) for n, v in out.items()}


def size_play(
    clearance: Clearance,
    loads: np.ndarray,
    mass: PlayMass,
    *,
    segments: int | None,
    ripple_limit: float,
    flat: bool,
) -> PlaySizing:
    """Size one bearing.

    Where no segment count meets the ripple bound (light loads) the rule's least rippled count is
    kept and its ripple recorded: `clearance.retrofit.accuracy` refuses or warns about it.

    Args:
        clearance: the play's physics.
        loads: (n,) in-plane load sizes over the motion [N].
        mass: its effective mass over the motion.
        segments: a fixed segment count (0: no ring, the exact contact), or None for the ripple rule.
        ripple_limit: the rule's largest force ripple [-].
        flat: box segments (flat faces).
    """
    K = bearing_stiffness(clearance)
    c = clearance.radial_clearance
    fmed = float(np.median(loads)) if len(loads) else 0.0
    fmax = float(np.max(loads)) if len(loads) else 0.0
    dtyp = (max(fmed, 1e-3 * max(fmax, 1e-9)) / K) ** (2 / 3) if fmax > 0 else 1e-7
    m = mass.median
    fpk = max(fmax, 1e-9)
    v = math.sqrt(2 * fpk * c / m)
    d_imp = (5 * m * v**2 / (4 * K)) ** 0.4
    lim = 4 * max(d_imp, (fpk / K) ** (2 / 3))
    if segments is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # the rule's fallback: the ripple miss reports it
            segments = choose_segments(clearance.bearing_radius, c, dtyp, ripple_limit=ripple_limit, flat=flat)
    ripple = (
        band_ripple(RingGeometry.make(clearance.bearing_radius, c, segments, flat=flat), dtyp) if segments else math.nan
    )
    return PlaySizing(
        K, fmed, fmax, dtyp, v, m, (mass.minimum, mass.maximum), lim, segments, contact_omega(K, lim, m), ripple
    )


def choose_time_step(sizings: Mapping[str, PlaySizing], model_step: float) -> float:
    """The largest 1, 2 or 5 x 10^k s with ω h <= `STEP_OMEGA_H` at every bearing, at most ``model_step``.

    Raises:
        RetrofitError: the step needed is below `MIN_TIMESTEP` (the backlash stop's floor too), naming the
            hinge with the stiffest bearing.
    """
    omega = max((s.omega for s in sizings.values()), default=0.0)
    if omega <= 0:
        return model_step
    target = STEP_OMEGA_H / omega
    if target < MIN_TIMESTEP:
        name, worst = max(sizings.items(), key=lambda item: item[1].omega)
        raise RetrofitError(
            f"hinge '{name}': its bearing needs a time step of {target:.3g} s (omega = {worst.omega:.4g} rad/s on an "
            f"effective mass of {worst.effective_mass:.3g} kg), below the smallest allowed {MIN_TIMESTEP:g} s: what "
            "the hinge carries is too light for its bearing; give those links their real mass, give the play a softer "
            "material (--youngs-modulus-gpa), or leave this hinge out",
            reason=Refusal.TOO_LIGHT,
            hinge=name,
        )
    exp = math.floor(math.log10(target))
    steps = [float(f"{mant}e{e}") for e in (exp - 1, exp, exp + 1) for mant in (1, 2, 5)]  # decimal values
    return min(max(h for h in steps if h <= target * (1 + 1e-12)), model_step)


def check_time_step(name: str, sizing: PlaySizing, h: float) -> None:
    """Refuse a time step with ω h >= 2 at a bearing (the run's explicit stability limit).

    Raises:
        RetrofitError: naming the hinge, ω h, and the largest stable and the chosen step.
    """
    if sizing.omega * h >= 2.0:
        raise RetrofitError(
            f"time step {h:g} s is too large for the bearing of hinge '{name}': omega*h = {sizing.omega * h:.2f} >= 2 "
            f"at the largest expected penetration ({sizing.penetration_limit * 1e6:.3g} um, effective mass "
            f"{sizing.effective_mass:.3g} kg), so the contact would blow up; use a time step below "
            f"{2.0 / sizing.omega:.3g} s, or leave it out to get {STEP_OMEGA_H / sizing.omega:.3g} s or less"
        )
