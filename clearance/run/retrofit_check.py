"""One retrofit operation checked on one model: which hinges are eligible, which are refused and why,
and whether the retrofit of the rest keeps every invariant.

The checks are the retrofit's own (`benchmarks/retrofit_corpus.py` runs them over a fixed list of
third-party robots, ``tests/test_retrofit_corpus.py`` over a few of them copied into the tests):

- each hinge is tried alone: a refusal carries its listed reason (`Refusal`; a backlash stop that
  needs a step below 1e-7 s is `Refusal.TOO_LIGHT` too); a hinge is not eligible by its nature
  (`INELIGIBLE`) where it turns a planar floating base (`Refusal.FLOATING_BASE`: beside two slides in
  a body on the world, a freedom of the base, as a free joint is, with no bearing and no gear) or, for
  backlash, has no actuator of its own (`Refusal.NO_ACTUATOR`); any other refusal is unlisted;
- every accepted hinge at once: the edit compiles and keeps masses (`clearance.retrofit.masses`),
  ranges, reference angles, the softness of every constraint, sensors, actuators and keyframes
  (`clearance.retrofit.conventions`; a break raises RuntimeError, named here); zero play
  reproduces the twin over `DURATION` (`clearance.run.zero_play`, with the twin's own
  sensitivity to a rounding-size nudge, so that chaos is told from a defect); for a ring, every
  ring written to a file and read back within 1 % of c (`clearance.retrofit.output.check_rings`).
  A loop closure's check (a connect given play stays closed) is issue 27's four-bar benchmark
  (`benchmarks/retrofit_invariants.py`); ``loops`` counts a model's connects, so a table can say
  where it would apply.

An exception other than these is a traceback: the check records its type and message.
"""

from __future__ import annotations

import enum
import tempfile
import time
import traceback
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco

from clearance.contact_calibration.torsional_stop import StopStabilityError
from clearance.options import ContactMode
from clearance.retrofit.backlash import add_backlash
from clearance.retrofit.output import write_retrofit
from clearance.retrofit.pipeline import retrofit
from clearance.retrofit.play import Backlash, RadialPlay, Refusal, RetrofitError, RetrofitOptions, SineControl
from clearance.run.play_candidates import end_effector
from clearance.run.simulation import SimulationError
from clearance.run.zero_play import ZERO_BAND, ZeroPlay, backlash_at_zero, radial_at_zero, zero_play

__all__ = ["DRIVE", "DURATION", "INELIGIBLE", "Operation", "OperationCheck", "check_operation", "refusal_of"]

DURATION = 0.1
"""The zero-play check's span [s]."""

DRIVE = SineControl(amplitude=0.1)
"""The check's motion: a tenth of each control half-range at 1 Hz. At the sizing default of one half,
robosuite's open-loop torque ranges spin a wrist to hundreds of rad/s within 0.1 s (IIWA: 300 rad/s,
kN of unbalance on its last bearing), where a play's whirl changes the phase of the spin and no
geometric bound holds; a tenth keeps every corpus arm below 30 rad/s."""


INELIGIBLE = frozenset({Refusal.NO_ACTUATOR, Refusal.FLOATING_BASE})
"""Reasons that make a hinge ineligible by its nature, not refused by the retrofit's limits."""


class Operation(enum.Enum):
    """A retrofit operation: the kind of play and what makes its contact or stop."""

    RADIAL_EXACT = "radial exact"
    BACKLASH_EXACT = "backlash exact"
    RADIAL_CALIBRATED = "radial calibrated"
    BACKLASH_CALIBRATED = "backlash calibrated"

    @property
    def radial(self) -> bool:
        """Radial play (else backlash)."""
        return self in (Operation.RADIAL_EXACT, Operation.RADIAL_CALIBRATED)

    @property
    def exact(self) -> bool:
        """The compiled exact contact or stop (else a calibrated ring or stop)."""
        return self in (Operation.RADIAL_EXACT, Operation.BACKLASH_EXACT)


@dataclass
class OperationCheck:
    """What one operation did on one model.

    Attributes:
        operation: the operation.
        hinges: every hinge of the model, in joint order.
        ineligible: hinge -> why it cannot take this play by its nature (`INELIGIBLE`).
        refused: hinge -> its listed reason, or the message of an unlisted refusal.
        accepted: hinges retrofitted together for the invariants.
        broken: the invariant that broke, with its numbers (None: none broke).
        tracebacks: unexpected exceptions, one line each (type and message).
        zero_play: the zero-play check of the accepted hinges (None where not reached).
        timestep: the retrofitted model's step [s] (None where not reached).
        seconds: wall time of the whole check [s].
        loops: the model's connect equalities (loop closures).
    """

    operation: Operation
    hinges: list[str]
    ineligible: dict[str, Refusal] = field(default_factory=dict)
    refused: dict[str, Refusal | str] = field(default_factory=dict)
    accepted: list[str] = field(default_factory=list)
    broken: str | None = None
    tracebacks: list[str] = field(default_factory=list)
    zero_play: ZeroPlay | None = None
    timestep: float | None = None
    seconds: float = 0.0
    loops: int = 0

    @property
    def eligible(self) -> list[str]:
        """Hinges eligible for this play (refused ones included)."""
        return [h for h in self.hinges if h not in self.ineligible]

    @property
    def unlisted(self) -> dict[str, str]:
        """Refusals without a listed reason."""
        return {h: r for h, r in self.refused.items() if isinstance(r, str)}

    @property
    def passed(self) -> bool:
        """Every accepted hinge kept every invariant, every refusal is listed and nothing raised."""
        return self.broken is None and not self.tracebacks and not self.unlisted


def refusal_of(err: BaseException) -> Refusal | None:
    """The listed reason of a refusal (a backlash stop below the smallest step is `Refusal.TOO_LIGHT`), or None."""
    if isinstance(err, RetrofitError):
        return err.reason
    if isinstance(err, StopStabilityError):
        return Refusal.TOO_LIGHT
    return None


def _hinges(model: mujoco.MjModel) -> list[str]:
    return [
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        for j in range(model.njnt)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE and mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
    ]


def _trial(spec: mujoco.MjSpec, hinge: str, operation: Operation) -> None:
    """The edit of one hinge alone (the check's play sizes; a ring at the default play, as a user gets it)."""
    if operation is Operation.RADIAL_CALIBRATED:
        retrofit(spec, {hinge: RadialPlay()}, RetrofitOptions(sizing_duration=0.3, measure_speed=False))
    elif operation.radial:
        radial_at_zero(spec, [hinge], ContactMode.EXACT)
    else:
        add_backlash(spec, {hinge: Backlash(ZERO_BAND, stop="exact" if operation.exact else "calibrated")})


def _line(err: BaseException) -> str:
    return f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"


def _rings(spec: mujoco.MjSpec, hinges: Sequence[str]) -> None:
    """Rings at the default play (kept whatever their accuracy) written and read back (RuntimeError if off)."""
    options = RetrofitOptions(sizing_duration=0.3, measure_speed=False, accept_inaccurate=True)
    with tempfile.TemporaryDirectory() as folder:
        write_retrofit(retrofit(spec, dict.fromkeys(hinges, RadialPlay()), options), folder)


def check_operation(
    spec: mujoco.MjSpec,
    operation: Operation,
    *,
    drive: SineControl = DRIVE,
    duration: float = DURATION,
    hinges: Sequence[str] | None = None,
) -> OperationCheck:
    """Run ``operation``'s eligibility, refusals and invariants on ``spec`` (module docstring).

    Args:
        spec: the model (not changed).
        operation: what to check.
        drive: the zero-play run's controls.
        duration: the zero-play run's span [s].
        hinges: the hinges to try (default every hinge of the model, in joint order).

    Returns:
        The outcome; nothing raises (an unexpected exception is in ``tracebacks``).
    """
    start = time.perf_counter()
    model = spec.copy().compile()
    connects = int((model.eq_type == mujoco.mjtEq.mjEQ_CONNECT).sum()) if model.neq else 0
    out = OperationCheck(operation, list(hinges) if hinges is not None else _hinges(model), loops=connects)
    try:
        _check(spec, out, drive, duration)
    except Exception as err:  # a traceback is an outcome the corpus counts
        out.tracebacks.append(_line(err) + " | " + traceback.format_exc().strip().splitlines()[-2].strip())
    out.seconds = time.perf_counter() - start
    return out


def _check(spec: mujoco.MjSpec, out: OperationCheck, drive: SineControl, duration: float) -> None:
    operation = out.operation
    for hinge in out.hinges:
        try:
            _trial(spec, hinge, operation)
        except (RetrofitError, StopStabilityError) as err:
            reason = refusal_of(err)
            if reason in INELIGIBLE:
                out.ineligible[hinge] = reason
            else:
                out.refused[hinge] = reason if reason is not None else _line(err)
            continue
        except RuntimeError as err:  # an invariant of the edit itself (masses, conventions)
            out.broken = f"{hinge} alone: {err}"
        out.accepted.append(hinge)
    if not out.accepted or out.broken:
        return
    try:
        if operation.radial:
            mode = ContactMode.EXACT if operation.exact else ContactMode.CALIBRATED
            loaded = radial_at_zero(spec, out.accepted, mode)
        else:
            loaded = backlash_at_zero(spec, out.accepted, "exact" if operation.exact else "calibrated")
    except RuntimeError as err:
        out.broken = f"edit: {err}"
        return
    out.timestep = loaded.manifest.timestep
    site = end_effector(loaded.twin, out.accepted, avoid=list(out.refused))
    try:
        out.zero_play = z = zero_play(loaded, drive, duration, site, output_interval=1e-4, chaos=True)
    except SimulationError as err:
        out.broken = f"zero play: the run stopped ({_line(err)})"
        return
    if not z.holds:
        kind = "chaotic twin" if z.chaotic else "drift"
        out.broken = (
            f"zero play: {site} {z.deviation * 1e6:.3g} um from the twin, bound {z.bound * 1e6:.3g} um ({kind}; "
            f"twin nudged by rounding: {(z.sensitivity or 0) * 1e6:.3g} um)"
        )
        return
    if operation is Operation.RADIAL_CALIBRATED:
        try:
            _rings(spec, out.accepted)
        except RuntimeError as err:
            out.broken = f"ring precision: {err}"
