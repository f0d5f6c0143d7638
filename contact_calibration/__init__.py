"""clearance.contact_calibration: contact laws, impact reference, fitting, exact LN, store.

The pure laws (`laws`) and the point-mass impact reference (`impact`) import no MuJoCo and
are loaded eagerly. Everything that runs MuJoCo (nominal parameters, the fit, the store,
exact-LN mode, cycle effective mass, reports) is imported on first use, so
``import clearance.contact_calibration`` stays cheap.

Main entry points:
  * `calibrated_parameters(joint, ring, sizing, options)`: the cached calibration used by
    `ContactMode.CALIBRATED`;
  * `calibrate(...)` / `fit_contact(...)`: a full `CalibrationResult` with its accuracy per
    impact speed;
  * `exact_ln_impact(...)`, `ExactLNContact`: LN imposed on the rows each step;
  * `cycle_effective_mass(...)`: effective mass at a bearing over the ideal cycle;
  * `calibration_report(...)`, `main_calibrate(argv)`: Markdown table + plot, CLI.
"""

from __future__ import annotations

import importlib
from typing import Any

from clearance.contact_calibration.impact import (
    HertzImpact,
    ImpactResult,
    clearance_impact,
    hertz_impact,
    law_impact,
    simulate_impact,
    simulate_oblique_impact,
)
from clearance.contact_calibration.laws import (
    MIN_APPROACH_SPEED,
    STIFFNESS_FORMULA,
    UnverifiedLawWarning,
    ambrosio_friction,
    bearing_stiffness,
    bearing_stiffness_from,
    flores,
    gonthier,
    hertz,
    hu_guo,
    hunt_crossley,
    hysteresis_factor,
    impact_law,
    lankarani_nikravesh,
    normal_force,
)

_LAZY = {
    # nominal
    "NOMINAL_IMPACT_SPEED": "nominal",
    "nominal_parameters": "nominal",
    "ring_impact": "nominal",
    # MuJoCo scene impacts
    "SceneImpact": "scene_impact",
    "scene_impacts": "scene_impact",
    "ring_gap": "scene_impact",
    "onset_radius": "scene_impact",
    # fit
    "GOALS": "fit",
    "SpeedRow": "fit",
    "Stability": "fit",
    "CalibrationResult": "fit",
    "CalibrationStabilityError": "fit",
    "default_speeds": "fit",
    "reference_impacts": "fit",
    "evaluate": "fit",
    "accuracy_rows": "fit",
    "check_stability": "fit",
    "fit_contact": "fit",
    # store
    "CACHE_ENV": "store",
    "CalibrationCacheWarning": "store",
    "cache_dir": "store",
    "calibration_key": "store",
    "calibration_path": "store",
    "load_calibration": "store",
    "save_calibration": "store",
    "calibrate": "store",
    "calibrate_joint": "store",
    "calibrated_parameters": "store",
    # exact LN
    "ExactLNContact": "exact_ln",
    "impose_exact_ln": "exact_ln",
    "step_exact_ln": "exact_ln",
    "ExactLNRun": "exact_ln",
    "ExactLNStepError": "exact_ln",
    "ExactLNCost": "exact_ln",
    "exact_ln_impact": "exact_ln",
    "exact_ln_cost": "exact_ln",
    "polygon_margin": "exact_ln",
    # effective mass
    "EffectiveMass": "effective_mass",
    "cycle_effective_mass": "effective_mass",
    "normal_effective_mass": "effective_mass",
    # report / CLI
    "calibration_report": "report",
    "accuracy_table": "report",
    "main_calibrate": "report",
    "ReportFiles": "report",
}

__all__ = [
    "HertzImpact",
    "ImpactResult",
    "clearance_impact",
    "hertz_impact",
    "law_impact",
    "simulate_impact",
    "simulate_oblique_impact",
    "MIN_APPROACH_SPEED",
    "STIFFNESS_FORMULA",
    "UnverifiedLawWarning",
    "ambrosio_friction",
    "bearing_stiffness",
    "bearing_stiffness_from",
    "flores",
    "gonthier",
    "hertz",
    "hu_guo",
    "hunt_crossley",
    "hysteresis_factor",
    "impact_law",
    "lankarani_nikravesh",
    "normal_force",
    *_LAZY,
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        module = importlib.import_module(f"clearance.contact_calibration.{_LAZY[name]}")
        return getattr(module, name)
    raise AttributeError(f"module 'clearance.contact_calibration' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
