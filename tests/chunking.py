"""A run's bits do not depend on how it was chunked or thinned (`tests/test_chunked_runs.py` says why)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from clearance.results import SimulationResult


def assert_chunking_is_invisible(run: Callable[..., SimulationResult], h: float, nstep: int) -> None:
    """``run(duration=..., chunk_steps=..., output_interval=...)`` gives the same bits whatever the
    chunks: chunks of 1 step (over the first 300 steps), of 777 steps and the whole run in one
    chunk, and every third row of the run thinned to 3 h."""
    whole = run(duration=nstep * h, chunk_steps=10 * nstep).arrays()
    thinned = run(duration=nstep * h, chunk_steps=1000, output_interval=3 * h).arrays()
    cases = {
        "chunks of 1 step": (run(duration=300 * h, chunk_steps=1).arrays(), slice(0, 300)),
        "chunks of 777 steps": (run(duration=nstep * h, chunk_steps=777).arrays(), slice(None)),
        "thinned to 3 h": (thinned, slice(0, None, 3)),
    }
    for case, (got, rows) in cases.items():
        assert set(got) == set(whole), case
        differ = [k for k, v in whole.items() if not np.array_equal(v[rows], got[k])]
        assert not differ, f"{case}: {differ} differ from the one-chunk run"
