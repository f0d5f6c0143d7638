"""Figures of a run: output response against ideal, contact force, journal orbit.

matplotlib only (Agg backend, no display needed); the numerical core never imports this.
Every function returns the figure and, given a path, saves a PNG atomically.
"""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from clearance.results import SimulationResult, atomic_write_bytes

__all__ = ["plot_response", "plot_contact_force", "plot_orbit", "save_figure"]


def save_figure(fig: plt.Figure, path: str | Path, *, dpi: int = 130) -> Path:
    """Save a figure as PNG atomically and close it.

    Args:
        fig: the figure (closed afterwards).
        path: PNG file to write (replaced atomically).
        dpi: resolution [dots per inch].

    Returns:
        ``path``.
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())
    return Path(path)


def plot_response(
    result: SimulationResult,
    ideal: SimulationResult | None,
    output: str,
    *,
    angular: bool = False,
    path: str | Path | None = None,
) -> plt.Figure:
    """Output displacement, velocity and acceleration against the ideal mechanism.

    Args:
        result: run with clearance.
        ideal: run of the ideal twin (or None).
        output: output name (e.g. ``slider_x``).
        angular: the output is an angle (units rad, rad/s, rad/s²).
        path: PNG path to save to.
    """
    fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    t_ms = result.times * 1e3
    labels = [
        ("displacement", output, "rad" if angular else "mm", 1.0 if angular else 1e3),
        ("velocity", output + "_vel", "rad/s" if angular else "m/s", 1.0),
        ("acceleration", output + "_acc", "rad/s²" if angular else "m/s²", 1.0),
    ]
    for ax, (title, key, unit, scale) in zip(axes, labels):
        if ideal is not None:
            ax.plot(ideal.times * 1e3, ideal.outputs[key] * scale, color="0.55", lw=1.6, label="ideal")
        ax.plot(t_ms, result.outputs[key] * scale, color="C3", lw=0.8, label="with clearance")
        ax.set_ylabel(f"{title} [{unit}]")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right")
    axes[-1].set_xlabel("time [ms]")
    cl = ", ".join(result.joints) or "none"
    fig.suptitle(f"{result.metadata.get('mechanism', '')}: {output} (clearance at {cl})")
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_contact_force(result: SimulationResult, *, path: str | Path | None = None) -> plt.Figure:
    """Contact-force magnitude against time, one line per clearance joint."""
    fig, ax = plt.subplots(figsize=(9, 4))
    for name, jr in result.joints.items():
        ax.plot(result.times * 1e3, jr.force_magnitude / 1e3, lw=0.8, label=name)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("contact force [kN]")
    ax.grid(alpha=0.3)
    if result.joints:
        ax.legend(loc="upper right")
    ax.set_title(f"{result.metadata.get('mechanism', '')}: contact force at the clearance joints")
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_orbit(result: SimulationResult, joint: str, clearance: float, *, path: str | Path | None = None) -> plt.Figure:
    """Journal-centre orbit in the bearing frame inside the clearance circle (µm).

    Args:
        result: the run.
        joint: clearance joint name.
        clearance: radial clearance c [m] (the circle drawn).
        path: PNG path to save to.
    """
    jr = result.joints[joint]
    e = jr.eccentricity * 1e6
    c = clearance * 1e6
    fig, ax = plt.subplots(figsize=(6.4, 6))
    th = np.linspace(0, 2 * np.pi, 400)
    ax.plot(c * np.cos(th), c * np.sin(th), color="k", lw=1.2, label=f"clearance circle (c = {c:g} µm)")
    sc = ax.scatter(e[:, 0], e[:, 1], c=result.times * 1e3, s=1.5, cmap="viridis", lw=0)
    ax.plot(e[0, 0], e[0, 1], "o", color="C3", ms=5, label="start")
    fig.colorbar(sc, ax=ax, label="time [ms]", shrink=0.8)
    ax.set_aspect("equal")
    lim = 1.15 * max(c, float(np.abs(e).max()) if len(e) else c)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_xlabel("eccentricity x in bearing frame [µm]")
    ax.set_ylabel("eccentricity y in bearing frame [µm]")
    ax.set_title(f"journal-centre orbit at {joint}")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    if path is not None:
        save_figure(fig, path)
    return fig
