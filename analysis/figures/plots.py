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
from matplotlib.cm import ScalarMappable
from matplotlib.colors import BoundaryNorm
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import FormatStrFormatter, MaxNLocator

from clearance.analysis.figures.canvas import Trace, axes_pixels, new_figure, save_png, thin_path
from clearance.analysis.figures.time_rows import (
    Layout,
    Row,
    TimeAxis,
    band_legend_entry,
    draw_time_rows,
    head_and_legend,
    time_axis,
)
from clearance.analysis.metrics.response import ContactMode, JointContactModes, contact_modes
from clearance.results import SimulationResult, atomic_write_bytes
from clearance.units import scaled_unit

__all__ = [
    "MODE_COLOURS",
    "plot_response",
    "plot_contact_force",
    "plot_orbit",
    "on_times",
    "save_figure",
    "scale_note",
    "steady_peak",
]

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


def _window(result: SimulationResult, startup: float, time: TimeAxis) -> tuple[float, float]:
    """The start-up window on the run's time axis (in ``time``'s unit)."""
    t0 = float(result.times[0]) * time.scale
    return t0, t0 + startup * time.scale


def on_times(times: np.ndarray, other_times: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` sampled at ``other_times``, read at ``times`` (linear); as they are where the times agree.

    Args:
        times: (n,) where to read [s].
        other_times: (m,) increasing, where ``values`` were sampled [s].
        values: (m,) the series.
    """
    if len(times) == len(other_times) and np.array_equal(times, other_times):
        return values
    return np.interp(times, other_times, values)


def scaled(values: np.ndarray, scale: float) -> np.ndarray:
    """``values * scale``; ``values`` themselves for a scale of 1 (no copy of a long series)."""
    return values if scale == 1.0 else values * scale


def steady_peak(times: np.ndarray, y: np.ndarray, startup: float) -> float:
    """Largest |y| after the start-up window (the whole run's without one or without samples after it).

    Args:
        times: (n,) [s].
        y: (n,) the series.
        startup: the start-up window from the run's start [s] (0: none).
    """
    k0 = int(np.searchsorted(times, times[0] + startup)) if startup > 0 else 0
    part = y[k0:] if k0 < len(y) else y
    return float(np.max(np.abs(part))) if len(part) else 0.0


def scale_note(times: np.ndarray, startup: float) -> str:
    """A time figure's title note on its y-scale: that of the steady state (after ``startup``), or
    that the whole run is its start-up window; empty without a start-up window.

    Args:
        times: (n,) the run's sample times [s].
        startup: the start-up window from the run's start [s] (0: none).
    """
    if not startup > 0:
        return ""
    steady = times[-1] > times[0] + startup
    return "; y-scale of the steady state" if steady else "; the whole run is its start-up window"


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

    Each row is scaled to the steady state (after ``startup``); the start-up window is
    shaded, its samples beyond that scale are marked by triangles at the edge and shown at
    full scale in a small panel beside. A crowded series is drawn as its envelope band with
    the mean line, the ideal on top; where a row cannot be read over the whole run (crowded,
    or more than `time_rows.ZOOM_AFTER_CYCLES` drive cycles) a zoom into the steady state
    comes beside it (`time_rows.draw_time_rows`). Velocity and acceleration units are chosen
    by size (``km/s²`` for 1.6e5 m/s²).

    Args:
        result: run with clearance.
        ideal: run of the ideal twin (or None).
        output: output name (e.g. ``slider_x``).
        angular: the output is an angle (units rad, rad/s, rad/s²).
        startup: start-up window from the run's start [s] (0: none); also the drive period
            that a zoom shows.
        path: PNG path to save to.

    Returns:
        The figure; its axes carry the labels ``displacement``, ``velocity``, ``acceleration``.

    Raises:
        KeyError: unknown output.
    """
    labels = [
        ("displacement", output, "rad" if angular else "m"),
        ("velocity", output + "_vel", "rad/s" if angular else "m/s"),
        ("acceleration", output + "_acc", "rad/s²" if angular else "m/s²"),
    ]
    time = time_axis(result.times)
    t_ms = result.times * time.scale
    rows = []
    for title, key, si in labels:
        y = result.outputs[key]
        if angular:
            unit, scale = si, 1.0
        elif key == output:
            unit, scale = "mm", 1e3  # positions of a mechanism: mm throughout
        else:
            unit, scale = scaled_unit(steady_peak(result.times, y, startup), si)
        traces = []
        if ideal is not None:
            y0 = scaled(on_times(result.times, ideal.times, ideal.outputs[key]), scale)
            traces.append(
                Trace(t_ms, y0, {"color": "0.5", "lw": 1.8, "label": "ideal", "zorder": 2.0}, marks_clipping=False)
            )
        traces.append(
            Trace(t_ms, scaled(y, scale), {"color": "C3", "lw": 0.8, "label": "with clearance", "zorder": 2.2})
        )
        rows.append(Row(traces, title, f"{title} [{unit}]", si, scale))
    fig, drawn, _ = draw_time_rows(
        rows,
        window=_window(result, startup, time),
        cycle=startup * time.scale,
        layout=Layout(row_height=2.0, top=0.75),
        time=time,
    )
    cl = ", ".join(result.joints) or "none"
    head = f"{result.metadata.get('mechanism', '')}: {output} (clearance at {cl}){scale_note(result.times, startup)}"
    head_and_legend(fig, drawn, head, band_colour="C3")
    if path is not None:
        save_png(fig, path)
    return fig


def plot_contact_force(
    result: SimulationResult,
    *,
    startup: float = 0.0,
    modes: Sequence[JointContactModes] | None = None,
    path: str | Path | None = None,
) -> Figure:
    """Contact force of each clearance joint against time, its contact modes shaded beneath.

    One row per joint, scaled to the steady state (after ``startup``): the background is
    coloured by contact mode (impact, continuous contact; free flight unshaded), the start-up
    window is shaded grey, start-up peaks beyond the scale are marked at the edge and shown
    at full scale beside (named above the row when the joints fill two columns). A crowded
    force is drawn as its envelope band with the mean line; a zoom into the steady state comes
    beside where the whole run cannot be read (`time_rows.draw_time_rows`). The force unit is
    chosen by the steady peak (N, kN, MN). More than 4 joints get lower rows, more than 8 two
    columns of rows.

    Args:
        result: the run.
        startup: start-up window from the run's start [s] (0: none); also the drive period
            that a zoom shows.
        modes: the joints' `JointContactModes` (events over the whole run); default
            computed with `contact_modes`.
        path: PNG path to save to.

    Returns:
        The figure (one axes per joint, labelled with the joint name).
    """
    joints = list(result.joints)
    by_joint = {m.joint: m for m in modes} if modes is not None else {j: contact_modes(result, j) for j in joints}
    time = time_axis(result.times)
    t_ms = result.times * time.scale
    window = _window(result, startup, time)
    rows = []
    for j in joints:
        f = result.joints[j].force_magnitude
        unit, scale = scaled_unit(steady_peak(result.times, f, startup), "N")
        rows.append(
            Row(
                [Trace(t_ms, scaled(f, scale), {"color": "0.15", "lw": 0.6})],
                j,
                f"{j} force [{unit}]",
                "N",
                scale,
                True,
            )
        )
    many = len(joints) > 4
    layout = Layout(row_height=1.45 if many else 2.0, top=1.0, groups=2 if len(joints) > 8 else 1)
    fig, drawn, _ = draw_time_rows(rows, window=window, cycle=startup * time.scale, layout=layout, time=time)
    for d in drawn:
        m = by_joint[d.row.label]
        for ax in (d.main, d.zoom):
            if ax is None:
                continue
            lo, hi = ax.get_xlim()
            shown = [e for e in m.events if e.end * time.scale >= lo and e.start * time.scale <= hi]
            # events closer than 3 pixels apart stripe the axes: fainter there
            alpha = 0.22 if len(shown) * 3 <= axes_pixels(ax)[0] else 0.12
            for mode in (ContactMode.IMPACT, ContactMode.CONTINUOUS):
                spans = [(e.start * time.scale, e.duration * time.scale) for e in shown if e.mode is mode]
                if spans:
                    ax.broken_barh(
                        spans, (0, 1), transform=ax.get_xaxis_transform(), color=MODE_COLOURS[mode], alpha=alpha, lw=0
                    )
    h = fig.get_figheight()
    handles = [Patch(facecolor="white", edgecolor="0.6", label="free flight")]
    handles += [Patch(color=MODE_COLOURS[m], alpha=0.4, label=m.value.replace("_", " ")) for m in list(ContactMode)[1:]]
    if startup > 0:  # a run without a start-up window (a retrofitted model) has no span to name
        handles.append(Patch(color="0.85", label="start-up window"))
    if any(d.band for d in drawn):
        handles.append(band_legend_entry("0.15"))
    fig.legend(handles=handles, loc="upper left", ncol=3, fontsize=8, frameon=False, bbox_to_anchor=(0.01, 1 - 0.4 / h))
    title = f"{result.metadata.get('mechanism', '')}: contact force at the clearance joints, by contact mode"
    fig.text(0.02, 1 - 0.22 / h, title, fontsize=11, va="center")
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
    time = time_axis(result.times)
    t_ms = result.times * time.scale
    keep = thin_path(e[:, 0], e[:, 1])
    split = (result.times[0] + startup) * time.scale
    if split >= t_ms[-1]:  # no steady state: the whole run coloured by time
        split = float(t_ms[0])
    early, late = keep[t_ms[keep] < split], keep[t_ms[keep] >= split]
    fig = new_figure(6.6, 5.8)
    ax = fig.add_axes((0.13, 0.1, 0.66, 0.8))
    cax = fig.add_axes((0.83, 0.18, 0.03, 0.64))
    th = np.linspace(0, 2 * np.pi, 400)
    # the circle on top: a long run's orbit runs along it and would hide it
    ax.plot(
        c * np.cos(th), c * np.sin(th), color="k", lw=1.0, ls="--", zorder=4, label=f"clearance circle (c = {c:g} µm)"
    )
    if len(early):
        ax.plot(e[early, 0], e[early, 1], color="0.6", lw=0.5, label="start-up")
    edges = np.linspace(split, float(t_ms[-1]), 13)
    norm = BoundaryNorm(edges, 12)
    cmap = colormaps["viridis"].resampled(12)
    part = np.clip(np.searchsorted(edges, t_ms[late], side="right") - 1, 0, 11)
    # a long run's path crosses itself many times over: thinner lines keep the crossings apart
    width = 0.9 if len(late) < 100_000 else 0.45
    for k in range(12):
        idx = late[part == k]
        if len(idx):
            idx = np.concatenate([idx, late[part == k + 1][:1]])  # joined to the next span
            label = ("steady state" if startup > 0 else "run") if k == 0 else None
            ax.plot(e[idx, 0], e[idx, 1], color=cmap(k), lw=width, label=label)
    ax.plot(e[0, 0], e[0, 1], "o", color="C3", ms=5, label="start")
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), cax=cax, label=time.label)
    ticks = MaxNLocator(nbins=6).tick_values(edges[0], edges[-1])
    bar.set_ticks([v for v in ticks if edges[0] <= v <= edges[-1]])
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
