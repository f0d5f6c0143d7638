"""Running what `clearance retrofit` wrote: the retrofitted model and its unmodified twin.

`load_retrofitted` reads a folder (``model.xml``, ``original.xml``, ``retrofit.json``);
`simulate_retrofitted` runs one of its two models under a `Drive` (a control file or the
sinusoid) at the retrofit's time step, both models at the same step and controls, with
`mujoco.rollout` in chunks (`clearance.run.simulation.model_stepper`). A run that raises a
MuJoCo warning, goes non-finite or drives a journal beyond its divergence bound stops with
`SimulationError` naming the time, the hinge (when one is to blame) and a remedy, carrying
the rows before the first bad one.

Rows are the sensor rows of `mujoco.rollout` (row i at t = i h, before step i). Each row
carries every body's world pose (``body_poses``) and, per retrofitted hinge, the journal
centre in its bearing frame (the eccentricity sensor; its rate is the slides' velocities,
whose axes are the bearing frame's), the penetration |e| - c and the net contact force on
the journal rotated into the bearing frame; ``closure_violation`` is the largest residual of
the model's connect equalities (`clearance.retrofit.loop.connect_residual`: what their
constraint rows solve for; a loop closure given play ties body1's anchor to its pin, so it
reads the connect's own softness and the journal's eccentricity reads the play). The world
positions of the sites asked for (a site, or a body's origin where no site has the name:
gymnasium's reacher names its tip a body) are ``outputs`` ``site/<name>/x``, ``/y`` and ``/z``.
A backlash retrofit's run has no journals: per backlashed hinge its outputs
``backlash/<hinge>/angle`` (q_load - q_motor) and ``backlash/<hinge>/torque`` (the stop's torque;
`clearance.run.backlash_readout`).
"""

from __future__ import annotations

import os
import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from clearance.results import SimulationResult
from clearance.retrofit.drive import Drive, drive_controls
from clearance.retrofit.manifest import ROBOT_STEP_MODE, HingeRecord, RetrofitManifest, read_manifest
from clearance.retrofit.motion import initial_data, scalar_coordinates
from clearance.retrofit.play import RetrofitError
from clearance.run.backlash_readout import add_backlash_sensors
from clearance.run.retrofit_rows import RowReader
from clearance.run.retrofit_rows import point_of as point_of
from clearance.run.retrofit_rows import site_output_names as site_output_names
from clearance.run.simulation import SimulationError, StepFailure, model_stepper
from clearance.version import __version__

__all__ = [
    "Retrofitted",
    "load_retrofitted",
    "point_of",
    "retrofitted",
    "simulate_retrofitted",
    "site_output_names",
]


@dataclass
class Retrofitted:
    """A written retrofit, loaded.

    Attributes:
        folder: where it was read from.
        manifest: its ``retrofit.json``.
        model: the retrofitted model (at the retrofit's time step).
        twin: the unmodified model, set to the retrofit's time step (its own is the
            manifest's ``original_timestep``).
    """

    folder: Path
    manifest: RetrofitManifest
    model: mujoco.MjModel
    twin: mujoco.MjModel

    def check_sites(self, sites: Sequence[str]) -> None:
        """`RetrofitError` naming a site (or body) that is not in both models."""
        for name in sites:
            for label, m in (("model.xml", self.model), ("original.xml", self.twin)):
                try:
                    point_of(m, name)
                except KeyError:
                    have = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_SITE, i) for i in range(m.nsite)]
                    have = [h for h in have if h and not h.startswith("clr_")]
                    raise RetrofitError(
                        f"site {name!r} does not exist in {self.folder / label}: name a site "
                        f"({', '.join(have) or 'it has none'}) or a body"
                    ) from None


def load_retrofitted(path: str | os.PathLike[str]) -> Retrofitted:
    """Load the retrofit in folder ``path`` (or the folder of ``path``, a ``model.xml`` in it).

    Raises:
        RetrofitError: no such folder, no ``retrofit.json``, a model that does not compile,
            or models that do not match the record (naming the file).
    """
    p = Path(path)
    folder = p.parent if p.is_file() else p
    if not folder.is_dir():
        raise RetrofitError(f"{p} does not exist (expected a folder written by clearance retrofit)")
    manifest = read_manifest(folder)
    models = []
    for name in (manifest.model, manifest.original):
        file = folder / name
        try:
            spec = mujoco.MjSpec.from_file(str(file))
            if name == manifest.model:
                add_backlash_sensors(spec, manifest.backlash)
            models.append(spec.compile())
        except ValueError as err:
            raise RetrofitError(f"{file} does not compile: {err}") from None
    model, twin = models
    added = 2 * len(manifest.hinges) + len(manifest.backlash)
    if (model.nq, model.nv) != (twin.nq + added, twin.nv + added):
        raise RetrofitError(f"{folder}: model.xml and original.xml do not match {folder / 'retrofit.json'}")
    return retrofitted(folder, manifest, model, twin)


def retrofitted(
    folder: str | os.PathLike[str], manifest: RetrofitManifest, model: mujoco.MjModel, twin: mujoco.MjModel
) -> Retrofitted:
    """A retrofit held in memory (its models compiled; a backlash model with `add_backlash_sensors`),
    both models set to the manifest's time step, as `load_retrofitted` returns one read from files.

    Args:
        folder: where it came from (a model file's folder), for messages and metadata.
        manifest: its record (`clearance.retrofit.output.manifest_of` or `backlash_manifest_of`).
        model, twin: the retrofitted and the unmodified model (their time steps are set here).
    """
    model.opt.timestep = manifest.timestep
    twin.opt.timestep = manifest.timestep
    return Retrofitted(Path(folder), manifest, model, twin)


def simulate_retrofitted(
    loaded: Retrofitted,
    drive: Drive,
    duration: float,
    *,
    twin: bool = False,
    sites: Sequence[str] = (),
    output_interval: float | None = None,
    progress: Callable[[float], None] | None = None,
    chunk_steps: int = 50_000,
    perturbation: float = 0.0,
    every_step: Callable[[np.ndarray, dict[str, tuple[np.ndarray, np.ndarray]]], None] | None = None,
) -> SimulationResult:
    """Run the retrofitted model (or, with ``twin``, the unmodified one) from its first keyframe.

    Args:
        loaded: the retrofit.
        drive: the controls (both models get the same).
        duration: simulated time [s].
        twin: run the unmodified model instead.
        sites: sites whose world positions become outputs (`site_output_names`).
        output_interval: interval of stored rows [s]; default every step.
        progress: called with the fraction done after each chunk.
        chunk_steps: steps per `mujoco.rollout` call.
        perturbation: added to every hinge and slide coordinate of the first keyframe [rad or m]
            (`clearance.run.sensitivity`: a rounding-size nudge that shows chaos); 0: none.
        every_step: called after each chunk with the times of every step kept (rows or not) and,
            per hinge with radial play, its penetration |e| - c [m] and contact-force magnitude [N]
            at each: full-rate peaks and statistics where the rows are thinned.

    Raises:
        ValueError: a bad duration or interval; `RetrofitError` an unknown site (before any work).
        SimulationError: the run diverged or raised a MuJoCo warning (partial result attached).
    """
    if not (isinstance(duration, (int, float)) and np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be a positive number of seconds (got {duration!r})")
    if output_interval is not None and not (np.isfinite(output_interval) and output_interval > 0):
        raise ValueError(f"output_interval must be > 0 s (got {output_interval!r})")
    loaded.check_sites(sites)
    model = loaded.twin if twin else loaded.model
    hinges = () if twin else loaded.manifest.hinges
    backlash = () if twin else loaded.manifest.backlash
    h = float(model.opt.timestep)
    nstep = max(1, int(round(duration / h)))
    every = 1 if output_interval is None else max(1, int(round(output_interval / h)))
    data = initial_data(model)
    if perturbation:
        data.qpos[scalar_coordinates(model)] += perturbation
    reader = RowReader(model, hinges, sites, backlash)
    step = model_stepper(model, data)
    parts: list[SimulationResult] = []
    qpos_before = data.qpos.copy()
    qvel_before = data.qvel.copy()
    t0 = _time.perf_counter()
    done = 0
    while done < nstep:
        n = min(chunk_steps, nstep - done)
        times = (done + np.arange(n)) * h
        ctrl = drive_controls(model, drive, times)
        failure = None
        try:
            states, sens, _ = step(ctrl, n)
        except StepFailure as fail:
            states, sens, failure = fail.states, fail.sens, fail.reason
        k = len(sens)
        q = np.vstack([qpos_before[None], states[: max(k - 1, 0), 1 : 1 + model.nq]])[:k]
        v = np.vstack([qvel_before[None], states[: max(k - 1, 0), 1 + model.nq : 1 + model.nq + model.nv]])[:k]
        bad = _first_bad(reader.penetrations(sens[:k]), hinges, sens[:k], q)
        if bad is None and failure is not None:
            bad = (k, None, failure)
        # only the rows kept are read (poses need a kinematics pass each); the bounds saw every row
        rows = np.arange((-done) % every, k if bad is None else bad[0], every)
        if every_step is not None:
            stop = k if bad is None else bad[0]
            every_step(times[:stop], reader.full_rate(sens[:stop]))
        parts.append(reader.read(times[rows], sens[rows], q[rows], v[rows]))
        if bad is not None:
            idx, joint, why = bad
            result = _finish(parts, loaded, twin, drive, t0, done + idx, every, sites)
            tb = float(done + idx) * h
            where = f" at hinge {joint!r}" if joint else ""
            raise SimulationError(
                f"{'the unmodified model' if twin else 'the retrofitted model'} diverged at t = {tb:.6g} s{where}: "
                f"{why}. Remedy: {_remedy(loaded, twin)}. The result up to t = {tb:.6g} s is attached as .partial.",
                result,
                time=tb,
                joint=joint,
            )
        qpos_before = states[-1, 1 : 1 + model.nq].copy()
        qvel_before = states[-1, 1 + model.nq : 1 + model.nq + model.nv].copy()
        done += n
        if progress is not None:
            progress(done / nstep)
    return _finish(parts, loaded, twin, drive, t0, nstep, every, sites)


def _remedy(loaded: Retrofitted, twin: bool) -> str:
    h = loaded.manifest.timestep
    if twin:
        return f"the unmodified model does not run at the retrofit's step {h:g} s under these controls; check them"
    if not loaded.manifest.hinges:
        return "drive the model more gently (a smaller --sine-amplitude), or give the hinges a wider backlash band"
    if loaded.manifest.contact_mode == ROBOT_STEP_MODE:
        return (
            f"retrofit again with a larger clearance or a smaller --robot-step (now {h * 1e3:g} ms), sized from a "
            "motion as strong as this one (--sizing-control), or drive the model more gently"
        )
    return (
        f"retrofit again with a smaller time step (--timestep-us {h * 1e6 / 2:g}; now {h * 1e6:g}) or more ring "
        "segments (--segments), or drive the model more gently"
    )


def _first_bad(
    penetrations: dict[str, np.ndarray], hinges: Sequence[HingeRecord], sens: np.ndarray, q: np.ndarray
) -> tuple[int, str | None, str] | None:
    """(row, hinge or None, reason) of a chunk's first row beyond a bound or non-finite, or None."""
    n = len(sens)
    finite = np.isfinite(sens).all(axis=1) & np.isfinite(q).all(axis=1)
    first_nan = int(np.argmin(finite)) if not finite.all() else n
    worst: tuple[int, str, float, float] | None = None
    for hr in hinges:
        pen = penetrations[hr.name]
        over = np.nonzero(pen > hr.penetration_limit)[0]
        if len(over) and (worst is None or over[0] < worst[0]):
            worst = (int(over[0]), hr.name, float(pen[over[0]]), hr.penetration_limit)
    if worst is not None and worst[0] <= first_nan:
        return (
            worst[0],
            worst[1],
            f"the journal penetrated {worst[2] * 1e6:.3g} um into its bearing, beyond the bound {worst[3] * 1e6:.3g} "
            "um (4 x the penetration of the sized impact)",
        )
    if first_nan < n:
        return first_nan, None, "the state became non-finite (NaN or Inf)"
    return None


def _finish(
    parts: list[SimulationResult],
    loaded: Retrofitted,
    twin: bool,
    drive: Drive,
    t0: float,
    steps: int,
    every: int,
    sites: Sequence[str],
) -> SimulationResult:
    res = SimulationResult.concatenate(parts)
    model = loaded.twin if twin else loaded.model
    wall = _time.perf_counter() - t0
    m = loaded.manifest
    res.metadata = {
        "solver": "mujoco",
        "mechanism": f"{loaded.folder / (m.original if twin else m.model)}",
        "retrofit": str(loaded.folder),
        "model_kind": "unmodified twin" if twin else "retrofitted",
        "timestep": float(model.opt.timestep),
        "original_timestep": m.original_timestep,
        "contact_mode": m.contact_mode,
        "clearance_joints": [] if twin else [h.name for h in m.hinges],
        "radial_clearance": {} if twin else {h.name: h.radial_clearance for h in m.hinges},
        "backlash": {} if twin else {b.name: b.half_width for b in m.backlash},
        "bodies": [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"#{b}" for b in range(model.nbody)],
        "sites": list(sites),
        "drive": getattr(drive, "source", "") or repr(drive),
        "drives": [],
        "links": [],
        "steps": steps,
        "output_every_steps": every,
        "wall_time_s": float(f"{wall:.4g}"),  # 4 significant digits, as simulate's
        "steps_per_second": float(f"{steps / wall:.4g}") if wall > 0 else None,
        "mujoco_version": mujoco.__version__,
        "package_version": __version__,
    }
    return res
