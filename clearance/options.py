"""Numerical options of a MuJoCo run: the choices that are not physics.

`ModelOptions` is passed to `clearance.mjcf` and `clearance.simulate`; the reference
solver ignores it. `ContactParameters` are the per-segment spring-damper values a
clearance joint's contact pairs get, in physical units.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from clearance.checks import NotANumberError, finite, of_type

__all__ = ["GeomType", "ContactMode", "DEFAULT_TIMESTEP", "ModelOptions", "ContactParameters"]


class GeomType(enum.Enum):
    """Geom shape of a journal or of a bearing segment."""

    SPHERE = "sphere"
    CAPSULE = "capsule"
    BOX = "box"
    CYLINDER = "cylinder"


class ContactMode(enum.Enum):
    """How contact parameters are chosen.

    NOMINAL: per-segment stiffness from the journal-bearing stiffness K (docs/references.md)
        spread over the ring, damping giving LN's restitution at a nominal
        impact speed; no fitting.
    CALIBRATED: parameters fitted to LN impacts (`clearance.contact_calibration`), cached.
    EXACT: every clearance joint's own contact law (any `ContactLaw`, with Ambrósio
        friction) computed on exact circle geometry by the compiled engine plugin
        `clearance.journal_bearing` (`clearance.contact_plugin`); no ring, no contact rows.
        ``"exact_ln"`` is accepted for it (the name it had when it imposed LN alone).
    """

    NOMINAL = "nominal"
    CALIBRATED = "calibrated"
    EXACT = "exact"
    EXACT_LN = "exact"  # the same member: the mode's name when it imposed LN alone

    @classmethod
    def _missing_(cls, value: object) -> ContactMode | None:
        return cls.EXACT if value == "exact_ln" else None


DEFAULT_TIMESTEP: dict[ContactMode, float] = {
    ContactMode.NOMINAL: 2e-6,
    ContactMode.CALIBRATED: 2e-6,
    ContactMode.EXACT: 3e-6,
}
"""Each contact mode's default time step [s], chosen from the measured front of speed against
error (benchmarks/speed_error.md)."""


@dataclass(frozen=True)
class ModelOptions:
    """Numerical choices of a MuJoCo model and run.

    Attributes:
        segments: bearing segment count N (>= 8), or None (default) to choose N per joint
            by the ripple rule (`clearance.mjcf.bearing.choose_segments`; N = 144 for the
            default scenario, see benchmarks/segments_speed.md).
        journal_geom: journal geom type (SPHERE or CAPSULE; CYLINDER uses the convex
            collider).
        segment_geom: bearing segment geom type (SPHERE, CAPSULE, BOX or CYLINDER).
        timestep: integration time step h [s]; 0 (the default) for the contact mode's own
            default, `DEFAULT_TIMESTEP` (benchmarks/speed_error.md).
        integrator: MuJoCo integrator name ("implicitfast", "euler", "implicit", "rk4").
        contact_mode: the contact model (default EXACT, the compiled exact contact: first
            impacts within 0.3 % of the reference and the benchmark's statistics within the
            reference's own scatter on three of its four scenarios, at 3 µs and 25x the
            reference's speed; CALIBRATED, the portable ring, needs no compiled plugin;
            benchmarks/speed_error.md).
        ripple_limit: largest force ripple allowed by the segment-count rule [-].
        impedance: constant solimp impedance d of the contact rows (small: the contact
            then behaves as a plain spring-damper; docs/mujoco_notes.md).
        closure_timeconst: time constant of ideal loop-closure equalities [s]; None for
            2 * timestep (the stiffest value MuJoCo accepts).
    """

    segments: int | None = None
    journal_geom: GeomType = GeomType.SPHERE
    segment_geom: GeomType = GeomType.SPHERE
    timestep: float = 0.0
    integrator: str = "implicitfast"
    contact_mode: ContactMode = ContactMode.EXACT
    ripple_limit: float = 0.02
    impedance: float = 1e-3
    closure_timeconst: float | None = None

    def __post_init__(self) -> None:
        if self.segments is not None:
            if not isinstance(self.segments, int) or isinstance(self.segments, bool):
                raise NotANumberError(f"segments must be an integer >= 8 (got {self.segments!r})")
            if self.segments < 8:
                raise ValueError(f"segments must be an integer >= 8 (got {self.segments!r})")
        for name in ("journal_geom", "segment_geom"):
            v = getattr(self, name)
            if not isinstance(v, (GeomType, str)):
                of_type(name, v, GeomType, f"a GeomType or one of {[g.value for g in GeomType]}")
            if not isinstance(v, GeomType):
                try:
                    object.__setattr__(self, name, GeomType(v))
                except ValueError:
                    raise ValueError(f"{name} must be one of {[g.value for g in GeomType]} (got {v!r})") from None
        if self.journal_geom is GeomType.BOX:
            raise ValueError("journal_geom must be sphere, capsule or cylinder (got 'box')")
        if not isinstance(self.contact_mode, (ContactMode, str)):
            of_type(
                "contact_mode",
                self.contact_mode,
                ContactMode,
                f"a ContactMode or one of {[c.value for c in ContactMode]}",
            )
        if not isinstance(self.contact_mode, ContactMode):
            try:
                object.__setattr__(self, "contact_mode", ContactMode(self.contact_mode))
            except ValueError:
                raise ValueError(
                    f"contact_mode must be one of {[c.value for c in ContactMode]} (got {self.contact_mode!r})"
                ) from None
        finite("timestep", self.timestep)  # a number: a string or None is a type error, named
        if self.timestep == 0:
            object.__setattr__(self, "timestep", DEFAULT_TIMESTEP[self.contact_mode])
        h = self.timestep
        if not isinstance(h, (int, float)) or not math.isfinite(h) or not 0 < h <= 1e-2:
            raise ValueError(f"timestep must be in (0, 0.01] s (got {h!r})")
        if self.integrator not in ("implicitfast", "euler", "implicit", "rk4"):
            raise ValueError(
                f"integrator must be one of 'implicitfast', 'euler', 'implicit', 'rk4' (got {self.integrator!r})"
            )
        if not 0 < self.ripple_limit < 1:
            raise ValueError(f"ripple_limit must be in (0, 1) (got {self.ripple_limit!r})")
        if not 0 < self.impedance < 0.5:
            raise ValueError(f"impedance must be in (0, 0.5) (got {self.impedance!r})")
        if self.closure_timeconst is not None and not self.closure_timeconst >= 2 * h:
            raise ValueError(
                f"closure_timeconst must be >= 2 * timestep = {2 * h:g} s (got {self.closure_timeconst!r})"
            )


@dataclass(frozen=True)
class ContactParameters:
    """Per-segment spring-damper of a clearance joint's contact pairs (physical units).

    Attributes:
        stiffness: normal stiffness of one journal-segment contact row [N/m], at full
            impedance (with ``impedance_rise`` > 0: at row penetrations of the radial
            clearance and beyond).
        damping: normal damping of one contact row [N s/m], at full impedance likewise.
        source: where the values come from ("nominal", "calibrated: <file>", ...).
        impedance_rise: ε [-], the shape of the rows' impedance: each row's solimp is
            (d(1 − ε), d, c, 0.5, 1), an impedance rising linearly with the row's
            penetration r from d(1 − ε) at r = 0 to d at r = c (d = `ModelOptions.impedance`,
            c = the joint's radial clearance). MuJoCo's direct-mode row force is then
            (d(r)/d)² k r + (d(r)/d) b ṙ, so each row stiffens with its own penetration
            (`clearance.mjcf.contact.row_solimp`). 0 (the default): the constant impedance d
            the ring is built with, solimp (d, d, 0.001, 0.5, 2) left as it is. The
            calibrated mode fits ε (`clearance.contact_calibration.fit`).
    """

    stiffness: float
    damping: float
    source: str = "nominal"
    impedance_rise: float = 0.0

    def __post_init__(self) -> None:
        for name in ("stiffness", "damping"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"ContactParameters.{name} must be finite and >= 0 (got {v!r})")
        if self.stiffness == 0:
            raise ValueError("ContactParameters.stiffness must be > 0 (got 0)")
        eps = self.impedance_rise
        if not isinstance(eps, (int, float)) or isinstance(eps, bool) or not 0 <= eps < 1:
            raise ValueError(f"ContactParameters.impedance_rise must be in [0, 1) (got {eps!r})")
