"""Writing a retrofit: the model, its unmodified twin and the report, each atomically.

``model.xml`` (the retrofitted model, ring mode: stock MuJoCo compiles it), ``original.xml``
(the unmodified model with the same asset-path fixes, for comparison runs) and
``retrofit.md`` (every change; `clearance.retrofit.report`) and ``retrofit.json`` (what a run
of the model reads: `clearance.retrofit.manifest`). The written model is compiled
again from its file before the report is written, and its rings are measured there against
their nominal geometry (`check_rings`), so a model that would not load, or whose rings MuJoCo's
6-digit writer bent, is never reported as done.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import mujoco
import numpy as np

from clearance.results import atomic_write_text
from clearance.retrofit.assets import relocate_assets
from clearance.retrofit.backlash import BacklashRetrofit
from clearance.retrofit.backlash_report import backlash_report
from clearance.retrofit.manifest import (
    MANIFEST_FILE,
    ROBOT_STEP_BOUND,
    ROBOT_STEP_MODE,
    BacklashRecord,
    HingeRecord,
    RetrofitManifest,
)
from clearance.retrofit.pipeline import Retrofit, RetrofittedHinge
from clearance.retrofit.report import retrofit_report

__all__ = [
    "MODEL_FILE",
    "TWIN_FILE",
    "REPORT_FILE",
    "RING_TOLERANCE",
    "check_rings",
    "backlash_manifest_of",
    "manifest_of",
    "write_backlash",
    "write_retrofit",
]

MODEL_FILE = "model.xml"
TWIN_FILE = "original.xml"
REPORT_FILE = "retrofit.md"


def write_retrofit(
    result: Retrofit,
    out_dir: str | os.PathLike[str],
    *,
    source_dir: str | os.PathLike[str] | None = None,
    source: str = "",
    command: str = "",
) -> dict[str, Path]:
    """Write ``model.xml``, ``original.xml``, ``retrofit.md`` and ``retrofit.json`` into ``out_dir``.

    Args:
        result: the retrofit.
        out_dir: the output folder (created if missing).
        source_dir: the folder the model was read from (default: the spec's own
            ``modelfiledir``, else the current folder); asset folders are rewritten from it.
        source: the model file, for the report.
        command: the command line, for the report.

    Returns:
        File role ('model', 'original', 'report', 'manifest') -> path.

    Raises:
        RuntimeError: the written model does not compile from its file.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    src = Path(source_dir if source_dir is not None else (result.twin_spec.modelfiledir or "."))
    paths = {
        "model": out / MODEL_FILE,
        "original": out / TWIN_FILE,
        "report": out / REPORT_FILE,
        "manifest": out / MANIFEST_FILE,
    }
    changes, written = _write_models(result.spec, result.twin_spec, src, out, paths)
    check_rings(written, result.hinges.values(), str(paths["model"]))
    atomic_write_text(paths["manifest"], manifest_of(result).to_json())
    atomic_write_text(paths["report"], retrofit_report(result, source=source, command=command, asset_changes=changes))
    return paths


RING_TOLERANCE = 0.01
"""Largest error of a written ring, as a fraction of its clearance c [-]: each segment's implied
clearance (its distance from the bearing centre less its radius and the journal's) and the
journal's offset from the bearing centre at qpos0, read back from the file."""


def check_rings(model: mujoco.MjModel, hinges: Iterable[RetrofittedHinge], where: str) -> None:
    """Check each ring of ``model`` (a written model, read back) against its nominal geometry.

    Raises:
        RuntimeError: a segment's implied clearance, or the journal's offset at qpos0, is off by more
            than `RING_TOLERANCE` of c (naming the hinge and the numbers).
    """
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    for h in hinges:
        if h.ring is None:
            continue
        el, c = h.elements, h.play.clearance.radial_clearance
        site = model.site(el.bearing_site).id
        centre, axes = data.site_xpos[site], data.site_xmat[site].reshape(3, 3)
        journal = model.geom(el.journal_geom).id
        r_j = float(model.geom_size[journal, 0])
        local = np.array([axes.T @ (data.geom_xpos[model.geom(g).id] - centre) for g in el.segments])
        sizes = np.array([model.geom_size[model.geom(g).id, 0] for g in el.segments])
        implied = np.hypot(local[:, 0], local[:, 1]) - sizes - r_j
        offset = float(np.linalg.norm((axes.T @ (data.geom_xpos[journal] - centre))[:2]))
        error = max(float(np.max(np.abs(implied - c))), float(np.max(np.abs(local[:, 2]))), offset)
        if error > RING_TOLERANCE * c:
            raise RuntimeError(
                f"{where}: the ring of hinge '{h.name}' is {error * 1e6:.3g} um off its nominal geometry (implied "
                f"clearance {implied.min() * 1e6:.4g}..{implied.max() * 1e6:.4g} um for c = {c * 1e6:.4g} um, journal "
                f"{offset * 1e6:.3g} um off centre), more than {RING_TOLERANCE:.0%} of c"
            )


def _write_models(
    spec: mujoco.MjSpec, twin_spec: mujoco.MjSpec, src: Path, out: Path, paths: dict[str, Path]
) -> tuple[list[str], mujoco.MjModel]:
    """Write the edited model and its twin (asset folders rewritten for ``out``); (the model's asset
    changes, the model read back from its file).

    Raises:
        RuntimeError: the written model does not compile from its file.
    """
    changes: list[str] = []
    for role, s in (("model", spec), ("original", twin_spec)):
        copy = s.copy()
        found = relocate_assets(copy, src, out)
        if role == "model":
            changes = found
        atomic_write_text(paths[role], copy.to_xml())
    try:
        written = mujoco.MjModel.from_xml_path(str(paths["model"]))
    except ValueError as err:
        raise RuntimeError(f"the written model {paths['model']} does not compile: {err}") from None
    return changes, written


def write_backlash(
    result: BacklashRetrofit,
    out_dir: str | os.PathLike[str],
    *,
    source_dir: str | os.PathLike[str] | None = None,
    source: str = "",
    command: str = "",
) -> dict[str, Path]:
    """Write ``model.xml``, ``original.xml``, ``retrofit.md`` and ``retrofit.json`` of a backlash edit.

    Arguments as `write_retrofit`'s; returns file role ('model', 'original', 'report',
    'manifest') -> path. ``clearance run --model`` reads the manifest (`backlash_manifest_of`).

    Raises:
        RuntimeError: the written model does not compile from its file.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    src = Path(source_dir if source_dir is not None else (result.twin_spec.modelfiledir or "."))
    paths = {"model": out / MODEL_FILE, "original": out / TWIN_FILE, "report": out / REPORT_FILE}
    changes, _ = _write_models(result.spec, result.twin_spec, src, out, paths)
    _exact_bands(paths["model"], {h.tendon: h.backlash.half_width for h in result.hinges.values()})
    paths["manifest"] = out / MANIFEST_FILE
    atomic_write_text(paths["manifest"], backlash_manifest_of(result).to_json())
    atomic_write_text(paths["report"], backlash_report(result, source=source, command=command, changes=changes))
    return paths


def _exact_bands(path: Path, bands: dict[str, float]) -> None:
    """Write each band's range at full precision in the model file ``path`` (tendon name -> b [rad]).

    MuJoCo's MJCF writer keeps 6 significant digits; the band is the user's number, copied, so
    it is written as the shortest text that reads back as the same double.

    Raises:
        RuntimeError: a band's tendon is not in the file, or the file no longer compiles.
    """
    import xml.etree.ElementTree as ET

    tree = ET.parse(path)
    found = {t.get("name"): t for t in tree.iter("fixed") if t.get("name") in bands}
    for name, b in bands.items():
        if name not in found:
            raise RuntimeError(f"the written model {path} has no fixed tendon '{name}'")
        found[name].set("range", f"{-b!r} {b!r}")
    atomic_write_text(path, ET.tostring(tree.getroot(), encoding="unicode") + "\n")
    try:
        mujoco.MjModel.from_xml_path(str(path))
    except ValueError as err:
        raise RuntimeError(f"the written model {path} does not compile: {err}") from None


def manifest_of(result: Retrofit) -> RetrofitManifest:
    """The machine-readable record of ``result`` (`clearance.retrofit.manifest`)."""
    hinges = tuple(
        HingeRecord(
            name=h.name,
            slides=h.elements.slides,
            journal_site=h.elements.journal_site,
            bearing_site=h.elements.bearing_site,
            journal_body=h.elements.journal_body,
            bearing_body=h.elements.bearing_body,
            eccentricity_sensor=h.elements.sensors[0],
            force_sensor=h.elements.sensors[1],
            radial_clearance=h.play.clearance.radial_clearance,
            bearing_radius=h.play.clearance.bearing_radius,
            penetration_limit=h.sizing.penetration_limit if h.stop is None else ROBOT_STEP_BOUND * h.stop.penetration,
            segments=h.sizing.segments,
        )
        for h in result.hinges.values()
    )
    return RetrofitManifest(
        model=MODEL_FILE,
        original=TWIN_FILE,
        timestep=result.timestep,
        original_timestep=float(result.twin.opt.timestep),
        contact_mode=ROBOT_STEP_MODE if result.options.robot_step is not None else result.options.contact_mode.value,
        hinges=hinges,
        qpos_map=tuple(int(i) for i in result.cmap.qpos),
        qvel_map=tuple(int(i) for i in result.cmap.qvel),
    )


def backlash_manifest_of(result: BacklashRetrofit) -> RetrofitManifest:
    """The machine-readable record of a backlash edit: no radial hinges, a `BacklashRecord` per hinge,
    the model's own time step, and where each of the unmodified model's joints sits in the edited one."""
    model, twin = result.model, result.twin
    motors = {model.joint(h.motor_joint).id for h in result.hinges.values()}
    kept = [j for j in range(model.njnt) if j not in motors]  # a motor body adds one hinge; the rest keep their order
    qpos: list[int] = []
    qvel: list[int] = []
    for j, jm in enumerate(kept):
        nq = (int(twin.jnt_qposadr[j + 1]) if j + 1 < twin.njnt else twin.nq) - int(twin.jnt_qposadr[j])
        nv = (int(twin.jnt_dofadr[j + 1]) if j + 1 < twin.njnt else twin.nv) - int(twin.jnt_dofadr[j])
        qpos += range(int(model.jnt_qposadr[jm]), int(model.jnt_qposadr[jm]) + nq)
        qvel += range(int(model.jnt_dofadr[jm]), int(model.jnt_dofadr[jm]) + nv)
    records = tuple(
        BacklashRecord(h.name, h.motor_joint, h.motor_body, h.tendon, h.backlash.half_width, h.actuators, h.stop.kind)
        for h in result.hinges.values()
    )
    step = float(model.opt.timestep)
    return RetrofitManifest(
        model=MODEL_FILE,
        original=TWIN_FILE,
        timestep=step,
        original_timestep=float(twin.opt.timestep),
        contact_mode="backlash",
        hinges=(),
        qpos_map=tuple(qpos),
        qvel_map=tuple(qvel),
        backlash=records,
    )
