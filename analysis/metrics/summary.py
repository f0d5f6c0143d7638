"""Per-joint contact statistics and output deviation: the numbers of `summary.csv`.

Works on any `SimulationResult` (MuJoCo or reference solver).
"""

from __future__ import annotations

import csv
import io
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from clearance.results import SimulationResult, atomic_write_text

__all__ = [
    "JointSummary",
    "contact_series",
    "joint_summary",
    "rms_deviation",
    "summarise",
    "summary_of_series",
    "write_summary_csv",
]


@dataclass(frozen=True)
class JointSummary:
    """Contact statistics of one clearance joint over a run, or of one slider with play (its deepest
    corner's penetration, the net contact force on the slider: `summarise`).

    Attributes:
        joint: joint name.
        peak_force: largest contact-force magnitude [N].
        p95_force: 95th percentile of the force magnitude over in-contact samples [N].
        peak_force_time: time of the peak [s].
        impacts: number of contact onsets (penetration crossing zero upwards).
        contact_fraction: fraction of samples in contact [-].
        max_penetration: largest penetration [m].
        output_rms_deviation: RMS of (output - ideal output) of the first output over the
            whole run [m or rad] (NaN without an ideal result).
        startup_window: the start-up window [s] (the first period of the slowest prescribed
            drive): the ``steady_*`` values are taken after it; 0 when none was asked for.
        steady_peak_force, steady_p95_force, steady_impacts, steady_contact_fraction,
            steady_max_penetration: the same statistics over the steady state only (after
            the start-up window, where the journal released from the bearing centre makes
            its first, largest impacts); NaN (impacts -1) when the run is no longer than
            the window.
        steady_output_rms_deviation: the RMS deviation of the first output over the steady
            state only [m or rad], the one the report and ``deviation.png`` give; NaN
            without an ideal result or a steady state.
    """

    joint: str
    peak_force: float
    p95_force: float
    peak_force_time: float
    impacts: int
    contact_fraction: float
    max_penetration: float
    output_rms_deviation: float
    startup_window: float = 0.0
    steady_peak_force: float = float("nan")
    steady_p95_force: float = float("nan")
    steady_impacts: int = -1
    steady_contact_fraction: float = float("nan")
    steady_max_penetration: float = float("nan")
    steady_output_rms_deviation: float = float("nan")

    @property
    def has_steady_state(self) -> bool:
        """Whether the run went on after its start-up window (the steady values exist)."""
        return self.steady_impacts >= 0


def rms_deviation(result: SimulationResult, ideal: SimulationResult, output: str, *, since: float = 0.0) -> float:
    """RMS of result - ideal for one output, the ideal interpolated on the result's times.

    Args:
        result: a run.
        ideal: its ideal twin's run.
        output: the output's name.
        since: only the samples at or after this time [s] (0: the whole run).

    Returns:
        The RMS deviation [the output's unit]; NaN when no sample is at or after ``since``.
    """
    k0 = int(np.searchsorted(result.times, since)) if since > 0 else 0
    if k0 >= len(result.times):
        return float("nan")
    times = result.times[k0:]
    ref = np.interp(times, ideal.times, ideal.outputs[output])
    return float(np.sqrt(np.mean((result.outputs[output][k0:] - ref) ** 2)))


def contact_series(result: SimulationResult, joint: str) -> tuple[np.ndarray, np.ndarray]:
    """Penetration and contact-force magnitude of a clearance joint or of a slider with play.

    A slider counts as in contact while any corner is: its penetration is the deepest
    corner's, its force the net contact force on the slider.

    Args:
        result: a run.
        joint: one of its clearance joints (`SimulationResult.joints`) or sliders with play
            (`SimulationResult.sliders`).

    Returns:
        penetration (n,) [m] (> 0 in contact) and force magnitude (n,) [N].

    Raises:
        KeyError: a name that is neither.
    """
    if joint in result.joints:
        jr = result.joints[joint]
        return jr.penetration, jr.force_magnitude
    if joint in result.sliders:
        sr = result.sliders[joint]
        return sr.corner_penetration.max(axis=1), np.hypot(sr.contact_force[:, 0], sr.contact_force[:, 1])
    raise KeyError(
        f"no clearance joint or slider with play {joint!r} (have {list(result.joints)} and {list(result.sliders)})"
    )


def joint_summary(
    result: SimulationResult,
    joint: str,
    *,
    deviation: float = float("nan"),
    startup: float = 0.0,
    steady_deviation: float = float("nan"),
) -> JointSummary:
    """Contact statistics of ``joint`` (see `JointSummary`).

    Args:
        result: a run.
        joint: name of one of its clearance joints or sliders with play (`contact_series`).
        deviation: RMS deviation of the output from ideal over the whole run, carried into the
            summary [m or rad].
        startup: start-up window [s]; > 0 adds the steady-state statistics after it.
        steady_deviation: the same over the steady state [m or rad], carried into the summary
            where the run has a steady state.

    Returns:
        The joint's `JointSummary`.
    """
    penetration, force = contact_series(result, joint)
    return summary_of_series(
        joint,
        result.times,
        penetration,
        force,
        deviation=deviation,
        startup=startup,
        steady_deviation=steady_deviation,
    )


def summary_of_series(
    joint: str,
    times: np.ndarray,
    penetration: np.ndarray,
    force: np.ndarray,
    *,
    deviation: float = float("nan"),
    startup: float = 0.0,
    steady_deviation: float = float("nan"),
) -> JointSummary:
    """`joint_summary` of a joint's series: a run's rows, or every step of a run whose rows are thinned.

    Args:
        joint: the joint's name.
        times: (n,) [s]. penetration: (n,) |e| - c [m]. force: (n,) contact-force magnitude [N].
        deviation, startup, steady_deviation: as `joint_summary`'s.
    """
    f = force
    contact = penetration > 0
    onsets = int(np.count_nonzero(contact[1:] & ~contact[:-1]) + (1 if len(contact) and contact[0] else 0))
    k = int(np.argmax(f)) if len(f) else 0
    nan = float("nan")
    s_peak, s_p95, s_impacts, s_fraction, s_pen = nan, nan, -1, nan, nan
    k0 = int(np.searchsorted(times, startup)) if startup > 0 else len(f)
    if startup > 0 and k0 < len(f) - 1:
        fs, cs = f[k0:], contact[k0:]
        before = bool(contact[k0 - 1]) if k0 > 0 else False  # an onset needs the sample before it
        s_peak = float(fs.max())
        s_p95 = float(np.percentile(fs[cs], 95)) if cs.any() else 0.0
        s_impacts = int(np.count_nonzero(cs[1:] & ~cs[:-1]) + (1 if cs[0] and not before else 0))
        s_fraction = float(cs.mean())
        s_pen = float(penetration[k0:].max())
    return JointSummary(
        joint=joint,
        peak_force=float(f.max()) if len(f) else 0.0,
        p95_force=float(np.percentile(f[contact], 95)) if contact.any() else 0.0,
        peak_force_time=float(times[k]) if len(f) else float("nan"),
        impacts=onsets,
        contact_fraction=float(contact.mean()) if len(contact) else 0.0,
        max_penetration=float(penetration.max()) if len(f) else 0.0,
        output_rms_deviation=deviation,
        startup_window=startup,
        steady_peak_force=s_peak,
        steady_p95_force=s_p95,
        steady_impacts=s_impacts,
        steady_contact_fraction=s_fraction,
        steady_max_penetration=s_pen,
        steady_output_rms_deviation=steady_deviation if s_impacts >= 0 else float("nan"),
    )


def summarise(
    result: SimulationResult, ideal: SimulationResult | None = None, *, startup: float = 0.0
) -> list[JointSummary]:
    """One `JointSummary` per clearance joint, then one per slider with play (in contact while any
    corner is: its penetration is the deepest corner's, its force the net contact force on the
    slider); the deviation uses the first output.

    Args:
        result: a run.
        ideal: its ideal twin's run, for the output deviation (None: NaN).
        startup: start-up window [s]; > 0 adds each joint's steady-state statistics after it.
    """
    outputs = [k for k in result.outputs if not k.endswith(("_vel", "_acc"))]
    nan = float("nan")
    dev = rms_deviation(result, ideal, outputs[0]) if (ideal is not None and outputs) else nan
    steady = (
        rms_deviation(result, ideal, outputs[0], since=startup)
        if (ideal is not None and outputs and startup > 0)
        else nan
    )
    joints = [*result.joints, *result.sliders]
    return [joint_summary(result, j, deviation=dev, startup=startup, steady_deviation=steady) for j in joints]


def write_summary_csv(rows: list[JointSummary], path: str | Path) -> Path:
    """Write the summary rows as CSV (atomically); returns the path."""
    buf = io.StringIO()
    fields = list(JointSummary.__dataclass_fields__)
    w = csv.DictWriter(buf, fieldnames=fields)
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in asdict(r).items()})
    atomic_write_text(path, buf.getvalue())
    return Path(path)
