"""Rerun recording of a retrofitted model's run: its bodies moving in 3-D, the orbits beside them.

Entities (3-D in metres, orbits in micrometres as the mechanisms' recordings have them):

* ``model/bodies/<body>``: the body's world pose per display row (`SimulationResult.body_poses`);
  ``model/bodies/<body>/geoms/<geom>`` (static; the geom's name, or its index in the body):
  each visible geom of the body (group 0-2) as a rerun primitive in the body frame
  (spheres and ellipsoids as ellipsoids, capsules, cylinders, boxes; a mesh or a plane as a
  small point at its position);
* ``twin/bodies/<body>``: the unmodified twin's bodies likewise, in grey;
* ``joints/<hinge>/orbit``: journal centre in the bearing frame [µm] coloured by contact
  force, ``joints/<hinge>/clearance_circle`` (static), ``joints/<hinge>/force/magnitude`` [N];
* ``site/<name>/deviation`` [mm]: distance of the chosen site from the twin's (when given).

Timeline ``sim_time``. Bodies are decimated to ``max_rate_hz`` rows per simulated second;
orbits and series are logged at full rate. The numerical core never imports this module.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import mujoco
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from clearance.analysis.metrics.site_deviation import SiteDeviation
from clearance.analysis.recording.rerun_log import (
    DEFAULT_MAX_RATE_HZ,
    TIME_TIMELINE,
    _display_rows,
    _force_colors,
    _ns,
    _scalars,
    recording_file,
)
from clearance.results import SimulationResult

__all__ = ["record_model_run"]

_UM = 1e6
_GEOM = mujoco.mjtGeom


def _idx(times: np.ndarray) -> list[rr.TimeColumn]:
    return [rr.TimeColumn(TIME_TIMELINE, duration=_ns(times))]


def _rgba(rgba: np.ndarray, grey: bool) -> np.ndarray:
    c = np.array([0.6, 0.6, 0.6, 0.35]) if grey else np.asarray(rgba, float)
    v = np.clip(np.round(c * 255), 0, 255).astype(np.uint32)
    return np.array([(v[0] << 24) | (v[1] << 16) | (v[2] << 8) | v[3]], np.uint32)


def _shape(model: mujoco.MjModel, g: int, grey: bool) -> rr.AsComponents:
    """A rerun primitive of geom ``g`` centred at its frame's origin, its axis along z."""
    kind, size, colors = int(model.geom_type[g]), model.geom_size[g], _rgba(model.geom_rgba[g], grey)
    if kind == _GEOM.mjGEOM_SPHERE:
        return rr.Ellipsoids3D(half_sizes=[[size[0]] * 3], colors=colors)
    if kind == _GEOM.mjGEOM_ELLIPSOID:
        return rr.Ellipsoids3D(half_sizes=[size[:3]], colors=colors)
    if kind == _GEOM.mjGEOM_CAPSULE:
        return rr.Capsules3D(lengths=[2 * size[1]], radii=[size[0]], translations=[[0.0, 0.0, -size[1]]], colors=colors)
    if kind == _GEOM.mjGEOM_CYLINDER:
        return rr.Cylinders3D(lengths=[2 * size[1]], radii=[size[0]], colors=colors)
    if kind == _GEOM.mjGEOM_BOX:
        return rr.Boxes3D(half_sizes=[size[:3]], colors=colors)
    return rr.Points3D([[0.0, 0.0, 0.0]], radii=[0.005], colors=colors)


def _log_bodies(
    rec: rr.RecordingStream, root: str, model: mujoco.MjModel, res: SimulationResult, rows: np.ndarray, grey: bool
) -> None:
    names = res.metadata.get("bodies") or [f"#{b}" for b in range(model.nbody)]
    for b in range(1, model.nbody):
        path = f"{root}/bodies/{names[b]}"
        pose = res.body_poses[rows, b]
        quat_xyzw = np.concatenate([pose[:, 4:7], pose[:, 3:4]], axis=1)
        rec.send_columns(
            path,
            indexes=_idx(res.times[rows]),
            columns=rr.Transform3D.columns(translation=pose[:, :3], quaternion=quat_xyzw),
        )
        for g in range(int(model.body_geomadr[b]), int(model.body_geomadr[b] + model.body_geomnum[b])):
            if g < 0 or model.geom_group[g] > 2:
                continue
            q = model.geom_quat[g]
            label = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or str(g - int(model.body_geomadr[b]))
            geom = f"{path}/geoms/{label}"
            rec.log(
                geom,
                rr.Transform3D(translation=model.geom_pos[g], quaternion=rr.Quaternion(xyzw=[q[1], q[2], q[3], q[0]])),
                static=True,
            )
            rec.log(geom, _shape(model, g, grey), static=True)


def _log_orbits(rec: rr.RecordingStream, res: SimulationResult) -> list[str]:
    clearances = res.metadata.get("radial_clearance", {})
    idx = _idx(res.times)
    for hinge, jr in res.joints.items():
        c = float(clearances[hinge])
        fmag = jr.force_magnitude
        base = f"joints/{hinge}"
        rec.send_columns(
            f"{base}/orbit",
            indexes=idx,
            columns=rr.Points2D.columns(
                positions=jr.eccentricity * _UM, colors=_force_colors(fmag, float(fmag.max(initial=0.0)))
            ),
        )
        rec.log(f"{base}/orbit", rr.Points2D.from_fields(radii=c * _UM / 200), static=True)
        th = np.linspace(0.0, 2 * math.pi, 361)
        rec.log(
            f"{base}/clearance_circle",
            rr.LineStrips2D(
                [np.c_[np.cos(th), np.sin(th)] * c * _UM], radii=c * _UM / 400, labels=[f"c = {c * _UM:.4g} µm"]
            ),
            static=True,
        )
        _scalars(rec, f"{base}/force/magnitude", idx, fmag, f"{hinge} |F| [N]")
    return list(res.joints)


def _blueprint(hinges: list[str], site: str | None) -> rrb.Blueprint:
    trail = rrb.VisibleTimeRange(
        TIME_TIMELINE, start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.cursor_relative()
    )
    orbits = [
        rrb.Spatial2DView(
            name=f"orbit {h} [µm, bearing frame]",
            origin=f"/joints/{h}",
            contents=["+ $origin/orbit", "+ $origin/clearance_circle"],
            time_ranges=[trail],
        )
        for h in hinges
    ]
    series = [rrb.TimeSeriesView(name="contact force [N]", origin="/joints", contents=["+ $origin/*/force/**"])]
    if site:
        series.append(rrb.TimeSeriesView(name=f"{site}: distance from the twin's [mm]", origin=f"/site/{site}"))
    right = rrb.Vertical(rrb.Grid(*orbits), *series) if orbits else rrb.Vertical(*series)
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Spatial3DView(name="model (twin in grey) [m]", origin="/"), right, column_shares=[3, 2]),
        rrb.TimePanel(timeline=TIME_TIMELINE),
        collapse_panels=False,
    )


def record_model_run(
    result: SimulationResult,
    twin: SimulationResult,
    model: mujoco.MjModel,
    twin_model: mujoco.MjModel,
    path: str | os.PathLike[str],
    *,
    deviation: SiteDeviation | None = None,
    max_rate_hz: float | None = DEFAULT_MAX_RATE_HZ,
) -> Path:
    """Write a retrofitted model's run and its twin's into one ``.rrd`` file (atomically).

    Args:
        result: the retrofitted model's run (with ``body_poses``).
        twin: the unmodified twin's run.
        model, twin_model: the two compiled models (their geoms are drawn).
        path: the ``.rrd`` file.
        deviation: the chosen site's deviation (its distance is logged), or None.
        max_rate_hz: display rate of the bodies [rows per simulated second]; None: every row.

    Raises:
        ValueError: a result without body poses, or a bad ``max_rate_hz``.
    """
    if not len(result.body_poses) or not len(twin.body_poses):
        raise ValueError("record_model_run needs results with body poses (runs of clearance.run.retrofitted)")
    if max_rate_hz is not None and not (math.isfinite(max_rate_hz) and max_rate_hz > 0):
        raise ValueError(f"max_rate_hz must be > 0 or None (got {max_rate_hz!r})")
    hinges = list(result.joints)
    blueprint = _blueprint(hinges, deviation.site if deviation else None)
    with recording_file(path, blueprint) as rec:
        _log_bodies(rec, "model", model, result, _display_rows(result.times, max_rate_hz), grey=False)
        _log_bodies(rec, "twin", twin_model, twin, _display_rows(twin.times, max_rate_hz), grey=True)
        _log_orbits(rec, result)
        if deviation is not None:
            _scalars(
                rec,
                f"site/{deviation.site}/deviation",
                _idx(deviation.times),
                deviation.distance * 1e3,
                f"{deviation.site} |p - p_twin| [mm]",
            )
    return Path(path)
