"""A slider with play in a report: its position and tilt in the guide, its contact case over time.

`plot_slider` draws, for one prismatic joint with play, three rows against time: the slider
centre's position across the guide over the clearance c (the guide's lines bound it at +-1
when the slider is level), its tilt against the largest tilt the guide allows, and the
contact case (`clearance.translational.SliderContact`). `slider_section` writes the report's
Markdown section with the numbers of `clearance.analysis.metrics.slider` and that figure.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from clearance.analysis.figures.canvas import new_figure, save_png
from clearance.analysis.figures.drawing import draw
from clearance.analysis.metrics.slider import contact_phases, slider_summary, touched_lines
from clearance.results import SimulationResult
from clearance.translational import SliderContact
from clearance.units import format_quantity

__all__ = ["plot_slider", "slider_section"]

_SHOWN_PHASES = 12
"""Contact phases listed one by one in the report (the first ones)."""


def _guide(result: SimulationResult, joint: str) -> dict[str, Any]:
    """The slider's clearance and largest tilt from the run's metadata (empty if not recorded)."""
    return dict(result.metadata.get("guides", {}).get(joint, {}))


def plot_slider(result: SimulationResult, joint: str, *, path: str | Path | None = None) -> Figure:
    """Position across the guide, tilt and contact case of one slider against time.

    Args:
        result: a run with the slider (`SimulationResult.sliders`).
        joint: the prismatic joint with play.
        path: PNG path to save to.

    Returns:
        The figure: three rows sharing the time axis [ms]. Across and tilt are scaled by the
        clearance c and the largest tilt when the run's metadata records them (the reference
        solver's ``guides``), else drawn in mm and mrad.

    Raises:
        KeyError: the result has no such slider.
    """
    if joint not in result.sliders:
        raise KeyError(f"the result has no slider with play {joint!r} (it has {sorted(result.sliders)})")
    sr, guide = result.sliders[joint], _guide(result, joint)
    t = result.times * 1e3
    fig = new_figure(9.0, 6.0)
    ax = fig.subplots(3, 1, sharex=True)
    c, tilt_max = guide.get("clearance"), guide.get("max_tilt")
    if c:
        ax[0].plot(t, sr.position[:, 1] / c, color="C0", lw=0.8)
        ax[0].axhline(1.0, color="0.4", ls="--", lw=0.8)
        ax[0].axhline(-1.0, color="0.4", ls="--", lw=0.8)
        ax[0].set_ylabel(f"across / c\n(c = {format_quantity(c, 'm')})")
    else:
        ax[0].plot(t, sr.position[:, 1] * 1e3, color="C0", lw=0.8)
        ax[0].set_ylabel("across [mm]")
    if tilt_max:
        ax[1].plot(t, sr.tilt / tilt_max, color="C1", lw=0.8)
        ax[1].axhline(1.0, color="0.4", ls="--", lw=0.8)
        ax[1].axhline(-1.0, color="0.4", ls="--", lw=0.8)
        ax[1].set_ylabel(f"tilt / guide's limit\n({format_quantity(tilt_max, 'rad')})")
    else:
        ax[1].plot(t, sr.tilt * 1e3, color="C1", lw=0.8)
        ax[1].set_ylabel("tilt [mrad]")
    lines = touched_lines(sr.corner_penetration)
    for code, colour, label in ((1, "C2", "+n line"), (2, "C3", "-n line"), (3, "C4", "both lines")):
        case = np.where(lines == code, sr.contact_case, np.nan)
        ax[2].plot(t, case, ".", ms=1.5, color=colour, label=label)
    ax[2].plot(t, np.where(lines == 0, 0.0, np.nan), ".", ms=1.5, color="0.5", label="free")
    ax[2].set_yticks([c.value for c in SliderContact], [c.name.lower().replace("_", " ") for c in SliderContact])
    ax[2].set_ylim(-0.5, 3.5)
    ax[2].legend(loc="upper right", fontsize=7, markerscale=5, ncols=4)
    ax[2].set_xlabel("time [ms]")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(f"{joint}: the slider in its guide")
    fig.tight_layout()
    if path is not None:
        save_png(fig, path)
    return fig


def slider_section(result: SimulationResult, out: Path) -> list[str]:
    """The report's section on every slider with play, and its figures (``slider_<joint>.png``).

    Args:
        result: a run.
        out: the report's folder.

    Returns:
        Markdown lines (none for a run without sliders with play): per slider the time share
        and number of phases of each contact case, the switches, the largest excursions and
        forces, the first contact phases, and the figure.
    """
    q = format_quantity
    lines: list[str] = []
    for joint, sr in result.sliders.items():
        s = slider_summary(result.times, sr)
        figure = f"slider_{joint}.png"
        draw(plot_slider, result, joint, path=out / figure)
        guide = _guide(result, joint)
        lines += [f"## Slider in its guide: {joint}", ""]
        if guide:
            lines += [
                f"Block {q(guide['slider_length'], 'm')} by {q(guide['slider_height'], 'm')}, clearance "
                f"{q(guide['clearance'], 'm')} on each side, largest tilt {q(guide['max_tilt'], 'rad')}. Cases "
                "after Flores, Ambrósio, Claro and Lankarani (2008): free flight, one corner, two corners on one "
                "side, two diagonal corners.",
                "",
            ]
        lines += ["| contact case | share of the run | phases |", "|---|---:|---:|"]
        for c in SliderContact:
            lines.append(f"| {c.name.lower().replace('_', ' ')} | {s.shares[c]:.1%} | {s.phase_counts[c]} |")
        lines += [
            "",
            f"{s.switches} switches of case or line; largest position across the guide {q(s.max_across, 'm')}, "
            f"largest tilt {q(s.max_tilt, 'rad')}, deepest corner penetration {q(s.max_penetration, 'm')}, "
            f"peak corner force {q(s.peak_corner_force, 'N')}.",
            "",
        ]
        phases = contact_phases(result.times, sr.contact_case, touched_lines(sr.corner_penetration))
        shown = "; ".join(f"{q(p.start, 's')} {p.label()}" for p in phases[:_SHOWN_PHASES])
        more = f" (and {len(phases) - _SHOWN_PHASES} more)" if len(phases) > _SHOWN_PHASES else ""
        lines += [f"First contact phases (start, case): {shown}{more}.", "", f"![{joint}]({figure})", ""]
    return lines
