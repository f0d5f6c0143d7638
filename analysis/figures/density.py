"""Time series denser than the pixels that draw them: envelopes, a crowding test, a zoom window.

A series with more samples than its axis has pixel columns is drawn from its `Envelope`: the
smallest, largest and mean sample of each pixel column. The envelope keeps every peak (its
largest ``high`` is the series' largest sample, its smallest ``low`` the smallest), so nothing
the full series would reach is lost, and drawing it costs a few thousand points whatever the
run's length.

Drawn as a line, a series that turns back and forth several times within a pixel column paints
that column solid: a band that hides whatever lies beneath (the ideal curve, a threshold).
`crowded_columns` finds such columns: those holding `CROWDED_TURNS` or more direction reversals
of at least `MIN_SWING_PX` pixels. A crowded series is drawn as a
translucent min-max band with its mean line on top (`canvas.draw_series`); a sparse one as the
min-max line, which paints the same pixels as the full series, with the band only over the
blocks a line would fill solid (`solid_columns`: a start-up's dense impacts beyond the scale).
`zoom_span` chooses a stretch of the steady state short enough for the series to read as a
curve, shown beside the whole run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "CROWDED_SHARE",
    "CROWDED_TURNS",
    "MIN_SWING_PX",
    "SOLID_INK",
    "SOLID_RUN",
    "Envelope",
    "column_envelope",
    "column_of",
    "crowded_columns",
    "solid_columns",
    "turn_rate",
    "zoom_span",
]

MIN_SWING_PX = 2.0
"""Smallest swing between two direction reversals that counts [pixels]: below it a wiggle
is within the line's own width."""

CROWDED_TURNS = 2
"""Reversals within one pixel column from which a line paints the column along the series' whole
swing there (a spike, or an oscillation faster than a pixel)."""

SOLID_INK = 0.5
"""Share of the axes' height a pixel column's line covers from which the column counts as inked."""

SOLID_RUN = 8
"""Columns of which half or more inked read as a solid block: vertical strokes a pixel or two
apart (a start-up's dense impacts beyond the scale)."""

CROWDED_SHARE = 0.2
"""Share of a series' pixel columns that are crowded from which the series is drawn as a band: a
spike in every fifth column or more reads as a comb that hides what lies beneath; sparser ones
read as spikes (the default slider-crank's impacts: about 5 % of the columns)."""

_READABLE_COLUMNS_PER_TURN = 3.0
"""Pixel columns per direction reversal in a zoom: an oscillation of 6 px or more per cycle reads
as a curve."""


@dataclass(frozen=True)
class Envelope:
    """A series reduced to its pixel columns.

    Attributes:
        x: (m,) mean abscissa of each non-empty column.
        low: (m,) smallest sample of each column.
        high: (m,) largest sample of each column.
        mean: (m,) mean sample of each column.
        counts: (m,) samples in each column.
    """

    x: np.ndarray
    low: np.ndarray
    high: np.ndarray
    mean: np.ndarray
    counts: np.ndarray


def _window(x: np.ndarray, start: float | None, end: float | None) -> slice:
    """Rows of increasing ``x`` within [start, end] (None: the series' own end)."""
    a = 0 if start is None else int(np.searchsorted(x, start, side="left"))
    b = len(x) if end is None else int(np.searchsorted(x, end, side="right"))
    return slice(a, max(a, b))


def _column_starts(x: np.ndarray, columns: int, start: float, end: float) -> np.ndarray:
    """First row of each non-empty column of [start, end] cut into ``columns`` equal spans."""
    edges = np.linspace(start, end, columns + 1)[:-1]
    starts = np.searchsorted(x, edges, side="left")
    starts = starts[starts < len(x)]
    return np.unique(starts)


def column_envelope(
    x: np.ndarray, y: np.ndarray, *, columns: int, start: float | None = None, end: float | None = None
) -> Envelope:
    """Smallest, largest and mean sample of each of ``columns`` equal spans of x.

    Args:
        x: (n,) abscissa, increasing.
        y: (n,) values.
        columns: spans to cut [start, end] into (about the axis width in pixels).
        start, end: the stretch of x reduced (default: the whole series).

    Returns:
        The `Envelope` (empty spans left out; empty when no sample lies in [start, end]).

    Raises:
        ValueError: ``columns`` below 1, or x and y of different lengths.
    """
    if columns < 1:
        raise ValueError(f"columns must be at least 1 (got {columns})")
    if len(x) != len(y):
        raise ValueError(f"x ({len(x)}) and y ({len(y)}) must have the same length")
    sel = _window(x, start, end)
    xs, ys = np.asarray(x[sel], dtype=float), np.asarray(y[sel], dtype=float)
    if not len(xs):
        empty = np.zeros(0)
        return Envelope(empty, empty, empty, empty, np.zeros(0, dtype=int))
    lo_x = float(xs[0]) if start is None else float(start)
    hi_x = float(xs[-1]) if end is None else float(end)
    idx = _column_starts(xs, columns, lo_x, hi_x)
    counts = np.diff(np.append(idx, len(xs)))
    return Envelope(
        x=np.add.reduceat(xs, idx) / counts,
        low=np.minimum.reduceat(ys, idx),
        high=np.maximum.reduceat(ys, idx),
        mean=np.add.reduceat(ys, idx) / counts,
        counts=counts,
    )


def _turns(y: np.ndarray, min_swing: float) -> np.ndarray:
    """Rows where ``y`` reverses direction after a swing of at least ``min_swing``.

    A step without change counts as rising (a flat stretch between falls adds one short swing,
    which the swing's threshold drops unless the fall before it was large).
    """
    falling = y[1:] < y[:-1]  # no float difference array: one byte per step
    turn = np.flatnonzero(falling[1:] != falling[:-1]) + 1  # the extremum's row
    if not len(turn):
        return turn
    swing = np.abs(np.diff(y[turn], prepend=y[0]))
    return turn[swing >= min_swing]


def crowded_columns(
    x: np.ndarray,
    y: np.ndarray,
    *,
    columns: int,
    pixel: float,
    start: float | None = None,
    end: float | None = None,
) -> np.ndarray:
    """Which pixel columns of [start, end] a line through the series crowds.

    A column is crowded when it holds `CROWDED_TURNS` or more direction reversals, each after a
    swing of at least `MIN_SWING_PX` pixels.

    Args:
        x: (n,) abscissa, increasing.
        y: (n,) values.
        columns: pixel columns of the stretch (equal spans of x, as `column_envelope` cuts them).
        pixel: the size of one pixel in y's unit (the axis's y-range over its height in pixels).
        start, end: the stretch (default: the whole series).

    Returns:
        (columns,) booleans (all False for fewer than two samples).
    """
    sel = _window(x, start, end)
    xs, ys = x[sel], y[sel]
    if len(xs) < 2 or columns < 1:
        return np.zeros(max(columns, 0), dtype=bool)
    at = _turns(ys, MIN_SWING_PX * pixel)
    lo = float(xs[0]) if start is None else float(start)
    hi = float(xs[-1]) if end is None else float(end)
    return np.bincount(column_of(xs[at], columns=columns, start=lo, end=hi), minlength=columns) >= CROWDED_TURNS


def column_of(x: np.ndarray, *, columns: int, start: float, end: float) -> np.ndarray:
    """The pixel column (0 .. columns - 1) of each abscissa, [start, end] cut into equal spans."""
    span = end - start if end > start else 1.0
    return np.clip(((np.asarray(x) - start) / span * columns).astype(int), 0, columns - 1)


def solid_columns(envelope: Envelope, limits: tuple[float, float]) -> np.ndarray:
    """Which columns of an envelope a line paints as part of a solid block.

    A column is inked when the line covers `SOLID_INK` of the axes' height or more there (its
    envelope clipped to ``limits``). Strokes a pixel or two apart merge into one dark block, so
    every run of `SOLID_RUN` columns of which half or more are inked is a block.

    Args:
        envelope: the series' `Envelope` at the axes' columns.
        limits: (low, high) of the axes' y-range.

    Returns:
        (m,) booleans, one per column of the envelope.
    """
    lo, hi = limits
    height = hi - lo if hi > lo else 1.0
    inked = ((np.minimum(envelope.high, hi) - np.maximum(envelope.low, lo)) >= SOLID_INK * height).astype(int)
    if len(inked) < SOLID_RUN:
        return np.zeros(len(inked), dtype=bool)
    dense = np.convolve(inked, np.ones(SOLID_RUN, dtype=int), mode="valid") * 2 >= SOLID_RUN  # run k: k .. k+RUN-1
    solid = np.zeros(len(inked), dtype=bool)
    for k in np.flatnonzero(dense):
        solid[k : k + SOLID_RUN] = True
    return solid


def turn_rate(x: np.ndarray, y: np.ndarray, *, pixel: float, start: float, end: float) -> float:
    """Direction reversals per unit of x over [start, end], counting swings of `MIN_SWING_PX` or more.

    Args:
        x: (n,) abscissa, increasing.
        y: (n,) values.
        pixel: one pixel in y's unit.
        start, end: the stretch.

    Returns:
        Reversals per unit x (0 for a stretch of fewer than two samples or no length).
    """
    sel = _window(x, start, end)
    if sel.stop - sel.start < 2 or not end > start:
        return 0.0
    return len(_turns(y[sel], MIN_SWING_PX * pixel)) / (end - start)


def zoom_span(
    x: np.ndarray,
    y: np.ndarray,
    *,
    start: float,
    end: float,
    cycle: float,
    columns: int,
    pixel: float,
    centre: float,
) -> tuple[float, float]:
    """A stretch of [start, end] short enough for the series to read as a curve on ``columns`` pixels.

    One ``cycle`` when the series turns slowly enough over it; else the length at which it turns
    about once every three pixel columns, from its reversal rate over [start, end].

    Args:
        x: (n,) abscissa, increasing.
        y: (n,) values.
        start, end: where the stretch may lie (the steady state).
        cycle: the drive period on x (0: none, the stretch is then bounded by [start, end]).
        columns: pixel columns of the zoom's axes.
        pixel: one pixel of the whole run's axes in y's unit (the swings that count there).
        centre: the abscissa the stretch is centred on where it fits (e.g. the steady peak's).

    Returns:
        (a, b) within [start, end].
    """
    longest = end - start
    if cycle > 0:
        longest = min(longest, cycle)
    rate = turn_rate(x, y, pixel=pixel, start=start, end=end)
    length = longest if rate <= 0 else min(longest, columns / _READABLE_COLUMNS_PER_TURN / rate)
    step = float(np.median(np.diff(x[: min(len(x), 1000)]))) if len(x) > 1 else 0.0
    length = max(length, min(longest, 50 * step))  # at least 50 samples
    a = min(max(centre - 0.5 * length, start), end - length)
    return a, a + length
