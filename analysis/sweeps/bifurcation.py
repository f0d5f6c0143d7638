"""Bifurcation diagrams: Poincaré samples of one quantity against a swept parameter.

Each sweep point runs ``periods`` drive periods; the Poincaré section (t = k T of the
constant-speed drive) of the chosen quantity over the last ``sampled`` periods is stored
with the point's row and classified (`chaos.classify_poincare`). Typical quantities: the
journal eccentricity ``<joint>.ex`` or the slider velocity ``slider_x_vel``; typical
parameters: ``radial_clearance`` [m] or ``crank_speed`` [rad/s].
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.sweeps.sweep import MechanismFactory, SweepEvaluation, run_sweep
from clearance.options import ModelOptions

__all__ = ["BifurcationDiagram", "bifurcation_from_rows", "run_bifurcation"]


@dataclass(frozen=True)
class BifurcationDiagram:
    """Poincaré samples per parameter value.

    Attributes:
        parameter: swept point key.
        quantity: sampled quantity name.
        values: (P,) parameter values (points in index order).
        samples: P arrays (K_p,) of section samples (empty for failed points).
        regimes: P regime names (``periodic``, ``quasi_periodic``, ``chaotic``,
            ``undetermined``, or ``error``).
        errors: P error messages ('' for points that ran).
    """

    parameter: str
    quantity: str
    values: np.ndarray
    samples: tuple[np.ndarray, ...]
    regimes: tuple[str, ...]
    errors: tuple[str, ...]

    def scatter(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) arrays of every sample with its parameter value, for plotting."""
        xs = [np.full(len(s), v) for v, s in zip(self.values, self.samples)]
        if not xs:
            return np.zeros(0), np.zeros(0)
        return np.concatenate(xs), np.concatenate(self.samples)


def bifurcation_from_rows(
    rows: Sequence[Mapping[str, Any]], parameter: str, quantity: str | None = None
) -> BifurcationDiagram:
    """Build the diagram from sweep rows (`run_sweep` output or `load_rows`).

    Args:
        rows: sweep rows sorted by index.
        parameter: point key of the swept parameter.
        quantity: sampled quantity (default: the first Poincaré quantity of the rows).

    Raises:
        KeyError: the rows have no such parameter or quantity.
    """
    values, samples, regimes, errors = [], [], [], []
    q = quantity
    for r in rows:
        values.append(float(r["point"][parameter]))
        if r["status"] != "ok":
            samples.append(np.zeros(0))
            regimes.append("error")
            errors.append(r["error"])
            continue
        pc = r["poincare"]
        q = q or pc["quantities"][0]
        col = pc["quantities"].index(q)
        pts = np.asarray(pc["points"], float).reshape(-1, len(pc["quantities"]))
        samples.append(pts[:, col])
        regimes.append(pc["regime"])
        errors.append("")
    return BifurcationDiagram(parameter, q or "", np.asarray(values), tuple(samples), tuple(regimes), tuple(errors))


def run_bifurcation(
    values: Sequence[float] | np.ndarray,
    make_mechanism: MechanismFactory,
    *,
    out_dir: str | Path,
    parameter: str = "radial_clearance",
    quantity: str = "rod_slider.ex",
    periods: int = 60,
    sampled: int = 40,
    fixed: Mapping[str, Any] | None = None,
    options: ModelOptions | None = None,
    executor: Executor | None = None,
    scheduler_address: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
    max_workers: int | None = None,
) -> BifurcationDiagram:
    """Sweep one parameter and sample the Poincaré section of a quantity (resumable).

    Args:
        values: parameter values (SI units: m for a clearance, rad/s for a speed).
        make_mechanism: picklable point -> Mechanism (points are ``{parameter: value,
            **fixed}``).
        out_dir: sweep folder.
        parameter: point key swept.
        quantity: quantity sampled (`chaos.quantity_series` name).
        periods: drive periods simulated per point.
        sampled: last periods sampled (``sampled <= periods - 1``; the rest is transient).
        fixed: other point keys held constant.
        options, executor, scheduler_address, progress, stop_after, max_workers: as in
            `run_sweep`.

    Returns:
        The diagram of the points finished so far (all of them unless stopped).

    Raises:
        ValueError: no values, or sampled not in [1, periods - 1].
    """
    from clearance.run.simulation import default_duration

    if not len(values):
        raise ValueError("values must not be empty")
    if not (isinstance(sampled, int) and isinstance(periods, int) and 1 <= sampled <= periods - 1):
        raise ValueError(f"sampled must be in [1, periods - 1] (got sampled={sampled!r}, periods={periods!r})")
    points = [{parameter: float(v), **dict(fixed or {})} for v in values]
    evaluation = SweepEvaluation(
        poincare=(quantity,), last_periods=sampled, skip_periods=float(periods - sampled), ideal=False
    )
    out = run_sweep(
        points,
        make_mechanism,
        out_dir=out_dir,
        duration=functools.partial(default_duration, revolutions=float(periods)),
        options=options,
        executor=executor,
        scheduler_address=scheduler_address,
        progress=progress,
        stop_after=stop_after,
        evaluation=evaluation,
        max_workers=max_workers,
    )
    return bifurcation_from_rows(out.rows, parameter, quantity)
