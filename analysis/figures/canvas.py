"""Drawing without pyplot: Agg figures, PNGs written once, lines thinned to what the pixels show,
and the start-up window marked on time axes.

Every figure of a run is a `matplotlib.figure.Figure` on an Agg canvas (`new_figure`): no
pyplot import, no figure manager, nothing to close. `save_png` draws it once (a fixed layout,
no tight bounding box, which would draw it twice) and writes the PNG atomically.

Time series with far more samples than the axis has pixel columns are drawn by `draw_series`:
a crowded one as the min-max band of each pixel column with the column means as its line
(`density`), any other as its min-max line (`thin_series`: the smallest and largest sample of
each column, in time order); every peak stays. Paths drawn in a plane (orbits, phase
portraits) are thinned by `thin_path` (a point every fraction of the figure's size along the
path). Axes scaled to the steady state (`steady_scale`) get the start-up window shaded
(`mark_startup`) and the start-up samples beyond their limits marked at the edge
(`mark_clipped`); `time_rows` lays such axes out.
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

from clearance.analysis.figures.density import CROWDED_SHARE, column_envelope, column_of, crowded_columns, solid_columns
from clearance.results import atomic_write_bytes

__all__ = [
    "BAND_ALPHA",
    "DPI",
    "STARTUP_COLOUR",
    "Clipped",
    "Trace",
    "axes_pixels",
    "draw_series",
    "mark_clipped",
    "mark_startup",
    "new_figure",
    "save_png",
    "steady_scale",
    "thin_path",
    "thin_series",
]

DPI = 100
"""Resolution of the written PNGs [dots per inch]."""

STARTUP_COLOUR = "0.88"
"""Fill of the start-up window on time axes (light grey)."""

BAND_ALPHA = 0.25
"""Opacity of an envelope band (`draw_series`): the lines beneath show through."""

_MARKER_PX = 20
"""Pixels per edge marker of `mark_clipped` at most: a marker is 7 px wide, and a row of them closer
than a few widths reads as a bar."""

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


def thin_series(x: np.ndarray, y: np.ndarray, *, columns: int = _ENVELOPE_COLUMNS) -> tuple[np.ndarray, np.ndarray]:
    """Min/max thinning of a time series for drawing as a line.

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


def mark_clipped(ax: Axes, x: np.ndarray, y: np.ndarray, limits: tuple[float, float], *, colour: str) -> Clipped | None:
    """Mark where a series leaves the axis's limits: a triangle at the edge per excursion.

    Excursions closer than a marker's width are marked once (a dense run of them would
    otherwise draw a solid bar along the edge).

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
    x0, x1 = ax.get_xlim()
    slot = np.floor((x[tips_arr] - x0) / ((x1 - x0) or 1.0) * axes_pixels(ax)[0] / _MARKER_PX).astype(int)
    for sel, yy, marker in ((up, 0.985, "^"), (~up, 0.015, "v")):
        if sel.any():
            shown = tips_arr[sel][np.unique(slot[sel], return_index=True)[1]]
            ax.plot(x[shown], np.full(len(shown), yy), marker, color=colour, ms=5, transform=tr, clip_on=False)
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


def steady_scale(traces: list[Trace], steady_from: float, *, include_zero: bool = False) -> tuple[float, float] | None:
    """y-limits holding every sample of ``traces`` from ``steady_from`` on, with a 6 % margin.

    Args:
        traces: the traces of one axes (x increasing).
        steady_from: start of the steady state on their abscissa (their first time: the whole run).
        include_zero: the limits reach down (or up) to 0 (a magnitude).

    Returns:
        (low, high), or None when no trace has a finite sample from ``steady_from`` on.
    """
    lo, hi = np.inf, -np.inf
    for tr in traces:
        part = tr.y[int(np.searchsorted(tr.x, steady_from, side="left")) :]  # a view: nothing copied
        if len(part):  # fmin/fmax skip NaN without a warning
            lo, hi = min(lo, float(np.fmin.reduce(part))), max(hi, float(np.fmax.reduce(part)))
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return None
    if include_zero:
        lo, hi = min(lo, 0.0), max(hi, 0.0)
    margin = 0.06 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.06
    return lo - margin, hi + margin


def axes_pixels(ax: Axes) -> tuple[int, int]:
    """(width, height) of an axes in pixels of the saved PNG (from its position; nothing drawn)."""
    fig = ax.get_figure(root=True)
    pos = ax.get_position()
    w, h = (fig.get_size_inches() if fig is not None else (6.4, 4.8)) * DPI
    return max(1, int(pos.width * w)), max(1, int(pos.height * h))


def draw_series(
    ax: Axes,
    x: np.ndarray,
    y: np.ndarray,
    *,
    style: dict[str, Any],
    limits: tuple[float, float] | None = None,
    reach: tuple[float, ...] = (),
) -> bool:
    """Draw a time series at the axes' resolution; a crowded one as its envelope band and mean line.

    Up to two samples per pixel column the series is drawn as it is. Beyond, a series that a
    line would crowd (a share of `density.crowded_columns` of `density.CROWDED_SHARE` or more) is drawn as the
    min-max band of each pixel column (translucent, beneath the other lines) with the column
    means as its line; any other as its min-max line (`thin_series`), which covers the same
    pixels as the full series, with the band and mean in place of the line over the blocks a
    line would fill solid (`density.solid_columns`), if any. Every peak stays either way.

    Args:
        ax: the axes (placed: its pixel width sets the columns).
        x, y: (n,) the series in display units.
        style: ``Axes.plot`` keywords (``color``, ``lw``, ``label``, ``zorder``).
        limits: the axes' y-limits (default: the range of ``y`` and ``reach``).
        reach: other values the axes will show (lines drawn beside the series).

    Returns:
        Whether a band was drawn.
    """
    columns, rows = axes_pixels(ax)
    if limits is None:
        lo = min([float(np.min(y)), *reach]) if len(y) else 0.0
        hi = max([float(np.max(y)), *reach]) if len(y) else 1.0
        limits = (lo, hi)
    if len(x) <= 2 * columns:
        ax.plot(x, y, **style)
        return False
    pixel = ((limits[1] - limits[0]) or 1.0) / rows
    env = column_envelope(x, y, columns=columns)
    colour = style.get("color", "k")
    z = float(style.get("zorder", 2.0))
    band = dict(color=colour, alpha=BAND_ALPHA, lw=0, zorder=z - 0.3)
    if crowded_columns(x, y, columns=columns, pixel=pixel).mean() >= CROWDED_SHARE:
        ax.fill_between(env.x, env.low, env.high, **band)
        ax.plot(env.x, env.mean, **style)
        return True
    here = solid_columns(env, limits)
    if not here.any():
        ax.plot(*thin_series(x, y, columns=columns), **style)
        return False
    # a sparse series with blocks a line fills solid: the band and the mean there, the line elsewhere
    x0, x1 = float(x[0]), float(x[-1])
    solid = np.zeros(columns, dtype=bool)
    solid[column_of(env.x[here], columns=columns, start=x0, end=x1)] = True
    ax.fill_between(env.x, env.low, env.high, where=here, **band)
    ax.plot(env.x, np.where(here, env.mean, np.nan), **{k: v for k, v in style.items() if k != "label"})
    tx, ty = thin_series(x, y, columns=columns)
    ax.plot(tx, np.where(solid[column_of(tx, columns=columns, start=x0, end=x1)], np.nan, ty), **style)
    return True
