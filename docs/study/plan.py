"""What the study runs: named press runs, bifurcation sweeps and criticality sweeps.

Every run and sweep is resumable (kept in the cache folder as it finishes); numerical
choices are set here, once, and quoted by study.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from clearance.analysis.sweeps.bifurcation import BifurcationDiagram, run_bifurcation
from clearance.analysis.sweeps.criticality import (
    ClearanceAtJoint,
    CriticalityRanking,
    run_criticality,
)
from clearance.analysis.sweeps.run_store import RunSpec, RunStore, run_batch
from clearance.analysis.sweeps.sweep import KeywordFactory
from clearance.builders import CATALOGUE, rpm, seven_bar_press
from clearance.options import ContactMode, ModelOptions

CONTACT = ContactMode.CALIBRATED  # contact fitted to LN impacts per joint (the package default)


def options(step: float) -> ModelOptions:
    """The study's numerical options at time step ``step`` [s]."""
    return ModelOptions(timestep=step, contact_mode=CONTACT)


# -- press (the hybrid seven-bar press paper, Shock and Vibration 2020) --------------------------
PRESS_STEP = 10e-6  # short runs (4 periods); checked against 5 us below
PRESS_CHECK_STEP = 5e-6
PRESS_LONG_STEP = 20e-6  # Poincaré runs and bifurcation sweeps; checked against 10 us
PRESS_LONG_CHECK_STEP = 10e-6
PRESS_PERIODS = 4  # the first is the start-up transient
KEEP_INTERVAL = 1e-4  # stored rows every 0.1 ms (peaks come from every step)
SPEEDS = (1.0, 2.0, 3.0)  # crank 2 speed / pi rad/s (the press paper's range)
SERIES_SPEED = 3.0
SERIES_CLEARANCES_MM = (0.01, 0.03, 0.06, 0.09, 0.2, 0.5, 0.8)
PAIR_CLEARANCES_MM = (0.03, 0.09, 0.5)
SPEED_CLEARANCE_MM = 0.09
SPEED_ORBIT_CLEARANCE_MM = 0.5  # orbits against speed: the clearance of the speed diagram
POINCARE_CLEARANCES_MM = (0.01, 0.8)
POINCARE_PERIODS = 80  # the first 20 are skipped
POINCARE_SKIP = 20
BIF_CLEARANCES_MM = tuple(float(v) for v in np.geomspace(0.01, 1.0, 16))
BIF_SPEEDS = tuple(float(v) for v in np.linspace(1.0, 3.0, 12))
BIF_SPEED_CLEARANCE_MM = 0.5
BIF_PERIODS, BIF_SAMPLED = 30, 20
BIF_CHECK_EVERY = 5  # every 5th clearance of the diagram again at 10 us

# -- criticality (Alok, Chaudhary and Guha 2020) ---------------------------------------------------
CRIT_STEP = 5e-6  # benchmarks/criticality_speed.md: same ranking as 1 us
CRIT_PERIODS = 6
FULL_GRID = ((0.02, 0.1, 0.5), (100.0, 1000.0, 3000.0))  # clearances [mm], speeds [rpm]
SMALL_GRID = ((0.1,), (1000.0, 3000.0))
FULL_GRID_MECHANISMS = ("watt_six_bar", "watt_six_bar_slider_1")
SMALL_GRID_MECHANISMS = ("four_bar", "stephenson_i", "stephenson_i_slider", "eight_bar", "ten_bar")
SC_CLEARANCES_MM = (0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
SC_SPEEDS_RPM = (100.0, 1000.0, 3000.0)


def press_name(at: tuple[str, ...], c_mm: float | None, speed: float, step: float = PRESS_STEP) -> str:
    """Run name of a press run (``ideal`` when ``at`` is empty)."""
    where = "+".join(at) if at else "ideal"
    c = "" if not at else f"_c{c_mm:g}mm"
    h = "" if step == PRESS_STEP else f"_h{step * 1e6:g}us"
    return f"press_{where}{c}_w{speed:g}pi{h}".replace("+", "").replace(".", "p")


def _press(at: tuple[str, ...], c_mm: float | None, speed: float, step: float, periods: int) -> RunSpec:
    point = {"clearance_at": at, "crank2_speed": speed * math.pi}
    if c_mm is not None:
        point["radial_clearance"] = c_mm * 1e-3
    return RunSpec(
        press_name(at, c_mm, speed, step),
        KeywordFactory(seven_bar_press),
        point,
        periods * 2 / speed,
        options(step),
        keep_every=max(1, round(KEEP_INTERVAL / step)),
    )


def press_runs() -> list[RunSpec]:
    """Every single press run of the study."""
    runs = [_press((), None, w, PRESS_STEP, PRESS_PERIODS) for w in SPEEDS]
    for h in (PRESS_STEP, PRESS_CHECK_STEP):
        runs += [_press(("A",), c, SERIES_SPEED, h, PRESS_PERIODS) for c in SERIES_CLEARANCES_MM]
    runs.append(_press((), None, SERIES_SPEED, PRESS_CHECK_STEP, PRESS_PERIODS))
    for at in (("C",), ("A", "C")):
        runs += [_press(at, c, SERIES_SPEED, PRESS_STEP, PRESS_PERIODS) for c in PAIR_CLEARANCES_MM]
    for at in (("A",), ("A", "C")):
        runs += [_press(at, SPEED_CLEARANCE_MM, w, PRESS_STEP, PRESS_PERIODS) for w in SPEEDS if w != SERIES_SPEED]
    runs += [_press(("A", "C"), SPEED_ORBIT_CLEARANCE_MM, w, PRESS_STEP, PRESS_PERIODS) for w in SPEEDS]
    runs += [_press(("A", "C"), c, SERIES_SPEED, PRESS_LONG_STEP, POINCARE_PERIODS) for c in POINCARE_CLEARANCES_MM]
    return [r for i, r in enumerate(runs) if r.name not in {q.name for q in runs[:i]}]


def run_press(cache: Path, workers: int) -> RunStore:
    """Simulate (or load) every single press run."""
    return run_batch(press_runs(), cache / "press_runs", max_workers=workers)


def run_press_bifurcations(cache: Path, workers: int) -> dict[str, BifurcationDiagram]:
    """Bifurcation diagrams of the press (clearances A and C) over clearance and over speed."""
    common = dict(quantity="A.ex", periods=BIF_PERIODS, sampled=BIF_SAMPLED, max_workers=workers)
    over_c = KeywordFactory(seven_bar_press, fixed={"crank2_speed": SERIES_SPEED * math.pi})
    values_c = [c * 1e-3 for c in BIF_CLEARANCES_MM]
    out = {
        "clearance": run_bifurcation(
            values_c, over_c, out_dir=cache / "bif_clearance", options=options(PRESS_LONG_STEP), **common
        ),
        "clearance_check": run_bifurcation(
            values_c[::BIF_CHECK_EVERY],
            over_c,
            out_dir=cache / "bif_clearance_check",
            options=options(PRESS_LONG_CHECK_STEP),
            **common,
        ),
    }
    over_w = KeywordFactory(seven_bar_press, fixed={"radial_clearance": BIF_SPEED_CLEARANCE_MM * 1e-3})
    out["speed"] = run_bifurcation(
        [w * math.pi for w in BIF_SPEEDS],
        over_w,
        out_dir=cache / "bif_speed",
        parameter="crank2_speed",
        options=options(PRESS_LONG_STEP),
        **common,
    )
    return out


@dataclass(frozen=True)
class CriticalityRun:
    """A criticality sweep of one mechanism: its ranking and grid."""

    mechanism: str
    ranking: CriticalityRanking
    clearances_mm: tuple[float, ...]
    speeds_rpm: tuple[float, ...]
    joints: tuple[str, ...]


def _criticality(cache: Path, name: str, grid, workers: int, joints=None) -> CriticalityRun:
    clearances, speeds = grid
    ranking = run_criticality(
        ClearanceAtJoint(CATALOGUE[name].builder),
        clearances=[c * 1e-3 for c in clearances],
        speeds=[rpm(s) for s in speeds],
        joints=joints,
        out_dir=cache / f"crit_{name}",
        periods=CRIT_PERIODS,
        options=options(CRIT_STEP),
        max_workers=workers,
    )
    return CriticalityRun(name, ranking, tuple(clearances), tuple(speeds), tuple(s.joint for s in ranking.scores))


def run_criticalities(cache: Path, workers: int) -> dict[str, CriticalityRun]:
    """Criticality sweeps: the full grid, the small grid, and the slider-crank's clearance grid."""
    out = {n: _criticality(cache, n, FULL_GRID, workers) for n in FULL_GRID_MECHANISMS}
    out.update({n: _criticality(cache, n, SMALL_GRID, workers) for n in SMALL_GRID_MECHANISMS})
    out["slider_crank"] = _criticality(cache, "slider_crank", (SC_CLEARANCES_MM, SC_SPEEDS_RPM), workers)
    return out
