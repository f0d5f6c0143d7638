"""Numerical options of a MuJoCo run: the choices that are not physics.

`ModelOptions` is passed to `clearance.mjcf` and `clearance.simulate`; the reference
solver ignores it. `ContactParameters` are the per-segment spring-damper values a
clearance joint's contact pairs get, in physical units.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

__all__ = ["GeomType", "ContactMode", "ModelOptions", "ContactParameters"]


class GeomType(enum.Enum):
    """Geom shape of a journal or of a bearing segment."""

    SPHERE = "sphere"
    CAPSULE = "capsule"
    BOX = "box"
    CYLINDER = "cylinder"


class ContactMode(enum.Enum):
    """How contact parameters are chosen.

    NOMINAL: per-segment stiffness from the journal-bearing stiffness K (REFERENCES.md
        section 1) spread over the ring, damping giving LN's restitution at a nominal
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
        timestep: integration time step h [s] (default 2 µs: on the default scenario the
            first-impact peak is within 5 % of the reference, 0.2 points worse than at
            1 µs at half the cost; benchmarks/speed_error.md).
        integrator: MuJoCo integrator name ("implicitfast", "euler", "implicit", "rk4").
        contact_mode: how contact parameters are chosen (default CALIBRATED: the lowest
            statistics errors of the two rollout modes over the benchmark scenarios;
            EXACT_LN for accuracy at about ten times the cost; benchmarks/speed_error.md).
        ripple_limit: largest force ripple allowed by the segment-count rule [-].
        impedance: constant solimp impedance d of the contact rows (small: the contact
            then behaves as a plain spring-damper; MUJOCO_NOTES.md).
        closure_timeconst: time constant of ideal loop-closure equalities [s]; None for
            2 * timestep (the stiffest value MuJoCo accepts).
    """

    segments: int | None = None
    journal_geom: GeomType = GeomType.SPHERE
    segment_geom: GeomType = GeomType.SPHERE
    timestep: float = 2e-6
    integrator: str = "implicitfast"
    contact_mode: ContactMode = ContactMode.CALIBRATED
    ripple_limit: float = 0.02
    impedance: float = 1e-3
    closure_timeconst: float | None = None

    def __post_init__(self) -> None:
        if self.segments is not None:
            if not isinstance(self.segments, int) or isinstance(self.segments, bool) or self.segments < 8:
                raise ValueError(f"segments must be an integer >= 8 (got {self.segments!r})")
        for name in ("journal_geom", "segment_geom"):
            v = getattr(self, name)
            if not isinstance(v, GeomType):
                try:
                    object.__setattr__(self, name, GeomType(v))
                except ValueError:
                    raise ValueError(f"{name} must be one of {[g.value for g in GeomType]} (got {v!r})") from None
        if self.journal_geom is GeomType.BOX:
            raise ValueError("journal_geom must be sphere, capsule or cylinder (got 'box')")
        if not isinstance(self.contact_mode, ContactMode):
            try:
                object.__setattr__(self, "contact_mode", ContactMode(self.contact_mode))
            except ValueError:
                raise ValueError(
                    f"contact_mode must be one of {[c.value for c in ContactMode]} (got {self.contact_mode!r})"
                ) from None
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
        stiffness: normal stiffness of one journal-segment contact row [N/m].
        damping: normal damping of one contact row [N s/m].
        source: where the values come from ("nominal", "calibrated: <file>", ...).
    """

    stiffness: float
    damping: float
    source: str = "nominal"

    def __post_init__(self) -> None:
        for name in ("stiffness", "damping"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"ContactParameters.{name} must be finite and >= 0 (got {v!r})")
        if self.stiffness == 0:
            raise ValueError("ContactParameters.stiffness must be > 0 (got 0)")
