"""Choice of the MuJoCo body tree for a mechanism graph.

A spanning tree of the mechanism graph (links as nodes, joints as edges) becomes the body
tree; the other joints are cuts. Preference when building the tree (Kruskal with weights):
driven joints and ideal prismatic pairs must be tree edges (MuJoCo cannot cut them), ideal
revolute joints next, joints with play (a journal in its bearing, a slider in its guide) last.
So a joint with play is a cut whenever the loops allow it (contact alone closes that loop),
the fewest ideal `connect` equalities remain, and only joints with play beyond the number of
loops become tree edges with planar freedom (slide / slide / hinge).
"""

from __future__ import annotations

from dataclasses import dataclass

from clearance.model import Joint, JointType, Mechanism

__all__ = ["BodyTree", "body_tree"]


@dataclass(frozen=True)
class BodyTree:
    """The body tree of a mechanism.

    Attributes:
        parent: link name -> (parent link name, joint) for every moving link.
        order: moving links, parents before children.
        cuts: joints that are not tree edges.
    """

    parent: dict[str, tuple[str, Joint]]
    order: tuple[str, ...]
    cuts: tuple[Joint, ...]

    @property
    def ideal_cuts(self) -> tuple[Joint, ...]:
        """Cut joints without play (become `connect` equalities)."""
        return tuple(j for j in self.cuts if not j.has_play)


def _weight(j: Joint, driven: set[str]) -> int:
    if j.name in driven:
        return 0
    if j.has_play:
        return 3
    if j.kind is JointType.PRISMATIC:
        return 1
    return 2


def body_tree(mechanism: Mechanism) -> BodyTree:
    """Choose the spanning tree and the cuts.

    Raises:
        ValueError: a prismatic pair would have to be cut (two prismatic pairs closing a
            loop on their own), which MuJoCo cannot express as an equality here.
    """
    driven = {d.joint for d in mechanism.drives}
    root = {lk.name: lk.name for lk in mechanism.links}

    def find(x: str) -> str:
        while root[x] != x:
            root[x] = root[root[x]]
            x = root[x]
        return x

    order_index = {j.name: i for i, j in enumerate(mechanism.joints)}
    edges = sorted(mechanism.joints, key=lambda j: (_weight(j, driven), order_index[j.name]))
    tree_edges, cuts = [], []
    for j in edges:
        a, b = find(j.link_a), find(j.link_b)
        if a == b:
            cuts.append(j)
        else:
            root[a] = b
            tree_edges.append(j)
    for j in cuts:
        if j.kind is JointType.PRISMATIC and not j.has_play:
            raise ValueError(
                f"joint '{j.name}': a prismatic pair closes a loop that no revolute joint can "
                "cut; MuJoCo models need a revolute joint in every loop"
            )
    # orient the tree from ground
    adj: dict[str, list[tuple[str, Joint]]] = {lk.name: [] for lk in mechanism.links}
    for j in tree_edges:
        adj[j.link_a].append((j.link_b, j))
        adj[j.link_b].append((j.link_a, j))
    parent: dict[str, tuple[str, Joint]] = {}
    order: list[str] = []
    frontier = [mechanism.ground]
    seen = {mechanism.ground}
    while frontier:
        nxt = []
        for n in frontier:
            for child, j in adj[n]:
                if child not in seen:
                    seen.add(child)
                    parent[child] = (n, j)
                    order.append(child)
                    nxt.append(child)
        frontier = nxt
    cuts.sort(key=lambda j: order_index[j.name])
    return BodyTree(parent, tuple(order), tuple(cuts))
