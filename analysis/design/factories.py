"""Picklable mechanism factories of design points: a clearance per joint, a drive speed.

A design point is ``{"clearances": {joint: c [m], ...}, **rest}``. `JointClearances` builds
the base mechanism from ``rest`` (a builder's speed keyword, say) and gives each named joint
its own radial clearance, keeping the rest of its `Clearance` record (bearing radius,
materials, restitution, friction, law; a slider's `TranslationalClearance`, its play c) or,
for a joint the base leaves ideal, the record ``template`` with that clearance.
`FixedMechanism` serves a mechanism read from a file as a base, its first constant-speed
drive set to the point's ``speed`` when one is given.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from clearance.analysis.sweeps.sweep import MechanismFactory
from clearance.model import Clearance, DriveKind, JointType, Mechanism

__all__ = ["FixedMechanism", "JointClearances", "with_clearances"]


def with_clearances(mechanism: Mechanism, clearances: Mapping[str, float], template: Clearance) -> Mechanism:
    """The mechanism with each named joint at its own radial clearance [m] (a slider: its play c).

    Args:
        mechanism: the design (not changed: a new one is returned).
        clearances: joint name -> its radial clearance [m].
        template: the clearance record (bearing, materials, law) of a named joint that has
            none yet; a joint that has one keeps it and changes only its radial clearance.

    Raises:
        KeyError: a name that is not a joint of the mechanism.
        ValueError: a prismatic joint without play in its guide in ``mechanism``, or a
            clearance its bearing or guide cannot hold.
    """
    names = {j.name for j in mechanism.joints}
    unknown = [k for k in clearances if k not in names]
    if unknown:
        raise KeyError(f"no joint {unknown} in mechanism '{mechanism.name}' (joints: {sorted(names)})")
    joints = []
    for j in mechanism.joints:
        if j.name in clearances and j.translational_clearance is not None:  # a slider's play in its guide
            play = dataclasses.replace(j.translational_clearance, clearance=float(clearances[j.name]))
            j = dataclasses.replace(j, translational_clearance=play)
        elif j.name in clearances:
            if j.kind is not JointType.REVOLUTE:
                raise ValueError(
                    f"joint '{j.name}' is a slider without play in its guide: give it play in the base mechanism "
                    "(clearance_at) to allocate it a clearance"
                )
            base = j.clearance or dataclasses.replace(template, journal_link=None)
            j = dataclasses.replace(j, clearance=dataclasses.replace(base, radial_clearance=float(clearances[j.name])))
        joints.append(j)
    return dataclasses.replace(mechanism, joints=tuple(joints))


@dataclass(frozen=True)
class JointClearances:
    """Picklable design point -> Mechanism: ``base(rest)`` with per-joint clearances.

    Attributes:
        base: picklable point -> Mechanism for the point without its ``clearances``.
        template: clearance record of joints the base leaves ideal (its radial clearance is
            replaced).
    """

    base: MechanismFactory
    template: Clearance = field(default_factory=lambda: Clearance(radial_clearance=1e-4))

    def __call__(self, point: Mapping[str, Any]) -> Mechanism:
        rest = {k: v for k, v in point.items() if k != "clearances"}
        return with_clearances(self.base(rest), dict(point.get("clearances", {})), self.template)


@dataclass(frozen=True)
class FixedMechanism:
    """Picklable point -> a given mechanism; ``speed`` [rad/s] sets its first constant-speed drive.

    Attributes:
        mechanism: the mechanism.
    """

    mechanism: Mechanism

    def __call__(self, point: Mapping[str, Any]) -> Mechanism:
        extra = sorted(set(point) - {"speed"})
        if extra:
            raise ValueError(f"a fixed mechanism takes only 'speed' in its point (got {extra})")
        if "speed" not in point:
            return self.mechanism
        drives = list(self.mechanism.drives)
        for i, d in enumerate(drives):
            if d.kind is DriveKind.CONSTANT_SPEED:
                drives[i] = dataclasses.replace(d, speed=float(point["speed"]))
                return dataclasses.replace(self.mechanism, drives=tuple(drives))
        raise ValueError(f"mechanism '{self.mechanism.name}' has no constant-speed drive whose speed could be set")
