"""A lubricated journal bearing: the oil film of a revolute clearance joint. Physics only.

A `Clearance` may carry a `Lubrication`: the gap between journal and bearing is then full of
oil of dynamic viscosity ``viscosity``, and the film's pressure pushes the journal back
towards the centre and ahead of the line of centres before the surfaces touch (Flores,
Ambrósio, Claro & Lankarani 2009). The bearing's axial length L is the clearance's
``bearing_length``. ``film`` chooses the approximation of Reynolds' equation: the short
bearing (Ocvirk; L/D below about 1/2) or the infinitely long one (Sommerfeld; Pinkus &
Sternlicht; L/D above about 2). The forces are `clearance.contact_calibration.film`'s.

Below ``transition_thickness`` of minimum film thickness h = c - |e| the film is taken to
rupture (the surfaces' roughness meets) and the joint's dry contact law takes over; the film
force is held at its value at that thickness (see `film.lubricated_force`), so the force
has no jump.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from clearance.checks import positive

__all__ = ["FilmModel", "Lubrication", "DEFAULT_TRANSITION_THICKNESS"]

DEFAULT_TRANSITION_THICKNESS = 1.0e-6
"""Default film thickness [m] below which the dry contact law takes over: about three times
the combined roughness of ground journal and bearing surfaces (Ra 0.2-0.4 um each), where
mixed lubrication begins (a rule of tribology texts, [recalled]; not a value of the papers
the film forces come from)."""


class FilmModel(enum.Enum):
    """Approximation of Reynolds' equation for the film force (docs/references.md).

    SHORT: the short bearing (Ocvirk): circumferential pressure flow neglected; for L/D
        below about 1/2.
    LONG: the infinitely long bearing (Sommerfeld; Pinkus & Sternlicht's form with the
        pi film): axial flow neglected; for L/D above about 2.
    """

    SHORT = "short"
    LONG = "long"


@dataclass(frozen=True)
class Lubrication:
    """The oil film of a lubricated revolute clearance joint.

    Attributes:
        viscosity: dynamic viscosity of the oil mu_oil [Pa s], > 0 (an SAE 30 engine oil at
            about 60 C: 0.03 Pa s).
        film: the approximation of Reynolds' equation (`FilmModel`).
        transition_thickness: minimum film thickness h_t [m] > 0 below which the dry
            contact law takes over; must be below the joint's radial clearance (checked by
            `Clearance`).
    """

    viscosity: float
    film: FilmModel = FilmModel.SHORT
    transition_thickness: float = DEFAULT_TRANSITION_THICKNESS

    def __post_init__(self) -> None:
        positive("viscosity", self.viscosity, "Pa s")
        if not isinstance(self.film, FilmModel):
            raise ValueError(f"film must be a FilmModel, one of {[f.value for f in FilmModel]} (got {self.film!r})")
        positive("transition_thickness", self.transition_thickness, "m")
