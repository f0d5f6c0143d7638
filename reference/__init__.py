"""clearance.reference: the exact-geometry planar multibody solver (ground truth, slow).

The seeds' method done carefully: Cartesian coordinates (x, y, theta) per link; ideal
revolute and prismatic joints and the prescribed drives as constraints with Lagrange
multipliers, held by Baumgarte stabilisation or coordinate projection; clearance joints
with exact circle-in-circle geometry, sliders with play with exact corner geometry (each
of the four corners against the guide's two lines, `corner_contact`), any normal law of
`clearance.contact_calibration.laws` with the approach speed recorded at each contact
onset, and Ambrosio friction; integration with a scipy `OdeSolver` (LSODA by default) at
tight tolerances, every contact onset located on the dense output so no impact is stepped
over. It returns the same `SimulationResult` as MuJoCo runs.

Entry points:
  * `run_reference(mechanism, duration, ...)`: a mechanism from its assembled start.
  * `ReferenceSystem` + `simulate_system(system, q0, qd0, duration, ...)`: any explicit
    initial state, and systems built `from_parts` (`journal_in_bearing`: a free body in a
    ground-fixed bearing, the single-impact check against the calibration's reference;
    `slider_in_guide`: a free block with play in a ground-fixed guide).

A `ReferenceSystem` keeps scratch buffers: use one per thread (process pools are fine).
"""

from clearance.reference.examples import journal_in_bearing, slider_in_guide
from clearance.reference.integrator import (
    METHODS,
    IntegrationFailure,
    Trajectory,
    integrate_system,
)
from clearance.reference.run import (
    ReferenceSolverError,
    Stabilisation,
    run_reference,
    simulate_system,
    to_result,
)
from clearance.reference.system import (
    Evaluation,
    ReferenceOptions,
    ReferenceSystem,
    SingularConstraintsError,
)

__all__ = [
    "METHODS",
    "Evaluation",
    "IntegrationFailure",
    "ReferenceOptions",
    "ReferenceSolverError",
    "ReferenceSystem",
    "SingularConstraintsError",
    "Stabilisation",
    "Trajectory",
    "integrate_system",
    "journal_in_bearing",
    "slider_in_guide",
    "run_reference",
    "simulate_system",
    "to_result",
]
