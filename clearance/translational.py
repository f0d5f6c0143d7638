"""Translational clearance: a slider with play in its guide, and what a run records of it.

A prismatic joint may carry a `TranslationalClearance`: the slider is then a block of
``slider_length`` by ``slider_height`` centred on the joint's ``point_b`` and the guide a
channel of height ``slider_height + 2 clearance`` whose centre line runs through ``point_a``
along the joint's axis. The slider is no longer held on the line: it moves in the plane
(along the guide, across it, and tilting) and only contact of its four corners with the
guide's two lines holds it (Flores, Ambrósio, Claro & Lankarani 2008). The papers and the
public examples of the benchmark write the block's half-length and half-height as a and b
(guide height d = 2 (b + c)); here the record holds the full length and height.

Corners are numbered in the slider's own frame at zero tilt, in the guide's axes (u along
the axis, n across it, n = u turned by +90 degrees): 0 = (-L/2, +H/2), 1 = (+L/2, +H/2),
2 = (-L/2, -H/2), 3 = (+L/2, -H/2): corners 0 and 1 face the guide's +n line, 2 and 3 its
-n line. `SliderContact` names the four contact cases of that paper; `classify_contact`
tells them from the corners' penetrations. `SliderResult` holds a run's series of one
translational clearance joint.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from clearance.checks import finite, positive
from clearance.model import ContactLaw

__all__ = [
    "CORNERS",
    "DEFAULT_GUIDE_STIFFNESS",
    "TranslationalClearance",
    "SliderContact",
    "SliderResult",
    "classify_contact",
    "SLIDER_FIELDS",
]

CORNERS: tuple[tuple[float, float], ...] = ((-0.5, 0.5), (0.5, 0.5), (-0.5, -0.5), (0.5, -0.5))
"""Corner k at (s_u L, s_n H) in the guide's axes at zero tilt, (s_u, s_n) = CORNERS[k]."""

DEFAULT_GUIDE_STIFFNESS = 1.0e10
"""Default corner contact stiffness K [N/m^1.5]: the value chosen for the Flores, Leine and
Glocker (2010) slider-crank (benchmarks/translational_clearance.md), a stand-in for its rigid
guide: its corners sink about 3 % of the 1 mm clearance, and ten times softer or stiffer
corners move the energy left after 0.2 s by under 0.2 % and the contact episodes by at most
0.5 ms, within the spread of the published examples' own runs."""


@dataclass(frozen=True)
class TranslationalClearance:
    """Play of a slider in its guide (a prismatic joint with clearance). Physics only.

    Attributes:
        clearance: c [m]: the gap on each side of the centred slider (guide height H + 2c).
        slider_length: L [m]: the block's length along the guide.
        slider_height: H [m]: the block's height across the guide.
        stiffness: K [N/m^1.5] of each corner's contact with a guide line (F = K delta^1.5
            before damping); default `DEFAULT_GUIDE_STIFFNESS`.
        restitution: coefficient of restitution c_e in (0, 1].
        friction: Coulomb friction coefficient mu >= 0 (Ambrosio's law along the guide).
        law: normal contact force law (`ContactLaw`; IMPACT needs its C_max, d_max in the
            solver's options).
    """

    clearance: float
    slider_length: float
    slider_height: float
    stiffness: float = DEFAULT_GUIDE_STIFFNESS
    restitution: float = 0.9
    friction: float = 0.0
    law: ContactLaw = ContactLaw.LANKARANI_NIKRAVESH

    def __post_init__(self) -> None:
        c = positive("clearance", self.clearance, "m")
        length = positive("slider_length", self.slider_length, "m")
        positive("slider_height", self.slider_height, "m")
        positive("stiffness", self.stiffness, "N/m^1.5")
        # the slider must not be able to turn over in its guide: its diagonal must exceed the
        # guide height, L^2 + H^2 > (H + 2c)^2, i.e. L > 2 sqrt(c (H + c))
        least = 2.0 * math.sqrt(c * (self.slider_height + c))
        if not length > least:
            raise ValueError(
                f"slider_length must be > 2 sqrt(clearance (slider_height + clearance)) = {least:.6g} m, or the "
                f"slider can turn over in its guide (got {self.slider_length!r} m)"
            )
        e = finite("restitution", self.restitution)
        if not 0.0 < e <= 1.0:
            raise ValueError(f"restitution must be in (0, 1] (got {self.restitution!r})")
        if finite("friction", self.friction) < 0:
            raise ValueError(f"friction must be >= 0 (got {self.friction!r})")
        if not isinstance(self.law, ContactLaw):
            raise ValueError(f"law must be a ContactLaw (got {self.law!r})")

    @property
    def guide_height(self) -> float:
        """H + 2c [m]: the distance between the guide's two lines."""
        return self.slider_height + 2.0 * self.clearance

    @property
    def max_tilt(self) -> float:
        """Largest tilt of the slider in its guide [rad] (two diagonal corners touching).

        The diagonal D = sqrt(L^2 + H^2) at angle beta = atan(H / L) to the axis spans the
        guide's height when D sin(beta + tilt) = H + 2c.
        """
        d = math.hypot(self.slider_length, self.slider_height)
        return math.asin(self.guide_height / d) - math.atan2(self.slider_height, self.slider_length)


class SliderContact(enum.Enum):
    """The four contact cases of a slider in its guide (Flores et al. 2008).

    Values are the codes stored in `SliderResult.contact_case`.
    """

    FREE = 0
    """No corner touches: free flight inside the clearance."""
    ONE_CORNER = 1
    """One corner touches one guide line."""
    ONE_SIDE = 2
    """Two corners of one side touch the same guide line (the slider lies flat on it)."""
    DIAGONAL = 3
    """Two opposite corners touch opposite guide lines (the slider is wedged, tilted)."""


def classify_contact(corner_penetration: np.ndarray) -> np.ndarray:
    """The contact case of each sample from the corners' penetrations.

    Args:
        corner_penetration: (n, 4) penetration of corners 0-3 into their guide line [m]
            (> 0 in contact), in the order of `CORNERS`.

    Returns:
        (n,) int8 codes of `SliderContact`. Corners touching both lines count as DIAGONAL
        (a compliant contact squeezed from both sides); three or four corners touching one
        line cannot happen to a rectangle and are counted by the lines they touch.

    Raises:
        ValueError: the array is not (n, 4).
    """
    p = np.asarray(corner_penetration, dtype=float)
    if p.ndim != 2 or p.shape[1] != 4:
        raise ValueError(f"corner_penetration must have shape (n, 4) (got {p.shape})")
    on = p > 0.0
    upper = on[:, 0] | on[:, 1]
    lower = on[:, 2] | on[:, 3]
    count = on.sum(axis=1)
    case = np.full(len(p), SliderContact.FREE.value, dtype=np.int8)
    case[count == 1] = SliderContact.ONE_CORNER.value
    case[(count >= 2) & (upper != lower)] = SliderContact.ONE_SIDE.value
    case[upper & lower] = SliderContact.DIAGONAL.value
    return case


@dataclass
class SliderResult:
    """Series of one translational clearance joint, in the guide frame (u along, n across).

    Attributes:
        position: (n, 2) slider centre (the joint's point_b) relative to the guide's point_a:
            along the axis and across it [m]; across is within +-c when no corner touches
            at zero tilt.
        velocity: (n, 2) time derivative of ``position`` [m/s].
        tilt: (n,) slider angle relative to the guide, theta_b - theta_a minus its value
            at assembly [rad]; positive turns u towards n.
        tilt_rate: (n,) its time derivative [rad/s].
        corner_penetration: (n, 4) penetration of each corner into its guide line [m],
            > 0 in contact, corners as in `CORNERS`.
        corner_force: (n, 4) normal force at each corner [N] (>= 0).
        contact_force: (n, 2) net contact force on the slider (normal and friction) along
            and across the guide [N].
        contact_case: (n,) int8 codes of `SliderContact`.
    """

    position: np.ndarray
    velocity: np.ndarray
    tilt: np.ndarray
    tilt_rate: np.ndarray
    corner_penetration: np.ndarray
    corner_force: np.ndarray
    contact_force: np.ndarray
    contact_case: np.ndarray

    def cases(self) -> list[SliderContact]:
        """`contact_case` as `SliderContact` members, one per sample."""
        members = list(SliderContact)
        return [members[int(v)] for v in self.contact_case]

    def sliced(self, sl: slice | np.ndarray) -> SliderResult:
        """The same series restricted to ``sl`` (rows)."""
        return SliderResult(*(getattr(self, f)[sl] for f in SLIDER_FIELDS))


SLIDER_FIELDS = (
    "position",
    "velocity",
    "tilt",
    "tilt_rate",
    "corner_penetration",
    "corner_force",
    "contact_force",
    "contact_case",
)
"""`SliderResult`'s series, in order (names in a saved ``.npz``: ``slider/<joint>/<field>``)."""
