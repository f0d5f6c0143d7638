"""clearance.contact_calibration: contact laws, impact reference, fitting, exact LN, store.

The package re-exports its pure parts, which import no MuJoCo: the contact laws (`laws`)
and the point-mass impact reference (`impact`). The impact reference is imported on first
use of one of its names (it needs `scipy.integrate`, about 0.3 s to import), so
``import clearance.contact_calibration`` and its cheap modules (`laws`, `effective_mass`)
stay cheap. The parts that run MuJoCo are imported from their own modules:

  * `store.calibrated_parameters(joint, ring, sizing, options)`: the cached calibration used
    by `ContactMode.CALIBRATED`; `store.calibrate(...)`, `fit.fit_contact(...)`: a full
    `CalibrationResult` with its accuracy per impact speed;
  * `nominal.nominal_parameters(...)`: contact parameters from the formulas alone;
  * `exact_ln.exact_ln_impact(...)`, `exact_ln.ExactLNContact`: LN imposed on the rows each step;
  * `effective_mass.cycle_effective_mass(...)`: effective mass at a bearing over the ideal cycle;
  * `report.calibration_report(...)`: Markdown table + plot.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from clearance.contact_calibration.laws import MIN_APPROACH_SPEED as MIN_APPROACH_SPEED
from clearance.contact_calibration.laws import STIFFNESS_FORMULA as STIFFNESS_FORMULA
from clearance.contact_calibration.laws import (
    UnverifiedLawWarning as UnverifiedLawWarning,
)
from clearance.contact_calibration.laws import ambrosio_friction as ambrosio_friction
from clearance.contact_calibration.laws import bearing_stiffness as bearing_stiffness
from clearance.contact_calibration.laws import (
    bearing_stiffness_from as bearing_stiffness_from,
)
from clearance.contact_calibration.laws import flores as flores
from clearance.contact_calibration.laws import gonthier as gonthier
from clearance.contact_calibration.laws import hertz as hertz
from clearance.contact_calibration.laws import hu_guo as hu_guo
from clearance.contact_calibration.laws import hunt_crossley as hunt_crossley
from clearance.contact_calibration.laws import hysteresis_factor as hysteresis_factor
from clearance.contact_calibration.laws import impact_law as impact_law
from clearance.contact_calibration.laws import (
    lankarani_nikravesh as lankarani_nikravesh,
)
from clearance.contact_calibration.laws import normal_force as normal_force

if TYPE_CHECKING:
    from clearance.contact_calibration.impact import HertzImpact as HertzImpact
    from clearance.contact_calibration.impact import ImpactResult as ImpactResult
    from clearance.contact_calibration.impact import clearance_impact as clearance_impact
    from clearance.contact_calibration.impact import hertz_impact as hertz_impact
    from clearance.contact_calibration.impact import law_impact as law_impact
    from clearance.contact_calibration.impact import simulate_impact as simulate_impact
    from clearance.contact_calibration.impact import (
        simulate_oblique_impact as simulate_oblique_impact,
    )

_FROM_IMPACT = frozenset(
    {
        "HertzImpact",
        "ImpactResult",
        "clearance_impact",
        "hertz_impact",
        "law_impact",
        "simulate_impact",
        "simulate_oblique_impact",
    }
)
"""Names re-exported from `impact`, imported on first use."""


def __getattr__(name: str) -> object:
    """A re-exported name of the impact reference, importing `impact` on first use."""
    if name not in _FROM_IMPACT:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.impact"), name)
    globals()[name] = value
    return value
