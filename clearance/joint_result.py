"""`JointResult`: the series of one revolute clearance joint in a `SimulationResult`.

All in the bearing frame (the bearing link's axes, origin at the bearing centre). A lubricated
joint (`clearance.lubrication`) also carries its oil film's force, ``film_force``; its minimum
film thickness h = c − |e| and eccentricity ratio ε = |e|/c follow from the eccentricity and the
penetration (`JointResult.film_thickness`, `JointResult.eccentricity_ratio`), for any joint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["JOINT_FIELDS", "OPTIONAL_JOINT_FIELDS", "JointResult"]

JOINT_FIELDS: tuple[str, ...] = ("eccentricity", "eccentricity_rate", "penetration", "contact_force")
"""The series every clearance joint has, in `JointResult`'s order (``joint/<joint>/<field>`` in a
saved ``.npz``)."""

OPTIONAL_JOINT_FIELDS: tuple[str, ...] = ("film_force",)
"""Series only some joints have (None otherwise; absent from the ``.npz`` then, and from files
saved before they existed)."""


@dataclass
class JointResult:
    """Per-clearance-joint series, all in the bearing frame.

    Attributes:
        eccentricity: (n, 2) journal-centre position relative to the bearing centre [m].
        eccentricity_rate: (n, 2) its time derivative [m/s].
        penetration: (n,) |e| - c [m]; positive means in contact.
        contact_force: (n, 2) net contact force on the journal [N]: the dry contact's, plus a
            lubricated joint's film force.
        film_force: (n, 2) the oil film's force on the journal [N] (part of ``contact_force``)
            for a lubricated joint; None for a dry one. A MuJoCo run reads it from the compiled
            contact's sensor (the force it applied over each step), a reference run evaluates
            the film at each sample's state (`clearance.contact_calibration.film.film_scalar`).
    """

    eccentricity: np.ndarray
    eccentricity_rate: np.ndarray
    penetration: np.ndarray
    contact_force: np.ndarray
    film_force: np.ndarray | None = None

    @property
    def force_magnitude(self) -> np.ndarray:
        """(n,) magnitude of the contact force [N]."""
        return np.hypot(self.contact_force[:, 0], self.contact_force[:, 1])

    @property
    def film_thickness(self) -> np.ndarray:
        """(n,) minimum film thickness h = c − |e| [m] (the gap where it is thinnest; negative in
        dry contact, where the surfaces overlap by −h)."""
        return -self.penetration

    @property
    def eccentricity_ratio(self) -> np.ndarray:
        """(n,) ε = |e|/c [-] (1: the journal touches the bearing), c = |e| − penetration."""
        d = np.hypot(self.eccentricity[:, 0], self.eccentricity[:, 1])
        return d / (d - self.penetration)

    @property
    def film_force_magnitude(self) -> np.ndarray | None:
        """(n,) magnitude of the film force [N]; None for a dry joint."""
        if self.film_force is None:
            return None
        return np.hypot(self.film_force[:, 0], self.film_force[:, 1])

    @property
    def lubricated(self) -> bool:
        """Whether the joint carries an oil film's force series."""
        return self.film_force is not None

    def sliced(self, sl: slice | np.ndarray) -> JointResult:
        """The same series restricted to ``sl`` (rows)."""
        return JointResult(
            self.eccentricity[sl],
            self.eccentricity_rate[sl],
            self.penetration[sl],
            self.contact_force[sl],
            None if self.film_force is None else self.film_force[sl],
        )

    def series(self) -> dict[str, np.ndarray]:
        """Every series the joint has by field name (`JOINT_FIELDS`, then those of
        `OPTIONAL_JOINT_FIELDS` that are not None)."""
        out = {f: getattr(self, f) for f in JOINT_FIELDS}
        out.update({f: getattr(self, f) for f in OPTIONAL_JOINT_FIELDS if getattr(self, f) is not None})
        return out

    @classmethod
    def from_series(cls, series: dict[str, np.ndarray]) -> JointResult:
        """A joint from `series`' mapping (the optional fields may be missing).

        Raises:
            KeyError: a field of `JOINT_FIELDS` is missing.
        """
        return cls(*(series[f] for f in JOINT_FIELDS), **{f: series[f] for f in OPTIONAL_JOINT_FIELDS if f in series})

    @staticmethod
    def concatenate(parts: list[JointResult]) -> JointResult:
        """Join consecutive parts of one joint's series (an optional series only if every part has it).

        Raises:
            ValueError: no parts.
        """
        if not parts:
            raise ValueError("concatenate needs at least one part")
        each = [p.series() for p in parts]
        names = [f for f in each[0] if all(f in s for s in each)]
        return JointResult.from_series({f: np.concatenate([s[f] for s in each]) for f in names})
