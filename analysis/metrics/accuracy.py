"""Accuracy of a run against a reference run: first impacts point by point, the rest by statistics.

Clearance-joint responses are chaotic (docs/references.md, "The default scenario, measured"): two exact solutions that
differ only in integration details separate after a few milliseconds. So a run is compared
with the reference in two ways:

* point by point over the first impact of each clearance joint, which is deterministic
  (`first_impact`, `separation_time`): onset time, peak contact force, maximum penetration
  and impulse;
* by statistics over a steady-state window (`run_statistics`): per-revolution peak contact
  force, 95th percentile of the in-contact force, fraction of time in contact, impacts per
  revolution, RMS output deviation from the exact ideal mechanism, and the distribution of
  the journal eccentricity |e| (mean, spread, 10th/50th/90th percentiles). Each statistic
  carries its own scatter, estimated by batch means: the window is cut into blocks of whole
  revolutions, the statistic is taken per block, and the standard error of the
  whole-window value is std(blocks)/sqrt(blocks).
  That is the run-to-run scatter a statistic of this length has (runs that differ only in
  integration details sample the same attractor independently once they separate).

Works on any `SimulationResult` (MuJoCo or the reference solver).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass

import numpy as np

from clearance.results import JointResult, SimulationResult

__all__ = [
    "ECC_PERCENTILES",
    "FORCE_QUANTILES",
    "STATISTICS",
    "FirstImpact",
    "Statistic",
    "distributions",
    "first_impact",
    "first_impact_errors",
    "run_statistics",
    "separation_time",
    "statistic_errors",
    "statistics_as_dict",
]

STATISTICS: dict[str, str] = {
    "peak_force": "per-revolution peak contact force (mean over revolutions) [N]",
    "p95_force": "95th percentile of the contact force while in contact [N]",
    "contact_fraction": "fraction of time in contact [-]",
    "impacts_per_rev": "contact onsets per drive revolution [-]",
    "rms_deviation": "RMS deviation of the output from the exact ideal mechanism [output unit]",
    "ecc_mean": "mean journal eccentricity |e| [m]",
    "ecc_std": "standard deviation of |e| [m]",
    "ecc_p10": "10th percentile of |e| [m]",
    "ecc_p50": "median of |e| [m]",
    "ecc_p90": "90th percentile of |e| [m]",
}
"""Statistic name -> meaning, per clearance joint (the deviation is of the mechanism)."""


@dataclass(frozen=True)
class FirstImpact:
    """The first contact event of a clearance joint (penetration > 0 without a break).

    Attributes:
        joint: joint name.
        onset: time of the first sample in contact [s].
        peak_force: largest contact-force magnitude during the event [N].
        max_penetration: largest penetration during the event [m].
        impulse: integral of the force magnitude over the event (trapezoid) [N s].
        end: time of the last sample in contact [s].
    """

    joint: str
    onset: float
    peak_force: float
    max_penetration: float
    impulse: float
    end: float


@dataclass(frozen=True)
class Statistic:
    """A statistic of a run with its batch-means standard error.

    Attributes:
        value: the statistic over the whole window.
        scatter: standard error of ``value`` from the spread of per-block values.
        blocks: number of blocks.
        block_values: the statistic in each block.
    """

    value: float
    scatter: float
    blocks: int
    block_values: tuple[float, ...] = ()


def first_impact(result: SimulationResult, joint: str) -> FirstImpact | None:
    """The first contact event of ``joint``, or None if it never touches.

    Args:
        result: a run.
        joint: clearance joint name.

    Raises:
        KeyError: unknown joint.
    """
    if joint not in result.joints:
        raise KeyError(f"no clearance joint {joint!r} (have {list(result.joints)})")
    jr = result.joints[joint]
    contact = jr.penetration > 0
    if not contact.any():
        return None
    a = int(np.argmax(contact))
    rest = np.flatnonzero(~contact[a:])
    b = a + (int(rest[0]) if len(rest) else len(contact) - a)  # one past the event
    t, f = result.times[a:b], jr.force_magnitude[a:b]
    # the event's samples plus the zero-force samples either side: the trapezoid then
    # integrates a sampled pulse the same way whatever the grid
    lo, hi = max(a - 1, 0), min(b + 1, len(contact))
    tt, ff = result.times[lo:hi], jr.force_magnitude[lo:hi].copy()
    if lo < a:
        ff[0] = 0.0
    if hi > b:
        ff[-1] = 0.0
    impulse = float(np.sum(0.5 * (ff[1:] + ff[:-1]) * np.diff(tt)))
    return FirstImpact(joint, float(t[0]), float(f.max()), float(jr.penetration[a:b].max()), impulse, float(t[-1]))


def first_impact_errors(run: FirstImpact | None, ref: FirstImpact | None) -> dict[str, float]:
    """Errors of a first impact against the reference's.

    Returns:
        ``peak_force``, ``max_penetration``, ``impulse``: relative errors (run/ref - 1);
        ``onset``: onset time difference [s]. NaN where either impact is missing.
    """
    keys = ("peak_force", "max_penetration", "impulse", "onset")
    if run is None or ref is None:
        return {k: float("nan") for k in keys}
    out = {k: getattr(run, k) / getattr(ref, k) - 1.0 for k in keys[:3]}
    out["onset"] = run.onset - ref.onset
    return out


def separation_time(run: SimulationResult, ref: SimulationResult, joint: str, *, threshold: float) -> float:
    """First time the journal positions of two runs differ by more than ``threshold``.

    The reference's eccentricity is interpolated onto the run's times.

    Args:
        run, ref: two runs of the same scenario.
        joint: clearance joint name.
        threshold: distance between the two journal centres [m] (e.g. 10 % of the clearance).

    Returns:
        The separation time [s], or the end of the common time span if they never separate.
    """
    t = run.times[run.times <= ref.times[-1]]
    ea = run.joints[joint].eccentricity[: len(t)]
    er = ref.joints[joint].eccentricity
    eb = np.column_stack([np.interp(t, ref.times, er[:, k]) for k in range(2)])
    apart = np.flatnonzero(np.hypot(*(ea - eb).T) > threshold)
    return float(t[apart[0]]) if len(apart) else float(t[-1]) if len(t) else 0.0


ECC_PERCENTILES = (10, 50, 90)
"""Percentiles of |e| among the statistics (the shape of the eccentricity distribution)."""


def _joint_stats(times: np.ndarray, jr: JointResult, period: float) -> dict[str, float]:
    f, p = jr.force_magnitude, jr.penetration
    contact = p > 0
    e = np.hypot(*jr.eccentricity.T)
    dt = float(np.median(np.diff(times))) if len(times) > 1 else period
    revs = np.floor((times - times[0] + 0.5 * dt) / period).astype(int)  # half a sample: no float slivers
    peaks = [f[revs == k].max() for k in np.unique(revs)]
    onsets = int(np.count_nonzero(contact[1:] & ~contact[:-1]))
    span = len(times) * dt
    return {
        "peak_force": float(np.mean(peaks)),
        "p95_force": float(np.percentile(f[contact], 95)) if contact.any() else 0.0,
        "contact_fraction": float(contact.mean()),
        "impacts_per_rev": onsets * period / span,
        "ecc_mean": float(e.mean()),
        "ecc_std": float(e.std()),
        **{f"ecc_p{q}": float(v) for q, v in zip(ECC_PERCENTILES, np.percentile(e, ECC_PERCENTILES))},
    }


def run_statistics(
    result: SimulationResult,
    *,
    period: float,
    skip: float,
    blocks: int = 6,
    ideal_output: Callable[[np.ndarray], np.ndarray] | None = None,
    output: str | None = None,
) -> dict[str, dict[str, Statistic]]:
    """Statistics of every clearance joint over the window t >= skip, with their scatter.

    Args:
        result: a run.
        period: drive period [s] (revolutions count from ``skip``).
        skip: start-up transient left out [s].
        blocks: number of blocks of whole revolutions for the scatter (>= 2, at most the
            number of whole revolutions in the window).
        ideal_output: exact ideal output as a function of time (vectorised), for
            ``rms_deviation``; None leaves it out.
        output: the output it describes (default the result's first).

    Returns:
        joint -> statistic name (`STATISTICS`) -> `Statistic`; ``rms_deviation`` is the
        same for every joint.

    Raises:
        ValueError: a window shorter than ``blocks`` whole revolutions, or bad arguments.
    """
    if not (period > 0 and skip >= 0):
        raise ValueError(f"period must be > 0 and skip >= 0 (got {period!r}, {skip!r})")
    if not isinstance(blocks, int) or blocks < 2:
        raise ValueError(f"blocks must be an integer >= 2 (got {blocks!r})")
    t = result.times
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    # a run of duration T stores samples up to T - dt: its last sample closes the last period
    whole = int(np.floor((t[-1] + dt - skip) / period + 1e-9)) if len(t) else 0
    if whole < blocks:
        raise ValueError(
            f"the window after skip = {skip:g} s holds {whole} whole revolutions of {period:g} s; "
            f"need at least blocks = {blocks}: run longer"
        )
    per_block = whole // blocks
    edges = skip + period * per_block * np.arange(blocks + 1)
    edges[-1] += 0.5 * dt  # keep the last block's final sample
    sel = [(t >= edges[k] - 0.5 * dt) & (t < edges[k + 1] - 0.5 * dt) for k in range(blocks)]
    full = (t >= edges[0] - 0.5 * dt) & (t < edges[-1] - 0.5 * dt)
    dev = None
    if ideal_output is not None:
        name = output or next(k for k in result.outputs if not k.endswith(("_vel", "_acc")))
        dev = result.outputs[name] - ideal_output(t)
    out: dict[str, dict[str, Statistic]] = {}
    for j, jr in result.joints.items():
        whole_stats = _joint_stats(t[full], jr.sliced(full), period)
        per = [_joint_stats(t[s], jr.sliced(s), period) for s in sel]
        if dev is not None:
            whole_stats["rms_deviation"] = float(np.sqrt(np.mean(dev[full] ** 2)))
            for s, d in zip(sel, per):
                d["rms_deviation"] = float(np.sqrt(np.mean(dev[s] ** 2)))
        out[j] = {
            k: Statistic(
                v, float(np.std([d[k] for d in per], ddof=1) / np.sqrt(blocks)), blocks, tuple(d[k] for d in per)
            )
            for k, v in whole_stats.items()
        }
    return out


def distributions(result: SimulationResult, *, skip: float, bins: int = 60) -> dict[str, dict[str, list[float]]]:
    """Histograms of |e|/c and quantiles of the in-contact force, per joint, over t >= skip.

    Args:
        result: a run.
        skip: start-up transient left out [s].
        bins: histogram bins of |e|/c over [0, 1.2].

    Returns:
        joint -> {``ecc_edges``, ``ecc_density`` (of |e|/c), ``force_quantiles`` (at
        ``FORCE_QUANTILES``) [N]}. The clearance c comes from the result's metadata
        (``clearance``) when present, else from the largest |e| rounded down.
    """
    keep = result.times >= result.times[0] + skip
    clear = result.metadata.get("clearance") or {}
    out = {}
    for j, jr in result.joints.items():
        e = np.hypot(*jr.eccentricity[keep].T)
        c = float(clear.get(j, np.percentile(e, 50) if len(e) else 1.0))
        dens, edges = np.histogram(e / c, bins=bins, range=(0.0, 1.2), density=True)
        f = jr.force_magnitude[keep][jr.penetration[keep] > 0]
        q = np.percentile(f, [100 * x for x in FORCE_QUANTILES]).tolist() if len(f) else [0.0] * len(FORCE_QUANTILES)
        out[j] = {"ecc_edges": edges.tolist(), "ecc_density": dens.tolist(), "force_quantiles": q}
    return out


FORCE_QUANTILES = (0.5, 0.75, 0.9, 0.95, 0.99)
"""Quantiles of the in-contact force that `distributions` reports."""


def statistic_errors(
    run: Mapping[str, Mapping[str, Statistic]],
    ref: Mapping[str, Mapping[str, Statistic]],
    *,
    clearance: Mapping[str, float] | None = None,
) -> dict[str, dict[str, dict[str, float]]]:
    """Error of each statistic against the reference, with both scatters, on a stated scale.

    Errors are relative to the reference's value, except where that value can be close to
    zero: the eccentricity statistics (``ecc_*``) are measured in units of the joint's
    clearance c (|e| lives in [0, c + δ]; a journal resting on its bearing has ``ecc_std``
    near 0), and ``impacts_per_rev`` relative to max(reference, 1) (a joint in permanent
    contact has none). Any other statistic whose reference value is exactly 0 (a joint that
    never touches) has error 0 if the run's is 0 too, else infinity.

    Args:
        run: `run_statistics` of the run.
        ref: `run_statistics` of the reference.
        clearance: joint -> radial clearance c [m], for the eccentricity scales (without
            it they are relative too).

    Returns:
        joint -> statistic -> {``error``: (run - ref) / scale, ``ref_scatter``: the
        reference's standard error / scale, ``scatter``: sqrt(se_run^2 + se_ref^2) /
        scale, ``scale``: the scale}.
    """
    out: dict[str, dict[str, dict[str, float]]] = {}
    for j, stats in ref.items():
        out[j] = {}
        for k, r in stats.items():
            m = run[j][k]
            if k.startswith("ecc_") and clearance and j in clearance:
                scale = float(clearance[j])
            elif k == "impacts_per_rev":
                scale = max(abs(r.value), 1.0)
            else:
                scale = abs(r.value) if r.value else float("nan")
            if math.isnan(scale):  # reference exactly 0: no relative scale
                error = 0.0 if m.value == r.value else math.inf
            else:
                error = (m.value - r.value) / scale
            out[j][k] = {
                "error": error,
                "ref_scatter": r.scatter / scale,
                "scatter": float(np.hypot(m.scatter, r.scatter)) / scale,
                "scale": scale,
            }
    return out


def statistics_as_dict(stats: Mapping[str, Mapping[str, Statistic]]) -> dict[str, dict[str, dict[str, float]]]:
    """JSON-friendly form of `run_statistics`' output."""
    return {j: {k: asdict(s) for k, s in d.items()} for j, d in stats.items()}
