"""Figures of the analyses: deviation, contact modes, phase portraits, Poincaré sections,
bifurcation diagrams and criticality rankings.

matplotlib only (Agg); the run figures (response, contact force, orbit) are in
`clearance.analysis.figures.plots`. Every function returns the figure and, given a path, saves a
PNG atomically (`plots.save_figure`).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from clearance.analysis.chaos.poincare import PhasePortrait, PoincareClassification
from clearance.analysis.figures.plots import save_figure
from clearance.analysis.metrics.response import ContactMode, JointContactModes
from clearance.analysis.metrics.statistics import DeviationStatistics, deviation_series
from clearance.analysis.sweeps.bifurcation import BifurcationDiagram
from clearance.analysis.sweeps.criticality import CriticalityRanking
from clearance.results import SimulationResult

__all__ = [
    "quantity_label",
    "plot_bifurcation",
    "plot_contact_modes",
    "plot_criticality",
    "plot_deviation",
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
_MODE_COLOURS = {ContactMode.IMPACT: "C3", ContactMode.CONTINUOUS: "C0"}


def quantity_label(name: str) -> tuple[str, str, float]:
    """(label, unit, scale from SI) of a quantity or output name, for axes.

    Joint parts ``.ex/.ey/.e`` are shown in µm, ``.vx/.vy`` in mm/s, ``.force`` in N;
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


def plot_deviation(
    result: SimulationResult,
    ideal: SimulationResult,
    output: str,
    stats: DeviationStatistics,
    *,
    path: str | Path | None = None,
) -> plt.Figure:
    """Deviation from ideal over the statistics window, its 90 % band, and distributions.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin.
        output: output name.
        stats: its `DeviationStatistics` (the window is taken from them).
        path: PNG path to save to.
    """
    t, y, y0 = deviation_series(result, ideal, output, skip=stats.window_start - result.times[0])
    label, unit, scale = quantity_label(output)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [2, 1]})
    a1.plot(t * 1e3, (y - y0) * scale, lw=0.7, color="C3", label="deviation y - y_ideal")
    for v, lab in ((stats.band90, "90 % band ±"), (-stats.band90, None)):
        a1.axhline(v * scale, color="k", ls="--", lw=0.9, label=lab and f"{lab}{stats.band90 * scale:.3g} {unit}")
    a1.axhline(stats.mean_signed_deviation * scale, color="C2", lw=1.0, label="mean (signed)")
    a1.set_xlabel("time [ms]")
    a1.set_ylabel(f"{label} deviation [{unit}]")
    a1.legend(loc="upper right", fontsize=8)
    a1.grid(alpha=0.3)
    bins = np.linspace(min(y.min(), y0.min()), max(y.max(), y0.max()), 40) * scale
    a2.hist(y0 * scale, bins=bins, alpha=0.5, color="0.5", label="ideal")
    a2.hist(y * scale, bins=bins, alpha=0.5, color="C3", label="with clearance")
    a2.set_xlabel(f"{label} [{unit}]")
    a2.set_ylabel("samples")
    a2.legend(fontsize=8)
    a2.set_title(f"KS = {stats.ks_statistic:.3g}, F = {stats.f_statistic:.4g}", fontsize=9)
    fig.suptitle(
        f"{output}: mean deviation {stats.mean_deviation * scale:.3g} {unit}, "
        f"RMS {stats.rms_deviation * scale:.3g} {unit} (from t = {stats.window_start * 1e3:.3g} ms)"
    )
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_contact_modes(
    result: SimulationResult, modes: list[JointContactModes], *, path: str | Path | None = None
) -> plt.Figure:
    """Contact-force magnitude per joint with each contact event shaded by its mode.

    Args:
        result: the run.
        modes: `JointContactModes` of the joints to show (one panel each).
        path: PNG path to save to.
    """
    fig, axes = plt.subplots(len(modes), 1, figsize=(9, 2.8 * len(modes)), sharex=True, squeeze=False)
    for ax, m in zip(axes[:, 0], modes):
        jr = result.joints[m.joint]
        ax.plot(result.times * 1e3, jr.force_magnitude, color="k", lw=0.6, label="contact force")
        seen = set()
        for e in m.events:
            lab = None if e.mode in seen else e.mode.value.replace("_", " ")
            seen.add(e.mode)
            ax.axvspan(
                e.start * 1e3, (e.start + e.duration) * 1e3, color=_MODE_COLOURS[e.mode], alpha=0.25, lw=0, label=lab
            )
        fr = ", ".join(f"{k.value.replace('_', ' ')} {v:.0%}" for k, v in m.fractions.items())
        ax.set_title(
            f"{m.joint}: {fr}; impulse {m.impulse:.3g} N s; continuous if ≥ {m.continuous_after * 1e3:.3g} ms",
            fontsize=9,
        )
        ax.set_ylabel("force [N]")
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [ms]")
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_phase_portrait(
    portrait: PhasePortrait, *, section: np.ndarray | None = None, path: str | Path | None = None
) -> plt.Figure:
    """Phase portrait (quantity against its rate), with Poincaré points on top if given.

    Args:
        portrait: `PhasePortrait` data.
        section: (K, 2) Poincaré points (quantity, rate) to mark.
        path: PNG path to save to.
    """
    label, unit, scale = quantity_label(portrait.name)
    vlab, vunit, vscale = quantity_label(
        f"{portrait.name}_vel" if "." not in portrait.name else portrait.name.replace(".e", ".v")
    )
    fig, ax = plt.subplots(figsize=(7, 5.5))
    ax.plot(portrait.position * scale, portrait.velocity * vscale, lw=0.4, color="0.4", label="trajectory")
    if section is not None and len(section):
        ax.plot(
            section[:, 0] * scale, section[:, 1] * vscale, "o", ms=3.5, color="C3", label="Poincaré points (t = kT)"
        )
    ax.set_xlabel(f"{label} [{unit}]")
    ax.set_ylabel(f"{vlab} [{vunit}]")
    ax.set_title(f"phase portrait of {portrait.name}")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_poincare(
    points: np.ndarray,
    names: tuple[str, str],
    classification: PoincareClassification | None = None,
    *,
    trajectory: np.ndarray | None = None,
    path: str | Path | None = None,
    ax: plt.Axes | None = None,
    label: str | None = None,
) -> plt.Figure:
    """Poincaré section of two quantities, coloured by section index, with the regime.

    Args:
        points: (K, 2) section points.
        names: the two quantity names (for labels and units).
        classification: regime to show in the title.
        trajectory: (n, 2) full trajectory of the same quantities, drawn in grey behind.
        path: PNG path to save to.
        ax: axes to draw into (a panel of a larger figure); default a new figure.
        label: text put before the title (e.g. the run's clearance).
    """
    (l1, u1, s1), (l2, u2, s2) = quantity_label(names[0]), quantity_label(names[1])
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.5, 5.5))
    else:
        parent = ax.figure
        fig = parent if isinstance(parent, Figure) else parent.figure  # a SubFigure's root figure
    if trajectory is not None:
        ax.plot(trajectory[:, 0] * s1, trajectory[:, 1] * s2, lw=0.3, color="0.7", label="trajectory")
    sc = ax.scatter(
        points[:, 0] * s1,
        points[:, 1] * s2,
        c=np.arange(len(points)),
        s=12,
        cmap="viridis",
        label="section points",
        zorder=3,
    )
    fig.colorbar(sc, ax=ax, label="drive period index k")
    if u1 == u2:
        ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{l1} [{u1}]")
    ax.set_ylabel(f"{l2} [{u2}]")
    title = f"{label}: " if label else ""
    title += "Poincaré section (t = kT)"
    if classification is not None:
        c = classification
        title += f": {c.regime.value.replace('_', '-')}"
        title += (
            f" (period {c.period})"
            if c.period
            else f" (divergence {c.divergence:.2f}, D2 {c.correlation_dimension:.2f})"
        )
    ax.set_title(title, fontsize=10)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_bifurcation(diagram: BifurcationDiagram, *, path: str | Path | None = None) -> plt.Figure:
    """Bifurcation diagram: section samples against the parameter, coloured by regime."""
    pl, pu, ps = quantity_label(diagram.parameter)
    ql, qu, qs = quantity_label(diagram.quantity)
    fig, ax = plt.subplots(figsize=(9, 5))
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


def plot_criticality(ranking: CriticalityRanking, *, path: str | Path | None = None) -> plt.Figure:
    """Bar chart of joint scores (mean deviation / clearance) with 95 % intervals.

    The axis unit follows the ranking's output kind (`CriticalityRanking.score_unit`): [-]
    for a position output, [rad/m] for an angle output.
    """
    s = ranking.scores
    fig, ax = plt.subplots(figsize=(max(5, 1.4 * len(s) + 2), 4))
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
