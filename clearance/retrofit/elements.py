"""Spec elements a retrofit adds or rebuilds: a default class of MuJoCo's own values, and the
two slides put before a hinge.

MuJoCo applies a model's default classes to every element the spec API adds, so a model
whose defaults give joints damping, armature or limits (gymnasium's arms do) would pass them
to the new slides, and a default geom margin or density to the new geoms. Everything a
retrofit adds is created in the class `DEFAULT_CLASS`, which holds MuJoCo's built-in values
(read from an empty spec) for joints, geoms, sites and pairs.

A body's joints act in their order in the body, and the spec API only appends; so the hinge
is rebuilt after the slides with every attribute of the original and its default class:
the slides then translate the child body in the parent's frame (the bearing frame) and the
hinge turns it about the axis through the moved anchor.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

from clearance.retrofit.play import DEFAULT_CLASS

__all__ = ["add_builtin_class", "copy_attributes", "rebuild_hinge_after_slides"]

_NOT_COPIED = frozenset({"id", "parent", "signature", "compiler", "classname", "frame", "name", "info"})
"""Element attributes that are identity or structure, not values."""


def _values(element: Any) -> dict[str, Any]:
    """The settable value attributes of a spec element (or of a default class's element)."""
    out = {}
    for attr in dir(element):
        if attr.startswith("_") or attr in _NOT_COPIED:
            continue
        value = getattr(element, attr)
        if callable(value):
            continue
        out[attr] = list(value) if isinstance(value, mujoco.MjDoubleVec) else value
    return out


def copy_attributes(source: Any, target: Any) -> None:
    """Set every value attribute of ``target`` to that of ``source`` (same element kind)."""
    for attr, value in _values(source).items():
        setattr(target, attr, value)


def add_builtin_class(spec: mujoco.MjSpec) -> mujoco.MjsDefault:
    """Add `DEFAULT_CLASS` to ``spec``: joints, geoms, sites and pairs at MuJoCo's built-in values.

    Joints are made unlimited explicitly (the built-in 'auto' would follow a model's
    ``autolimits`` setting).
    """
    builtin = mujoco.MjSpec().default
    cls = spec.add_default(DEFAULT_CLASS, spec.default)
    for kind in ("joint", "geom", "site", "pair"):
        copy_attributes(getattr(builtin, kind), getattr(cls, kind))
    cls.joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    cls.joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_FALSE
    return cls


def rebuild_hinge_after_slides(
    spec: mujoco.MjSpec,
    hinge: mujoco.MjsJoint,
    prefix: str,
    origin: Sequence[float],
    axes: np.ndarray,
    default: mujoco.MjsDefault,
) -> tuple[list[mujoco.MjsJoint], mujoco.MjsJoint]:
    """Give a hinge's body two slides before the hinge; returns (slides, the rebuilt hinge).

    Args:
        spec: the spec being edited.
        hinge: the hinge (the only joint of its body).
        prefix: name prefix of the slides (``<prefix>__x``, ``<prefix>__y``).
        origin: (3,) the hinge position in the body frame [m] (where the slides sit).
        axes: (2, 3) the slide directions in the body frame: the bearing frame's x and y.
        default: the class the slides are created in (`add_builtin_class`).
    """
    body = hinge.parent
    saved = _values(hinge)
    name, info, cls, frame = hinge.name, hinge.info, hinge.classname, hinge.frame
    spec.delete(hinge)
    slides = [
        body.add_joint(
            default=default,
            name=f"{prefix}__{k}",
            type=mujoco.mjtJoint.mjJNT_SLIDE,
            pos=[float(v) for v in origin],
            axis=[float(v) for v in axis],
        )
        for k, axis in zip(("x", "y"), axes)
    ]
    rebuilt = body.add_joint(default=cls, name=name)
    for attr, value in saved.items():
        setattr(rebuilt, attr, value)
    rebuilt.info = info
    if frame is not None:
        rebuilt.set_frame(frame)
    return slides, rebuilt
