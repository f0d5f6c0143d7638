"""Drawing of a planar mechanism at a pose, with link and joint names (matplotlib).

No MuJoCo here: poses come from `clearance.kinematics` (the assembly at a time, or any q).
Revolute joints are circles (clearance joints in red), ground pivots carry a hatched base,
prismatic guides are hatched lines along the slider's travel, ternary links are shaded
plates, sliders are blocks. Joint names are placed greedily where they collide least
with links, joints and the other names. Optionally the joint paths over one drive cycle
are drawn as thin lines.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from clearance.kinematics import assemble, link_point_world, solve_kinematics
from clearance.model import JointType, Mechanism

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_linkage"]

_COLOURS = ["#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf", "#bcbd22", "#e377c2", "#7f7f7f"]


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = 0.0 if not ab.any() else float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def _hull_order(pts: np.ndarray) -> np.ndarray:
    c = pts.mean(axis=0)
    return pts[np.argsort(np.arctan2(pts[:, 1] - c[1], pts[:, 0] - c[0]))]


def plot_linkage(
    mechanism: Mechanism,
    q: np.ndarray | None = None,
    *,
    ax: Axes | None = None,
    t: float = 0.0,
    trace: bool = True,
    trace_points: int = 181,
    title: str | None = None,
    link_names: bool = True,
    joint_names: bool = True,
) -> Axes:
    """Draw a mechanism at a pose with its link and joint names.

    Args:
        mechanism: the mechanism.
        q: coordinates (nq,) [m, rad]; default: the assembly at time ``t``.
        ax: matplotlib Axes to draw on; default: a new figure.
        t: time [s] of the pose when ``q`` is not given.
        trace: also draw the path of every joint over one period of the slowest drive.
        trace_points: samples of that path.
        title: axes title; default the mechanism name.
        link_names, joint_names: label the links / joints.

    Returns:
        The matplotlib Axes.

    Raises:
        AssemblyError: the mechanism cannot be assembled at ``t``.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgba
    from matplotlib.figure import Figure
    from matplotlib.patches import Polygon, Rectangle

    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 6.0))
    q = assemble(mechanism, t) if q is None else np.asarray(q, dtype=float)
    links = {lk.name: lk for lk in mechanism.links}
    colour = {lk.name: _COLOURS[i % len(_COLOURS)] for i, lk in enumerate(mechanism.moving_links)}
    world = {
        name: {p: link_point_world(mechanism, q, name, xy) for p, xy in lk.points.items()} for name, lk in links.items()
    }
    paths: dict[str, np.ndarray] = {}
    if trace:
        period = mechanism.drive_period
        if period is not None:
            times = t + np.linspace(0.0, period, trace_points)
            qs = solve_kinematics(mechanism, times).q
            for j in mechanism.joints:
                lk = links[j.link_b]
                paths[j.name] = link_point_world(mechanism, qs, j.link_b, lk.point(j.point_b))
    all_pts = np.array([p for pts in world.values() for p in pts.values()] + [p for v in paths.values() for p in v])
    span = float(np.max(np.ptp(all_pts, axis=0))) if len(all_pts) > 1 else 0.1
    r_joint = 0.012 * span
    segments: list[tuple[np.ndarray, np.ndarray]] = []

    # joint paths
    for path in paths.values():
        if np.ptp(path, axis=0).max() > 1e-9:
            ax.plot(path[:, 0], path[:, 1], lw=0.6, ls=":", color="0.55", zorder=1)
    # prismatic guides and sliders
    for j in mechanism.joints:
        if j.kind is not JointType.PRISMATIC:
            continue
        pa = world[j.link_b][j.point_b]
        th = (
            0.0 if j.link_a == mechanism.ground else q[3 * [m.name for m in mechanism.moving_links].index(j.link_a) + 2]
        )
        ax_w = np.array(
            [math.cos(th) * j.axis[0] - math.sin(th) * j.axis[1], math.sin(th) * j.axis[0] + math.cos(th) * j.axis[1]]
        )
        s = (paths[j.name] - pa) @ ax_w if j.name in paths else np.array([0.0])
        lo, hi = s.min() - 0.12 * span, s.max() + 0.12 * span
        nrm = np.array([-ax_w[1], ax_w[0]])
        off = 0.035 * span
        for side in (1, -1):
            a, b = pa + lo * ax_w + side * off * nrm, pa + hi * ax_w + side * off * nrm
            ax.plot([a[0], b[0]], [a[1], b[1]], color="k", lw=1.2, zorder=2)
            for k in np.linspace(0, 1, 14):
                h = a + k * (b - a)
                h2 = h + side * 0.02 * span * (nrm + ax_w)
                ax.plot([h[0], h2[0]], [h[1], h2[1]], color="k", lw=0.6, zorder=2)
            segments.append((a, b))
    # moving links
    for lk in mechanism.moving_links:
        pts = np.array(list(world[lk.name].values()))
        i = [m.name for m in mechanism.moving_links].index(lk.name)
        th = q[3 * i + 2]
        is_slider = any(j.kind is JointType.PRISMATIC and j.link_b == lk.name for j in mechanism.joints)
        if is_slider:
            w, h = 0.09 * span, 0.07 * span
            pj = next(j for j in mechanism.joints if j.kind is JointType.PRISMATIC and j.link_b == lk.name)
            c = world[lk.name][pj.point_b]
            corner = c + np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]]) @ np.array(
                [-w / 2, -h / 2]
            )
            ax.add_patch(
                Rectangle(
                    tuple(corner),
                    w,
                    h,
                    angle=math.degrees(th),
                    facecolor=to_rgba(colour[lk.name], 0.35),
                    edgecolor=colour[lk.name],
                    lw=1.5,
                    zorder=3,
                )
            )
            segments.append((c - np.array([w / 2, 0]), c + np.array([w / 2, 0])))
            for p in pts:
                if np.linalg.norm(p - c) > 1e-12:
                    ax.plot([c[0], p[0]], [c[1], p[1]], color=colour[lk.name], lw=3, zorder=3)
                    segments.append((c, p))
        elif len(pts) >= 3:
            hull = _hull_order(pts)
            ax.add_patch(
                Polygon(
                    hull,
                    closed=True,
                    facecolor=to_rgba(colour[lk.name], 0.22),
                    edgecolor=colour[lk.name],
                    lw=2.5,
                    zorder=3,
                )
            )
            segments += [(hull[k], hull[(k + 1) % len(hull)]) for k in range(len(hull))]
        else:
            ax.plot(pts[:, 0], pts[:, 1], color=colour[lk.name], lw=4, solid_capstyle="round", zorder=3)
            segments.append((pts[0], pts[-1]))
    # joints and ground pivots
    jpos: dict[str, np.ndarray] = {}
    for j in mechanism.joints:
        if j.kind is not JointType.REVOLUTE:
            continue
        p = world[j.link_b][j.point_b]
        jpos[j.name] = p
        if mechanism.ground in (j.link_a, j.link_b):
            tri = np.array([p, p + [-1.6 * r_joint, -2.6 * r_joint], p + [1.6 * r_joint, -2.6 * r_joint]])
            ax.add_patch(Polygon(tri, closed=True, facecolor="0.85", edgecolor="k", lw=1.0, zorder=2))
            ax.plot(
                [p[0] - 2.4 * r_joint, p[0] + 2.4 * r_joint], [p[1] - 2.6 * r_joint] * 2, color="k", lw=1.2, zorder=2
            )
        clear = j.clearance is not None
        ax.add_patch(
            plt.Circle(
                tuple(p),
                r_joint * (1.35 if clear else 1.0),
                facecolor="white",
                edgecolor="#d62728" if clear else "k",
                lw=2.0 if clear else 1.2,
                zorder=5,
            )
        )
    # labels, placed greedily as boxes (size estimated from the font size and the data scale)
    parent = ax.figure
    fig = parent if isinstance(parent, Figure) else parent.figure  # a SubFigure's root figure
    fig_w, fig_h = fig.get_size_inches()
    pos = ax.get_position()
    width, height = np.ptp(all_pts, axis=0) + 0.25 * span
    scale = max(width / (fig_w * pos.width), height / (fig_h * pos.height))  # data units per inch
    boxes: list[tuple[np.ndarray, float, float]] = []
    placed: list[np.ndarray] = []
    along = [a + f * (b - a) for a, b in segments for f in np.linspace(0.0, 1.0, 12)]
    samples = np.array(along) if along else np.zeros((0, 2))
    joints_xy = np.array(list(jpos.values())) if jpos else np.zeros((0, 2))

    def place(anchor: np.ndarray, text: str, size: float, **kw: Any) -> None:
        hw = 0.5 * len(text) * 0.62 * size / 72 * scale + 0.004 * span
        hh = 0.62 * size / 72 * scale + 0.004 * span
        best, best_cost = anchor, math.inf
        for r in (0.035 * span, 0.07 * span, 0.11 * span):
            for k in range(16):
                d = np.array([math.cos(k * math.pi / 8 + 0.1), math.sin(k * math.pi / 8 + 0.1)])
                c = anchor + d * r + np.array([d[0] * hw, d[1] * hh])
                inside = lambda p, m=0.0, c=c: (np.abs(p[:, 0] - c[0]) < hw + m) & (np.abs(p[:, 1] - c[1]) < hh + m)  # noqa: E731
                cost = 0.3 * r / span
                cost += 3.0 * np.count_nonzero(inside(joints_xy, r_joint)) + 1.0 * np.count_nonzero(inside(samples))
                for bc, bw, bh in boxes:
                    ox = max(0.0, min(c[0] + hw, bc[0] + bw) - max(c[0] - hw, bc[0] - bw))
                    oy = max(0.0, min(c[1] + hh, bc[1] + bh) - max(c[1] - hh, bc[1] - bh))
                    cost += 20.0 * ox * oy / (hw * hh)
                if cost < best_cost:
                    best, best_cost = c, cost
        boxes.append((best, hw, hh))
        placed.extend([best + [hw, hh], best - [hw, hh]])
        ax.annotate(
            text,
            xy=tuple(anchor),
            xytext=tuple(best),
            ha="center",
            va="center",
            zorder=6,
            fontsize=size,
            arrowprops=dict(arrowstyle="-", color="0.5", lw=0.6, shrinkA=0, shrinkB=3),
            **kw,
        )

    if joint_names:
        for j in mechanism.joints:
            anchor = jpos.get(j.name, world[j.link_b][j.point_b])
            label = j.name + (" (c)" if j.clearance is not None else "")
            place(
                anchor,
                label,
                9.0,
                fontweight="bold",
                color="#d62728" if j.clearance is not None else "k",
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8),
            )
    if link_names:
        for lk in mechanism.moving_links:
            pts = np.array(list(world[lk.name].values()))
            place(pts.mean(axis=0), lk.name, 8.5, style="italic", color=colour[lk.name])
    ax.set_aspect("equal")
    ext = np.vstack([all_pts, *placed]) if placed else all_pts
    m = 0.06 * span
    ax.set_xlim(ext[:, 0].min() - m, ext[:, 0].max() + m)
    ax.set_ylim(ext[:, 1].min() - m - 2.6 * r_joint, ext[:, 1].max() + m)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title if title is not None else mechanism.name)
    ax.grid(True, lw=0.3, alpha=0.5)
    return ax
