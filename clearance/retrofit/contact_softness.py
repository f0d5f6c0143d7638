"""The model's own contacts keep their softness after a retrofit (`clearance.retrofit.softness`).

A contact row's inverse weight Â is the sum of its two bodies' translational ``body_invweight0``,
which the retrofit's added coordinates raise for every body below a hinge with play (robosuite's
Panda, whose fifth and seventh links touch at its reference pose, pushed them apart 1.4 times more
softly with play at one hinge). A geom's own solref and solimp cannot fix that: a contact mixes the
two geoms' values and its Â depends on both bodies. So every geom pair that MuJoCo's collision
filters let touch (contype and conaffinity, distinct weld bodies not both static, parent and child
filtered unless the model disables it, excluded body pairs) and whose Â moved gets an explicit
``<pair>`` with the values MuJoCo would have mixed for it (priority, condim, solmix-weighted
solref and solimp, the larger friction, margin and gap, the summed adhesion) and its solimp and
solref rescaled by `kept_softness`. MuJoCo then skips the dynamic contact of that geom pair (an
explicit pair takes its place). The model's own explicit pairs are rescaled in place.

Friction rows of a pyramidal cone weigh rotation in too (Â = tran + mu^2 rot for torsion and
rolling); the rescale keeps the normal row's, which the translational weights set.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.retrofit.play import PREFIX
from clearance.retrofit.softness import Softness, kept_softness, moved, refsafe

__all__ = ["KeptContact", "collidable_pairs", "keep_contact_softness", "mixed_contact"]

_MINVAL = 1e-15
"""MuJoCo's mjMINVAL (the solmix test)."""


@dataclass(frozen=True)
class KeptContact:
    """A geom pair whose contacts the edit rescaled.

    Attributes:
        geoms: the two geoms' names (as written; an unnamed geom is given ``clr_geom<id>``).
        added: True for a new explicit pair, False for the model's own pair rescaled.
        softness: what was written.
    """

    geoms: tuple[str, str]
    added: bool
    softness: Softness

    @property
    def label(self) -> str:
        """How a report names the pair, e.g. "contact link5/link7 (pair added)"."""
        return f"contact {self.geoms[0]}/{self.geoms[1]} ({'pair added' if self.added else 'pair'})"


@dataclass(frozen=True)
class MixedContact:
    """What MuJoCo gives a dynamic contact of two geoms (``mj_contactParam`` and ``getMargin``)."""

    condim: int
    friction: tuple[float, float, float, float, float]
    solref: tuple[float, float]
    solimp: tuple[float, ...]
    margin: float
    gap: float
    adhesion: float


def mixed_contact(model: mujoco.MjModel, g1: int, g2: int) -> MixedContact:
    """The parameters of a dynamic contact between geoms ``g1`` and ``g2`` of ``model``, mixed as MuJoCo mixes them."""
    p1, p2 = int(model.geom_priority[g1]), int(model.geom_priority[g2])
    adhesion = float(model.geom_adhesion[g1] + model.geom_adhesion[g2])
    if p1 != p2:
        g = g1 if p1 > p2 else g2
        condim, solref = int(model.geom_condim[g]), model.geom_solref[g]
        solimp, fri, adhesion = model.geom_solimp[g], model.geom_friction[g], float(model.geom_adhesion[g])
    else:
        condim = max(int(model.geom_condim[g1]), int(model.geom_condim[g2]))
        s1, s2 = float(model.geom_solmix[g1]), float(model.geom_solmix[g2])
        if s1 >= _MINVAL and s2 >= _MINVAL:
            mix = s1 / (s1 + s2)
        else:
            mix = 0.5 if s1 < _MINVAL and s2 < _MINVAL else (0.0 if s1 < _MINVAL else 1.0)
        r1, r2 = model.geom_solref[g1], model.geom_solref[g2]
        solref = mix * r1 + (1 - mix) * r2 if r1[0] > 0 and r2[0] > 0 else np.minimum(r1, r2)
        solimp = mix * model.geom_solimp[g1] + (1 - mix) * model.geom_solimp[g2]
        fri = np.maximum(model.geom_friction[g1], model.geom_friction[g2])
    return MixedContact(
        condim,
        (float(fri[0]), float(fri[0]), float(fri[1]), float(fri[2]), float(fri[2])),
        (float(solref[0]), float(solref[1])),
        tuple(float(v) for v in solimp),
        float(max(model.geom_margin[g1], model.geom_margin[g2])),
        float(max(model.geom_gap[g1], model.geom_gap[g2])),
        adhesion,
    )


def collidable_pairs(model: mujoco.MjModel) -> list[tuple[int, int]]:
    """Geom pairs (g1 < g2) that MuJoCo's dynamic collision filters let touch (module docstring)."""
    excluded = {int(s) for s in model.exclude_signature}
    filter_parent = not int(model.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
    weld, parent = model.body_weldid, model.body_parentid
    active = [g for g in range(model.ngeom) if model.geom_contype[g] or model.geom_conaffinity[g]]
    out = []
    for i, g1 in enumerate(active):
        for g2 in active[i + 1 :]:
            if not (
                model.geom_contype[g1] & model.geom_conaffinity[g2]
                or model.geom_contype[g2] & model.geom_conaffinity[g1]
            ):
                continue
            b1, b2 = int(model.geom_bodyid[g1]), int(model.geom_bodyid[g2])
            w1, w2 = int(weld[b1]), int(weld[b2])
            if w1 == w2 or (model.body_dofnum[w1] == 0 and model.body_dofnum[w2] == 0):
                continue
            if filter_parent and w1 and w2 and (w1 == weld[parent[w2]] or w2 == weld[parent[w1]]):
                continue
            if (min(b1, b2) << 16) + max(b1, b2) in excluded:
                continue
            out.append((g1, g2))
    return out


def _weight(model: mujoco.MjModel, b1: int, b2: int) -> float:
    return float(model.body_invweight0[b1, 0] + model.body_invweight0[b2, 0])


def _geom_name(geom: mujoco.MjsGeom, twin_id: int) -> str:
    if not geom.name:
        geom.name = f"{PREFIX}geom{twin_id}"
    return str(geom.name)


def keep_contact_softness(
    spec: mujoco.MjSpec,
    twin: mujoco.MjModel,
    model: mujoco.MjModel,
    geoms: Mapping[int, mujoco.MjsGeom],
    step: float,
    default: mujoco.MjsDefault,
) -> list[KeptContact]:
    """Give every contact of the twin whose Â moved its twin's softness (module docstring).

    Args:
        spec: the edited spec, compiled into ``model`` (its elements carry ``model``'s ids).
        twin: the unmodified model.
        model: ``spec`` compiled after the edit's joints and bodies were added, before this rescale.
        geoms: the twin's geom id -> that geom in ``spec``.
        step: the time step both models run at [s].
        default: the class the added pairs are created in (MuJoCo's built-in values).

    Returns:
        Every geom pair added or rescaled.
    """
    safe = refsafe(twin)
    body = {g: int(model.geom_bodyid[int(s.id)]) for g, s in geoms.items()}
    kept: list[KeptContact] = []
    own = {(int(twin.pair_geom1[p]), int(twin.pair_geom2[p])) for p in range(twin.npair)}
    own |= {(b, a) for a, b in own}
    for g1, g2 in collidable_pairs(twin):
        if (g1, g2) in own:
            continue  # the model's explicit pair replaces this dynamic contact already: rescaled below
        a_old = _weight(twin, int(twin.geom_bodyid[g1]), int(twin.geom_bodyid[g2]))
        a_new = _weight(model, body[g1], body[g2])
        if not moved(a_old, a_new):
            continue
        mix = mixed_contact(twin, g1, g2)
        soft = kept_softness(a_old, a_new, mix.solimp, mix.solref, step=step, refsafe=safe)
        names = (_geom_name(geoms[g1], g1), _geom_name(geoms[g2], g2))
        spec.add_pair(
            default,
            name=f"{PREFIX}contact__{len(kept)}",
            geomname1=names[0],
            geomname2=names[1],
            condim=mix.condim,
            friction=list(mix.friction),
            solref=list(soft.solref),
            solimp=list(soft.solimp),
            margin=mix.margin,
            gap=mix.gap,
            adhesion=mix.adhesion,
        )
        kept.append(KeptContact(names, True, soft))
    pairs = list(spec.pairs)
    for p in range(twin.npair):
        g1, g2 = int(twin.pair_geom1[p]), int(twin.pair_geom2[p])
        a_old = _weight(twin, int(twin.geom_bodyid[g1]), int(twin.geom_bodyid[g2]))
        a_new = _weight(model, body[g1], body[g2])
        if not moved(a_old, a_new):
            continue
        soft = kept_softness(a_old, a_new, twin.pair_solimp[p], twin.pair_solref[p], step=step, refsafe=safe)
        pairs[p].solref, pairs[p].solimp = list(soft.solref), list(soft.solimp)
        kept.append(KeptContact((str(pairs[p].geomname1), str(pairs[p].geomname2)), False, soft))
    return kept
