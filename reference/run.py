"""`run_reference` and `simulate_system`: the reference solver's public entry points.

Both return the `SimulationResult` every MuJoCo run returns (same fields, frames and
signs), so every analysis and error metric works on both. See `clearance.reference` for
the method.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from clearance.checks import positive
from clearance.contact_calibration.laws import MIN_APPROACH_SPEED, STIFFNESS_FORMULA
from clearance.model import DriveKind, Mechanism
from clearance.reference.corner_contact import CornerContact
from clearance.reference.integrator import (
    METHODS,
    IntegrationFailure,
    Trajectory,
    integrate_system,
)
from clearance.reference.output import assemble_result
from clearance.reference.system import ReferenceSystem
from clearance.results import SimulationResult
from clearance.version import __version__

__all__ = ["Stabilisation", "ReferenceSolverError", "run_reference", "simulate_system"]

Progress = bool | Callable[[float, float], object]
"""False, True for a tqdm bar, or a callable progress(t [s], duration [s])."""


class Stabilisation(enum.Enum):
    """How constraint drift of the ideal joints is held down.

    BAUMGARTE: Baumgarte's terms in the acceleration equation (alpha = beta = 5 1/s by
        default, as in Flores and Ambrósio 2004).
    PROJECTION: mass-weighted projection of positions and velocities onto the constraints
        after any step whose drift exceeds 10 times the largest error weight
        (atol + rtol |y|) of a coordinate (positions) or of a velocity (velocities) at the
        start; the solver then restarts. Default.
    NONE: neither (for measuring drift).
    """

    BAUMGARTE = "baumgarte"
    PROJECTION = "projection"
    NONE = "none"


class ReferenceSolverError(RuntimeError):
    """A reference run failed. ``partial`` holds the `SimulationResult` up to the failure.

    Attributes:
        partial: result up to the last good output sample (None if there is none).
        time: time of the failure [s].
        joint: clearance joint concerned, or None.
    """

    def __init__(self, message: str, partial: SimulationResult | None, *, time: float, joint: str | None) -> None:
        super().__init__(message)
        self.partial, self.time, self.joint = partial, time, joint


def _scales(system: ReferenceSystem, zd0: np.ndarray) -> tuple[float, float, float]:
    """(length L [m], link size ell [m], angular rate Omega [1/s]) that scale tolerances."""
    ell = max(
        [math.hypot(px - lk.com[0], py - lk.com[1]) for lk in system.links for px, py in lk.points.values()] + [1e-3]
    )
    length = min([cj.c for cj in system.contacts], default=1e-3 * ell)
    rates = [abs(d.evaluate(0.0)[1]) for d in system.drives if d.kind is not DriveKind.TORQUE]
    vmax = float(np.max(np.abs(zd0))) if len(zd0) else 0.0
    omega = max(rates + [vmax / ell, 1.0])
    return length, ell, omega


def _default_atol(system: ReferenceSystem, rtol: float, scales: tuple[float, float, float]) -> np.ndarray:
    length, ell, omega = scales
    per_link_pos = [length, length, length / ell]
    per_link_vel = [length * omega, length * omega, length * omega / ell]
    n = len(system.links)
    return rtol * np.array(per_link_pos * n + per_link_vel * n)


def simulate_system(
    system: ReferenceSystem,
    q0: np.ndarray,
    qd0: np.ndarray,
    duration: float,
    *,
    output_interval: float = 1e-5,
    rtol: float = 1e-9,
    atol: float | np.ndarray | None = None,
    method: str = "LSODA",
    stabilisation: Stabilisation | str = Stabilisation.PROJECTION,
    max_penetration: float | None = None,
    track_work: bool = False,
    progress: Progress = False,
) -> SimulationResult:
    """Integrate a `ReferenceSystem` from an explicit initial state.

    Args:
        system: the equations of motion (its Baumgarte gains are used only with
            BAUMGARTE stabilisation).
        q0, qd0: link-frame coordinates (nq,) [m, rad] and velocities [m/s, rad/s] at t = 0.
        duration: simulated time [s] > 0.
        output_interval: output grid spacing [s] > 0 (samples at 0, dt, 2 dt, ...).
        rtol: relative tolerance, in [1e-13, 1e-3].
        atol: absolute tolerance: None (rtol times the clearance, the clearance over the
            link size for angles, and those times the drive speed for velocities), a
            float, or an array of shape (2 nq,) over (z, zd) in centre-of-mass coordinates.
        method: scipy `solve_ivp` method, one of `METHODS`. LSODA (Adams, switching to
            BDF where stiff) measured best: at rtol 1e-9 it places contact onsets 20x
            closer to a rtol 1e-12 solution than DOP853 with 25 % fewer calls
            (benchmarks/reference_speed.md).
        stabilisation: `Stabilisation` or its value. PROJECTION (default) held the closure
            error over the last tenth of long runs 7-20x below Baumgarte's (alpha = beta =
            5 1/s) at about the same cost (benchmarks/reference_speed.md): Baumgarte's 0.2 s
            time constant is slow against a 12 ms revolution.
        max_penetration: penetration [m] treated as divergence; default 5 % of each
            bearing radius, and a slider's whole clearance for its corners.
        track_work: also integrate the work of each drive (metadata ``drive_work``, (n,
            n_drives) [J], and ``energy`` series for the energy balance).
        progress: True for a tqdm bar, or a callable progress(t [s], duration [s]).

    Returns:
        The `SimulationResult` (metadata ``solver`` = "reference").

    Raises:
        TypeError, ValueError: bad arguments (checked before integrating).
        ReferenceSolverError: the run failed; ``.partial`` holds the result so far.
    """
    duration = positive("duration", duration, "s")
    output_interval = positive("output_interval", output_interval, "s")
    if output_interval > duration:
        raise ValueError(f"output_interval ({output_interval:g} s) must not exceed duration ({duration:g} s)")
    rtol = positive("rtol", rtol, "")
    if not 1e-13 <= rtol <= 1e-3:
        raise ValueError(f"rtol must be in [1e-13, 1e-3] (got {rtol!r})")
    if method not in METHODS:
        raise ValueError(f"method must be one of {list(METHODS)} (got {method!r})")
    try:
        stab = Stabilisation(stabilisation)
    except ValueError:
        raise ValueError(
            f"stabilisation must be one of {[s.value for s in Stabilisation]} (got {stabilisation!r})"
        ) from None
    if not (isinstance(progress, bool) or callable(progress)):
        raise TypeError(f"progress must be a bool or a callable (got {progress!r})")
    nq = system.nq
    q0, qd0 = np.asarray(q0, dtype=float), np.asarray(qd0, dtype=float)
    if q0.shape != (nq,) or qd0.shape != (nq,) or not (np.all(np.isfinite(q0)) and np.all(np.isfinite(qd0))):
        raise ValueError(f"q0 and qd0 must be finite arrays of shape ({nq},) (got {q0.shape}, {qd0.shape})")
    z0, zd0 = system.to_com(q0, qd0)
    scales = _scales(system, zd0)
    if atol is None:
        atol_v = _default_atol(system, rtol, scales)
    else:
        atol_v = np.broadcast_to(np.asarray(atol, dtype=float), (2 * nq,)).copy()
        if not np.all(np.isfinite(atol_v) & (atol_v > 0)):
            raise ValueError(f"atol must be positive and finite (got {atol!r})")
    if max_penetration is None:
        limits = [cj.penetration_limit for cj in system.contacts]
    else:
        limits = [positive("max_penetration", max_penetration, "m")] * len(system.contacts)
    if stab is not Stabilisation.BAUMGARTE and (system.alpha or system.beta):
        import copy

        system = copy.copy(system)
        system.alpha = system.beta = 0.0
    proj = None
    if stab is Stabilisation.PROJECTION:
        # 10x the largest error weight the solver allows a coordinate in one step: drift
        # of one step's size never triggers it (no restart cycles), accumulation does
        pos = np.abs(np.concatenate([z0, zd0]))
        weight = atol_v + rtol * pos
        proj = (10.0 * float(weight[:nq].max()), 10.0 * float(weight[nq:].max()))
    close, cb = _progress(progress, duration, system.name)
    try:
        traj = integrate_system(
            system,
            z0,
            zd0,
            duration,
            output_interval=output_interval,
            rtol=rtol,
            atol=atol_v,
            method=method,
            projection=proj,
            track_work=track_work,
            max_penetration=limits,
            progress=cb,
        )
        failure = None
    except IntegrationFailure as exc:
        traj, failure = exc.trajectory, exc
    finally:
        close()
    settings = dict(
        method=method,
        rtol=rtol,
        atol=atol_v.tolist(),
        stabilisation=stab.value,
        output_interval=output_interval,
        duration=duration,
        max_penetration=limits,
    )
    if failure is None:
        return to_result(system, traj, settings)
    partial = to_result(system, traj, settings) if len(traj.times) else None
    remedy = (
        "check the contact parameters and the drive speed, or raise max_penetration"
        if "penetration" in str(failure)
        else "check the mechanism for a singular (dead-centre) position"
        if "singular" in str(failure)
        else "try rtol=1e-8 or method='Radau'"
    )
    raise ReferenceSolverError(
        f"reference run of '{system.name}' failed at t = {failure.time:.9g} s"
        f"{f' (joint {failure.joint!r})' if failure.joint else ''}: {failure}. Remedy: {remedy}. "
        "The result computed so far is attached as .partial.",
        partial,
        time=failure.time,
        joint=failure.joint,
    )


def run_reference(
    mechanism: Mechanism,
    duration: float,
    *,
    output_interval: float = 1e-5,
    rtol: float = 1e-9,
    atol: float | np.ndarray | None = None,
    method: str = "LSODA",
    stabilisation: Stabilisation | str = Stabilisation.PROJECTION,
    baumgarte: tuple[float, float] = (5.0, 5.0),
    min_approach_speed: float = MIN_APPROACH_SPEED,
    friction_v0: float = 1e-4,
    friction_v1: float = 1e-3,
    impact_c_max: float | None = None,
    impact_d_max: float | None = None,
    max_penetration: float | None = None,
    track_work: bool = False,
    progress: Progress = False,
) -> SimulationResult:
    """Run a mechanism with the exact-geometry reference solver.

    Starts from the ideal mechanism assembled at t = 0 with ideal velocities, every
    journal centred in its bearing (Flores and Ambrósio 2004, docs/references.md).

    Args:
        mechanism: the mechanism (any builder's).
        duration: simulated time [s] > 0.
        output_interval: output grid spacing [s].
        rtol, atol, method, stabilisation, max_penetration, track_work, progress: see
            `simulate_system`.
        baumgarte: (alpha, beta) [1/s] for BAUMGARTE stabilisation.
        min_approach_speed: floor [m/s] on the approach speed recorded at contact onset
            (also for a journal already in contact at t = 0); the default is
            `clearance.contact_calibration.MIN_APPROACH_SPEED`, the floor of the exact-LN
            MuJoCo mode.
        friction_v0, friction_v1: Ambrosio's friction thresholds [m/s] (recalled values).
        impact_c_max, impact_d_max: C_max [N s/m] and d_max [m] for IMPACT-law joints.

    Returns:
        The `SimulationResult`.

    Raises:
        TypeError, ValueError: bad arguments (checked before integrating).
        AssemblyError: the mechanism cannot be assembled at t = 0.
        ReferenceSolverError: the run failed; ``.partial`` holds the result so far.
    """
    system = ReferenceSystem(
        mechanism,
        baumgarte=baumgarte,
        min_approach_speed=min_approach_speed,
        friction_v0=friction_v0,
        friction_v1=friction_v1,
        impact_c_max=impact_c_max,
        impact_d_max=impact_d_max,
    )
    positive("duration", duration, "s")
    q0, qd0 = system.initial_state()
    return simulate_system(
        system,
        q0,
        qd0,
        duration,
        output_interval=output_interval,
        rtol=rtol,
        atol=atol,
        method=method,
        stabilisation=stabilisation,
        max_penetration=max_penetration,
        track_work=track_work,
        progress=progress,
    )


def _progress(
    progress: Progress, duration: float, name: str
) -> tuple[Callable[[], None], Callable[[float], None] | None]:
    """(close, callback): what ends the progress display, and the integrator's callback (t [s])."""
    if progress is False:
        return _nothing, None
    if progress is True:
        from clearance.progress import progress_bar

        bar = progress_bar(round(duration * 1e3, 9), unit="ms", desc=f"reference {name}")
        done = [0.0]

        def cb(t: float) -> None:
            bar.update(t * 1e3 - done[0])
            done[0] = t * 1e3

        return bar.close, cb
    report = progress

    def call(t: float) -> None:
        report(t, duration)

    return _nothing, call


def _nothing() -> None:
    """No progress display to close."""


def to_result(system: ReferenceSystem, traj: Trajectory, settings: dict[str, Any]) -> SimulationResult:
    """Turn a `Trajectory` into a `SimulationResult` (see `clearance.results`).

    Args:
        system: the system that produced it.
        traj: the raw solution.
        settings: solver settings recorded in the metadata.
    """
    meta = _metadata(system, traj, settings)
    return assemble_result(system, traj, meta)


def _metadata(system: ReferenceSystem, traj: Trajectory, settings: dict[str, Any]) -> dict[str, Any]:
    """The run's metadata. A slider's four corners are one joint in ``impacts``,
    ``contact_onsets`` ([t, approach speed]) and ``contact_ends``; ``corner_onsets`` and
    ``corner_ends`` add the corner (`clearance.translational.CORNERS`) for sliders, and ``guides``
    each slider's clearance, block size [m] and largest tilt [rad]."""
    mech = system.mechanism
    names = list(dict.fromkeys(system.contact_names))
    onsets: dict[str, list[list[float]]] = {n: [] for n in names}
    ends: dict[str, list[float]] = {n: [] for n in names}
    sliders = {cj.name for cj in system.contacts if isinstance(cj, CornerContact)}
    corner_onsets: dict[str, list[list[float]]] = {n: [] for n in sliders}
    corner_ends: dict[str, list[list[float]]] = {n: [] for n in sliders}
    for t, k, v in traj.onsets:
        cp = system.contacts[k]
        onsets[cp.name].append([t, v])
        if isinstance(cp, CornerContact):
            corner_onsets[cp.name].append([t, v, cp.corner])
    for t, k in traj.ends:
        cp = system.contacts[k]
        ends[cp.name].append(t)
        if isinstance(cp, CornerContact):
            corner_ends[cp.name].append([t, cp.corner])
    return {
        "solver": "reference",
        **settings,
        "baumgarte": [system.alpha, system.beta],
        "mechanism": system.name,
        "parameters": dict(mech.parameters) if mech is not None else {},
        "clearance_joints": [n for n in names if n not in sliders],
        "translational_joints": sorted(sliders, key=names.index),
        "drives": list(system.drive_names),
        "links": list(system.link_names),
        "contact_law": {cj.name: cj.clearance.law.value for cj in system.contacts},
        "restitution": {cj.name: cj.clearance.restitution for cj in system.contacts},
        "friction": {cj.name: cj.mu for cj in system.contacts},
        "stiffness": {cj.name: cj.stiffness for cj in system.contacts},
        "stiffness_formula": STIFFNESS_FORMULA,
        "exponent": {cj.name: cj.exponent for cj in system.contacts},
        "friction_thresholds": [system.options["friction_v0"], system.options["friction_v1"]],
        "impact_c_max": system.options["impact_c_max"],
        "impact_d_max": system.options["impact_d_max"],
        "min_approach_speed": system.min_approach_speed,
        "impacts": {n: len(v) for n, v in onsets.items()},
        "contact_onsets": onsets,
        "contact_ends": ends,
        "corner_onsets": corner_onsets,
        "corner_ends": corner_ends,
        "guides": {
            cj.name: {
                "clearance": cj.clearance.clearance,
                "slider_length": cj.clearance.slider_length,
                "slider_height": cj.clearance.slider_height,
                "max_tilt": cj.clearance.max_tilt,
            }
            for cj in system.contacts
            if isinstance(cj, CornerContact)
        },
        "n_rhs": traj.n_rhs,
        "n_steps": traj.n_steps,
        "n_restarts": traj.n_restarts,
        "n_projections": traj.n_projections,
        "wall_time_s": float(f"{traj.wall_time_s:.4g}"),  # 4 significant digits, as simulate's
        "package_version": __version__,
        "mujoco_version": None,
        "time_step": None,
        "segments": None,
    }
