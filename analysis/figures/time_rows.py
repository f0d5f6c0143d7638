"""Rows of time series on one time axis: the whole run, a zoom into the steady state, the start-up.

`draw_time_rows` lays out a figure of rows (displacement, velocity and acceleration; a joint's
contact force; a joint's reaction), each on the steady state's scale (`canvas.steady_scale`)
with the start-up window shaded and its excursions beyond that scale marked at the edge. Beside
the whole run, where it cannot be read there, comes a zoom into the steady state
(`density.zoom_span`): when a row is crowded (a line would paint pixel columns solid) or the
run holds more than `ZOOM_AFTER_CYCLES` drive cycles. Beside that, where a row's start-up
leaves its scale, the start-up window at full scale; in a layout of several columns of rows a
line above the row names the start-up's peak instead.

Sizes are set in inches (`Layout`): the whole run's axes keep their width however many panels
come beside them, and the figure grows to hold them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from clearance.analysis.figures.canvas import (
    BAND_ALPHA,
    DPI,
    Clipped,
    Trace,
    draw_series,
    mark_clipped,
    mark_startup,
    new_figure,
    steady_scale,
)
from clearance.analysis.figures.density import CROWDED_SHARE, crowded_columns, turn_rate, zoom_span
from clearance.units import format_quantity, scaled_unit

__all__ = [
    "ZOOM_AFTER_CYCLES",
    "ZOOM_COLOUR",
    "DrawnRow",
    "Layout",
    "Row",
    "TimeAxis",
    "band_legend_entry",
    "draw_time_rows",
    "head_and_legend",
    "time_axis",
]

ZOOM_AFTER_CYCLES = 8
"""Drive cycles in a run above which one cycle is too narrow to read on the whole run's axes."""

ZOOM_COLOUR = "C1"
"""Colour of the zoom's span on the whole run's axes and of the zoom's frame."""

_GAP = 0.78
"""Space left of a side panel for its tick labels and y-label [inch]."""

_ZOOM_WIDTH = 2.5
"""Width of the zoom's axes [inch]."""

_STARTUP_WIDTH = 1.8
"""Width of the start-up panel's axes [inch]."""

_ROW_GAP = 0.42
"""Space between rows [inch] (a line of text fits above each)."""


@dataclass(frozen=True)
class TimeAxis:
    """The unit of a figure's time axis, chosen by the run's length (ms for 36 ms, s for 6 s).

    Attributes:
        unit: ``µs``, ``ms`` or ``s``.
        scale: display unit per second.
    """

    unit: str
    scale: float

    @property
    def label(self) -> str:
        """The axis label, ``time [ms]``."""
        return f"time [{self.unit}]"


def time_axis(times: np.ndarray) -> TimeAxis:
    """The time axis for a run's ``times`` [s]: the unit in which its end reads between 1 and 1000."""
    end = float(np.max(np.abs(times[[0, -1]]))) if len(times) else 1.0
    return TimeAxis(*scaled_unit(end, "s"))


@dataclass(frozen=True)
class Row:
    """One row of a `draw_time_rows` figure.

    Attributes:
        traces: the series, drawn in order (x in the figure's time unit, y in display units); those that mark
            clipping are the run's, the others (an ideal twin's) are drawn beneath.
        label: the whole run's axes label (``Axes.get_label``).
        ylabel: y-axis label with its unit.
        si_unit: the SI unit of the values (``N``, ``m/s²``), for the start-up note.
        scale: display unit per SI unit (1e-3 for values shown in kN).
        include_zero: the scale reaches down (or up) to 0 (a magnitude).
    """

    traces: list[Trace]
    label: str
    ylabel: str
    si_unit: str
    scale: float = 1.0
    include_zero: bool = False


@dataclass(frozen=True)
class Layout:
    """Sizes of a `draw_time_rows` figure [inch] and which side panels it may have.

    Attributes:
        row_height: height of each row's axes.
        main_width: width of the whole run's axes.
        top: space above the first row (title, legend).
        bottom: space below the last row (time label).
        left: space left of each column of rows (tick labels, y-label).
        groups: columns of rows (rows fill the first column first).
        startup_panels: a start-up panel beside rows whose start-up leaves the scale (one
            column of rows only; otherwise a note names the start-up's peak).
        zoom: a zoom into the steady state where the whole run cannot be read.
    """

    row_height: float = 1.9
    main_width: float = 6.4
    top: float = 0.9
    bottom: float = 0.55
    left: float = 0.95
    groups: int = 1
    startup_panels: bool = True
    zoom: bool = True


@dataclass(frozen=True)
class DrawnRow:
    """The axes of one drawn row.

    Attributes:
        row: the `Row`.
        main: the whole run's axes.
        zoom: the zoom's axes, or None.
        startup: the start-up panel's axes, or None.
        limits: y-limits of the whole run's axes (None: matplotlib's).
        clipped: excursions beyond them, one per trace that leaves them.
        band: whether a trace was drawn as its envelope band.
    """

    row: Row
    main: Axes
    zoom: Axes | None
    startup: Axes | None
    limits: tuple[float, float] | None
    clipped: list[Clipped]
    band: bool


def _px(limits: tuple[float, float] | None, traces: list[Trace], height: float) -> float:
    """One pixel of an axes of ``height`` inches in y's unit."""
    if limits is None:
        lo = min((float(np.nanmin(t.y)) for t in traces if len(t.y)), default=0.0)
        hi = max((float(np.nanmax(t.y)) for t in traces if len(t.y)), default=1.0)
        limits = (lo, hi)
    span = limits[1] - limits[0]
    return (span if span > 0 else 1.0) / (height * DPI)


def _early(trace: Trace, steady_from: float) -> int:
    """Rows of a trace before the steady state: the only ones that can leave its scale."""
    return int(np.searchsorted(trace.x, steady_from, side="left"))


def _beyond(trace: Trace, steady_from: float, limits: tuple[float, float]) -> bool:
    """Whether a start-up sample of the trace leaves ``limits``."""
    part = trace.y[: _early(trace, steady_from)]
    return bool(len(part)) and (float(np.fmin.reduce(part)) < limits[0] or float(np.fmax.reduce(part)) > limits[1])


def _run_traces(row: Row) -> list[Trace]:
    return [t for t in row.traces if t.marks_clipping]


def _zoom_span(
    rows: list[Row], pixels: list[float], window: tuple[float, float], cycle: float, width: float
) -> tuple[float, float] | None:
    """The zoom's span, or None when every row reads on the whole run's axes."""
    start, end = window[1], max((float(t.x[-1]) for r in rows for t in r.traces if len(t.x)), default=window[1])
    if not end > start:
        return None
    columns = int(_ZOOM_WIDTH * DPI)
    main = int(width * DPI)
    crowded = any(
        crowded_columns(t.x, t.y, columns=main, pixel=px, start=start, end=end).mean() >= CROWDED_SHARE
        for r, px in zip(rows, pixels)
        for t in _run_traces(r)
    )
    t0 = min((float(t.x[0]) for r in rows for t in r.traces if len(t.x)), default=start)
    many = cycle > 0 and (end - t0) / cycle > ZOOM_AFTER_CYCLES
    if not (crowded or many):
        return None
    # the row that turns fastest sets the length; its steady-state peak the centre
    rate, pick = -1.0, None
    for r, px in zip(rows, pixels):
        for t in _run_traces(r):
            v = turn_rate(t.x, t.y, pixel=px, start=start, end=end)
            if v > rate:
                rate, pick = v, (t, px)
    if pick is None:
        return None
    t, px = pick
    k0 = int(np.searchsorted(t.x, start))
    steady = t.y[k0:]
    centre = float(t.x[k0 + int(np.argmax(np.abs(steady - np.mean(steady))))]) if len(steady) else start
    return zoom_span(t.x, t.y, start=start, end=end, cycle=cycle, columns=columns, pixel=px, centre=centre)


def _draw_zoom(ax: Axes, row: Row, span: tuple[float, float]) -> bool:
    """The traces within ``span`` on their own scale; returns whether a band was drawn."""
    parts = []
    for tr in row.traces:
        a, b = np.searchsorted(tr.x, span[0]), np.searchsorted(tr.x, span[1], side="right")
        if b > a:
            parts.append((tr, slice(int(a), int(b))))
    if not parts:
        ax.set_xlim(*span)
        return False
    lo = min(float(np.min(tr.y[sl])) for tr, sl in parts)
    hi = max(float(np.max(tr.y[sl])) for tr, sl in parts)
    pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.08
    limits = (lo - pad, hi + pad)
    band = False
    for tr, sl in parts:
        style = {k: v for k, v in tr.style.items() if k != "label"}
        band |= draw_series(ax, tr.x[sl], tr.y[sl], limits=limits, style=style)
    ax.set_ylim(*limits)
    ax.set_xlim(*span)
    for side in ax.spines.values():
        side.set_edgecolor(ZOOM_COLOUR)
    return band


def _draw_startup(ax: Axes, row: Row, window: tuple[float, float], limits: tuple[float, float]) -> None:
    """The start-up window at full scale, the steady-state limits dashed."""
    for tr in row.traces:
        a, b = np.searchsorted(tr.x, window[0]), np.searchsorted(tr.x, window[1], side="right")
        style = {k: v for k, v in tr.style.items() if k != "label"}
        draw_series(ax, tr.x[a:b], tr.y[a:b], style=style)
    for v in limits:
        ax.axhline(v, color="0.3", lw=0.8, ls="--")
    ax.set_xlim(*window)
    ax.set_facecolor("0.96")


def _startup_note(ax: Axes, row: Row, clipped: list[Clipped], time: TimeAxis) -> None:
    """Name the largest start-up excursion beyond the scale above the axes."""
    worst = max(clipped, key=lambda k: abs(k.peak))
    ax.set_title(
        f"start-up peak {format_quantity(worst.peak / row.scale, row.si_unit)} at "
        f"{format_quantity(worst.peak_time / time.scale, 's')} (off this scale)",
        loc="left",
        fontsize=7,
        pad=2,
        color="0.3",
    )


def draw_time_rows(
    rows: list[Row], *, window: tuple[float, float], cycle: float, layout: Layout, time: TimeAxis
) -> tuple[Figure, list[DrawnRow], tuple[float, float] | None]:
    """A figure of rows sharing the time axis, each with its side panels where needed.

    Args:
        rows: the `Row`s, top to bottom (then the next column of rows).
        window: (start, end) of the start-up window in ``time``'s unit; equal for none (the
            scale is then the whole run's).
        cycle: the drive period in ``time``'s unit (0: none): a zoom shows one cycle where that reads.
        layout: sizes and side panels (`Layout`).
        time: the unit of the traces' x (`time_axis`).

    Returns:
        (figure, the drawn rows, the zoom's span in ``time``'s unit or None). The caller adds the
        title and legend in the space ``layout.top`` leaves.
    """
    n = len(rows)
    per = max(1, math.ceil(n / layout.groups))
    limits = [steady_scale(r.traces, window[1], include_zero=r.include_zero) for r in rows]
    pixels = [_px(lim, r.traces, layout.row_height) for lim, r in zip(limits, rows)]
    clipped_any = [
        lim is not None and any(_beyond(t, window[1], lim) for t in _run_traces(r)) for lim, r in zip(limits, rows)
    ]
    side = layout.startup_panels and layout.groups == 1 and any(clipped_any)
    span = _zoom_span(rows, pixels, window, cycle, layout.main_width) if layout.zoom else None
    group_w = (
        layout.left + layout.main_width + (_GAP + _ZOOM_WIDTH if span else 0) + (_GAP + _STARTUP_WIDTH if side else 0)
    )
    width = group_w * layout.groups + 0.25
    height = layout.top + per * layout.row_height + (per - 1) * _ROW_GAP + layout.bottom
    fig = new_figure(width, height)

    def box(x0: float, w: float, i: int) -> tuple[float, float, float, float]:
        y0 = height - layout.top - (i + 1) * layout.row_height - i * _ROW_GAP
        return (x0 / width, y0 / height, w / width, layout.row_height / height)

    drawn: list[DrawnRow] = []
    first: Axes | None = None
    for k, (row, lim) in enumerate(zip(rows, limits)):
        g, i = divmod(k, per)
        x0 = g * group_w + layout.left
        ax = fig.add_axes(box(x0, layout.main_width, i), sharex=first, label=row.label)
        first = first or ax
        band = False
        for tr in row.traces:
            band |= draw_series(ax, tr.x, tr.y, limits=lim, style=tr.style)
        ax.locator_params(axis="y", nbins=5)  # fewer ticks: each costs a few ms to draw
        mark_startup(ax, *window, label="start-up" if i == 0 else None)
        clipped: list[Clipped] = []
        if lim is not None:
            ax.set_ylim(*lim)
            for tr in _run_traces(row):
                early = _early(tr, window[1])
                c = mark_clipped(ax, tr.x[:early], tr.y[:early], lim, colour=str(tr.style.get("color", "k")))
                if c is not None:
                    clipped.append(c)
        ax.set_ylabel(row.ylabel, fontsize=9)
        ax.tick_params(labelsize=8)
        ax.grid(alpha=0.3)
        last = i == per - 1 or k == n - 1
        zoom_ax = startup_ax = None
        x = x0 + layout.main_width
        if span is not None:
            ax.axvspan(*span, facecolor=ZOOM_COLOUR, alpha=0.15, lw=0, zorder=0.5)
            for edge in span:
                ax.axvline(edge, color=ZOOM_COLOUR, lw=0.9, zorder=0.6)
            zoom_ax = fig.add_axes(box(x + _GAP, _ZOOM_WIDTH, i))
            band |= _draw_zoom(zoom_ax, row, span)
            zoom_ax.set_ylabel(row.ylabel, fontsize=7)
            zoom_ax.tick_params(labelsize=7)
            zoom_ax.locator_params(nbins=4)
            zoom_ax.grid(alpha=0.3)
            if i == 0:
                zoom_ax.set_title("zoom into the steady state\n(orange span on the left)", fontsize=8)
            if last:
                zoom_ax.set_xlabel(time.label, fontsize=8)
            x += _GAP + _ZOOM_WIDTH
        if side and clipped and lim is not None:
            startup_ax = fig.add_axes(box(x + _GAP, _STARTUP_WIDTH, i))
            _draw_startup(startup_ax, row, window, lim)
            startup_ax.set_ylabel(row.ylabel, fontsize=7)
            startup_ax.tick_params(labelsize=7)
            startup_ax.locator_params(nbins=4)
            startup_ax.grid(alpha=0.3)
            if not any(d.startup for d in drawn):  # the first (top) one names what the panels show
                startup_ax.set_title("start-up, full scale\n(dashes: steady-state scale)", fontsize=8)
        elif clipped:
            _startup_note(ax, row, clipped, time)
        if last:
            ax.set_xlabel(time.label, fontsize=9)
        else:
            ax.tick_params(labelbottom=False)
        drawn.append(DrawnRow(row, ax, zoom_ax, startup_ax, lim, clipped, band))
    panels = [d.startup for d in drawn if d.startup is not None]
    if panels:  # the lowest one carries the time label
        panels[-1].set_xlabel(time.label, fontsize=8)
    return fig, drawn, span


def band_legend_entry(colour: str = "0.5") -> Patch:
    """The legend's entry for envelope bands (`canvas.draw_series`)."""
    return Patch(color=colour, alpha=BAND_ALPHA, lw=0, label="band: min–max of each pixel column; line: its mean")


def head_and_legend(fig: Figure, drawn: list[DrawnRow], head: str, *, band_colour: str = "0.5") -> None:
    """A time-row figure's head line (top left) and its first row's legend, upper right.

    The legend holds that row's own entries, and the envelope band's (`band_legend_entry`) where
    any row drew its series as a band.

    Args:
        fig: the figure of `draw_time_rows`.
        drawn: its rows.
        head: the line written above the rows.
        band_colour: the band's colour in the legend.
    """
    handles, names = drawn[0].main.get_legend_handles_labels()
    if any(d.band for d in drawn):
        handles.append(band_legend_entry(band_colour))
        names.append(handles[-1].get_label())
    drawn[0].main.legend(handles, names, loc="upper right", fontsize=7)
    fig.text(0.02, 1 - 0.3 / fig.get_figheight(), head, fontsize=11, va="center")
