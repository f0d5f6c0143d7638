"""Joint reactions over a run: peaks, their times, per-cycle statistics, start-up and steady state.

Works on any `SimulationResult` (MuJoCo or reference solver) that carries
`SimulationResult.joint_reactions` (per joint, the force its link_a exerts on its link_b, world
frame [N]) and on its drive torques. The start-up window is the one every statistic of a run
uses, the first period of the slowest prescribed drive (`Mechanism.drive_period`): the
``steady_*`` values are taken after it; a run no longer than the window has none (NaN).

Cycle statistics take each whole drive period after the window: the peak magnitude in each,
then their mean, smallest and largest (a periodic steady state has all three equal; a
chaotic one spreads them).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields, replace
from functools import partial
from pathlib import Path

import numpy as np

from clearance.results import SimulationResult, atomic_write_text

__all__ = [
    "ReactionSummary",
    "reaction_in_frame",
    "reaction_magnitudes",
    "reaction_statistics",
    "summarise_reactions",
    "write_reactions_csv",
]

_NAN = float("nan")


@dataclass(frozen=True)
class ReactionSummary:
    """Load statistics of one joint's reaction force (or one drive's torque) over a run.

    Attributes:
        name: joint or drive name.
        kind: ``"joint"`` (a force [N]) or ``"drive"`` (a torque [N m], statistics of |torque|).
        unit: ``"N"`` or ``"N m"``.
        peak: largest magnitude over the whole run.
        peak_time: its time [s].
        startup_window: the start-up window [s] (0: none asked for, no steady values).
        steady_peak: largest magnitude after the window (NaN when the run ends within it).
        steady_peak_time: its time [s] (NaN likewise).
        steady_mean, steady_rms, steady_p95: mean, RMS and 95th percentile of the magnitude
            after the window.
        cycles: whole drive periods after the window (0 when no period was given).
        cycle_peak_mean, cycle_peak_min, cycle_peak_max: mean, smallest and largest of the
            per-period peaks (NaN without a whole period).
        ideal_peak, ideal_steady_peak: the ideal twin's peak over its run and after the window
            (NaN without an ideal run).
        steady_peak_ratio: steady_peak / ideal_steady_peak, the dynamic load factor the
            clearance adds in steady state (NaN without either).
    """

    name: str
    kind: str
    unit: str
    peak: float
    peak_time: float
    startup_window: float = 0.0
    steady_peak: float = _NAN
    steady_peak_time: float = _NAN
    steady_mean: float = _NAN
    steady_rms: float = _NAN
    steady_p95: float = _NAN
    cycles: int = 0
    cycle_peak_mean: float = _NAN
    cycle_peak_min: float = _NAN
    cycle_peak_max: float = _NAN
    ideal_peak: float = _NAN
    ideal_steady_peak: float = _NAN
    steady_peak_ratio: float = _NAN

    @property
    def has_steady_state(self) -> bool:
        """Whether the run went on after its start-up window (the steady values exist)."""
        return bool(np.isfinite(self.steady_peak))


def reaction_magnitudes(result: SimulationResult) -> dict[str, np.ndarray]:
    """Joint name -> (n,) magnitude of its reaction [N]; drive name -> (n,) |torque| [N m].

    Joints first (in the mechanism's order), then drives (named as in the result's metadata
    ``drives``, else ``drive<k>``); a drive named like a joint is listed as ``<name> (drive)``.
    """
    return {name: series() for name, series in _magnitude_series(result).items()}


def _magnitude_series(result: SimulationResult) -> dict[str, Callable[[], np.ndarray]]:
    """`reaction_magnitudes`' names, each with a function computing its series when called.

    One series at a time keeps a long run's memory (and its page faults) to one array's worth.
    """
    out: dict[str, Callable[[], np.ndarray]] = {j: partial(_norm, f) for j, f in result.joint_reactions.items()}
    names = list(result.metadata.get("drives") or [f"drive{k}" for k in range(result.drive_torque.shape[1])])
    for k, d in enumerate(names[: result.drive_torque.shape[1]]):
        out[d if d not in out else f"{d} (drive)"] = partial(np.abs, result.drive_torque[:, k])
    return out


def _norm(f: np.ndarray) -> np.ndarray:
    """(n,) length of each row of an (n, 2) array (4 times np.hypot's speed)."""
    return np.sqrt(f[:, 0] ** 2 + f[:, 1] ** 2)


def reaction_statistics(
    times: np.ndarray,
    magnitude: np.ndarray,
    *,
    name: str = "",
    kind: str = "joint",
    startup: float = 0.0,
    period: float | None = None,
) -> ReactionSummary:
    """Statistics of one magnitude series (no ideal values).

    Args:
        times: (n,) [s].
        magnitude: (n,) force [N] or torque [N m] magnitude.
        name: joint or drive name.
        kind: ``"joint"`` or ``"drive"``.
        startup: start-up window [s]; > 0 adds the steady-state statistics after it.
        period: cycle length [s] for the per-cycle peaks (default: ``startup``).

    Returns:
        The `ReactionSummary`.

    Raises:
        ValueError: ``kind`` is neither ``"joint"`` nor ``"drive"``, or times and magnitude
            differ in length.
    """
    if kind not in ("joint", "drive"):
        raise ValueError(f"kind must be 'joint' or 'drive' (got {kind!r})")
    times, magnitude = np.asarray(times, dtype=float), np.asarray(magnitude, dtype=float)
    if times.shape != magnitude.shape:
        raise ValueError(f"times {times.shape} and magnitude {magnitude.shape} must have the same shape")
    peak, peak_time = _peak(times, magnitude)
    out = ReactionSummary(name, kind, "N m" if kind == "drive" else "N", peak, peak_time, float(startup))
    k0 = int(np.searchsorted(times, startup)) if startup > 0 else len(times)
    if not (startup > 0 and k0 < len(times) - 1):
        return out
    ts, ms = times[k0:], magnitude[k0:]
    steady_peak, steady_time = _peak(ts, ms)
    out = replace(
        out,
        steady_peak=steady_peak,
        steady_peak_time=steady_time,
        steady_mean=float(np.mean(ms)),
        steady_rms=float(np.sqrt(np.mean(ms**2))),
        steady_p95=float(np.percentile(ms, 95)),
    )
    period = startup if period is None else period
    peaks = _cycle_peaks(times, magnitude, startup, period) if period and period > 0 else []
    if not peaks:
        return out
    return replace(
        out,
        cycles=len(peaks),
        cycle_peak_mean=float(np.mean(peaks)),
        cycle_peak_min=float(np.min(peaks)),
        cycle_peak_max=float(np.max(peaks)),
    )


def _peak(times: np.ndarray, magnitude: np.ndarray) -> tuple[float, float]:
    """(largest value, its time); NaN for an empty or all-NaN series."""
    if not len(magnitude) or not np.isfinite(magnitude).any():
        return _NAN, _NAN
    k = int(np.nanargmax(magnitude))
    return float(magnitude[k]), float(times[k])


def _cycle_peaks(times: np.ndarray, magnitude: np.ndarray, startup: float, period: float) -> list[float]:
    """Peak of each whole period [startup + c P, startup + (c + 1) P) the rows cover.

    A row at t stands for the step [t, t + h), so rows up to the last one's time plus h count.
    """
    h = float(np.median(np.diff(times[:1025]))) if len(times) > 1 else 0.0  # the sample interval
    count = int(np.floor((times[-1] + h - startup) / period + 1e-9))
    peaks = []
    for c in range(max(count, 0)):
        lo, hi = startup + c * period - 0.5 * h, startup + (c + 1) * period - 0.5 * h
        a, b = np.searchsorted(times, lo, side="left"), np.searchsorted(times, hi, side="left")
        if b > a:
            peaks.append(float(np.nanmax(magnitude[a:b])))
    return peaks


def summarise_reactions(
    result: SimulationResult,
    ideal: SimulationResult | None = None,
    *,
    startup: float = 0.0,
    period: float | None = None,
) -> list[ReactionSummary]:
    """One `ReactionSummary` per joint (mechanism order), then one per drive.

    Args:
        result: a run with joint reactions (a result without them gives only the drives).
        ideal: its ideal twin's run (for ``ideal_*`` and ``steady_peak_ratio``), or None.
        startup: start-up window [s] (the first period of the slowest drive); 0 for none.
        period: cycle length for the per-cycle peaks [s] (default: ``startup``).

    Returns:
        The summaries.
    """
    mags = _magnitude_series(result)
    drives = set(mags) - set(result.joint_reactions)
    ideal_mags = _magnitude_series(ideal) if ideal is not None else {}
    rows = []
    for name, series in mags.items():
        kind = "drive" if name in drives else "joint"
        row = reaction_statistics(result.times, series(), name=name, kind=kind, startup=startup, period=period)
        if ideal is not None and name in ideal_mags:
            ist = reaction_statistics(
                ideal.times, ideal_mags[name](), name=name, kind=kind, startup=startup, period=period
            )
            sp, ip = row.steady_peak, ist.steady_peak
            ratio = sp / ip if np.isfinite(sp) and np.isfinite(ip) and ip > 0 else _NAN
            row = replace(row, ideal_peak=ist.peak, ideal_steady_peak=ip, steady_peak_ratio=ratio)
        rows.append(row)
    return rows


def reaction_in_frame(result: SimulationResult, joint: str, link: str) -> np.ndarray:
    """A joint's reaction expressed in a link's frame, (n, 2) [N].

    For a clearance joint with ``link`` its bearing link, this is the bearing frame of
    ``contact_force`` (the same vector up to sign: the reaction is on link_b, the contact force
    on the journal).

    Args:
        result: a run with joint reactions and link poses (metadata ``links`` names them).
        joint: a joint of the run.
        link: a moving link of the run, or the ground (any name not among the moving links is
            the world frame).

    Raises:
        KeyError: no reaction for ``joint``.
    """
    if joint not in result.joint_reactions:
        raise KeyError(f"no reaction for joint '{joint}' (joints: {sorted(result.joint_reactions)})")
    f = result.joint_reactions[joint]
    links = list(result.metadata.get("links") or [])
    if link not in links:
        return f.copy()
    th = result.link_poses[:, links.index(link), 2]
    c, s = np.cos(th), np.sin(th)
    return np.stack([c * f[:, 0] + s * f[:, 1], -s * f[:, 0] + c * f[:, 1]], axis=1)


def write_reactions_csv(rows: list[ReactionSummary], path: str | Path) -> Path:
    """Write the summaries as CSV (atomically), one row per joint and drive; returns the path."""
    buf = io.StringIO()
    names = [f.name for f in fields(ReactionSummary)]
    w = csv.DictWriter(buf, fieldnames=names)
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in asdict(r).items()})
    atomic_write_text(path, buf.getvalue())
    return Path(path)
