"""Joint reactions of a MuJoCo run, from its sensor rows (vectorised, no per-step Python).

Every joint gets the force its link_a exerts on its link_b, world frame [N] (the convention of
`clearance.results.SimulationResult.joint_reactions`), read at the sensor row's state, where
MuJoCo's forward dynamics computed every force of the step:

* a tree joint (hinge or slide between a body and its parent): the ``<joint>__reaction`` FORCE
  sensor, the force the parent exerts on the child's subtree (MuJoCo's ``cfrc_int``). MuJoCo
  builds it from the subtree's accelerations and the external forces it records in
  ``cfrc_ext`` (contacts, equality constraints); the compiled exact contact acts through
  generalized passive forces, which ``cfrc_ext`` does not record, so a compiled contact between
  the subtree and the rest is added here;
* an ideal cut (a ``connect`` equality): the cut force follows from Newton's equation of each
  body it touches, ``m a_com - F_parent + sum F_children = cfrc_ext`` (``<link>__comacc``, the
  FORCE sensors of the body and its children), less the ring contacts on that body; with several
  cuts the bodies' equations are solved together (least squares, exact when the cuts form a
  forest, as every spanning-tree cut set of a planar linkage does);
* a clearance joint: its contact force (the run's ``contact_force``), turned into the world frame;
  a slider with play likewise: its corners' net contact force on the slider (its link_b), which
  stands in the layout where a journal's does (the slider as the journal, the guide as the
  bearing).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from clearance.model import Mechanism

__all__ = ["frame_rate", "ReactionLayout", "reaction_layout", "read_reactions", "rotate"]


@dataclass(frozen=True)
class _TreeJoint:
    """A tree joint read from its FORCE sensor.

    Attributes:
        joint: joint name (its sensor is ``<joint>__reaction``).
        child: the child link (its frame's x axis rotates the sensor into the world).
        sign: +1 when the child is the joint's link_b, else -1.
        passive: (clearance joint, s) with s = +1 when only its journal is in the child's
            subtree, -1 when only its bearing is: the compiled contact force on the journal
            times s is missing from the sensor.
    """

    joint: str
    child: str
    sign: float
    passive: tuple[tuple[str, float], ...]


@dataclass(frozen=True)
class ReactionLayout:
    """What a run's readout needs to turn sensor rows into joint reactions (one per model).

    Attributes:
        joints: every joint name, in the mechanism's order.
        parent_joint: moving link -> the tree joint to its parent.
        tree: tree joints read from FORCE sensors (clearance tree edges excluded).
        clearance: clearance joint -> (journal link, bearing link, sign): sign = +1 when the
            journal is the joint's link_b; a slider with play -> (slider, guide, +1).
        cuts: ideal cut joint names (connect equalities).
        bodies: links whose Newton equation gives the cut forces (touched by a cut).
        masses: (len(bodies),) their masses [kg].
        children: per body, the child links whose FORCE sensors enter its equation.
        ring_contacts: per body, (clearance joint, s): the ring contact on the journal times s
            acts on the body and is in ``cfrc_ext`` (empty for the compiled contact).
        solve: (2 n_cuts, 2 n_bodies) least-squares solution matrix, body forces -> cut forces.
        determined: (n_cuts,) whether each cut's force is determined by the bodies' equations.
    """

    joints: tuple[str, ...]
    parent_joint: dict[str, str]
    tree: tuple[_TreeJoint, ...]
    clearance: dict[str, tuple[str, str, float]]
    cuts: tuple[str, ...]
    bodies: tuple[str, ...]
    masses: np.ndarray
    children: tuple[tuple[str, ...], ...]
    ring_contacts: tuple[tuple[tuple[str, float], ...], ...]
    solve: np.ndarray
    determined: np.ndarray


def _subtree(parent: dict[str, str], link: str) -> set[str]:
    out = {link}
    changed = True
    while changed:
        changed = False
        for child, par in parent.items():
            if par in out and child not in out:
                out.add(child)
                changed = True
    return out


def reaction_layout(
    mechanism: Mechanism,
    parents: dict[str, tuple[str, str]],
    cuts: tuple[str, ...],
    *,
    exact_contact: bool,
) -> ReactionLayout:
    """The layout of a model's reaction readout.

    Args:
        mechanism: the mechanism the model was built from.
        parents: the body tree: moving link -> (parent link, tree joint name).
        cuts: the ideal cut joints' names (connect equalities).
        exact_contact: whether clearance joints are compiled contacts (passive forces) rather
            than ring contacts (constraint rows).

    Returns:
        The `ReactionLayout`.
    """
    parent_of = {child: par for child, (par, _) in parents.items()}
    clearance: dict[str, tuple[str, str, float]] = {}
    for j in mechanism.clearance_joints:
        jl = j.require_clearance().journal_link
        assert jl is not None  # Mechanism resolves the journal side of every clearance
        bl = j.link_b if jl == j.link_a else j.link_a
        clearance[j.name] = (jl, bl, 1.0 if jl == j.link_b else -1.0)
    for j in mechanism.translational_joints:
        clearance[j.name] = (j.link_b, j.link_a, 1.0)
    tree = []
    for child, (_, jname) in parents.items():
        if jname in clearance:
            continue  # its reaction is its contact force
        sub = _subtree(parent_of, child)
        passive: tuple[tuple[str, float], ...] = ()
        if exact_contact:
            passive = tuple(
                (k, 1.0 if jl in sub else -1.0) for k, (jl, bl, _) in clearance.items() if (jl in sub) != (bl in sub)
            )
        sign = 1.0 if mechanism.joint(jname).link_b == child else -1.0
        tree.append(_TreeJoint(jname, child, sign, passive))
    moving = {lk.name for lk in mechanism.moving_links}
    bodies = tuple(
        sorted({lk for c in cuts for lk in (mechanism.joint(c).link_a, mechanism.joint(c).link_b) if lk in moving})
    )
    incidence = np.zeros((2 * len(bodies), 2 * len(cuts)))
    for k, c in enumerate(cuts):
        j = mechanism.joint(c)
        for link, s in ((j.link_b, 1.0), (j.link_a, -1.0)):
            if link in bodies:
                b = bodies.index(link)
                incidence[2 * b, 2 * k] = incidence[2 * b + 1, 2 * k + 1] = s
    determined = np.ones(len(cuts), dtype=bool)
    if cuts:
        # a cut is determined when no other cut combination reproduces its columns' effect
        null = _null_space(incidence)
        determined = ~np.any(np.abs(null.reshape(len(cuts), 2, -1)) > 1e-9, axis=(1, 2))
    ring: list[tuple[tuple[str, float], ...]] = []
    for body in bodies:
        ring.append(
            ()
            if exact_contact
            else tuple(
                (name, 1.0 if body == jl else -1.0)
                for name, (jl, bl, _) in clearance.items()
                if body in (jl, bl) and jl != bl
            )
        )
    return ReactionLayout(
        joints=tuple(j.name for j in mechanism.joints),
        parent_joint={child: jname for child, (_, jname) in parents.items()},
        tree=tuple(tree),
        clearance=clearance,
        cuts=tuple(cuts),
        bodies=bodies,
        masses=np.array([mechanism.link(b).mass for b in bodies]),
        children=tuple(tuple(c for c, p in parent_of.items() if p == b) for b in bodies),
        ring_contacts=tuple(ring),
        solve=np.linalg.pinv(incidence) if cuts else np.zeros((0, 0)),
        determined=determined,
    )


def _null_space(a: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the null space of ``a``, (ncols, k)."""
    _, sv, vt = np.linalg.svd(a)
    rank = int(np.sum(sv > 1e-9 * max(1.0, sv.max(initial=0.0))))
    return vt[rank:].T


def rotate(xaxis: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors ``v`` (n, 2) given in frames whose x axes are ``xaxis`` (n, >=2), in the world."""
    c, s = xaxis[:, 0], xaxis[:, 1]
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=1)


def frame_rate(xaxis: np.ndarray, dv: np.ndarray, spin: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The rate of p = Rᵀ (x_a − x_b), a point's position in a turning frame, (n, 2).

    p' = Rᵀ (v_a − v_b) + ω (p_y, −p_x), with R the frame's rotation (x axis ``xaxis`` (n, >=2)),
    ``dv`` (n, 2) the two points' world velocity difference and ``spin`` (n,) the frame's angular
    velocity ω: a journal's eccentricity rate in its bearing, a slider's velocity in its guide.
    """
    c, s = xaxis[:, 0], xaxis[:, 1]
    return np.stack(
        [c * dv[:, 0] + s * dv[:, 1] + spin * p[:, 1], -s * dv[:, 0] + c * dv[:, 1] - spin * p[:, 0]], axis=1
    )


def read_reactions(
    layout: ReactionLayout,
    get: Callable[[str], np.ndarray],
    journal_force: dict[str, np.ndarray],
    n: int,
) -> dict[str, np.ndarray]:
    """Joint reactions of a chunk of sensor rows (see the module docstring).

    Args:
        layout: the model's `ReactionLayout`.
        get: sensor name -> (n, dim) rows of that sensor (a callable).
        journal_force: clearance joint -> (n, 2) contact force on the journal, world frame [N].
        n: number of rows.

    Returns:
        Joint name -> (n, 2) force that the joint's link_a exerts on its link_b, world [N], in
        the mechanism's joint order.
    """
    frame: dict[str, np.ndarray] = {}

    def parent_force(child: str, joint: str) -> np.ndarray:
        # the raw cfrc_int force of the child's subtree in the world frame (what the sensor sees)
        if child not in frame:
            frame[child] = rotate(get(f"{child}__xaxis"), get(f"{joint}__reaction")[:, :2])
        return frame[child]

    out: dict[str, np.ndarray] = {}
    for t in layout.tree:
        f = parent_force(t.child, t.joint).copy()
        for joint, s in t.passive:
            f -= s * journal_force[joint]
        out[t.joint] = t.sign * f
    for joint, (_, _, sign) in layout.clearance.items():
        out[joint] = sign * journal_force[joint]
    if layout.cuts:
        ext = np.empty((n, 2 * len(layout.bodies)))
        tree_joint = layout.parent_joint
        for b, body in enumerate(layout.bodies):
            e = layout.masses[b] * get(f"{body}__comacc")[:, :2] - parent_force(body, tree_joint[body])
            for c in layout.children[b]:
                e = e + parent_force(c, tree_joint[c])
            for joint, s in layout.ring_contacts[b]:
                e = e - s * journal_force[joint]
            ext[:, 2 * b : 2 * b + 2] = e
        cut = ext @ layout.solve.T
        for k, name in enumerate(layout.cuts):
            f = cut[:, 2 * k : 2 * k + 2]
            out[name] = f if layout.determined[k] else np.full_like(f, np.nan)
    return {j: out[j] for j in layout.joints if j in out}
