"""Figures of a run: output response against ideal, contact force, journal orbit.

Drawn on Agg figures without pyplot (`canvas`); the numerical core never imports this. Time
axes are scaled to the steady state, with the start-up window (``startup``, the first
period of the slowest drive in a report) shaded and, where the start-up goes beyond that
scale, a small panel beside showing it at full scale. Every function returns the figure and,
given a path, saves a PNG atomically.
"""

from __future__ import annotations

import io
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.colors import BoundaryNorm
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import FormatStrFormatter

from clearance.analysis.figures.canvas import (
    Trace,
    draw_startup_panel,
    draw_steady_scaled,
    new_figure,
    save_png,
    thin_path,
    traces_clipped,
)
from clearance.analysis.metrics.response import ContactMode, JointContactModes, contact_modes
from clearance.results import SimulationResult, atomic_write_bytes

__all__ = ["MODE_COLOURS", "force_unit", "plot_response", "plot_contact_force", "plot_orbit", "save_figure"]

MODE_COLOURS = {ContactMode.FREE_FLIGHT: "0.93", ContactMode.IMPACT: "C3", ContactMode.CONTINUOUS: "C0"}
"""Colour of each contact mode in the contact figures."""


def save_figure(fig: Figure, path: str | Path, *, dpi: int = 130) -> Path:
    """Save any figure (pyplot's too) as PNG atomically, cropped to its content, and close it.

    The run's own figures use `canvas.save_png` (drawn once, fixed layout); this one keeps
    the tight crop for figures laid out by other code.

    Args:
        fig: the figure (closed afterwards if pyplot made it).
        path: PNG file to write (replaced atomically).
        dpi: resolution [dots per inch].

    Returns:
        ``path``.
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close(fig)
    atomic_write_bytes(path, buf.getvalue())
    return Path(path)


def _window(result: SimulationResult, startup: float) -> tuple[float, float]:
    """The start-up window on the run's time axis [ms]."""
    t0 = float(result.times[0]) * 1e3
    return t0, t0 + startup * 1e3


def _steady_rows(
    fig: Figure,
    rows: Sequence[list[Trace]],
    window: tuple[float, float],
    *,
    left: float,
    top: float,
    bottom: float,
    include_zero: bool = False,
) -> list[tuple[Axes, list[Trace]]]:
    """Axes for rows of traces sharing time: a start-up panel beside each row that needs one.

    Returns (main axes, traces) per row, drawn; the panels are drawn too.
    """
    clipped = [traces_clipped(tr, window[1], include_zero=include_zero) for tr in rows]
    panel = any(clipped)
    gs = fig.add_gridspec(
        len(rows),
        2 if panel else 1,
        width_ratios=[4.3, 1] if panel else None,
        left=left,
        right=0.98,
        top=top,
        bottom=bottom,
        hspace=0.32,
        wspace=0.26,
    )
    out = []
    first = None
    for i, traces in enumerate(rows):
        ax = fig.add_subplot(gs[i, 0], sharex=first)
        first = first or ax
        lim, _ = draw_steady_scaled(ax, traces, window, label="start-up" if i == 0 else None, include_zero=include_zero)
        if clipped[i] and lim is not None:
            draw_startup_panel(fig.add_subplot(gs[i, 1]), traces, window, lim)
        if i < len(rows) - 1:
            ax.tick_params(labelbottom=False)
        out.append((ax, traces))
    return out


def plot_response(
    result: SimulationResult,
    ideal: SimulationResult | None,
    output: str,
    *,
    angular: bool = False,
    startup: float = 0.0,
    path: str | Path | None = None,
) -> Figure:
    """Output displacement, velocity and acceleration against the ideal mechanism.

    Each panel is scaled to the steady state (after ``startup``); the start-up window is
    shaded, its samples beyond that scale are marked by triangles at the edge and shown at
    full scale in a small panel beside.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin (or None).
        output: output name (e.g. ``slider_x``).
        angular: the output is an angle (units rad, rad/s, rad/s²).
        startup: start-up window from the run's start [s] (0: none).
        path: PNG path to save to.

    Returns:
        The figure; its axes carry the labels ``displacement``, ``velocity``, ``acceleration``.

    Raises:
        KeyError: unknown output.
    """
    labels = [
        ("displacement", output, "rad" if angular else "mm", 1.0 if angular else 1e3),
        ("velocity", output + "_vel", "rad/s" if angular else "m/s", 1.0),
        ("acceleration", output + "_acc", "rad/s²" if angular else "m/s²", 1.0),
    ]
    t_ms = result.times * 1e3
    rows = []
    for _, key, _, scale in labels:
        traces = []
        if ideal is not None:
            y0 = np.interp(result.times, ideal.times, ideal.outputs[key]) * scale
            traces.append(Trace(t_ms, y0, {"color": "0.55", "lw": 1.6, "label": "ideal"}, marks_clipping=False))
        traces.append(Trace(t_ms, result.outputs[key] * scale, {"color": "C3", "lw": 0.8, "label": "with clearance"}))
        rows.append(traces)
    fig = new_figure(9.5, 8.0)
    drawn = _steady_rows(fig, rows, _window(result, startup), left=0.1, top=0.91, bottom=0.07)
    for (ax, _), (title, _, unit, _) in zip(drawn, labels):
        ax.set_label(title)
        ax.set_ylabel(f"{title} [{unit}]")
        ax.grid(alpha=0.3)
    drawn[0][0].legend(loc="upper right", fontsize=8)
    drawn[-1][0].set_xlabel("time [ms]")
    cl = ", ".join(result.joints) or "none"
    scale_note = ""
    if startup > 0:
        steady = result.times[-1] > result.times[0] + startup
        scale_note = "; y-scale of the steady state" if steady else "; the whole run is its start-up window"
    fig.suptitle(f"{result.metadata.get('mechanism', '')}: {output} (clearance at {cl}){scale_note}", fontsize=11)
    if path is not None:
        save_png(fig, path)
    return fig


def force_unit(peak: float) -> tuple[str, float]:
    """(unit, scale from N) for a force axis whose largest value is ``peak`` [N]: kN from 1 kN on."""
    return ("kN", 1e-3) if peak >= 1e3 else ("N", 1.0)


def plot_contact_force(
    result: SimulationResult,
    *,
    startup: float = 0.0,
    modes: Sequence[JointContactModes] | None = None,
    path: str | Path | None = None,
) -> Figure:
    """Contact force of each clearance joint against time, its contact modes shaded beneath.

    One panel per joint, scaled to the steady state (after ``startup``): the background is
    coloured by contact mode (impact, continuous contact; free flight unshaded), the start-up
    window is shaded grey, start-up peaks beyond the scale are marked at the edge and shown
    at full scale beside. The force unit is kN when the steady peak is 1 kN or more.

    Args:
        result: the run.
        startup: start-up window from the run's start [s] (0: none).
        modes: the joints' `JointContactModes` (events over the whole run); default
            computed with `contact_modes`.
        path: PNG path to save to.

    Returns:
        The figure (one axes per joint, labelled with the joint name).
    """
    joints = list(result.joints)
    by_joint = {m.joint: m for m in modes} if modes is not None else {j: contact_modes(result, j) for j in joints}
    t_ms = result.times * 1e3
    window = _window(result, startup)
    rows = []
    units = []
    for j in joints:
        f = result.joints[j].force_magnitude
        steady = f[t_ms >= window[1]]
        unit, scale = force_unit(float(steady.max()) if len(steady) and startup > 0 else float(f.max(initial=0.0)))
        units.append(unit)
        rows.append([Trace(t_ms, f * scale, {"color": "k", "lw": 0.6, "label": "contact force"})])
    fig = new_figure(9.5, 1.3 + 2.6 * max(1, len(joints)))
    h = fig.get_figheight()
    drawn = _steady_rows(fig, rows, window, left=0.09, top=1 - 1.0 / h, bottom=0.55 / h, include_zero=True)
    for (ax, _), j, unit in zip(drawn, joints, units):
        ax.set_label(j)
        m = by_joint[j]
        for mode in (ContactMode.IMPACT, ContactMode.CONTINUOUS):
            spans = [(e.start * 1e3, e.duration * 1e3) for e in m.events if e.mode is mode]
            if spans:
                ax.broken_barh(
                    spans, (0, 1), transform=ax.get_xaxis_transform(), color=MODE_COLOURS[mode], alpha=0.22, lw=0
                )
        ax.set_ylabel(f"{j} force [{unit}]")
        ax.grid(alpha=0.3)
    if drawn:
        drawn[-1][0].set_xlabel("time [ms]")
    handles = [Patch(facecolor="white", edgecolor="0.6", label="free flight")]
    handles += [Patch(color=MODE_COLOURS[m], alpha=0.4, label=m.value.replace("_", " ")) for m in list(ContactMode)[1:]]
    if startup > 0:  # a run without a start-up window (a retrofitted model) has no span to name
        handles.append(Patch(color="0.85", label="start-up window"))
    fig.legend(
        handles=handles, loc="upper left", ncol=4, fontsize=8, frameon=False, bbox_to_anchor=(0.08, 1 - 0.42 / h)
    )
    title = f"{result.metadata.get('mechanism', '')}: contact force at the clearance joints, by contact mode"
    fig.text(0.09, 1 - 0.25 / h, title, fontsize=11, va="center")
    if path is not None:
        save_png(fig, path)
    return fig


def plot_orbit(
    result: SimulationResult, joint: str, clearance: float, *, startup: float = 0.0, path: str | Path | None = None
) -> Figure:
    """Journal-centre orbit in the bearing frame inside the clearance circle (µm).

    The start-up window's part is a thin grey line; the steady state is cut into 12 equal
    spans of time, each a line of its own colour (a stepped colour bar of time), which draws
    far faster than a colour per sample; the path is thinned to about a pixel
    (`canvas.thin_path`).

    Args:
        result: the run.
        joint: clearance joint name.
        clearance: radial clearance c [m] (the circle drawn).
        startup: start-up window from the run's start [s] (0: none).
        path: PNG path to save to.
    """
    jr = result.joints[joint]
    e = jr.eccentricity * 1e6
    c = clearance * 1e6
    t_ms = result.times * 1e3
    keep = thin_path(e[:, 0], e[:, 1])
    split = (result.times[0] + startup) * 1e3
    if split >= t_ms[-1]:  # no steady state: the whole run coloured by time
        split = float(t_ms[0])
    early, late = keep[t_ms[keep] < split], keep[t_ms[keep] >= split]
    fig = new_figure(6.6, 5.8)
    ax = fig.add_axes((0.13, 0.1, 0.66, 0.8))
    cax = fig.add_axes((0.83, 0.18, 0.03, 0.64))
    th = np.linspace(0, 2 * np.pi, 400)
    ax.plot(c * np.cos(th), c * np.sin(th), color="k", lw=1.2, label=f"clearance circle (c = {c:g} µm)")
    if len(early):
        ax.plot(e[early, 0], e[early, 1], color="0.6", lw=0.5, label="start-up")
    edges = np.linspace(split, float(t_ms[-1]), 13)
    norm = BoundaryNorm(edges, 12)
    cmap = colormaps["viridis"].resampled(12)
    part = np.clip(np.searchsorted(edges, t_ms[late], side="right") - 1, 0, 11)
    for k in range(12):
        idx = late[part == k]
        if len(idx):
            idx = np.concatenate([idx, late[part == k + 1][:1]])  # joined to the next span
            label = ("steady state" if startup > 0 else "run") if k == 0 else None
            ax.plot(e[idx, 0], e[idx, 1], color=cmap(k), lw=0.9, label=label)
    ax.plot(e[0, 0], e[0, 1], "o", color="C3", ms=5, label="start")
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), cax=cax, label="time [ms]")
    bar.set_ticks(edges[::3].tolist())
    bar.ax.yaxis.set_major_formatter(FormatStrFormatter("%.4g"))
    ax.set_aspect("equal")
    lim = 1.15 * max(c, float(np.abs(e).max()) if len(e) else c)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_xlabel("eccentricity x in bearing frame [µm]")
    ax.set_ylabel("eccentricity y in bearing frame [µm]")
    ax.set_title(f"journal-centre orbit at {joint}", fontsize=11)
    ax.legend(loc="upper right", fontsize=7)
    ax.grid(alpha=0.3)
    if path is not None:
        save_png(fig, path)
    return fig
