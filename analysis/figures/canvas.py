"""Drawing without pyplot: Agg figures, PNGs written once, lines thinned to what the pixels show,
and the start-up window marked on time axes.

Every figure of a run is a `matplotlib.figure.Figure` on an Agg canvas (`new_figure`): no
pyplot import, no figure manager, nothing to close. `save_png` draws it once (a fixed layout,
no tight bounding box, which would draw it twice) and writes the PNG atomically.

Time series with far more samples than the axis has pixel columns are thinned by `envelope`
(the smallest and largest sample of each column, in time order, so every peak stays); paths
drawn in a plane (orbits, phase portraits) by `thin_path` (a point every fraction of the
figure's size along the path). Axes scaled to the steady state get the start-up window
shaded (`mark_startup`) and the start-up samples beyond their limits marked at the edge
(`mark_clipped`).
"""

from __future__ import annotations

import io
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.transforms import blended_transform_factory

from clearance.results import atomic_write_bytes

__all__ = [
    "DPI",
    "STARTUP_COLOUR",
    "Clipped",
    "Trace",
    "draw_startup_panel",
    "draw_steady_scaled",
    "envelope",
    "mark_clipped",
    "mark_startup",
    "new_figure",
    "save_png",
    "steady_limits",
    "thin_path",
    "traces_clipped",
]

DPI = 100
"""Resolution of the written PNGs [dots per inch]."""

STARTUP_COLOUR = "0.88"
"""Fill of the start-up window on time axes (light grey)."""

_ENVELOPE_COLUMNS = 1500
"""Columns of `envelope`: above the pixel width of every time axis drawn at `DPI`."""


def new_figure(width: float, height: float) -> Figure:
    """A figure on an Agg canvas (no pyplot).

    Args:
        width, height: size [inch].

    Returns:
        The figure; draw into it with ``fig.add_subplot`` / ``fig.subplots`` / ``fig.add_gridspec``.
    """
    fig = Figure(figsize=(width, height), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def save_png(fig: Figure, path: str | Path, *, dpi: int = DPI) -> Path:
    """Draw a figure once and write it as PNG atomically.

    The figure's own layout is kept (no tight bounding box). A figure made by pyplot is
    closed afterwards so pyplot releases it.

    Args:
        fig: the figure.
        path: PNG file (replaced atomically).
        dpi: resolution [dots per inch].

    Returns:
        ``path``.
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    if "matplotlib.pyplot" in sys.modules:  # only a pyplot figure is registered there
        sys.modules["matplotlib.pyplot"].close(fig)
    atomic_write_bytes(path, buf.getvalue())
    return Path(path)


def envelope(x: np.ndarray, y: np.ndarray, *, columns: int = _ENVELOPE_COLUMNS) -> tuple[np.ndarray, np.ndarray]:
    """Min/max thinning of a time series for drawing.

    The samples are cut into ``columns`` runs of equal count; each run keeps its smallest and
    largest sample, in time order, plus the first and last sample of the series. Drawn as a
    line, the result covers the same pixels as the full series (every peak stays).

    Args:
        x: (n,) abscissa, increasing.
        y: (n,) values.
        columns: runs to cut into (about the axis width in pixels, or more).

    Returns:
        (x, y) thinned, or the inputs when they have at most 4 ``columns`` samples.
    """
    n = len(x)
    if n <= 4 * columns:
        return x, y
    per = n // columns
    m = per * columns
    block = np.asarray(y[:m]).reshape(columns, per)
    base = np.arange(columns) * per
    keep = np.concatenate([base + np.argmin(block, axis=1), base + np.argmax(block, axis=1), [0], np.arange(m, n)])
    keep = np.unique(keep)
    return x[keep], y[keep]


def thin_path(x: np.ndarray, y: np.ndarray, *, resolution: float = 1.0 / 600) -> np.ndarray:
    """Indices of a planar path, one point every ``resolution`` of its extent along the path.

    Distances are measured with each coordinate divided by its range, so a step is a fixed
    fraction of the plot either way; the first and last points are kept.

    Args:
        x, y: (n,) the path.
        resolution: spacing as a fraction of the path's extent (about one pixel).

    Returns:
        Increasing indices into ``x``, ``y``.
    """
    n = len(x)
    if n < 3:
        return np.arange(n)
    sx = float(np.ptp(x)) or 1.0
    sy = float(np.ptp(y)) or 1.0
    step = np.hypot(np.diff(x) / sx, np.diff(y) / sy)
    s = np.concatenate([[0.0], np.cumsum(step)])
    keep = np.unique(np.floor(s / resolution), return_index=True)[1]
    return np.unique(np.concatenate([keep, [n - 1]]))


def mark_startup(ax: Axes, start: float, end: float, *, label: str | None = "start-up") -> None:
    """Shade the start-up window of a time axis and name it at the top.

    Args:
        ax: axes with time on x.
        start, end: the window, in the axis's time unit.
        label: text written in the band (None: none).
    """
    if not end > start:
        return
    ax.axvspan(start, end, color=STARTUP_COLOUR, lw=0, zorder=0)
    ax.axvline(end, color="0.45", lw=0.8, ls="--", zorder=1)
    if label:
        tr = blended_transform_factory(ax.transData, ax.transAxes)
        ax.text(0.5 * (start + end), 0.97, label, transform=tr, ha="center", va="top", fontsize=8, color="0.35")


@dataclass(frozen=True)
class Clipped:
    """Samples of a series beyond an axis's steady-state limits.

    Attributes:
        count: number of excursions beyond the limits (maximal runs of samples outside).
        peak: the sample farthest beyond, in the series' display unit.
        peak_time: its abscissa.
    """

    count: int
    peak: float
    peak_time: float


def steady_limits(
    x: np.ndarray, series: list[np.ndarray], steady_from: float, *, pad: float = 0.06
) -> tuple[float, float] | None:
    """y-limits that hold every sample of ``series`` from ``steady_from`` on, padded.

    Args:
        x: (n,) abscissa shared by the series.
        series: (n,) arrays.
        steady_from: start of the steady state on ``x``.
        pad: margin on each side as a fraction of the range.

    Returns:
        (low, high), or None when no sample lies in the steady state (the caller keeps
        matplotlib's automatic limits).
    """
    sel = x >= steady_from
    if not sel.any():
        return None
    vals = np.concatenate([np.asarray(s)[sel] for s in series])
    vals = vals[np.isfinite(vals)]
    if len(vals) == 0:
        return None
    lo, hi = float(vals.min()), float(vals.max())
    margin = pad * (hi - lo) if hi > lo else max(abs(hi), 1.0) * pad
    return lo - margin, hi + margin


def mark_clipped(ax: Axes, x: np.ndarray, y: np.ndarray, limits: tuple[float, float], *, colour: str) -> Clipped | None:
    """Mark where a series leaves the axis's limits: a triangle at the edge per excursion.

    Args:
        ax: the axes (its y-limits are ``limits``).
        x, y: (n,) the series as drawn.
        limits: (low, high) of the axis.
        colour: marker colour (the series' colour).

    Returns:
        The excursions (`Clipped`), or None when the series stays inside.
    """
    lo, hi = limits
    out = (y > hi) | (y < lo)
    if not out.any():
        return None
    edges = np.diff(np.concatenate([[0], out.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    tips = [a + int(np.argmax(np.abs(y[a:b]))) for a, b in zip(starts, ends)]
    tips_arr = np.asarray(tips)
    up = y[tips_arr] > hi
    tr = blended_transform_factory(ax.transData, ax.transAxes)
    for sel, yy, marker in ((up, 0.985, "^"), (~up, 0.015, "v")):
        if sel.any():
            ax.plot(
                x[tips_arr[sel]], np.full(int(sel.sum()), yy), marker, color=colour, ms=5, transform=tr, clip_on=False
            )
    beyond = np.maximum(y[tips_arr] - hi, lo - y[tips_arr])
    worst = tips_arr[int(np.argmax(beyond))]
    return Clipped(len(tips), float(y[worst]), float(x[worst]))


@dataclass(frozen=True)
class Trace:
    """A time series to draw on a steady-state scale.

    Attributes:
        x: (n,) abscissa in display units (e.g. ms).
        y: (n,) values in display units.
        style: keyword arguments of ``Axes.plot`` (colour, width, label).
        marks_clipping: whether its samples beyond the limits are marked (`mark_clipped`).
    """

    x: np.ndarray
    y: np.ndarray
    style: dict[str, Any] = field(default_factory=dict)
    marks_clipping: bool = True


def _limits_of(traces: list[Trace], steady_from: float, include_zero: bool) -> tuple[float, float] | None:
    lims = [steady_limits(tr.x, [tr.y], steady_from, pad=0.0) for tr in traces]
    got = [lim for lim in lims if lim is not None]
    if not got:
        return None
    lo, hi = min(lim[0] for lim in got), max(lim[1] for lim in got)
    if include_zero:
        lo, hi = min(lo, 0.0), max(hi, 0.0)
    margin = 0.06 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.06
    return lo - margin, hi + margin


def traces_clipped(traces: list[Trace], steady_from: float, *, include_zero: bool = False) -> bool:
    """Whether a clipping-marked trace leaves the steady-state limits of ``traces`` (`draw_steady_scaled`).

    Args:
        traces: the traces of one axes.
        steady_from: start of the steady state on their abscissa.
        include_zero: the limits reach down (or up) to 0 (a magnitude).
    """
    lim = _limits_of(traces, steady_from, include_zero)
    if lim is None:
        return False
    return any(tr.marks_clipping and bool(np.any((tr.y < lim[0]) | (tr.y > lim[1]))) for tr in traces)


def draw_steady_scaled(
    ax: Axes,
    traces: list[Trace],
    startup: tuple[float, float],
    *,
    label: str | None = "start-up",
    include_zero: bool = False,
) -> tuple[tuple[float, float] | None, list[Clipped]]:
    """Draw traces (thinned by `envelope`) with y-limits from the steady state and the start-up marked.

    The limits hold every sample after the start-up window of every trace; the window is
    shaded (`mark_startup`) and start-up samples beyond the limits are marked at the edge
    (`mark_clipped`). With no sample after the window the limits are matplotlib's.

    Args:
        ax: axes with time on x.
        traces: the series, drawn in order.
        startup: (start, end) of the start-up window on x.
        label: text of the window (None: none).
        include_zero: the limits reach down (or up) to 0 (a magnitude).

    Returns:
        The limits set (None: automatic) and the excursions beyond them, one per marked trace
        that leaves them.
    """
    for tr in traces:
        ax.plot(*envelope(tr.x, tr.y), **tr.style)
    ax.locator_params(axis="y", nbins=5)  # fewer ticks: each costs a few ms to draw
    mark_startup(ax, *startup, label=label)
    lim = _limits_of(traces, startup[1], include_zero)
    clipped: list[Clipped] = []
    if lim is not None:
        ax.set_ylim(*lim)
        for tr in traces:
            if tr.marks_clipping:
                c = mark_clipped(ax, tr.x, tr.y, lim, colour=str(tr.style.get("color", "k")))
                if c is not None:
                    clipped.append(c)
    return lim, clipped


def draw_startup_panel(
    ax: Axes, traces: list[Trace], startup: tuple[float, float], limits: tuple[float, float]
) -> None:
    """The start-up window at full scale, with the steady-state limits as dashed lines.

    Args:
        ax: the (small) axes beside the steady-scaled one.
        traces: the same traces.
        startup: (start, end) of the start-up window on x.
        limits: the steady-state limits of the main axes.
    """
    for tr in traces:
        sel = (tr.x >= startup[0]) & (tr.x <= startup[1])
        style = {k: v for k, v in tr.style.items() if k != "label"}
        ax.plot(*envelope(tr.x[sel], tr.y[sel], columns=400), **style)
    for v in limits:
        ax.axhline(v, color="0.3", lw=0.8, ls="--")
    ax.set_xlim(*startup)
    ax.locator_params(nbins=4)
    ax.set_facecolor("0.96")
    ax.tick_params(labelsize=7)
    ax.set_title("start-up, full scale\n(dashes: steady-state scale)", fontsize=8)
    ax.grid(alpha=0.3)
