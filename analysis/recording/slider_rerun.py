"""Rerun entities of a slider with play: the slider drawn in its guide, with its contact case.

Per slider with play (`SimulationResult.sliders`), under ``<prefix>/sliders/<joint>/``:

* ``guide`` (static): the guide's two lines at +-(H/2 + c) across its axis, in the guide frame
  centred on the slider's position along it [mm];
* ``block``: the block (L by H) at its position across the guide and its tilt, one rectangle per
  displayed row, coloured by its contact case (`SLIDER_CASE_COLORS`; the case's name is the
  strip's label);
* ``contact``: the corners touching a guide line at those rows [mm];
* ``across`` [µm], ``tilt`` [µrad], ``force/magnitude`` (the net contact force) [N] and
  ``contact_case`` (the `clearance.translational.SliderContact` code, 0 to 3): full-rate series.

`log_sliders` is called by `rerun_log.log_run`; `slider_views` gives the blueprint's views.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from clearance.model import Mechanism
from clearance.results import SimulationResult
from clearance.translational import CORNERS, SliderContact

__all__ = ["SLIDER_CASE_COLORS", "log_sliders", "slider_views"]

SLIDER_CASE_COLORS: dict[SliderContact, int] = {
    SliderContact.FREE: 0x808080FF,
    SliderContact.ONE_CORNER: 0xFF7F0EFF,
    SliderContact.ONE_SIDE: 0x2CA02CFF,
    SliderContact.DIAGONAL: 0xD62728FF,
}
"""The block's colour in each contact case (RGBA): grey free, orange one corner, green one side,
red diagonal (wedged)."""

_MM, _UM = 1e3, 1e6
_OUTLINE = (0, 1, 3, 2, 0)  # CORNERS around the block: top left, top right, bottom right, bottom left


def log_sliders(
    recording: rr.RecordingStream,
    *,
    result: SimulationResult,
    mechanism: Mechanism,
    path: Callable[[str], str],
    indexes: Callable[[np.ndarray | slice], list[Any]],
    rows: np.ndarray,
    tag: str = "",
) -> list[str]:
    """Log every slider with play of ``result`` (the entities of this module's docstring).

    Args:
        recording: the rerun recording stream.
        result: the run.
        mechanism: its mechanism (each slider's `TranslationalClearance`: L, H, c).
        path: entity path of a name under the run's prefix.
        indexes: the timeline columns of rows of the result (a slice: every row).
        rows: (r,) the displayed rows of the drawing (the series take every row).
        tag: the run's label before each series name ("" for none).

    Returns:
        The entity paths logged.

    Raises:
        ValueError: a slider of the result that has no play in ``mechanism``.
    """
    logged: list[str] = []
    for joint, sr in result.sliders.items():
        play = mechanism.joint(joint).translational_clearance
        if play is None:
            raise ValueError(f"result slider '{joint}' has no play in its guide in mechanism '{mechanism.name}'")
        length, height, c = play.slider_length, play.slider_height, play.clearance
        base = f"sliders/{joint}"
        y = height / 2 + c
        recording.log(
            path(f"{base}/guide"),
            rr.LineStrips2D(
                [
                    [[-length * _MM, y * _MM], [length * _MM, y * _MM]],
                    [[-length * _MM, -y * _MM], [length * _MM, -y * _MM]],
                ],
                colors=np.array([0x303030FF], np.uint32),
                radii=c * _MM / 20,
                labels=[f"guide, c = {c * _UM:.4g} µm", ""],
            ),
            static=True,
        )
        # the corners in the guide frame, relative to the slider's position along it [m]
        local = np.array(CORNERS) * (length, height)  # (4, 2)
        tilt = sr.tilt[rows]
        cs, sn = np.cos(tilt)[:, None], np.sin(tilt)[:, None]
        corners = np.stack(
            [cs * local[:, 0] - sn * local[:, 1], sr.position[rows, 1:2] + sn * local[:, 0] + cs * local[:, 1]],
            axis=-1,
        )  # (r, 4, 2)
        cases = [list(SliderContact)[int(k)] for k in sr.contact_case[rows]]
        recording.send_columns(
            path(f"{base}/block"),
            indexes=indexes(rows),
            columns=rr.LineStrips2D.columns(
                strips=(corners[:, _OUTLINE] * _MM).astype(np.float32),  # what rerun stores
                colors=np.array([SLIDER_CASE_COLORS[k] for k in cases], np.uint32),
                labels=[k.name.lower().replace("_", " ") for k in cases],
            ),
        )
        recording.log(path(f"{base}/block"), rr.LineStrips2D.from_fields(radii=c * _MM / 40), static=True)
        logged += [path(f"{base}/guide"), path(f"{base}/block")]
        touching = sr.corner_penetration[rows] > 0  # (r, 4)
        on = np.nonzero(touching.any(axis=1))[0]
        if len(on):
            recording.send_columns(
                path(f"{base}/contact"),
                indexes=indexes(rows[on]),
                columns=rr.Points2D.columns(positions=corners[on][touching[on]] * _MM).partition(
                    touching[on].sum(axis=1)
                ),
            )
            recording.log(
                path(f"{base}/contact"),
                rr.Points2D.from_fields(colors=np.array([0xD62728FF], np.uint32), radii=c * _MM / 10),
                static=True,
            )
            logged.append(path(f"{base}/contact"))
        every = indexes(slice(None))
        for rest, values, name in (
            ("across", sr.position[:, 1] * _UM, "across the guide [µm]"),
            ("tilt", sr.tilt * _UM, "tilt [µrad]"),
            ("force/magnitude", np.hypot(sr.contact_force[:, 0], sr.contact_force[:, 1]), "|F| [N]"),
            ("contact_case", sr.contact_case.astype(float), "contact case (0 free .. 3 diagonal)"),
        ):
            recording.log(path(f"{base}/{rest}"), rr.SeriesLines(names=f"{tag}{joint} {name}"), static=True)
            recording.send_columns(
                path(f"{base}/{rest}"), indexes=every, columns=rr.Scalars.columns(scalars=np.asarray(values, float))
            )
            logged.append(path(f"{base}/{rest}"))
    return logged


def slider_views(
    runs: Sequence[tuple[SimulationResult, Callable[[str], str]]],
) -> tuple[list[rrb.Spatial2DView], list[rrb.TimeSeriesView]]:
    """The blueprint's views of the sliders with play: each in its guide, and its series.

    Args:
        runs: (result, entity path of a name under its prefix) of each logged run.

    Returns:
        One drawing per slider (every run overlaid), and one time series view per slider of
        its position across, tilt and contact case; both empty without sliders.
    """
    drawings, series = [], []
    for j in dict.fromkeys(j for res, _ in runs for j in res.sliders):
        paths = [p(f"sliders/{j}") for res, p in runs if j in res.sliders]
        drawings.append(
            rrb.Spatial2DView(
                name=f"{j} in its guide [mm, guide frame]",
                origin="/",
                contents=[f"+ {p}/{e}" for p in paths for e in ("guide", "block", "contact")],
            )
        )
        series.append(
            rrb.TimeSeriesView(
                name=f"{j}: across [µm], tilt [µrad], contact case",
                origin="/",
                contents=[f"+ {p}/{e}" for p in paths for e in ("across", "tilt", "contact_case")],
            )
        )
    return drawings, series
