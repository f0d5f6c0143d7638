"""clearance: planar mechanisms with revolute-joint clearance, simulated in MuJoCo.

Importing this package is cheap: MuJoCo-dependent parts (`simulate`, `SimulationError`,
`SimulationResult`, `ModelOptions`) are imported on first use.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from clearance.model import (
    STEEL,
    Clearance,
    ContactLaw,
    Drive,
    DriveKind,
    Joint,
    JointType,
    Link,
    Material,
    Mechanism,
    MotionLaw,
    Output,
    OutputKind,
)
from clearance.version import __version__ as __version__

if TYPE_CHECKING:  # for type checkers; at run time `__getattr__` imports these on first use
    from clearance.options import ContactMode as ContactMode
    from clearance.options import GeomType as GeomType
    from clearance.options import ModelOptions as ModelOptions
    from clearance.results import SimulationResult as SimulationResult
    from clearance.run.simulation import SimulationError as SimulationError
    from clearance.run.simulation import simulate as simulate

_LAZY = {
    "simulate": "clearance.run.simulation",
    "SimulationError": "clearance.run.simulation",
    "SimulationResult": "clearance.results",
    "ModelOptions": "clearance.options",
    "ContactMode": "clearance.options",
    "GeomType": "clearance.options",
}

__all__ = [
    "STEEL",
    "Clearance",
    "ContactLaw",
    "Drive",
    "DriveKind",
    "Joint",
    "JointType",
    "Link",
    "Material",
    "Mechanism",
    "MotionLaw",
    "Output",
    "OutputKind",
    *_LAZY,
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'clearance' has no attribute {name!r}")
