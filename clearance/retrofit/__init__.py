"""clearance.retrofit: radial clearance at the hinges of any MuJoCo model.

`retrofit` edits a copy of a user's `mujoco.MjSpec` in place of building a model from a
`Mechanism`: each named hinge keeps its hinge and gains two in-plane slides, the parent body
a ring bearing and the child body a journal, with the ring's soft contact calibrated at the
bearing's own effective mass and impact speeds (the mechanisms' bearing, calibration and
contact code, unchanged). `write_retrofit` writes the model, its unmodified twin and a report
of every change. Planar play only: the journal cannot tilt in its bearing. `add_backlash`
gives actuated hinges angular play instead (gear backlash: a motor side, a load side and a
dead band, `clearance.retrofit.backlash`).

The request's records (`RadialPlay`, `RetrofitOptions`, ...) import no MuJoCo; `retrofit`,
`Retrofit`, `RetrofittedHinge` and `write_retrofit` are imported on first use.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from clearance.retrofit.play import (
    DEFAULT_BEARING_RADIUS,
    DEFAULT_RADIAL_CLEARANCE,
    MAX_BACKLASH,
    PREFIX,
    Backlash,
    ControlTable,
    RadialPlay,
    RetrofitError,
    RetrofitOptions,
    SineControl,
)

if TYPE_CHECKING:
    from clearance.retrofit.backlash import BacklashRetrofit, add_backlash
    from clearance.retrofit.output import write_retrofit
    from clearance.retrofit.pipeline import Retrofit, RetrofittedHinge, retrofit

__all__ = [
    "Backlash",
    "BacklashRetrofit",
    "ControlTable",
    "DEFAULT_BEARING_RADIUS",
    "DEFAULT_RADIAL_CLEARANCE",
    "MAX_BACKLASH",
    "PREFIX",
    "RadialPlay",
    "Retrofit",
    "RetrofitError",
    "RetrofitOptions",
    "RetrofittedHinge",
    "SineControl",
    "add_backlash",
    "retrofit",
    "write_retrofit",
]

_LAZY = {
    "add_backlash": "backlash",
    "BacklashRetrofit": "backlash",
    "retrofit": "pipeline",
    "Retrofit": "pipeline",
    "RetrofittedHinge": "pipeline",
    "write_retrofit": "output",
}
"""Names imported on first use -> their module."""


def __getattr__(name: str) -> object:
    """A name of the MuJoCo-dependent part, importing its module on first use."""
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    globals()[name] = value
    return value
