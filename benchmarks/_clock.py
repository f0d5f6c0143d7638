"""CPU and wall clocks read together (benchmark scripts)."""

from __future__ import annotations

import time


def clock() -> tuple[float, float]:
    """(CPU time of the process, wall time) [s] now."""
    return time.process_time(), time.perf_counter()


def since(start: tuple[float, float]) -> tuple[float, float]:
    """(CPU, wall) [s] elapsed since ``start`` (a `clock` reading)."""
    c, w = clock()
    return c - start[0], w - start[1]
