"""Scenes of the compiled-contact tests: a body free to move in the plane of its bearing."""

from __future__ import annotations

from typing import Any

import mujoco

from clearance.contact_plugin import attributes

PLANAR_DOFS = (("x", "SLIDE", (1, 0, 0)), ("y", "SLIDE", (0, 1, 0)), ("spin", "HINGE", (0, 0, 1)))
"""(suffix, joint type, axis) of a planar body's three dofs."""


def planar_body(
    parent: mujoco.MjsBody, name: str, *, mass: float, inertia: float, prefix: str = "", moving: bool = True
) -> mujoco.MjsBody:
    """A body on slide x, slide y and hinge z (joints ``prefix + suffix``; none, fixed to its
    parent, when not ``moving``), its explicit mass and inertia [kg, kg m²], and a site of its
    own name at its origin."""
    body = parent.add_body(name=name)
    for suffix, kind, axis in PLANAR_DOFS if moving else ():
        body.add_joint(name=f"{prefix}{suffix}", axis=list(axis), type=getattr(mujoco.mjtJoint, f"mjJNT_{kind}"))
    body.explicitinertial = True
    body.mass = mass
    body.inertia = [inertia] * 3
    body.add_site(name=name)
    return body


def add_joint(spec: mujoco.MjSpec, **attrs: Any) -> None:
    """A journal-bearing contact named ``joint`` between the sites ``journal`` and ``bearing``
    (`attributes.add_journal_bearing` with ``attrs``)."""
    attributes.add_journal_bearing(spec, name="joint", journal_site="journal", bearing_site="bearing", **attrs)
