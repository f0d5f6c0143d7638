"""clearance.mjcf: Mechanism -> MuJoCo spec (ring-segment bearings, pairs, drives, sensors).

This package builds and compiles models; it never runs a simulation.
"""

from clearance.mjcf.bearing import (
    RingGeometry,
    choose_segments,
    force_ripple,
    ring_force,
)
from clearance.mjcf.contact import (
    add_initial_keyframe,
    apply_contact,
    effective_masses,
    initial_velocity,
    row_inverse_weight,
)
from clearance.mjcf.guide import GuideGeometry
from clearance.mjcf.spec import BuiltModel, build_spec, ring_geometry
from clearance.mjcf.tree import BodyTree, body_tree

__all__ = [
    "RingGeometry",
    "choose_segments",
    "force_ripple",
    "ring_force",
    "apply_contact",
    "add_initial_keyframe",
    "initial_velocity",
    "effective_masses",
    "row_inverse_weight",
    "BuiltModel",
    "build_spec",
    "GuideGeometry",
    "ring_geometry",
    "BodyTree",
    "body_tree",
]
