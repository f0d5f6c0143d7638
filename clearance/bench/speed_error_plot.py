"""Figure of speed against error: each scenario's settings, their Pareto fronts and the goals."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from clearance.analysis.figures.plots import save_figure
from clearance.bench.speed_error_report import SettingRow, pareto_front

__all__ = ["plot_speed_error"]

_COLORS = {"nominal": "tab:blue", "calibrated": "tab:orange", "exact": "tab:green"}
_MARKERS = {"sphere-sphere": "o", "capsule-capsule": "s", "sphere-box": "^", "cylinder-box": "D"}
_PANELS = (("statistics_error", "worst statistic error", 0.05), ("first_impact_error", "first-impact error", 0.01))


def plot_speed_error(
    rows: Mapping[str, Sequence[SettingRow]],
    *,
    path: str | Path | None = None,
    goals: tuple[float, float] = (30.0, 300.0),
) -> plt.Figure:
    """Error against speed-up for every scenario (one row of two panels per scenario).

    Args:
        rows: scenario name -> its `SettingRow`s.
        path: PNG to write (optional).
        goals: speed-ups drawn as vertical guides [-].

    Returns:
        The figure.
    """
    names = list(rows)
    fig, axes = plt.subplots(len(names), 2, figsize=(11, 3.6 * len(names)), squeeze=False)
    for i, name in enumerate(names):
        ok = [r for r in rows[name] if r.status == "ok"]
        for ax, (attr, title, tol) in zip(axes[i], _PANELS):
            for r in ok:
                y = getattr(r, attr)
                if not math.isfinite(y):
                    continue
                pair = f"{r.setting['journal_geom']}-{r.setting['segment_geom']}"
                ax.scatter(
                    r.speedup,
                    max(100 * y, 1e-2),
                    color=_COLORS.get(r.setting["contact_mode"], "k"),
                    marker=_MARKERS.get(pair, "x"),
                    s=28,
                    alpha=0.8,
                    edgecolors="none",
                )
            front = pareto_front(ok, attr)
            if front:
                ax.step(
                    [r.speedup for r in front],
                    [max(100 * getattr(r, attr), 1e-2) for r in front],
                    where="post",
                    color="k",
                    lw=1,
                    alpha=0.6,
                    label="Pareto front",
                )
            ax.axhline(100 * tol, color="tab:red", ls="--", lw=1, label=f"{100 * tol:g} % goal")
            for g in goals:
                ax.axvline(g, color="grey", ls=":", lw=1)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("speed-up against the reference solver [-] (one thread)")
            ax.set_ylabel(f"{title} [%]")
            ax.set_title(f"{name}: {title}", fontsize=10)
            ax.grid(True, which="both", alpha=0.25)
    handles = [plt.Line2D([], [], color=c, marker="o", ls="", label=m) for m, c in _COLORS.items()]
    shown = {
        f"{r.setting['journal_geom']}-{r.setting['segment_geom']}"
        for rs in rows.values()
        for r in rs
        if r.status == "ok"
    }  # the legend names only the geom pairs that were run
    handles += [
        plt.Line2D([], [], color="grey", marker=mk, ls="", label=p.replace("-", "/"))
        for p, mk in _MARKERS.items()
        if p in shown
    ]
    handles += [
        plt.Line2D([], [], color="k", lw=1, label="Pareto front"),
        plt.Line2D([], [], color="tab:red", ls="--", label="goal"),
        plt.Line2D([], [], color="grey", ls=":", label=" / ".join(f"{g:g}×" for g in goals)),
    ]
    fig.legend(handles=handles, loc="upper center", ncol=len(handles), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.35 / (3.6 * len(names))))
    if path is not None:
        save_figure(fig, path)
    return fig
