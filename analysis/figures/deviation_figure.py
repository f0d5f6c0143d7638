"""The deviation figure: the output's deviation from the ideal over the statistics' window and
the two distributions compared (`clearance.analysis.metrics.statistics`).

Drawn on an Agg figure without pyplot (`canvas`); a crowded deviation as its envelope band
with the mean line, the 90 % band and the mean drawn on top.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from clearance.analysis.figures.analysis_figures import quantity_label
from clearance.analysis.figures.canvas import draw_series, new_figure, save_png
from clearance.analysis.figures.time_rows import band_legend_entry, time_axis
from clearance.analysis.metrics.statistics import DeviationStatistics, deviation_series
from clearance.results import SimulationResult
from clearance.units import format_quantity

__all__ = ["plot_deviation"]


def plot_deviation(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    stats: DeviationStatistics,
    *,
    path: str | Path | None = None,
) -> Figure:
    """Deviation from ideal over the statistics window, its 5th and 95th percentiles, and distributions.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin.
        output: output name.
        stats: its `DeviationStatistics` (the window is taken from them).
        path: PNG path to save to.
    """
    t, y, y0 = deviation_series(result, ideal, output, skip=stats.window_start - result.times[0])
    label, unit, scale = quantity_label(output)
    fig = new_figure(11, 4.4)
    gs = fig.add_gridspec(1, 2, width_ratios=[2, 1], left=0.08, right=0.98, top=0.8, bottom=0.13, wspace=0.22)
    a1, a2 = fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[0, 1])
    d = (y - y0) * scale
    short = output.rsplit("/", 1)[-1]  # a site's coordinate (x, y, z) or the output's own name
    style = {"lw": 0.7, "color": "C3", "label": f"deviation {short} − {short}_ideal"}
    time = time_axis(result.times)
    lo, hi = stats.band90_low * scale, stats.band90_high * scale
    band = draw_series(a1, t * time.scale, d, style=style, reach=(lo, hi))
    # the 5th and 95th percentiles of the signed deviation: they bound it where it is one-sided too
    between = f"90 % of samples between {lo:.3g} and {hi:.3g} {unit}"
    for v, lab in ((hi, between), (lo, None)):
        a1.axhline(v, color="k", ls="--", lw=0.9, zorder=3, label=lab)
    a1.axhline(stats.mean_signed_deviation * scale, color="C2", lw=1.0, zorder=3, label="mean (signed)")
    a1.set_xlabel(time.label)
    a1.set_ylabel(f"{label} deviation [{unit}]")
    handles, names = a1.get_legend_handles_labels()
    if band:
        handles.append(band_legend_entry("C3"))
        names.append(handles[-1].get_label())
    a1.legend(handles, names, loc="upper right", fontsize=7)
    a1.locator_params(axis="y", nbins=6)
    a1.grid(alpha=0.3)
    bins = np.linspace(min(y.min(), y0.min()), max(y.max(), y0.max()), 40) * scale
    for values, colour, name in ((y0, "0.5", "ideal"), (y, "C3", "with clearance")):
        counts, _ = np.histogram(values * scale, bins=bins)
        a2.stairs(counts, bins, fill=True, alpha=0.5, color=colour, label=name)  # one artist, not 40 bars
    a2.set_xlabel(f"{label} [{unit}]")
    a2.set_ylabel("samples")
    a2.legend(fontsize=8)
    a2.set_title(
        f"distributions of {short}: Kolmogorov–Smirnov distance\n"
        f"{stats.ks_statistic:.3g} (p = {stats.ks_pvalue:.2g}); variance ratio F = {stats.f_statistic:.4g} "
        f"(p = {stats.f_pvalue:.2g})",
        fontsize=8,
    )
    fig.suptitle(
        f"{output}: mean deviation {stats.mean_signed_deviation * scale:.3g} {unit} (the green line), mean "
        f"|deviation| {stats.mean_deviation * scale:.3g} {unit}, RMS {stats.rms_deviation * scale:.3g} {unit} over "
        + (
            f"the steady state (from t = {format_quantity(stats.window_start, 's')})"
            if stats.window_start > result.times[0]
            else "the whole run"
        ),
        fontsize=11,
    )
    if path is not None:
        save_png(fig, path)
    return fig
