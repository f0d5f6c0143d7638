"""Figures of the analyses: contact modes, phase portraits, Poincaré sections, bifurcation
diagrams and criticality rankings (the deviation's figure is in `deviation_figure`).

Drawn on Agg figures without pyplot (`canvas`); the run figures (response, contact force,
orbit) are in `clearance.analysis.figures.plots`. Every function returns the figure and,
given a path, saves a PNG atomically.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, Colormap
from matplotlib.figure import Figure, SubFigure
from matplotlib.ticker import MaxNLocator

from clearance.analysis.chaos.poincare import PhasePortrait, PoincareClassification, section_warning
from clearance.analysis.figures.canvas import new_figure, save_png, thin_path
from clearance.analysis.figures.plots import MODE_COLOURS, save_figure
from clearance.analysis.metrics.response import ContactMode, JointContactModes

if TYPE_CHECKING:  # the sweeps' modules load only where a diagram or ranking is drawn
    from clearance.analysis.sweeps.bifurcation import BifurcationDiagram
    from clearance.analysis.sweeps.criticality import CriticalityRanking


__all__ = [
    "quantity_label",
    "plot_bifurcation",
    "plot_contact_modes",
    "plot_criticality",
    "plot_phase_portrait",
    "plot_poincare",
]

_PARAMS = {
    "radial_clearance": ("radial clearance", "mm", 1e3),
    "clearance": ("radial clearance", "mm", 1e3),
    "crank_speed": ("crank speed", "rpm", 30 / np.pi),
    "speed": ("crank speed", "rpm", 30 / np.pi),
    "crank2_speed": ("crank 2 speed", "rad/s", 1.0),
}


def quantity_label(name: str) -> tuple[str, str, float]:
    """(label, unit, scale from SI) of a quantity or output name, for axes.

    Joint parts ``.ex/.ey/.e`` are shown in µm, ``.vx/.vy`` in mm/s, ``.force`` in N; a
    slider's ``.n`` in µm, ``.vn`` in mm/s, ``.tilt`` in µrad;
    outputs ending in ``_vel``/``_acc`` in m/s and m/s², other outputs in mm (angles named
    ``*angle*`` in rad). Sweep parameters: clearance in mm, speed in rpm.
    """
    if name in _PARAMS:
        return _PARAMS[name]
    joint, _, part = name.rpartition(".")
    if joint:
        units = {
            "ex": ("eccentricity x", "µm", 1e6),
            "ey": ("eccentricity y", "µm", 1e6),
            "e": ("|eccentricity|", "µm", 1e6),
            "vx": ("eccentricity rate x", "mm/s", 1e3),
            "vy": ("eccentricity rate y", "mm/s", 1e3),
            "force": ("contact force", "N", 1.0),
            "n": ("across the guide", "µm", 1e6),  # a slider with play (chaos.SLIDER_PARTS)
            "vn": ("rate across the guide", "mm/s", 1e3),
            "tilt": ("tilt", "µrad", 1e6),
        }
        if part in units:
            lab, unit, scale = units[part]
            return f"{joint} {lab}", unit, scale
    angular = "angle" in name
    if name.endswith("_vel"):
        return name, "rad/s" if angular else "m/s", 1.0
    if name.endswith("_acc"):
        return name, "rad/s²" if angular else "m/s²", 1.0
    return (name, "rad", 1.0) if angular else (name, "mm", 1e3)


def plot_contact_modes(
    windows: Mapping[str, Sequence[JointContactModes]], *, title: str = "", path: str | Path | None = None
) -> Figure:
    """Share of time in free flight, impact and continuous contact per joint and window (bars).

    One horizontal stacked bar per joint and window (e.g. the start-up window and the steady
    state), grouped by joint: the three modes' shares of the window's time, the share written
    in each segment of 6 % or more, and the window's contact events beside the bar.

    Args:
        windows: window label -> the joints' `JointContactModes` over that window.
        title: figure title.
        path: PNG path to save to.

    Returns:
        The figure (one axes).
    """
    labels = list(windows)
    joints = list(dict.fromkeys(m.joint for ms in windows.values() for m in ms))
    by = {(w, m.joint): m for w, ms in windows.items() for m in ms}
    rows = [(j, w) for j in joints for w in labels if (w, j) in by]
    height = 1.55 + 0.42 * len(rows) + 0.25 * len(joints)
    fig = new_figure(9.0, height)
    ax = fig.add_axes((0.3, 0.8 / height, 0.52, 1 - 1.5 / height))
    y = []
    pos = 0.0
    for k, (j, _) in enumerate(rows):
        if k and rows[k - 1][0] != j:
            pos += 0.6  # a gap between joints
        y.append(pos)
        pos += 1.0
    y_arr = -np.asarray(y)
    left = np.zeros(len(rows))
    for mode in ContactMode:
        share = np.array([by[(w, j)].fractions[mode] * 100 for j, w in rows])
        ax.barh(
            y_arr,
            share,
            left=left,
            height=0.8,
            color=MODE_COLOURS[mode],
            alpha=1.0 if mode is ContactMode.FREE_FLIGHT else 0.75,
            edgecolor="0.5",
            lw=0.5,
            label=mode.value.replace("_", " "),
        )
        for yy, lft, sh in zip(y_arr, left, share):
            if sh >= 6:
                colour = "k" if mode is ContactMode.FREE_FLIGHT else "white"
                ax.text(lft + sh / 2, yy, f"{sh:.0f} %", ha="center", va="center", fontsize=8, color=colour)
        left = left + share
    for yy, (j, w) in zip(y_arr, rows):
        m = by[(w, j)]
        n_imp = sum(e.mode is ContactMode.IMPACT for e in m.events)
        n_con = len(m.events) - n_imp
        ax.text(101.5, yy, f"events: {n_imp} impact,\n{n_con} continuous", va="center", fontsize=7, color="0.3")
    ax.set_yticks(y_arr, [f"{j}, {w}" for j, w in rows], fontsize=8)
    ax.set_xlim(0, 100)
    ax.set_xlabel("share of the window's time [%]")
    ax.grid(alpha=0.3, axis="x")
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, fontsize=8, frameon=False)
    if title:
        fig.suptitle(title, fontsize=10, x=0.02, ha="left", y=1 - 0.1 / height, va="top")
    first = next(iter(by.values()), None)
    if first is not None:
        fig.text(
            0.02,
            0.08 / height,
            f"continuous contact: a contact event of {first.continuous_after * 1e3:.3g} ms or longer "
            "(5 % of the drive period); an event is counted in the window it starts in",
            fontsize=7,
            color="0.3",
        )
    if path is not None:
        save_png(fig, path)
    return fig


def _warn(ax: Axes, text: str) -> None:
    """A caution written across the bottom of the axes (wrapped at 70 characters)."""
    ax.text(
        0.02,
        0.02,
        textwrap.fill(text, 70),
        transform=ax.transAxes,
        fontsize=7.5,
        color="C3",
        va="bottom",
        ha="left",
        bbox={"facecolor": "white", "edgecolor": "C3", "alpha": 0.85, "boxstyle": "round,pad=0.3"},
        zorder=5,
    )


def plot_phase_portrait(
    portrait: PhasePortrait,
    *,
    section: np.ndarray | None = None,
    label: str | None = None,
    path: str | Path | None = None,
) -> Figure:
    """Phase portrait (quantity against its rate), with Poincaré points on top if given.

    The path is thinned to about a pixel (`canvas.thin_path`). With fewer section points than
    `chaos.poincare.MIN_SECTION_POINTS` the figure says so (`section_warning`).

    Args:
        portrait: `PhasePortrait` data.
        section: (K, 2) Poincaré points (quantity, rate) to mark.
        label: text put before the title (e.g. the report's section number).
        path: PNG path to save to.
    """
    qlab, unit, scale = quantity_label(portrait.name)
    vlab, vunit, vscale = quantity_label(
        f"{portrait.name}_vel" if "." not in portrait.name else portrait.name.replace(".e", ".v")
    )
    fig = new_figure(7, 5.5)
    ax = fig.add_axes((0.13, 0.1, 0.83, 0.82))
    x, v = portrait.position * scale, portrait.velocity * vscale
    keep = thin_path(x, v)
    ax.plot(x[keep], v[keep], lw=0.4, color="0.4", label="trajectory")
    if section is not None and len(section):
        ax.plot(
            section[:, 0] * scale, section[:, 1] * vscale, "o", ms=3.5, color="C3", label="Poincaré points (t = kT)"
        )
    if section is not None:
        warning = section_warning(len(section))
        if warning:
            _warn(ax, warning)
    ax.set_xlabel(f"{qlab} [{unit}]")
    ax.set_ylabel(f"{vlab} [{vunit}]")
    ax.set_title(f"{label}: " * bool(label) + f"phase portrait of {portrait.name}", fontsize=11)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    if path is not None:
        save_png(fig, path)
    return fig


def _period_colours(periods: np.ndarray) -> tuple[Colormap, BoundaryNorm, list[int]]:
    """A discrete colour map with one colour per integer period, its norm and the integer ticks."""
    lo, hi = int(periods.min()), int(periods.max())
    bounds = np.arange(lo - 0.5, hi + 1.0, 1.0)
    cmap = colormaps["viridis"].resampled(len(bounds) - 1)
    if hi - lo < 12:
        ticks = list(range(lo, hi + 1))
    else:
        ticks = [int(v) for v in MaxNLocator(nbins=10, integer=True).tick_values(lo, hi) if lo <= v <= hi]
    return cmap, BoundaryNorm(bounds, cmap.N), ticks


def plot_poincare(
    points: np.ndarray,
    names: tuple[str, str],
    classification: PoincareClassification | None = None,
    *,
    trajectory: np.ndarray | None = None,
    periods: np.ndarray | None = None,
    clearance: float | None = None,
    path: str | Path | None = None,
    ax: Axes | None = None,
    label: str | None = None,
) -> Figure:
    """Poincaré section of two quantities, coloured by drive period, with the regime.

    Each point has the colour of its drive period k (t = kT), one colour per integer and an
    integer colour bar. A joint's eccentricity section (``<joint>.ex``, ``<joint>.ey``) can
    show its clearance circle. With fewer points than `chaos.poincare.MIN_SECTION_POINTS`
    the figure says so (`section_warning`).

    Args:
        points: (K, 2) section points.
        names: the two quantity names (for labels and units).
        classification: regime to show in the title.
        trajectory: (n, 2) full trajectory of the same quantities, drawn in grey behind
            (thinned to about a pixel).
        periods: (K,) the drive period k of each point (t = kT); default 0 .. K - 1.
        clearance: radial clearance c [m]: draws the circle of radius c about the bearing
            centre (for an eccentricity section).
        path: PNG path to save to.
        ax: axes to draw into (a panel of a larger figure); default a new figure.
        label: text put before the title (e.g. the run's clearance).
    """
    (l1, u1, s1), (l2, u2, s2) = quantity_label(names[0]), quantity_label(names[1])
    cax = None
    if ax is None:
        fig: Figure | SubFigure = new_figure(6.6, 5.6)
        ax = fig.add_axes((0.14, 0.1, 0.66, 0.8))
        cax = fig.add_axes((0.84, 0.18, 0.03, 0.64))
    else:
        fig = ax.figure
    root = fig if isinstance(fig, Figure) else fig.figure  # a SubFigure's root figure
    if trajectory is not None and len(trajectory):
        keep = thin_path(trajectory[:, 0], trajectory[:, 1])
        ax.plot(trajectory[keep, 0] * s1, trajectory[keep, 1] * s2, lw=0.3, color="0.7", label="trajectory")
    if clearance is not None:
        th = np.linspace(0, 2 * np.pi, 300)
        ax.plot(
            clearance * s1 * np.cos(th),
            clearance * s2 * np.sin(th),
            color="k",
            lw=1.0,
            label=f"clearance circle (c = {clearance * s1:.4g} {u1})",
        )
    ks = np.arange(len(points)) if periods is None else np.asarray(periods).astype(int)
    if len(points):
        cmap, norm, ticks = _period_colours(ks)
        sc = ax.scatter(
            points[:, 0] * s1, points[:, 1] * s2, c=ks, s=14, cmap=cmap, norm=norm, label="section points", zorder=3
        )
        cb = root.colorbar(sc, cax=cax) if cax is not None else root.colorbar(sc, ax=ax)
        cb.set_ticks(ticks)
        cb.set_label("drive period k (t = kT)")
    elif cax is not None:
        cax.set_visible(False)  # no point: no colour bar
    warning = section_warning(len(points))
    if warning:
        _warn(ax, warning)
    if u1 == u2:
        ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{l1} [{u1}]")
    ax.set_ylabel(f"{l2} [{u2}]")
    title = f"{label}: " if label else ""
    title += "Poincaré section (t = kT)"
    if classification is not None:
        c = classification
        title += f": {c.regime.value.replace('_', '-')}"
        if c.period:
            title += f" (period {c.period})"
        elif np.isfinite(c.divergence):
            title += f" (divergence {c.divergence:.2f}, D2 {c.correlation_dimension:.2f})"
    ax.set_title(title, fontsize=10)
    ax.legend(loc="upper right", fontsize=7)
    ax.grid(alpha=0.3)
    if path is not None:
        save_png(root, path)
    return root


def plot_bifurcation(diagram: BifurcationDiagram, *, path: str | Path | None = None) -> Figure:
    """Bifurcation diagram: section samples against the parameter, coloured by regime."""
    pl, pu, ps = quantity_label(diagram.parameter)
    ql, qu, qs = quantity_label(diagram.quantity)
    fig = new_figure(9, 5)
    ax = fig.add_subplot()
    colours = {"periodic": "C0", "quasi_periodic": "C2", "chaotic": "C3", "undetermined": "0.5"}
    for reg, col in colours.items():
        sel = [i for i, r in enumerate(diagram.regimes) if r == reg]
        if not sel:
            continue
        x = np.concatenate([np.full(len(diagram.samples[i]), diagram.values[i]) for i in sel]) * ps
        y = np.concatenate([diagram.samples[i] for i in sel]) * qs
        ax.plot(x, y, marker=".", ms=1.8, ls="none", color=col, label=reg.replace("_", "-"))
    bad = [v for v, r in zip(diagram.values, diagram.regimes) if r == "error"]
    if bad:
        ax.plot(np.asarray(bad) * ps, np.zeros(len(bad)), "x", color="k", label="run failed")
    ax.set_xlabel(f"{pl} [{pu}]")
    ax.set_ylabel(f"{ql} at t = kT [{qu}]")
    ax.set_title(f"bifurcation diagram of {diagram.quantity} over {pl}")
    ax.legend(loc="best", fontsize=8, markerscale=4)
    ax.grid(alpha=0.3)
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_criticality(ranking: CriticalityRanking, *, path: str | Path | None = None) -> Figure:
    """Bar chart of joint scores (mean deviation / clearance) with 95 % intervals.

    The axis unit follows the ranking's output kind (`CriticalityRanking.score_unit`): [-]
    for a position output, [rad/m] for an angle output.
    """
    s = ranking.scores
    fig = new_figure(max(5, 1.4 * len(s) + 2), 4)
    ax = fig.add_subplot()
    x = np.arange(len(s))
    err = np.array([[j.score - j.ci_low for j in s], [j.ci_high - j.score for j in s]])
    ax.bar(x, [j.score for j in s], yerr=err, capsize=4, color="C1", label="score, 95 % interval")
    ax.set_xticks(x, [f"{j.rank}. {j.joint}" for j in s])
    what = f"mean deviation of {ranking.output}" if ranking.output else "mean deviation"
    ax.set_ylabel(f"{what} / radial clearance [{ranking.score_unit}]")
    ax.set_xlabel("joint with clearance (most critical first)")
    ax.set_title("clearance-joint criticality (one joint at a time)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    if path is not None:
        save_figure(fig, path)
    return fig
