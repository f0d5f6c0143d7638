"""Ideal-twin runs reused within a sweep worker.

Many points of a sweep share one ideal twin: a criticality grid has one per drive speed,
whatever the joint and the clearance. `ideal_run` keeps a worker's last few ideal runs and
returns a kept one when the ideal twin, the duration and the options are equal; the
builder parameters (``Mechanism.parameters``), which only label a run, are left out of the
comparison. Runs are deterministic, so a reused ideal run gives the same row as a fresh
one. The store is per process and safe for threads (a Dask worker runs points in threads).
"""

from __future__ import annotations

import dataclasses
import threading
import time
from collections import OrderedDict
from typing import Any

from clearance.model import Mechanism
from clearance.options import ModelOptions
from clearance.results import SimulationResult

__all__ = ["IDEAL_RUNS_KEPT", "ideal_run", "forget_ideal_runs"]

IDEAL_RUNS_KEPT = 4
"""Ideal runs kept per process (a grid of up to four drive speeds reuses every one)."""

_RUNS: OrderedDict[str, SimulationResult] = OrderedDict()
_LOCK = threading.Lock()


def ideal_run(
    mechanism: Mechanism, duration: float, options: ModelOptions | None, timing: dict[str, Any] | None = None
) -> SimulationResult:
    """Simulate the mechanism's ideal twin, or return this process's run of the same twin.

    Args:
        mechanism: a `Mechanism` (with or without clearance).
        duration: simulated time [s].
        options: `ModelOptions` (None: defaults), as given to `simulate`.
        timing: if given, receives ``ideal_s`` (simulation wall time [s], 0 when reused) and
            ``ideal_reused`` (bool).

    Returns:
        The ideal twin's `SimulationResult`. A reused result is shared, not copied: do not
        modify it. Its metadata (parameters included) are those of the run that computed it.
    """
    from clearance.run.simulation import simulate

    twin = mechanism.ideal_twin()
    key = repr((dataclasses.replace(twin, parameters={}), float(duration), options))
    with _LOCK:
        hit = _RUNS.get(key)
        if hit is not None:
            _RUNS.move_to_end(key)
    if hit is not None:
        if timing is not None:
            timing.update(ideal_s=0.0, ideal_reused=True)
        return hit
    t0 = time.perf_counter()
    run = simulate(twin, duration=duration, options=options)
    if timing is not None:
        timing.update(ideal_s=time.perf_counter() - t0, ideal_reused=False)
    with _LOCK:
        _RUNS[key] = run
        while len(_RUNS) > IDEAL_RUNS_KEPT:
            _RUNS.popitem(last=False)
    return run


def forget_ideal_runs() -> None:
    """Drop this process's kept ideal runs (frees their memory)."""
    with _LOCK:
        _RUNS.clear()
