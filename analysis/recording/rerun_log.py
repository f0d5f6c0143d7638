"""Rerun recordings of a run: journal orbits, contact forces, outputs and the moving mechanism.

`record` writes one ``.rrd`` file that opens in the rerun viewer with a ready layout
(a default blueprint); `stream` logs the same into a live recording (a running viewer).
Several results (a MuJoCo run and a reference-solver run of the same scenario, say) go
into one recording under different entity-path prefixes, so they overlay in the same views.

Entities, under ``<prefix>/`` (units in brackets; Points2D and LineStrips2D store float32,
which is why orbits are logged relative to the bearing centre in micrometres):

* ``joints/<joint>/orbit``: journal centre in the bearing frame [µm], one point per row,
  coloured by the contact-force magnitude (grey when there is no force);
  ``joints/<joint>/contact``: the same points at rows in contact (penetration > 0);
  ``joints/<joint>/clearance_circle`` (static): the circle of radius c [µm];
  ``joints/<joint>/poincare`` (static, when given): Poincaré points [µm];
  ``joints/<joint>/force/{magnitude,x,y}`` [N] and ``joints/<joint>/penetration`` [µm].
* ``outputs/<output>/{displacement,velocity,acceleration}/{clearance,ideal}`` [SI: m or
  rad, per second, per second squared].
* ``drives/<drive>/{speed,torque}`` [rad/s, N m].
* ``reactions/<joint>/{magnitude,x,y}`` [N]: every joint's reaction, the force its link_a
  exerts on its link_b in the world frame (`SimulationResult.joint_reactions`), and
  ``reactions/<joint>/ideal`` the ideal twin's magnitude (when given);
  ``mechanism/reactions``: the same forces as arrows from each joint (on link_b), scaled so
  that the run's largest reaction is 40 % of the mechanism's size (the scale is in the label).
* ``sliders/<joint>/...``: a slider with play drawn in its guide with its contact case, and
  its series (`slider_rerun`).
* ``mechanism/links`` (line strips between each link's points), ``mechanism/joints`` and
  the static ``mechanism/ground`` [mm]. Only these are decimated to ``max_rate_hz`` rows
  per simulated second (a display rate); every other series is logged at full rate.

Timelines: ``sim_time`` (duration) and ``drive_microrev``, the first drive's angle in
millionths of a revolution (rerun sequences are integers: drive_angle / 2π · 10⁶).
Everything is sent with `send_columns` (one call per entity, no Python per row). The
numerical core never imports this module.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from clearance.model import Mechanism, OutputKind
from clearance.results import SimulationResult, temporary_file_beside

__all__ = [
    "DEFAULT_MAX_RATE_HZ",
    "REV_TIMELINE",
    "TIME_TIMELINE",
    "recording_file",
    "LoggedRun",
    "log_run",
    "make_blueprint",
    "record",
    "record_runs",
    "stream",
]

TIME_TIMELINE = "sim_time"
"""Timeline of simulated time (rerun duration, nanosecond resolution)."""
REV_TIMELINE = "drive_microrev"
"""Timeline of the first drive's angle in millionths of a revolution (integer sequence)."""
DEFAULT_MAX_RATE_HZ = 20_000.0
"""Default display rate of the mechanism drawing [rows per simulated second]."""

_UM, _MM = 1e6, 1e3
_GREY = 0x9A9A9AFF
# viridis at 0, 0.25, 0.5, 0.75, 1 (matplotlib's values, rounded to 8 bits)
_CMAP = np.array([[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], float)
_LINK_COLORS = (0x1F77B4FF, 0xFF7F0EFF, 0x2CA02CFF, 0x9467BDFF, 0x8C564BFF, 0xE377C2FF, 0x17BECFFF)


@dataclass(frozen=True)
class LoggedRun:
    """One result to log, with what belongs to it.

    Attributes:
        result: the run (MuJoCo or reference solver; the same `SimulationResult`).
        mechanism: the mechanism it ran (points, joints, clearances, drive names).
        prefix: entity-path prefix (``""`` for the root, e.g. ``"mujoco"``, ``"reference"``).
        ideal: the ideal twin's run, logged beside the outputs (or None).
        poincare: clearance joint name -> (k, 2) Poincaré points in the bearing frame [m].
    """

    result: SimulationResult
    mechanism: Mechanism
    prefix: str = ""
    ideal: SimulationResult | None = None
    poincare: Mapping[str, np.ndarray] | None = field(default=None)

    def __post_init__(self) -> None:
        if not isinstance(self.result, SimulationResult):
            raise TypeError(f"result must be a SimulationResult (got {type(self.result).__name__})")
        if not isinstance(self.mechanism, Mechanism):
            raise TypeError(f"mechanism must be a Mechanism (got {type(self.mechanism).__name__})")
        if self.ideal is not None and not isinstance(self.ideal, SimulationResult):
            raise TypeError(f"ideal must be a SimulationResult or None (got {type(self.ideal).__name__})")
        p = str(self.prefix).strip("/")
        if p and not all(part and part.replace("_", "").replace("-", "").isalnum() for part in p.split("/")):
            raise ValueError(
                f"prefix must be names of letters, digits, '_' or '-' separated by '/' (got {self.prefix!r})"
            )
        object.__setattr__(self, "prefix", p)
        if len(self.result) == 0:
            raise ValueError("result has no rows to log")
        cj = {j.name: j for j in self.mechanism.clearance_joints}
        missing = [j for j in self.result.joints if j not in cj]
        if missing:
            raise ValueError(f"result joints {missing} are not clearance joints of mechanism '{self.mechanism.name}'")
        n_links = len(self.mechanism.moving_links)
        if self.result.link_poses.shape[1:] != (n_links, 3):
            raise ValueError(
                f"link_poses must have shape (n, {n_links}, 3) for mechanism '{self.mechanism.name}' "
                f"(got {self.result.link_poses.shape})"
            )
        if self.poincare is not None:
            pts = {}
            for name, arr in self.poincare.items():
                if name not in self.result.joints:
                    raise ValueError(
                        f"poincare: '{name}' is not a clearance joint of the result ({self.result.joint_names})"
                    )
                a = np.asarray(arr, dtype=float)
                if a.ndim != 2 or a.shape[1] != 2:
                    raise ValueError(f"poincare['{name}'] must have shape (k, 2) [m] (got {a.shape})")
                pts[name] = a
            object.__setattr__(self, "poincare", pts)

    def path(self, rest: str) -> str:
        """Entity path ``/<prefix>/<rest>``."""
        return f"/{self.prefix}/{rest}" if self.prefix else f"/{rest}"


# -- helpers ------------------------------------------------------------------------------
def _ns(times: np.ndarray) -> np.ndarray:
    return np.round(np.asarray(times, float) * 1e9).astype(np.int64).astype("timedelta64[ns]")


def _indexes(times: np.ndarray, drive_angle: np.ndarray, rows: np.ndarray | slice = slice(None)) -> list:
    idx = [rr.TimeColumn(TIME_TIMELINE, duration=_ns(times[rows]))]
    if drive_angle.ndim == 2 and drive_angle.shape[1] > 0:
        rev = np.round(drive_angle[rows, 0] / (2 * math.pi) * 1e6).astype(np.int64)
        idx.append(rr.TimeColumn(REV_TIMELINE, sequence=rev))
    return idx


def _force_colors(force: np.ndarray, fmax: float) -> np.ndarray:
    """(n,) packed RGBA (0xRRGGBBAA) of viridis(force / fmax); grey where force == 0."""
    x = np.clip(force / fmax, 0.0, 1.0) if fmax > 0 else np.zeros_like(force)
    anchors = np.linspace(0.0, 1.0, len(_CMAP))
    rgb = np.stack([np.interp(x, anchors, _CMAP[:, k]) for k in range(3)], axis=1).round().astype(np.uint32)
    packed = (rgb[:, 0] << 24) | (rgb[:, 1] << 16) | (rgb[:, 2] << 8) | np.uint32(0xFF)
    return np.where(force > 0, packed, np.uint32(_GREY)).astype(np.uint32)


def _display_rows(times: np.ndarray, max_rate_hz: float | None) -> np.ndarray:
    """Row indices with at most ``max_rate_hz`` rows per simulated second (first and last kept)."""
    n = len(times)
    if max_rate_hz is None or n < 2:
        return np.arange(n)
    bins = np.floor((times - times[0]) * max_rate_hz + 1e-9)
    rows = np.unique(bins, return_index=True)[1]
    return np.union1d(rows, [n - 1])


def _world_points(run: LoggedRun, rows: np.ndarray) -> dict[str, np.ndarray]:
    """World positions [m] of every link's points at ``rows``: name -> (r, k, 2).

    ``link_poses`` hold each link frame's origin and angle (both solvers).
    """
    mech, poses = run.mechanism, run.result.link_poses
    moving = [lk.name for lk in mech.moving_links]
    out = {}
    for lk in mech.links:
        p = np.array(list(lk.points.values()), float).reshape(-1, 2)
        if lk.name not in moving:
            out[lk.name] = np.broadcast_to(p, (len(rows), *p.shape))
            continue
        pose = poses[rows, moving.index(lk.name)]
        c, s = np.cos(pose[:, 2])[:, None], np.sin(pose[:, 2])[:, None]
        out[lk.name] = np.stack(
            [pose[:, :1] + c * p[:, 0] - s * p[:, 1], pose[:, 1:2] + s * p[:, 0] + c * p[:, 1]], axis=-1
        )
    return out


def _drive_names(run: LoggedRun) -> list[str]:
    """Names of the result's drive columns (the mechanism's drive names, in order)."""
    n = run.result.drive_speed.shape[1] if run.result.drive_speed.ndim == 2 else 0
    names = [d.name for d in run.mechanism.drives]
    return [names[k] if k < len(names) else f"drive{k}" for k in range(n)]


def _scalars(
    rec: rr.RecordingStream, path: str, idx: list, values: np.ndarray, name: str, color: int | None = None
) -> None:
    rec.log(
        path, rr.SeriesLines(names=name, colors=None if color is None else np.array([color], np.uint32)), static=True
    )
    rec.send_columns(path, indexes=idx, columns=rr.Scalars.columns(scalars=np.asarray(values, float)))


# -- logging ------------------------------------------------------------------------------
def log_run(
    recording: rr.RecordingStream, run: LoggedRun, *, max_rate_hz: float | None = DEFAULT_MAX_RATE_HZ
) -> list[str]:
    """Log one run into ``recording`` (columns, one `send_columns` per entity).

    Args:
        recording: the rerun recording stream to log into.
        run: the run and what belongs to it.
        max_rate_hz: display rate of the mechanism drawing [rows per simulated second];
            None for every row. Orbits and series are always logged at full rate.

    Returns:
        The entity paths logged.

    Raises:
        ValueError: ``max_rate_hz`` not positive.
    """
    if max_rate_hz is not None and not (math.isfinite(max_rate_hz) and max_rate_hz > 0):
        raise ValueError(f"max_rate_hz must be > 0 or None (got {max_rate_hz!r})")
    res, mech = run.result, run.mechanism
    tag = f"{run.prefix} " if run.prefix else ""
    idx = _indexes(res.times, res.drive_angle)
    logged: list[str] = []

    def scal(rest: str, values: np.ndarray, name: str, color: int | None = None) -> None:
        _scalars(recording, run.path(rest), idx, values, name, color)
        logged.append(run.path(rest))

    # clearance joints
    for jname, jr in res.joints.items():
        c = mech.joint(jname).require_clearance().radial_clearance
        fmag = jr.force_magnitude
        colors = _force_colors(fmag, float(fmag.max(initial=0.0)))
        base = f"joints/{jname}"
        recording.send_columns(
            run.path(f"{base}/orbit"),
            indexes=idx,
            columns=rr.Points2D.columns(positions=jr.eccentricity * _UM, colors=colors),
        )
        recording.log(run.path(f"{base}/orbit"), rr.Points2D.from_fields(radii=c * _UM / 200), static=True)
        on = np.nonzero(jr.penetration > 0)[0]
        if len(on):
            recording.send_columns(
                run.path(f"{base}/contact"),
                indexes=_indexes(res.times, res.drive_angle, on),
                columns=rr.Points2D.columns(positions=jr.eccentricity[on] * _UM, colors=colors[on]),
            )
            recording.log(run.path(f"{base}/contact"), rr.Points2D.from_fields(radii=c * _UM / 80), static=True)
        th = np.linspace(0.0, 2 * math.pi, 361)
        recording.log(
            run.path(f"{base}/clearance_circle"),
            rr.LineStrips2D(
                [np.c_[np.cos(th), np.sin(th)] * c * _UM],
                colors=np.array([0x404040FF], np.uint32),
                radii=c * _UM / 400,
                labels=[f"c = {c * _UM:.4g} µm"],
            ),
            static=True,
        )
        logged += [
            run.path(f"{base}/{e}") for e in ("orbit", "contact", "clearance_circle") if e != "contact" or len(on)
        ]
        if run.poincare is not None and jname in run.poincare:
            recording.log(
                run.path(f"{base}/poincare"),
                rr.Points2D(run.poincare[jname] * _UM, colors=np.array([0xD62728FF], np.uint32), radii=c * _UM / 60),
                static=True,
            )
            logged.append(run.path(f"{base}/poincare"))
        scal(f"{base}/force/magnitude", fmag, f"{tag}{jname} |F| [N]")
        scal(f"{base}/force/x", jr.contact_force[:, 0], f"{tag}{jname} Fx [N]")
        scal(f"{base}/force/y", jr.contact_force[:, 1], f"{tag}{jname} Fy [N]")
        scal(f"{base}/penetration", jr.penetration * _UM, f"{tag}{jname} penetration [µm]")

    # outputs, with the ideal twin beside them
    angular = {o.name: o.kind is OutputKind.ANGLE for o in mech.outputs}
    for o in (name for name in res.outputs if not name.endswith(("_vel", "_acc"))):
        unit = "rad" if angular.get(o) else "m"
        for kind, suffix, u in (
            ("displacement", "", unit),
            ("velocity", "_vel", f"{unit}/s"),
            ("acceleration", "_acc", f"{unit}/s²"),
        ):
            if o + suffix not in res.outputs:
                continue
            scal(f"outputs/{o}/{kind}/clearance", res.outputs[o + suffix], f"{tag}{o} {kind} [{u}]")
            if run.ideal is not None and o + suffix in run.ideal.outputs:
                path = run.path(f"outputs/{o}/{kind}/ideal")
                _scalars(
                    recording,
                    path,
                    _indexes(run.ideal.times, run.ideal.drive_angle),
                    run.ideal.outputs[o + suffix],
                    f"{tag}{o} {kind} ideal [{u}]",
                    _GREY,
                )
                logged.append(path)

    # drives
    for k, d in enumerate(_drive_names(run)):
        scal(f"drives/{d}/speed", res.drive_speed[:, k], f"{tag}{d} speed [rad/s]")
        scal(f"drives/{d}/torque", res.drive_torque[:, k], f"{tag}{d} torque [N m]")

    # joint reactions (world frame), the ideal twin's magnitude beside them
    for jname, f in res.joint_reactions.items():
        base = f"reactions/{jname}"
        scal(f"{base}/magnitude", np.hypot(f[:, 0], f[:, 1]), f"{tag}{jname} reaction |F| [N]")
        scal(f"{base}/x", f[:, 0], f"{tag}{jname} reaction Fx [N]")
        scal(f"{base}/y", f[:, 1], f"{tag}{jname} reaction Fy [N]")
        if run.ideal is not None and jname in run.ideal.joint_reactions:
            fi = run.ideal.joint_reactions[jname]
            path = run.path(f"{base}/ideal")
            _scalars(
                recording,
                path,
                _indexes(run.ideal.times, run.ideal.drive_angle),
                np.hypot(fi[:, 0], fi[:, 1]),
                f"{tag}{jname} reaction |F| ideal [N]",
                _GREY,
            )
            logged.append(path)

    logged += _log_mechanism(recording, run, max_rate_hz)
    if res.sliders:  # sliders with play: each drawn in its guide with its contact case
        from clearance.analysis.recording.slider_rerun import log_sliders

        logged += log_sliders(
            recording,
            result=res,
            mechanism=mech,
            path=run.path,
            indexes=lambda rows: _indexes(res.times, res.drive_angle, rows),
            rows=_display_rows(res.times, max_rate_hz),
            tag=tag,
        )
    return logged


def _log_mechanism(recording: rr.RecordingStream, run: LoggedRun, max_rate_hz: float | None) -> list[str]:
    res, mech = run.result, run.mechanism
    rows = _display_rows(res.times, max_rate_hz)
    pts = _world_points(run, rows)
    idx = _indexes(res.times, res.drive_angle, rows)
    size = max((float(np.abs(p).max()) for p in pts.values() if p.size), default=0.1) or 0.1
    moving = [lk.name for lk in mech.moving_links]
    strips, colors, labels = [], [], []
    for i, name in enumerate(moving):
        p = pts[name] * _MM
        if p.shape[1] == 1:  # a single point (a slider): a small square around it
            h = 0.04 * size * _MM
            p = p + np.array([[-h, -h], [h, -h], [h, h], [-h, h], [-h, -h]])[None]
        elif p.shape[1] >= 3:
            p = np.concatenate([p, p[:, :1]], axis=1)
        strips.append(p)
        colors.append(_LINK_COLORS[i % len(_LINK_COLORS)])
        labels.append(name)
    n, kmax = len(rows), max(p.shape[1] for p in strips)
    # pad every strip to kmax points by repeating its last point (draws the same), so the
    # strips are one (n * n_links, kmax, 2) array: rerun's numpy fast path, no Python per row
    flat = np.stack(
        [np.concatenate([p, np.repeat(p[:, -1:], kmax - p.shape[1], axis=1)], axis=1) for p in strips], axis=1
    ).reshape(-1, kmax, 2)
    links_path, joints_path, ground_path = (run.path(f"mechanism/{e}") for e in ("links", "joints", "ground"))
    recording.send_columns(
        links_path, indexes=idx, columns=rr.LineStrips2D.columns(strips=flat).partition([len(strips)] * n)
    )
    recording.log(
        links_path,
        rr.LineStrips2D.from_fields(colors=np.array(colors, np.uint32), labels=labels, radii=0.006 * size * _MM),
        static=True,
    )
    jpos, jcol, jlab = [], [], []
    for j in mech.joints:
        jpos.append(pts[j.link_a][:, list(mech.link(j.link_a).points).index(j.point_a)] * _MM)
        jcol.append(0xD62728FF if j.clearance is not None else 0x303030FF)
        jlab.append(j.name)
    jp = np.stack(jpos, axis=1).reshape(-1, 2)
    recording.send_columns(
        joints_path, indexes=idx, columns=rr.Points2D.columns(positions=jp).partition([len(jpos)] * n)
    )
    recording.log(
        joints_path,
        rr.Points2D.from_fields(
            colors=np.array(jcol, np.uint32), labels=jlab, radii=0.015 * size * _MM, show_labels=False
        ),
        static=True,
    )
    ground = np.array(list(mech.link(mech.ground).points.values()), float).reshape(-1, 2) * _MM
    recording.log(
        ground_path,
        rr.Points2D(ground, colors=np.array([0x000000FF], np.uint32), radii=0.025 * size * _MM),
        static=True,
    )
    paths = [links_path, joints_path, ground_path]
    if res.joint_reactions:
        paths.append(_log_reaction_arrows(recording, run, rows, idx, pts, size))
    return paths


def _log_reaction_arrows(
    recording: rr.RecordingStream,
    run: LoggedRun,
    rows: np.ndarray,
    idx: list,
    pts: dict[str, np.ndarray],
    size: float,
) -> str:
    """Reaction arrows at the joints (on link_b's point) of the display rows; returns the path."""
    res, mech = run.result, run.mechanism
    names = [j for j in (jt.name for jt in mech.joints) if j in res.joint_reactions]
    forces = np.stack([res.joint_reactions[j][rows] for j in names], axis=1)  # (r, k, 2) [N]
    fmax = float(np.nanmax(np.hypot(forces[..., 0], forces[..., 1]), initial=0.0))
    scale = 0.4 * size * _MM / fmax if fmax > 0 else 0.0  # mm per N
    origins = np.stack(
        [
            pts[mech.joint(j).link_b][:, list(mech.link(mech.joint(j).link_b).points).index(mech.joint(j).point_b)]
            for j in names
        ],
        axis=1,
    )
    path = run.path("mechanism/reactions")
    n = len(rows)
    recording.send_columns(
        path,
        indexes=idx,
        columns=rr.Arrows2D.columns(
            origins=(origins * _MM).reshape(-1, 2), vectors=np.nan_to_num(forces * scale).reshape(-1, 2)
        ).partition([len(names)] * n),
    )
    recording.log(
        path,
        rr.Arrows2D.from_fields(
            colors=np.array([0x2CA02CFF], np.uint32),
            labels=[f"{j} (1 mm = {1 / scale:.3g} N)" if scale > 0 else j for j in names],
            show_labels=False,
        ),
        static=True,
    )
    return path


# -- blueprint ----------------------------------------------------------------------------
def make_blueprint(runs: Sequence[LoggedRun]) -> rrb.Blueprint:
    """The default layout: mechanism and orbits on the left, time series on the right.

    Each view overlays every run (prefix), so a MuJoCo and a reference run compare in place.

    Args:
        runs: the runs logged into the recording.

    Returns:
        The blueprint.
    """
    runs = list(runs)
    trail = rrb.VisibleTimeRange(
        TIME_TIMELINE, start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.cursor_relative()
    )
    trail_rev = rrb.VisibleTimeRange(
        REV_TIMELINE, start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.cursor_relative()
    )
    joints = list(dict.fromkeys(j for r in runs for j in r.result.joints))
    orbit_views = [
        rrb.Spatial2DView(
            name=f"orbit {j} [µm, bearing frame]",
            origin="/",
            contents=[f"+ {r.path(f'joints/{j}')}/**" for r in runs if j in r.result.joints]
            + [f"- {r.path(f'joints/{j}')}/force/**" for r in runs if j in r.result.joints]
            + [f"- {r.path(f'joints/{j}')}/penetration" for r in runs if j in r.result.joints],
            time_ranges=[trail, trail_rev],
        )
        for j in joints
    ]
    mech_view = rrb.Spatial2DView(
        name="mechanism [mm]", origin="/", contents=[f"+ {r.path('mechanism')}/**" for r in runs]
    )
    series = []
    if joints or any(r.result.sliders for r in runs):
        series.append(
            rrb.TimeSeriesView(
                name="contact force [N]",
                origin="/",
                contents=[f"+ {r.path(f'joints/{j}')}/force/magnitude" for r in runs for j in r.result.joints]
                + [f"+ {r.path(f'sliders/{j}')}/force/magnitude" for r in runs for j in r.result.sliders],
            )
        )
    outputs = list(dict.fromkeys(o for r in runs for o in r.result.outputs if not o.endswith(("_vel", "_acc"))))
    for o in outputs:
        for kind in ("displacement", "velocity", "acceleration"):
            series.append(
                rrb.TimeSeriesView(
                    name=f"{o} {kind}", origin="/", contents=[f"+ {r.path(f'outputs/{o}/{kind}')}/**" for r in runs]
                )
            )
    reactions = [
        f"+ {r.path(f'reactions/{j}')}/{e}"
        for r in runs
        for j in r.result.joint_reactions
        for e in ("magnitude", "ideal")
    ]
    if reactions:
        series.append(rrb.TimeSeriesView(name="joint reactions [N]", origin="/", contents=reactions))
    speeds = [f"+ {r.path(f'drives/{d}')}/speed" for r in runs for d in _drive_names(r)]
    if speeds:
        series.append(rrb.TimeSeriesView(name="drive speed [rad/s]", origin="/", contents=speeds))
    from clearance.analysis.recording.slider_rerun import slider_views

    drawings, slider_series = slider_views([(r.result, r.path) for r in runs])
    orbit_views += drawings  # each slider in its guide beside the orbits
    series += slider_series
    left = (
        rrb.Vertical(mech_view, rrb.Grid(*orbit_views) if len(orbit_views) > 1 else orbit_views[0])
        if orbit_views
        else mech_view
    )
    return rrb.Blueprint(
        rrb.Horizontal(left, rrb.Vertical(*series), column_shares=[1, 1]) if series else left,
        rrb.TimePanel(timeline=TIME_TIMELINE),
        collapse_panels=False,
    )


# -- entry points -------------------------------------------------------------------------
def record_runs(
    runs: Sequence[LoggedRun],
    path: str | os.PathLike,
    *,
    max_rate_hz: float | None = DEFAULT_MAX_RATE_HZ,
    application_id: str = "clearance",
) -> Path:
    """Write several runs (distinct prefixes) into one ``.rrd`` file with the default blueprint.

    The file is written to a temporary name in the same folder, then renamed.

    Args:
        runs: the runs; their prefixes must be distinct.
        path: the ``.rrd`` file to write.
        max_rate_hz: display rate of the mechanism drawing [rows per simulated second].
        application_id: rerun application id.

    Returns:
        The path written.

    Raises:
        ValueError: no runs, duplicate prefixes, or a bad ``max_rate_hz``.
    """
    runs = list(runs)
    if not runs:
        raise ValueError("record_runs needs at least one run")
    prefixes = [r.prefix for r in runs]
    if len(set(prefixes)) != len(prefixes):
        raise ValueError(f"runs must have distinct prefixes (got {prefixes})")
    if max_rate_hz is not None and not (math.isfinite(max_rate_hz) and max_rate_hz > 0):
        raise ValueError(f"max_rate_hz must be > 0 or None (got {max_rate_hz!r})")
    with recording_file(path, make_blueprint(runs), application_id) as rec:
        for r in runs:
            log_run(rec, r, max_rate_hz=max_rate_hz)
    return Path(path)


@contextmanager
def recording_file(
    path: str | os.PathLike[str], blueprint: rrb.Blueprint, application_id: str = "clearance"
) -> Iterator[rr.RecordingStream]:
    """A recording stream saved to ``path`` atomically: in place when the block ends, nothing on error.

    Args:
        path: the ``.rrd`` file (its folder is created).
        blueprint: the recording's default layout.
        application_id: rerun application id.

    Yields:
        The stream to log to.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = temporary_file_beside(path)  # the usual mode of a new file, not mkstemp's 0o600
    os.close(fd)
    rec = rr.RecordingStream(application_id)
    try:
        rec.save(str(tmp), default_blueprint=blueprint)
        yield rec
        rec.flush()
        rec.disconnect()
        os.replace(tmp, path)
    except BaseException:
        rec.disconnect()
        Path(tmp).unlink(missing_ok=True)
        raise


def record(
    result: SimulationResult,
    mechanism: Mechanism,
    path: str | os.PathLike,
    *,
    ideal: SimulationResult | None = None,
    poincare: Mapping[str, np.ndarray] | None = None,
    prefix: str = "",
    max_rate_hz: float | None = DEFAULT_MAX_RATE_HZ,
) -> Path:
    """Write one run to an ``.rrd`` file that opens with the default layout.

    Args:
        result: the run (MuJoCo or reference solver).
        mechanism: the mechanism it ran.
        path: the ``.rrd`` file to write (atomically).
        ideal: the ideal twin's run, shown beside the outputs.
        poincare: clearance joint name -> (k, 2) Poincaré points in the bearing frame [m].
        prefix: entity-path prefix (``""``: the root).
        max_rate_hz: display rate of the mechanism drawing [rows per simulated second];
            None for every row.

    Returns:
        The path written.

    Raises:
        TypeError, ValueError: bad arguments (see `LoggedRun`).
    """
    run = LoggedRun(result, mechanism, prefix=prefix, ideal=ideal, poincare=poincare)
    return record_runs([run], path, max_rate_hz=max_rate_hz)


def stream(
    result: SimulationResult,
    mechanism: Mechanism,
    *,
    recording: rr.RecordingStream | None = None,
    ideal: SimulationResult | None = None,
    poincare: Mapping[str, np.ndarray] | None = None,
    prefix: str = "",
    max_rate_hz: float | None = DEFAULT_MAX_RATE_HZ,
    url: str | None = None,
    spawn: bool = False,
    blueprint: bool = True,
) -> rr.RecordingStream:
    """Log one run into a live recording (a running or spawned viewer).

    Args:
        result, mechanism, ideal, poincare, prefix, max_rate_hz: as in `record`.
        recording: the stream to log into (already connected, e.g. after
            ``rec.spawn()``); None creates one and connects it as ``url``/``spawn`` say.
        url: gRPC address of a running viewer when ``recording`` is None (rerun's
            default address when None).
        spawn: when ``recording`` is None, start a viewer instead of connecting to one.
        blueprint: send the default layout of this run too. For several runs in one live
            recording, log each with ``blueprint=False`` and send
            ``make_blueprint(runs)`` once with ``recording.send_blueprint``.

    Returns:
        The recording stream (still open; later runs may be logged into it under other
        prefixes).
    """
    run = LoggedRun(result, mechanism, prefix=prefix, ideal=ideal, poincare=poincare)
    if recording is None:
        recording = rr.RecordingStream("clearance")
        if spawn:
            recording.spawn()
        else:
            recording.connect_grpc(url)
    if blueprint:
        recording.send_blueprint(make_blueprint([run]))
    log_run(recording, run, max_rate_hz=max_rate_hz)
    return recording
