"""Backlash at the robot's own time step: the step-limited stop where it represents the band, refused elsewhere.

`add_robot_step_backlash` gives actuated hinges backlash in a model that runs at the user's
step h (1–10 ms): the motor side, the load side and the band ±b of `add_backlash` (MuJoCo's
two-hinge recipe, built by it with the band, ``ref``, the limits and the sensors copied), with
the band's tendon limit made the step-limited stop of `clearance.retrofit.step_stop` (spring
time constant 2 h, damping ratio fitted to the compiled exact stop's rebound and impulse per
impact at h). The written model is stock MJCF: no engine plugin.

Where it represents the band: the retrofitted model runs the sizing motion (the sinusoid or
control file a retrofit sizes from) at h, and each band's fastest closing and deepest
penetration are read from its limit's rows. The stop represents the band where its
penetration at that closing speed, ``step_stop.smallest_band``, is at most
`step_stop.MAX_PENETRATION` of b. Otherwise the request is refused, naming the largest step
at which the asked bands are represented and the smallest band represented at every hinge at
the asked step; since the closing speed grows with the band and changes with the step, each is
found by re-running the sizing motion on a ladder of values a user can type back (`LADDER`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from clearance.checks import of_type, positive
from clearance.contact_calibration.torsional_stop import MeshLaw
from clearance.retrofit.backlash import BacklashRetrofit, add_backlash
from clearance.retrofit.motion import control_signal, initial_data
from clearance.retrofit.play import MAX_BACKLASH, Backlash, ControlTable, RetrofitError, SineControl
from clearance.retrofit.step_stop import (
    MAX_PENETRATION,
    StepStop,
    fit_step_stop,
    largest_step,
    smallest_band,
    step_omega,
)

__all__ = [
    "ROBOT_STEP_STOP",
    "SETTLE",
    "STEP_FLOOR",
    "BandAtStep",
    "RobotStepBacklash",
    "SizingRun",
    "add_robot_step_backlash",
    "LADDER",
    "ladder",
    "largest_common_step",
    "set_robot_step",
    "sizing_closings",
    "smallest_common_band",
]

ROBOT_STEP_STOP = "robot-step"
"""The stop kind recorded on a band closed by the step-limited stop."""

SETTLE = 0.02
"""A step counts as below the asked one when it is at least this fraction [-] smaller."""

STEP_FLOOR = 0.05
"""The smallest step a refusal tries, as a fraction [-] of the asked step."""

LADDER = (1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)
"""Mantissas of the bands [arcmin] and steps [ms] a refusal tries: values a user can type back."""

_LIMIT = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON)


@dataclass(frozen=True)
class BandAtStep:
    """One band at the robot's step.

    Attributes:
        hinge: the hinge. half_width: b [rad] (as asked: copied, never fitted).
        closing_speed: fastest closing under the sizing motion at the step [rad/s] (the drive's
            estimate, `backlash_stop.impact_speed`, where the band never closed).
        penetration: deepest penetration into the stop in that run [rad].
        smallest_band: smallest b the stop represents at this closing speed and step [rad].
        largest_step: largest step at which the stop represents b at this closing speed [s].
    """

    hinge: str
    half_width: float
    closing_speed: float
    penetration: float
    smallest_band: float
    largest_step: float


@dataclass
class RobotStepBacklash:
    """A model with backlash at the robot's step, and why its stops represent the bands.

    Attributes:
        retrofit: the model and its twin, both at the robot's step (`BacklashRetrofit`; its
            bands' stops recorded as `ROBOT_STEP_STOP`).
        robot_step: h [s]. stop: the step-limited stop fitted at h (one for every band: with
            the same mesh law it does not depend on the inertia).
        bands: hinge -> its band at h.
        sizing: the sizing motion on the written model (for `smallest_common_band`, `largest_common_step`).
    """

    retrofit: BacklashRetrofit
    robot_step: float
    stop: StepStop
    bands: dict[str, BandAtStep]
    sizing: SizingRun


def sizing_closings(
    model: mujoco.MjModel,
    tendons: Sequence[int],
    control: SineControl | ControlTable,
    duration: float,
) -> tuple[np.ndarray, np.ndarray, int]:
    """(fastest closing [rad/s], deepest penetration [rad], impacts) per band of ``model`` under ``control``.

    The model runs ``duration`` [s] at its step from its first keyframe (or qpos0); a closing is
    the band's rate when its tendon limit's row appears, the penetration |q_load - q_motor| - b
    while it is there.
    """
    n = max(1, int(round(duration / model.opt.timestep)))
    u = control_signal(model, control, np.arange(n) * model.opt.timestep)
    where = {int(t): k for k, t in enumerate(tendons)}
    fastest, deepest = np.zeros(len(tendons)), np.zeros(len(tendons))
    touching = np.zeros(len(tendons), dtype=bool)
    impacts = 0
    data = initial_data(model)
    for i in range(n):
        data.ctrl[:] = u[i]
        mujoco.mj_step(model, data)  # efc and ten_* describe the state the step started from
        now = np.zeros(len(tendons), dtype=bool)
        for r in range(data.nefc):
            k = where.get(int(data.efc_id[r]), -1) if data.efc_type[r] == _LIMIT else -1
            if k >= 0:
                now[k] = True
                t = tendons[k]
                deepest[k] = max(deepest[k], abs(float(data.ten_length[t])) - float(model.tendon_range[t, 1]))
                if not touching[k]:
                    impacts += 1
                    fastest[k] = max(fastest[k], abs(float(data.ten_velocity[t])))
        touching = now
    return fastest, deepest, impacts


def set_robot_step(model: mujoco.MjModel, tendons: Sequence[int], stop: StepStop, step: float) -> None:
    """Put a compiled ``model`` at ``step`` [s] with its bands' stops (``tendons``) scaled to it.

    The step-limited stop at another step is the same dimensionless stop: ω̂ = 1/(2 h), ζ unchanged
    (`clearance.retrofit.step_stop`).
    """
    model.opt.timestep = positive("step", step, "s")
    model.tendon_solref_lim[list(tendons)] = (1.0 / (step_omega(step) * stop.dampratio), stop.dampratio)


@dataclass(frozen=True)
class SizingRun:
    """The sizing motion of one retrofitted model: what each re-run at another band or step shares.

    Attributes:
        model: the compiled model (its band ranges and step are changed during a search, then restored).
        tendons: its bands' tendon ids. estimates: the drive's closing-speed estimate per band [rad/s].
        control: the sizing motion. duration: its length [s].
    """

    model: mujoco.MjModel
    tendons: list[int]
    estimates: np.ndarray
    control: SineControl | ControlTable
    duration: float

    def speeds(self) -> tuple[np.ndarray, np.ndarray]:
        """(closing speed [rad/s], deepest penetration [rad]) per band: the fastest closing, or the estimate
        where a band never closed."""
        fastest, deepest, _ = sizing_closings(self.model, self.tendons, self.control, self.duration)
        return np.where(fastest > 0, fastest, self.estimates), deepest


def ladder(lo: float, hi: float) -> list[float]:
    """The values of `LADDER` x 10^k in [lo, hi], ascending (a band [arcmin] or a step [ms] a user can type)."""
    out = []
    for k in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
        out += [m * 10.0**k for m in LADDER if lo <= m * 10.0**k <= hi]
    return sorted(set(out))


def _represented(run: SizingRun, stop: StepStop) -> bool:
    """Whether every band of ``run.model`` as it is now is represented at its step (penetration criterion)."""
    v, _ = run.speeds()
    widths = run.model.tendon_range[run.tendons, 1]
    scale = float(run.model.opt.timestep) / stop.timestep  # the penetration per speed goes with the step
    return all(scale * smallest_band(stop, float(s)) <= b for s, b in zip(v, widths, strict=True))


def smallest_common_band(run: SizingRun, stop: StepStop, *, lo_arcmin: float = 1.0) -> float | None:
    """Smallest half-width [arcmin] on `ladder` from ``lo_arcmin`` to `MAX_BACKLASH` that ``stop``
    represents when every band has it, or None.

    Each candidate re-runs the sizing motion (the closing speed grows with the band and is not
    monotonic in it: the first represented rung is the answer, and asking for it again runs the
    same motion). The model's ranges are restored afterwards.
    """
    saved = run.model.tendon_range.copy()
    try:
        for b in ladder(lo_arcmin, math.degrees(MAX_BACKLASH) * 60):
            run.model.tendon_range[run.tendons] = (-math.radians(b / 60), math.radians(b / 60))
            if _represented(run, stop):
                return b
        return None
    finally:
        run.model.tendon_range[:] = saved


def largest_common_step(run: SizingRun, stop: StepStop, *, down_to: float = STEP_FLOOR) -> float | None:
    """Largest step [ms] on `ladder` below ``stop``'s, down to ``down_to`` of it, at which it represents
    every band of ``run.model``, or None.

    The step changed on the compiled model (its stops scaled, `set_robot_step`); the model's step
    and stops are restored afterwards.
    """
    try:
        for h in reversed(ladder(down_to * stop.timestep * 1e3, stop.timestep * 1e3 * (1 - SETTLE))):
            set_robot_step(run.model, run.tendons, stop, h * 1e-3)
            if _represented(run, stop):
                return h
        return None
    finally:
        set_robot_step(run.model, run.tendons, stop, stop.timestep)


def _arcmin(rad: float) -> str:
    return f"{math.degrees(rad) * 60:.3g}'"


def add_robot_step_backlash(
    spec: mujoco.MjSpec,
    joints: Mapping[str, Backlash],
    *,
    robot_step: float,
    control: SineControl | ControlTable | None = None,
    duration: float = 1.0,
    refuse: bool = True,
) -> RobotStepBacklash:
    """Give actuated hinges backlash at the robot's step ``robot_step``, or refuse where it is not represented.

    Args:
        spec: the user's model (not changed).
        joints: hinge name -> its backlash (the band, the mesh law; its ``stop`` must be left at
            the default: the step-limited stop replaces it).
        robot_step: the step the model will run at, h [s].
        control: the sizing motion (default `SineControl()`).
        duration: the sizing motion's length [s].
        refuse: raise where a band is not represented (default); False returns the model and
            its measures anyway (a study of the region: `smallest_common_band`, `largest_common_step`).

    Returns:
        The model at h (twin at h too) with each band's step-limited stop, and each band's
        closing speed, penetration, smallest band and largest step.

    Raises:
        RetrofitError: a band the stop does not represent at h (naming the largest step for the
            bands and the smallest band for the step), a backlash asking for another stop, bands
            with different mesh laws, and every refusal of `add_backlash`.
        ValueError: a step or duration that is not a positive number.
    """
    h = positive("robot_step", robot_step, "s")
    result = _build(spec, joints, h, control, positive("duration", duration, "s"))
    stop = result.stop
    bands = list(result.bands.values())
    if not refuse or all(b.smallest_band <= b.half_width for b in bands):
        return result
    worst = max(bands, key=lambda b: b.smallest_band / b.half_width)
    step = largest_common_step(result.sizing, stop)
    band = smallest_common_band(result.sizing, stop)
    raise RetrofitError(
        f"hinge '{worst.hinge}': a +-{_arcmin(worst.half_width)} band is not represented at a {h * 1e3:g} ms step "
        f"(the step-limited stop would sink {worst.smallest_band / worst.half_width * MAX_PENETRATION:.2g} b at its "
        f"fastest closing {worst.closing_speed:.3g} rad/s under the sizing motion; at most {MAX_PENETRATION:g} b): "
        + (
            f"no step down to {STEP_FLOOR * h * 1e3:g} ms represents these bands"
            if step is None
            else f"the largest usable step for these bands is {step:g} ms"
        )
        + f"; at {h * 1e3:g} ms "
        + (
            "no band up to 10 degrees is represented"
            if band is None
            else f"the smallest band is {band:g} arcmin at every hinge"
        ),
        hinge=worst.hinge,
    )


def _build(
    spec: mujoco.MjSpec,
    joints: Mapping[str, Backlash],
    h: float,
    control: SineControl | ControlTable | None,
    t_run: float,
) -> RobotStepBacklash:
    """The model at step ``h`` [s] with its step-limited stops, and each band's measures under the sizing motion."""
    of_type("joints", joints, Mapping, "a mapping hinge name -> Backlash")
    for name, play in joints.items():
        of_type(f"joints[{name!r}]", play, Backlash, f"a Backlash (the backlash of hinge '{name}')")
        if play.stop != "calibrated":
            raise RetrofitError(
                f"hinge '{name}': stop {play.stop!r} with a robot step; the step-limited stop replaces it (leave "
                "the stop at its default)"
            )
    laws = {(p.mesh_stiffness, p.restitution, p.mesh_exponent) for p in joints.values()}
    if len(laws) > 1:
        raise RetrofitError("a robot step needs one mesh law (mesh_stiffness, restitution) for every band")
    at_step = spec.copy()
    at_step.option.timestep = h
    out = add_backlash(at_step, {name: replace(play, stop="recipe") for name, play in joints.items()})
    first = next(iter(out.hinges.values()))
    stop = fit_step_stop(
        MeshLaw(*next(iter(laws))),
        timestep=h,
        integrator=int(out.model.opt.integrator),
        inertia=first.stop.inertia,
        # the gear mesh's n = 1 rebounds alike at every speed: fit at 1 rad/s, so that the stop, and the sizing
        # motion it is measured with, do not change with the band asked for (the closings are chaotic)
        speed=1.0 if first.backlash.mesh_exponent == 1 else first.stop.impact_speed,
    )
    for x in out.hinges.values():
        band = out.spec.tendon(x.tendon)
        band.solref_limit = list(stop.solref)
        band.solimp_limit = list(stop.solimp)
    out.model = out.spec.compile()
    run = SizingRun(
        out.model,
        [int(out.model.tendon(x.tendon).id) for x in out.hinges.values()],
        np.array([x.stop.impact_speed for x in out.hinges.values()]),
        SineControl() if control is None else control,
        t_run,
    )
    speeds, depths = run.speeds()
    records = {}
    for k, (name, x) in enumerate(out.hinges.items()):
        out.hinges[name] = replace(
            x, stop=replace(x.stop, kind=ROBOT_STEP_STOP, solref=stop.solref, solimp=stop.solimp)
        )
        b, v = x.backlash.half_width, float(speeds[k])
        records[name] = BandAtStep(name, b, v, float(depths[k]), smallest_band(stop, v), largest_step(stop, b, v))
    out.notes = [n for n in out.notes if not n.startswith("hinge '")] + [_note(stop, r) for r in records.values()]
    return RobotStepBacklash(out, h, stop, records, run)


def _note(stop: StepStop, band: BandAtStep) -> str:
    """One line on a band at the robot's step."""
    return (
        f"hinge '{band.hinge}': band +-{_arcmin(band.half_width)} closed by the step-limited stop at "
        f"{stop.timestep * 1e3:g} ms (solref {stop.solref[0]:.4g} {stop.solref[1]:.4g}, rebound "
        f"{100 * stop.rebound_error:+.1f} % and impulse {100 * stop.impulse_error:+.1f} % against the exact stop); "
        f"fastest closing {band.closing_speed:.3g} rad/s, deepest {band.penetration / band.half_width:.2f} b; "
        f"smallest band at this step {_arcmin(band.smallest_band)}, largest step for this band "
        f"{band.largest_step * 1e3:.3g} ms"
    )
