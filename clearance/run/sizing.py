"""`JointSizing`: the loads and sizes of one joint with play, from the ideal mechanism's cycle.

The median load of a contact over the cycle gives its typical Hertz penetration, the peak load an
estimate of its impact speed (the speed the effective mass gains crossing the clearance under
it) and the divergence bound: 4 x the Hertz penetration of that impact, at least 4 x that under
the peak load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearance.contact_calibration.effective_mass import EffectiveMass

__all__ = ["JointSizing", "load_penetration", "median", "size_joint"]


@dataclass(frozen=True)
class JointSizing:
    """Loads and sizes of one clearance joint (a journal in its bearing; for a slider in its guide
    the same per corner: `clearance.run.slider_contact`).

    Attributes:
        stiffness: journal-bearing stiffness K [N/m^1.5].
        median_load, peak_load: ideal-mechanism reaction force over one cycle [N].
        typical_penetration: (median_load / K)^(2/3) [m].
        impact_speed: sqrt(2 peak_load c / m_eff), the speed gained crossing the clearance
            under the peak load [m/s].
        effective_mass: mass seen along the contact normal [kg]: median over the ideal
            cycle of the mass along the ideal joint's load (loop closures and velocity
            drives held), as `clearance.contact_calibration.cycle_effective_mass` measures it.
        effective_mass_range: (min, max) of that mass over the cycle [kg], the range a
            calibration is valid for.
        penetration_limit: divergence bound [m]: 4 x the Hertz penetration of an impact at
            ``impact_speed``, at least 4 x that under the peak load.
        segments: ring segment count N (0 for the exact contact, which has no ring).
    """

    stiffness: float
    median_load: float
    peak_load: float
    typical_penetration: float
    impact_speed: float
    effective_mass: float
    penetration_limit: float
    segments: int
    effective_mass_range: tuple[float, float] = (0.0, 0.0)


def median(values: np.ndarray, axis: int = -1) -> np.ndarray:
    """The median of finite ``values`` along ``axis``: np.median's values, bitwise (its middle element, or
    the mean (a + b) / 2 of its two middle ones), without np.median's first call importing numpy.ma (10 ms
    of a fresh process's first preparation).

    Args:
        values: array of finite values (a NaN is not propagated as np.median propagates it).
        axis: the axis to take it along.

    Returns:
        The medians, ``values``' shape without ``axis`` (a 0-d array for a 1-d input).
    """
    s = np.sort(np.asarray(values, dtype=float), axis=axis)
    n = s.shape[axis]
    if n % 2:
        return np.take(s, n // 2, axis=axis)
    return (np.take(s, n // 2 - 1, axis=axis) + np.take(s, n // 2, axis=axis)) / 2


def load_penetration(loads: np.ndarray, stiffness: float) -> tuple[float, float, float]:
    """(median load [N], peak load [N], typical penetration [m]) of a contact's loads over the cycle.

    The typical penetration is (median / K)^(2/3), the median floored at 1e-3 of the peak (1e-7 m
    when the contact carries no load at all).
    """
    fmed, fmax = float(median(loads)), float(np.max(loads))
    dtyp = (max(fmed, 1e-3 * max(fmax, 1e-9)) / stiffness) ** (2 / 3) if fmax > 0 else 1e-7
    return fmed, fmax, dtyp


def size_joint(
    *, stiffness: float, loads: np.ndarray, clearance: float, mass: EffectiveMass, segments: int
) -> JointSizing:
    """The `JointSizing` of a contact (module docstring).

    Args:
        stiffness: K [N/m^1.5].
        loads: (n,) the contact's load over the cycle [N].
        clearance: the gap the load drives the contact across [m].
        mass: its effective mass over the cycle.
        segments: its ring's segment count (0 without a ring).
    """
    fmed, fmax, dtyp = load_penetration(loads, stiffness)
    m = mass.median
    v = math.sqrt(2 * max(fmax, 1e-9) * clearance / m)
    d_imp = (5 * m * v**2 / (4 * stiffness)) ** 0.4
    lim = 4 * max(d_imp, (max(fmax, 1e-9) / stiffness) ** (2 / 3))
    return JointSizing(stiffness, fmed, fmax, dtyp, v, m, lim, segments, mass.valid_range)
