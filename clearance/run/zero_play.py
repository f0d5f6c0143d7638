"""Zero play reproduces the twin: one check that catches a locked joint, a wrong reference angle,
an open loop or a wrong frame in a retrofit.

A retrofit given (almost) no play must move as the unmodified model does. With a radial
clearance of `ZERO_CLEARANCE` (1 µm, the exact contact; `ZERO_RING_CLEARANCE`, 10 µm, for a
ring) at every hinge and loop closure, or a backlash band of `ZERO_BAND` (0.1 arc-minute), a
point of the model (the end effector) may drift from the twin's by no more than `FACTOR` times
the geometric play: the sum of the clearances c, or of b times the largest distance from each
backlashed hinge's axis to the point over the twin's run. A joint locked by a range in the
wrong units, a band that starts off its centre, a loop that opens or a bearing in the wrong
frame moves it by orders of magnitude more.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.options import ContactMode
from clearance.results import SimulationResult
from clearance.retrofit.backlash import add_backlash
from clearance.retrofit.drive import Drive
from clearance.retrofit.output import backlash_manifest_of, manifest_of
from clearance.retrofit.pipeline import retrofit
from clearance.retrofit.play import Backlash, RadialPlay, RetrofitOptions
from clearance.run.backlash_readout import add_backlash_sensors
from clearance.run.retrofitted import Retrofitted, retrofitted, simulate_retrofitted, site_output_names
from clearance.run.sensitivity import CHAOS_SHARE, point_distance, twin_sensitivity

__all__ = [
    "FACTOR",
    "ZERO_BAND",
    "ZERO_CLEARANCE",
    "ZERO_RING_CLEARANCE",
    "ZeroPlay",
    "backlash_at_zero",
    "geometric_play",
    "radial_at_zero",
    "zero_play",
]

ZERO_CLEARANCE = 1e-6
"""Radial clearance of the zero-play check with the exact contact [m]."""

ZERO_RING_CLEARANCE = 1e-5
"""Radial clearance of the zero-play check with a ring [m]: 6 written digits of its centimetre offsets
hold it to 0.5 % of that (a 1 um ring would miss the 1 % the written rings are held to), and its
calibration sees penetrations it can resolve."""

ZERO_BAND = math.radians(0.1 / 60)
"""Backlash half-width of the zero-play check [rad] (0.1 arc-minute)."""

FACTOR = 10.0
"""How many times the geometric play the point may drift from the twin's [-]."""


@dataclass(frozen=True)
class ZeroPlay:
    """The zero-play check of one retrofit.

    Attributes:
        site: the point watched (a site, or a body's origin).
        duration: simulated time [s].
        deviation: largest distance between the point in the retrofitted model and in the twin [m].
        play: the geometric play at the point (module docstring) [m].
        sensitivity: how far the point of the twin drifts under a rounding-size nudge of its start
            [m] (`clearance.run.sensitivity`), None where not measured.
    """

    site: str
    duration: float
    deviation: float
    play: float
    sensitivity: float | None = None

    @property
    def bound(self) -> float:
        """`FACTOR` x the geometric play [m]."""
        return FACTOR * self.play

    @property
    def holds(self) -> bool:
        """Whether the point stayed within the bound."""
        return self.deviation <= self.bound

    @property
    def chaotic(self) -> bool:
        """Whether the twin is chaotic at the check's scale: nudged by rounding, it drifts `CHAOS_SHARE` of the
        bound or more (then a drift beyond the bound cannot be told from chaos); False where not measured."""
        return self.sensitivity is not None and self.sensitivity >= CHAOS_SHARE * self.bound


def _points(result: SimulationResult, site: str) -> np.ndarray:
    """(n, 3) world positions of ``site`` over a run."""
    return np.column_stack([result.outputs[name] for name in site_output_names(site)])


def geometric_play(loaded: Retrofitted, twin_run: SimulationResult, site: str) -> float:
    """The play at ``site``: the radial clearances, plus each band's b times the largest distance from
    its hinge's axis to the point over the twin's run (body poses and site positions rows) [m]."""
    play = sum(h.radial_clearance for h in loaded.manifest.hinges)
    if not loaded.manifest.backlash:
        return play
    twin, point = loaded.twin, _points(twin_run, site)
    for b in loaded.manifest.backlash:
        j = twin.joint(b.name).id
        poses = twin_run.body_poses[:, int(twin.jnt_bodyid[j])]  # the twin's run: its own body order
        axis = np.zeros((len(poses), 3))
        anchor = np.zeros((len(poses), 3))
        mat = np.zeros(9)
        for i, pose in enumerate(poses):
            mujoco.mju_quat2Mat(mat, pose[3:])
            r = mat.reshape(3, 3)
            anchor[i] = pose[:3] + r @ twin.jnt_pos[j]
            axis[i] = r @ twin.jnt_axis[j]
        arm = point - anchor
        radius = np.linalg.norm(arm - np.sum(arm * axis, axis=1)[:, None] * axis, axis=1)
        play += b.half_width * float(radius.max())
    return play


def zero_play(
    loaded: Retrofitted,
    drive: Drive,
    duration: float,
    site: str,
    *,
    output_interval: float | None = None,
    chaos: bool = False,
) -> ZeroPlay:
    """Run a retrofit given (almost) no play and its twin under ``drive``; how far ``site`` drifts.

    Args:
        loaded: the retrofit (its plays should be `ZERO_CLEARANCE`, `ZERO_RING_CLEARANCE` or
            `ZERO_BAND`: the bound is relative to what it has).
        drive: the controls of both runs.
        duration: simulated time [s] (0.1 s is the check's).
        site: a site or body of both models (`clearance.run.retrofitted.point_of`).
        output_interval: rows kept [s] (the drift is read on them; default every step).
        chaos: also run the twin nudged by rounding (`clearance.run.sensitivity`: ``sensitivity``).

    Raises:
        SimulationError: a run diverged (the check fails loudly).
    """
    runs: Sequence[SimulationResult] = [
        simulate_retrofitted(loaded, drive, duration, twin=twin, sites=[site], output_interval=output_interval)
        for twin in (False, True)
    ]
    drift = float(np.max(point_distance(runs[0], runs[1], site)))
    nudged = twin_sensitivity(loaded, drive, runs[1], site, output_interval=output_interval) if chaos else None
    return ZeroPlay(
        site,
        duration,
        drift,
        geometric_play(loaded, runs[1], site),
        None if nudged is None else nudged.max_distance,
    )


def radial_at_zero(spec: mujoco.MjSpec, joints: Sequence[str], mode: ContactMode, *, segments: int = 64) -> Retrofitted:
    """``spec`` with radial play of `ZERO_CLEARANCE` (exact) or `ZERO_RING_CLEARANCE` (a ring of ``segments``,
    kept whatever its accuracy: the check is where the model moves) at ``joints``, in memory.

    Raises:
        RetrofitError: the joints cannot take radial play.
    """
    exact = mode is ContactMode.EXACT
    options = RetrofitOptions(
        contact_mode=mode,
        segments=None if exact else segments,
        sizing_duration=0.3,
        measure_speed=False,
        accept_inaccurate=True,
    )
    play = RadialPlay.make(ZERO_CLEARANCE if exact else ZERO_RING_CLEARANCE)
    r = retrofit(spec, dict.fromkeys(joints, play), options)
    return retrofitted(".", manifest_of(r), r.model, r.twin)


def backlash_at_zero(spec: mujoco.MjSpec, joints: Sequence[str], stop: str) -> Retrofitted:
    """``spec`` with a `ZERO_BAND` of backlash at ``joints`` closed by ``stop`` (`Backlash.stop`), in memory.

    Raises:
        RetrofitError: the joints cannot take backlash.
    """
    edit = add_backlash(spec, {j: Backlash(ZERO_BAND, stop=stop) for j in joints})
    manifest = backlash_manifest_of(edit)
    work = edit.spec.copy()
    add_backlash_sensors(work, manifest.backlash)
    return retrofitted(".", manifest, work.compile(), edit.twin)
