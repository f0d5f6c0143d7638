"""Calibration reports: a Markdown table and a force–time plot.

`calibration_report` writes ``<stem>.md`` (parameters, stability, accuracy per speed with
the goals marked) and ``<stem>.png`` (MuJoCo against LN force–time curves at several
speeds, both impact directions, plus exact-LN when asked). The command behind them is
``clearance calibrate`` (`clearance.cli.calibrate`).
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from clearance.contact_calibration.fit import (
    GOALS,
    CalibrationResult,
    SpeedRow,
    evaluate,
)
from clearance.mjcf.bearing import RingGeometry
from clearance.model import Clearance
from clearance.options import ModelOptions
from clearance.results import atomic_write_bytes

__all__ = ["ReportFiles", "accuracy_table", "calibration_report"]


@dataclass(frozen=True)
class ReportFiles:
    """Files written by `calibration_report`."""

    markdown: Path
    plot: Path


def _mark(value: float, goal: float, pct: bool) -> str:
    text = f"{value * 100:+.2f} %" if pct else f"{value:+.4f}"
    return text if abs(value) <= goal else f"**{text}**"


def accuracy_table(rows: Sequence[SpeedRow]) -> str:
    """Markdown table of MuJoCo-vs-LN errors per speed (bold: outside `GOALS`).

    Each cell gives the direction mean and, in brackets, the worst direction.
    """
    head = (
        "| v [m/s] | LN peak F [N] | LN δmax [µm] | LN T [µs] | LN e | peak F err | δmax err "
        "| T err | e − e_LN | goals |\n|---|---|---|---|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rows:
        cells = [
            f"{_mark(mean, GOALS[goal], pct)} ({_mark(worst, GOALS[goal], pct)})"
            for mean, worst, goal, pct in (
                (r.peak_force_err, r.peak_force_worst, "peak_force", True),
                (r.max_penetration_err, r.max_penetration_worst, "max_penetration", True),
                (r.duration_err, r.duration_worst, "duration", True),
                (r.restitution_err, r.restitution_worst, "restitution", False),
            )
        ]
        lines.append(
            f"| {r.speed:.3g} | {r.ln_peak_force:.4g} | {r.ln_max_penetration * 1e6:.3g} | "
            f"{r.ln_duration * 1e6:.3g} | {r.ln_restitution:.4f} | "
            + " | ".join(cells)
            + f" | {'met' if r.meets_goals() else 'missed'} |"
        )
    return head + "\n".join(lines) + "\n"


def _solimp_text(eps: float, options: ModelOptions, clearance: Clearance) -> str:
    d = options.impedance
    if eps == 0:
        return f"solimp ({d:g}, {d:g}, 0.001, 0.5, 2) as built (constant impedance)"
    return (
        f"solimp ({d * (1 - eps):.4g}, {d:g}, {clearance.radial_clearance:g}, 0.5, 1): the row impedance "
        f"rises linearly from d(1 − ε) at zero penetration to d at the clearance"
    )


def _markdown(
    result: CalibrationResult,
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    title: str,
    source: str | None,
) -> str:
    p, s = result.parameters, result.stability
    met = sum(r.meets_goals() for r in result.rows)
    lo, hi = result.mass_range
    return (
        f"# {title}\n\n"
        f"- Bearing: R_B = {clearance.bearing_radius * 1e3:g} mm, c = {clearance.radial_clearance * 1e3:g} mm, "
        f"law {clearance.law.value}, cₑ = {clearance.restitution:g}, μ = {clearance.friction:g}\n"
        f"- Ring: N = {ring.segments}, {options.journal_geom.value} journal / {options.segment_geom.value} "
        f"segments, time step {options.timestep * 1e6:g} µs, {options.integrator}, impedance {options.impedance:g}\n"
        f"- Effective mass {result.mass:.5g} kg (valid range {lo:.5g}–{hi:.5g} kg)\n"
        f"- Fitted per-row stiffness {p.stiffness:.6g} N/m, damping {p.damping:.6g} N·s/m "
        f"(at full impedance), impedance rise ε = {p.impedance_rise:.4f} "
        f"(nominal start {result.initial.stiffness:.6g} N/m, {result.initial.damping:.6g} N·s/m); "
        f"emitted as direct-mode solref (−k·Â, −b·Â) and {_solimp_text(p.impedance_rise, options, clearance)}\n"
        f"- Stability at δ = {s.penetration * 1e6:.3g} µm: ω·h = {s.omega_h:.3f} (< 2), "
        f"h²ω² + 2hβ = {s.damped_bound:.3f} (< 4)\n"
        f"- Fit: {result.nfev} MuJoCo evaluations, {result.wall_time:.2f} s; MuJoCo {result.meta.get('mujoco')}\n"
        + (f"- Calibration file: `{source}`\n" if source else "")
        + f"\nGoals: peak force and max penetration within {GOALS['peak_force']:.0%}, duration within "
        f"{GOALS['duration']:.0%}, restitution within {GOALS['restitution']} of the LN impact's own. "
        f"Cells: mean over impact directions (worst direction); bold = outside the goal. "
        f"{met} of {len(result.rows)} speeds meet all goals.\n\n" + accuracy_table(result.rows)
    )


def _plot(
    result: CalibrationResult,
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    speeds: np.ndarray,
    path: Path,
    exact: bool,
) -> None:
    # A Figure with its own Agg canvas: no pyplot, so the caller's backend (a notebook's,
    # say) and its open figures are left alone.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    err, imps, refs = evaluate(
        clearance,
        ring,
        options,
        result.parameters,
        mass=result.mass,
        speeds=speeds,
        directions=np.array(result.directions),
    )
    fig = Figure(figsize=(4.2 * len(speeds), 3.6))
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(speeds), squeeze=False)
    for ax, v, row, ref in zip(axes[0], speeds, imps, refs):
        ax.plot(ref.times * 1e6, ref.force, "k-", lw=2, label="LN reference")
        for imp, style in zip(row, ("C0--", "C1:")):
            frac = imp.direction * ring.segments / (2 * math.pi)
            ax.plot(imp.times * 1e6, imp.force, style, lw=1.5, label=f"MuJoCo calibrated, ψ = {frac:.2g}·2π/N")
        if exact:
            from clearance.contact_calibration.exact_ln import exact_ln_impact

            ex = exact_ln_impact(
                clearance, ring, options, mass=result.mass, speed=float(v), direction=float(result.directions[-1])
            )
            ax.plot(ex.times * 1e6, ex.force, "C3-.", lw=1, label="MuJoCo exact-LN")
        ax.set_title(f"v = {v:.3g} m/s")
        ax.set_xlabel("time from contact [µs]")
        ax.set_xlim(-0.05 * ref.duration * 1e6, 1.15 * ref.duration * 1e6)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("normal contact force [N]")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    atomic_write_bytes(path, buf.getvalue())


def calibration_report(
    result: CalibrationResult,
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    *,
    out_dir: str | os.PathLike,
    stem: str = "calibration",
    title: str = "Contact calibration",
    plot_speeds: Sequence[float] | None = None,
    exact_ln: bool = True,
    source: str | None = None,
) -> ReportFiles:
    """Write the Markdown report and the force–time plot of a calibration.

    Args:
        result: the calibration (`calibrate` / `fit_contact`).
        clearance: the joint's clearance.
        ring: its ring geometry.
        options: model options it was fitted with.
        out_dir: output folder (created).
        stem: file name stem.
        title: Markdown title.
        plot_speeds: speeds to plot [m/s]; default the lowest, middle and highest fitted.
        exact_ln: also plot the exact-LN MuJoCo curve.
        source: calibration file to cite.

    Returns:
        Paths of the two files (written atomically).
    """
    out = Path(out_dir)
    sp = np.asarray(result.speeds)
    speeds = np.asarray(plot_speeds if plot_speeds is not None else [sp[0], sp[len(sp) // 2], sp[-1]])
    md = out / f"{stem}.md"
    png = out / f"{stem}.png"
    atomic_write_bytes(md, _markdown(result, clearance, ring, options, title, source).encode())
    _plot(result, clearance, ring, options, speeds, png, exact_ln)
    return ReportFiles(md, png)
