"""The mechanism catalogue: a registry from names to builders, and a linkage check.

`CATALOGUE` maps each name to a `CatalogueEntry` (builder, family, `LinkageInfo`: topology,
driven joints, output pivot, clearable joints, the joints of a criticality ranking, where
transmission angles are measured, provenance of the dimensions; the builder's drive-speed
keyword and the speed range a sweep covers by default). `check_linkage` follows a
mechanism over whole drive cycles with the generic kinematics solver and reports the
transmission-angle ranges and the distance from singular positions.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from clearance.builders._linkage import LinkageInfo
from clearance.builders.four_bar import FOUR_BAR_INFO, four_bar
from clearance.builders.multiloop import (
    EIGHT_BAR_INFO,
    TEN_BAR_INFO,
    eight_bar,
    ten_bar,
)
from clearance.builders.press import PRESS_INFO, seven_bar_press
from clearance.builders.slider_crank import rpm, slider_crank
from clearance.builders.stephenson import (
    STEPHENSON_I_INFO,
    STEPHENSON_I_SLIDER_INFO,
    STEPHENSON_II_1_INFO,
    STEPHENSON_II_2_INFO,
    stephenson_i,
    stephenson_i_slider,
    stephenson_ii_1,
    stephenson_ii_2,
)
from clearance.builders.watt import (
    WATT_INFO,
    WATT_SLIDER_1_INFO,
    WATT_SLIDER_2_INFO,
    watt_six_bar,
    watt_six_bar_slider_1,
    watt_six_bar_slider_2,
)
from clearance.kinematics import TransmissionAngle, solve_kinematics, transmission_angle
from clearance.model import DriveKind, Mechanism

__all__ = [
    "CatalogueEntry",
    "CATALOGUE",
    "CRANK_SPEED_RANGE",
    "PRESS_SPEED_RANGE",
    "SLIDER_CRANK_INFO",
    "names",
    "get",
    "build",
    "LinkageCheck",
    "check_linkage",
]

SLIDER_CRANK_INFO = LinkageInfo(
    topology="In-line slider-crank: ground (crank_pivot, guide), crank (driven), rod, slider (output: its x position).",
    driven=("crank_pivot",),
    output_pivot="slider_guide",
    clearable=("crank_rod", "rod_slider"),
    criticality=("crank_rod", "rod_slider"),
    transmission=(TransmissionAngle("rod_slider", ("rod", "big_end"), guide="slider_guide"),),
    sliders=("slider_guide",),
    provenance="the benchmark of Flores and Ambrósio 2004 (docs/references.md; crank and rod checked, "
    "masses and inertias recalled)",
)


CRANK_SPEED_RANGE = (rpm(1000.0), rpm(5000.0))
"""Default speed range of the crank-driven mechanisms' sweeps [rad/s]: 1000-5000 rpm."""

PRESS_SPEED_RANGE = (math.pi, 3 * math.pi)
"""Default speed range of the press's sweeps [rad/s]: the press paper's 1-3 pi rad/s (see `seven_bar_press`)."""


@dataclass(frozen=True)
class CatalogueEntry:
    """One mechanism of the catalogue.

    Attributes:
        name: registry name (also the builder's default mechanism name).
        builder: keyword-only callable returning the `Mechanism`.
        family: slider-crank, four-bar, Watt six-bar, Stephenson six-bar, multi-loop or press.
        info: topology, joints and provenance (see `LinkageInfo`).
        speed_keyword: the builder's keyword for the speed of its (first) constant-speed
            drive [rad/s] (``crank_speed``; ``crank2_speed`` for the press).
        speed_range: (low, high) drive speeds a sweep covers by default [rad/s]; a
            clearance sweep holds the high one, a criticality grid uses the low one and
            the middle.
    """

    name: str
    builder: Callable[..., Mechanism]
    family: str
    info: LinkageInfo
    speed_keyword: str = "crank_speed"
    speed_range: tuple[float, float] = CRANK_SPEED_RANGE

    def __post_init__(self) -> None:
        lo, hi = self.speed_range
        if not (0 < lo <= hi < math.inf):
            raise ValueError(
                f"catalogue entry '{self.name}' speed_range must satisfy 0 < low <= high "
                f"(got {self.speed_range!r} rad/s)"
            )


CATALOGUE: Mapping[str, CatalogueEntry] = MappingProxyType(
    {
        e.name: e
        for e in (
            CatalogueEntry("slider_crank", slider_crank, "slider-crank", SLIDER_CRANK_INFO),
            CatalogueEntry("four_bar", four_bar, "four-bar", FOUR_BAR_INFO),
            CatalogueEntry("watt_six_bar", watt_six_bar, "Watt six-bar", WATT_INFO),
            CatalogueEntry("watt_six_bar_slider_1", watt_six_bar_slider_1, "Watt six-bar", WATT_SLIDER_1_INFO),
            CatalogueEntry("watt_six_bar_slider_2", watt_six_bar_slider_2, "Watt six-bar", WATT_SLIDER_2_INFO),
            CatalogueEntry("stephenson_i", stephenson_i, "Stephenson six-bar", STEPHENSON_I_INFO),
            CatalogueEntry("stephenson_i_slider", stephenson_i_slider, "Stephenson six-bar", STEPHENSON_I_SLIDER_INFO),
            CatalogueEntry("stephenson_ii_1", stephenson_ii_1, "Stephenson six-bar", STEPHENSON_II_1_INFO),
            CatalogueEntry("stephenson_ii_2", stephenson_ii_2, "Stephenson six-bar", STEPHENSON_II_2_INFO),
            CatalogueEntry("eight_bar", eight_bar, "multi-loop", EIGHT_BAR_INFO),
            CatalogueEntry("ten_bar", ten_bar, "multi-loop", TEN_BAR_INFO),
            CatalogueEntry(
                "seven_bar_press",
                seven_bar_press,
                "press",
                PRESS_INFO,
                speed_keyword="crank2_speed",
                speed_range=PRESS_SPEED_RANGE,
            ),
        )
    }
)
"""Every catalogue mechanism by name, in catalogue order."""


def names() -> tuple[str, ...]:
    """Names of the catalogue's mechanisms, in catalogue order."""
    return tuple(CATALOGUE)


def get(name: str) -> CatalogueEntry:
    """The catalogue entry called ``name``.

    Raises:
        KeyError: unknown name (the message lists the known ones).
    """
    try:
        return CATALOGUE[name]
    except KeyError:
        raise KeyError(f"unknown mechanism {name!r}; the catalogue has {list(CATALOGUE)}") from None


def build(name: str, **overrides: Any) -> Mechanism:
    """Build catalogue mechanism ``name`` with keyword overrides of its builder (SI units).

    Raises:
        KeyError: unknown name.
        TypeError: an argument the builder does not take.
        ValueError: a value the builder rejects.
    """
    return get(name).builder(**overrides)


@dataclass(frozen=True)
class LinkageCheck:
    """Result of `check_linkage`.

    Attributes:
        transmission: joint name -> (min, max) transmission angle over the cycle [deg].
        worst_transmission: smallest distance of any transmission angle from 0 or 180 deg [deg].
        min_singularity: smallest `singularity_measure` over the cycle (1 best, 0 singular).
        outputs: output name -> (min, max) over the cycle [m or rad].
        peak_output_acceleration: output name -> max |acceleration| [m/s^2 or rad/s^2].
        period: the checked time span [s].
    """

    transmission: dict[str, tuple[float, float]]
    worst_transmission: float
    min_singularity: float
    outputs: dict[str, tuple[float, float]]
    peak_output_acceleration: dict[str, float]
    period: float


def check_linkage(mechanism: Mechanism, info: LinkageInfo, *, samples: int = 721, cycles: float = 1.0) -> LinkageCheck:
    """Follow the ideal mechanism over ``cycles`` periods of its slowest drive.

    Args:
        mechanism: the mechanism.
        info: where to measure transmission angles.
        samples: time samples.
        cycles: periods of the slowest prescribed drive.

    Raises:
        AssemblyError: the linkage cannot be assembled, or reaches a singular position
            (`SingularPositionError`, naming the time and drive angles).
    """
    period = cycles * max(d.period for d in mechanism.drives if d.kind is not DriveKind.TORQUE)
    kin = solve_kinematics(mechanism, np.linspace(0.0, period, samples))
    trans, worst = {}, 90.0
    for spec in info.transmission:
        mu = np.degrees(transmission_angle(mechanism, kin.q, spec))
        trans[spec.joint] = (float(mu.min()), float(mu.max()))
        worst = min(worst, float(np.min(np.minimum(mu, 180.0 - mu))))
    outs = {o.name: (float(kin.outputs[o.name].min()), float(kin.outputs[o.name].max())) for o in mechanism.outputs}
    acc = {o.name: float(np.max(np.abs(kin.outputs[o.name + "_acc"]))) for o in mechanism.outputs}
    singular = math.nan if kin.singularity is None else float(np.nanmin(kin.singularity))
    return LinkageCheck(trans, worst, singular, outs, acc, period)
