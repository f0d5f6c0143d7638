"""`SimulationResult`: the one record every solver returns and every analysis reads.

A result saves to ``<stem>.npz`` (arrays) plus ``<stem>.json`` (metadata) and loads back
losslessly. Both files are written atomically (temporary file, then rename).

Energy balance. A run may carry its energy terms as time series (`SimulationResult.energy`,
`ENERGY_TERMS`); `energy_residual` closes the balance

    residual = Δkinetic + Δgravity_potential + Δcontact_potential
               − drive_work − equality_work − contact_work − other_constraint_work − damper_work
               + dissipated_work

(Δ: change since the first row; works: done ON the mechanism since the first row, so a damper's
or a contact's work is negative; dissipated_work >= 0 is the energy a compiled contact turned
into heat). A conservative run has residual 0 up to the integrator's error.

Joint reactions. `SimulationResult.joint_reactions` holds, per joint (ideal, clearance and
prismatic alike), the force the joint's first-named link (``Joint.link_a``) exerts on its second
(``link_b``) through the joint, (n, 2) in the world frame [N]; ``link_a`` receives the opposite. A
clearance joint's reaction is its contact force: ``R(theta_bearing) @ contact_force`` when the
journal is ``link_b``, minus that when the journal is ``link_a`` (``contact_force`` is the force
on the journal in the bearing frame). A prismatic pair's reaction is the force it transmits
(normal to the guide, plus any friction along it); the moment it carries is not included. The
drives' torques are `SimulationResult.drive_torque`.
"""

from __future__ import annotations

import json
import os
import secrets
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from clearance.joint_result import JointResult as JointResult
from clearance.translational import SLIDER_FIELDS, SliderResult

__all__ = [
    "ENERGY_TERMS",
    "JointResult",
    "SimulationResult",
    "atomic_write_bytes",
    "atomic_write_text",
    "energy_balance",
    "energy_residual",
    "temporary_file_beside",
]


def temporary_file_beside(path: str | os.PathLike) -> tuple[int, Path]:
    """Create a new, empty hidden file in ``path``'s folder for an atomic write.

    The file gets the mode a plain ``open(path, "w")`` gives (0o666 minus the umask), so
    that the renamed result is readable like any other output file (`tempfile.mkstemp`
    would make it 0o600, private to its owner).

    Returns:
        (open file descriptor for writing, path of the temporary file).

    Raises:
        OSError: the folder is not writable.
    """
    path = Path(path)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
        try:
            return os.open(tmp, flags, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary name beside {path}")


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write bytes to ``path`` atomically (temporary file in the same folder, then rename).

    The file gets the usual mode of a new file (0o666 minus the umask).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = temporary_file_beside(path)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write UTF-8 text to ``path`` atomically."""
    atomic_write_bytes(path, text.encode("utf-8"))


ENERGY_TERMS: dict[str, str] = {
    "kinetic": "kinetic energy ½ v'Mv of the links and the drives' armature [J]",
    "gravity_potential": "gravity (and spring) potential energy [J]",
    "contact_potential": "elastic energy K δ^(n+1)/(n+1) stored in compiled contacts [J]",
    "drive_work": "work done by the drives (actuators) on the mechanism since the first row [J]",
    "equality_work": "work done by equality constraints (connect loop closures) since the first row [J]",
    "contact_work": "work done by contact constraint rows (ring bearings) since the first row [J]",
    "other_constraint_work": "work done by other constraint rows (limits, friction loss) since the first row [J]",
    "damper_work": "work done by dampers, fluid, adhesion, gravity compensation since the first row [J]",
    "dissipated_work": "work dissipated by compiled contacts (damping, friction) since the first row, >= 0 [J]",
    "compiled_contact_work": (
        "work done by compiled contacts' forces since the first row [J] (a check, not a term of the "
        "residual: it should equal −Δcontact_potential − dissipated_work)"
    ),
}
"""Energy series a result may carry, name -> meaning; each is (n,) [J]."""

_BALANCE_SIGNS: dict[str, float] = {
    "kinetic": 1.0,
    "gravity_potential": 1.0,
    "contact_potential": 1.0,
    "drive_work": -1.0,
    "equality_work": -1.0,
    "contact_work": -1.0,
    "other_constraint_work": -1.0,
    "damper_work": -1.0,
    "dissipated_work": 1.0,
}
"""Sign of each term's change in the residual (see the module docstring)."""


def energy_residual(energy: dict[str, np.ndarray]) -> np.ndarray | None:
    """Residual of the energy balance at every row [J], (n,); None when a term is missing.

    Args:
        energy: the terms of `ENERGY_TERMS` (each (n,) [J]); every term of the balance must be
            present (`compiled_contact_work` is not one).

    Returns:
        Σ sign · (term − term[0]) over the balance's terms (signs in the module docstring), or
        None if ``energy`` lacks one of them.
    """
    if any(k not in energy for k in _BALANCE_SIGNS):
        return None
    total = np.zeros_like(np.asarray(energy["kinetic"], dtype=float))
    for k, sign in _BALANCE_SIGNS.items():
        v = np.asarray(energy[k], dtype=float)
        total += sign * (v - v[0])
    return total


def energy_balance(energy: dict[str, np.ndarray]) -> dict[str, Any] | None:
    """Summary of a run's energy balance (JSON-serialisable); None when the run has no energy series.

    Args:
        energy: the run's energy series (`SimulationResult.energy`).

    Returns:
        ``change_J``: each term's change from the first row to the last [J] (works: the work
        done over the run); ``scale_J``: the largest range (max − min) of any term over the run
        [J], the energy exchanged (an absolute level, like the drives' armature energy or the
        potential's zero, is arbitrary); ``residual_J``: the residual at the last row;
        ``residual_max_abs_J``: its largest magnitude over the run; ``residual_relative``: that
        over ``scale_J``; ``missing``: terms of the balance the run does not have (then the
        residual entries are None); ``convention``: the formula.
    """
    if not energy:
        return None
    n = len(next(iter(energy.values())))
    if n == 0:
        return None
    terms = {k: np.asarray(v, dtype=float) for k, v in energy.items()}
    residual = energy_residual(terms)
    scale = max(float(np.ptp(v)) for v in terms.values())
    worst = None if residual is None else float(np.max(np.abs(residual)))
    return {
        "change_J": {k: float(v[-1] - v[0]) for k, v in terms.items()},
        "scale_J": scale,
        "residual_J": None if residual is None else float(residual[-1]),
        "residual_max_abs_J": worst,
        "residual_relative": None if worst is None or scale == 0 else worst / scale,
        "missing": [k for k in _BALANCE_SIGNS if k not in terms],
        "convention": (
            "residual = Δkinetic + Δgravity_potential + Δcontact_potential − drive_work − equality_work "
            "− contact_work − other_constraint_work − damper_work + dissipated_work (works done on the "
            "mechanism since the first row)"
        ),
    }


@dataclass
class SimulationResult:
    """A simulated run of a mechanism (MuJoCo or the reference solver).

    Attributes:
        times: (n,) [s].
        outputs: name -> (n,) output position [m or rad]; ``<name>_vel`` and ``<name>_acc``
            hold its first and second time derivatives.
        joints: clearance joint name -> `JointResult` (`clearance.joint_result`); a lubricated
            joint's carries its oil film's force ``film_force`` too (None for a dry joint and in
            files saved before the field existed).
        drive_angle, drive_speed, drive_torque: (n, n_drives) [rad, rad/s, N m].
        link_poses: (n, n_links, 3) pose (x [m], y [m], theta [rad]) of each moving link.
        closure_violation: (n,) largest ideal loop-closure error [m] (zeros if none).
        metadata: mechanism name and parameters, solver, time step, segment count, geom
            types, contact mode and parameters, versions, wall time, the energy balance's
            summary (``energy_balance``, see `energy_balance`) (JSON-serialisable).
        energy: name -> (n,) energy series [J] (`ENERGY_TERMS`); empty when the run did not
            measure them (a model without the energy meter, a result saved before they existed).
        joint_reactions: joint name -> (n, 2) force that the joint's link_a exerts on its link_b,
            world frame [N] (module docstring); every joint of the mechanism, in its order; empty
            in results saved before reactions existed.
        body_poses: (n, n_bodies, 7) world position (x, y, z) [m] and orientation quaternion
            (w, x, y, z) of every body of a 3-D model (``metadata['bodies']`` names them, the
            world body first); empty (0 rows) for planar mechanisms, which use ``link_poses``.
        sliders: prismatic joint with play name -> `clearance.translational.SliderResult`
            (the slider's position and tilt in its guide, its corners' contact, the contact
            case); empty for a run without translational clearance.
    """

    times: np.ndarray
    outputs: dict[str, np.ndarray]
    joints: dict[str, JointResult]
    drive_angle: np.ndarray
    drive_speed: np.ndarray
    drive_torque: np.ndarray
    link_poses: np.ndarray
    closure_violation: np.ndarray
    metadata: dict[str, Any] = field(default_factory=dict)
    energy: dict[str, np.ndarray] = field(default_factory=dict)
    joint_reactions: dict[str, np.ndarray] = field(default_factory=dict)
    body_poses: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 7)))
    sliders: dict[str, SliderResult] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.times)

    @property
    def energy_residual(self) -> np.ndarray | None:
        """(n,) residual of the energy balance [J] (`energy_residual`), or None without the terms."""
        return energy_residual(self.energy) if self.energy else None

    def energy_balance(self) -> dict[str, Any] | None:
        """Summary of the energy balance over the rows of this result (`energy_balance`)."""
        return energy_balance(self.energy)

    @property
    def joint_names(self) -> list[str]:
        """Clearance joint names in model order."""
        return list(self.joints)

    def sliced(self, sl: slice | np.ndarray) -> SimulationResult:
        """The result restricted to rows ``sl`` (metadata shared)."""
        return SimulationResult(
            times=self.times[sl],
            outputs={k: v[sl] for k, v in self.outputs.items()},
            joints={k: v.sliced(sl) for k, v in self.joints.items()},
            drive_angle=self.drive_angle[sl],
            drive_speed=self.drive_speed[sl],
            drive_torque=self.drive_torque[sl],
            link_poses=self.link_poses[sl],
            closure_violation=self.closure_violation[sl],
            metadata=self.metadata,
            energy={k: v[sl] for k, v in self.energy.items()},
            joint_reactions={k: v[sl] for k, v in self.joint_reactions.items()},
            body_poses=self.body_poses[sl] if len(self.body_poses) else self.body_poses,
            sliders={k: v.sliced(sl) for k, v in self.sliders.items()},
        )

    def decimated(self, every: int) -> SimulationResult:
        """Every ``every``-th row, starting at the first."""
        if every < 1:
            raise ValueError(f"every must be >= 1 (got {every})")
        return self.sliced(slice(None, None, every))

    @staticmethod
    def concatenate(parts: list[SimulationResult]) -> SimulationResult:
        """Join consecutive results of the same run (metadata of the first)."""
        if not parts:
            raise ValueError("concatenate needs at least one result")
        first = parts[0]
        cat = np.concatenate
        return SimulationResult(
            times=cat([p.times for p in parts]),
            outputs={k: cat([p.outputs[k] for p in parts]) for k in first.outputs},
            joints={k: JointResult.concatenate([p.joints[k] for p in parts]) for k in first.joints},
            drive_angle=cat([p.drive_angle for p in parts]),
            drive_speed=cat([p.drive_speed for p in parts]),
            drive_torque=cat([p.drive_torque for p in parts]),
            link_poses=cat([p.link_poses for p in parts]),
            closure_violation=cat([p.closure_violation for p in parts]),
            metadata=first.metadata,
            energy={k: cat([p.energy[k] for p in parts]) for k in first.energy},
            joint_reactions={k: cat([p.joint_reactions[k] for p in parts]) for k in first.joint_reactions},
            body_poses=cat([p.body_poses for p in parts]) if len(first.body_poses) else first.body_poses,
            sliders={
                k: SliderResult(*(cat([getattr(p.sliders[k], f) for p in parts]) for f in SLIDER_FIELDS))
                for k in first.sliders
            },
        )

    def arrays(self) -> dict[str, np.ndarray]:
        """Every series of the result by its name in the saved ``.npz`` (``times``,
        ``output/<name>``, ``joint/<joint>/<field>``, ``energy/<term>``, ``reaction/<joint>``,
        ``slider/<joint>/<field>``, ...)."""
        arrays: dict[str, np.ndarray] = {
            "times": self.times,
            "drive_angle": self.drive_angle,
            "drive_speed": self.drive_speed,
            "drive_torque": self.drive_torque,
            "link_poses": self.link_poses,
            "closure_violation": self.closure_violation,
        }
        for k, v in self.outputs.items():
            arrays[f"output/{k}"] = v
        for j, jr in self.joints.items():
            for f, v in jr.series().items():
                arrays[f"joint/{j}/{f}"] = v
        for k, v in self.energy.items():
            arrays[f"energy/{k}"] = v
        for k, v in self.joint_reactions.items():
            arrays[f"reaction/{k}"] = v
        if len(self.body_poses):
            arrays["body_poses"] = self.body_poses
        for j, sr in self.sliders.items():
            for f in SLIDER_FIELDS:
                arrays[f"slider/{j}/{f}"] = getattr(sr, f)
        return arrays

    # -- persistence --------------------------------------------------------------------
    def save(self, path: str | os.PathLike, *, compress: bool = False) -> tuple[Path, Path]:
        """Save to ``<stem>.npz`` and ``<stem>.json``; returns both paths.

        The energy series go into the ``.npz`` (``energy/<term>``); with them, the JSON's
        ``energy_balance`` is the summary of the saved rows (`energy_balance`), written even if
        the metadata in memory has none.

        Args:
            path: file path; any suffix is replaced.
            compress: deflate the arrays (`numpy.savez_compressed`). The default run's two files
                then take 4.3 MB instead of 7.4 MB, but 0.23 s to write instead of 4 ms (numpy 2.4,
                benchmarks/startup_time.md), so runs are saved as they are and stores of many runs
                (`clearance.analysis.sweeps.run_store`) compress. `load` reads either.
        """
        import io

        stem = Path(path).with_suffix("")
        arrays = self.arrays()
        buf = io.BytesIO()
        # numpy's stubs type **kwds against the allow_pickle keyword (absent before numpy 2.1) too
        (np.savez_compressed if compress else np.savez)(buf, **arrays)  # type: ignore[arg-type]
        npz, js = stem.with_suffix(".npz"), stem.with_suffix(".json")
        meta = dict(self.metadata)
        meta["output_names"] = list(self.outputs)
        meta["joint_names"] = list(self.joints)
        if self.energy:
            # the summary always describes the arrays saved beside it
            meta["energy_balance"] = self.energy_balance()
            meta["energy_names"] = list(self.energy)
        meta["reaction_names"] = list(self.joint_reactions)
        meta["slider_names"] = list(self.sliders)
        atomic_write_bytes(npz, buf.getvalue())
        atomic_write_text(js, json.dumps(meta, indent=2, sort_keys=True, default=_json_default))
        return npz, js

    @classmethod
    def load(cls, path: str | os.PathLike) -> SimulationResult:
        """Load a result saved by `save` (give either file or the stem)."""
        stem = Path(path).with_suffix("")
        meta = json.loads(stem.with_suffix(".json").read_text())
        out_names = meta.pop("output_names")
        joint_names = meta.pop("joint_names")
        energy_names = meta.pop("energy_names", [])  # absent in files saved before energy series existed
        reaction_names = meta.pop("reaction_names", [])  # absent in files saved before reactions existed
        slider_names = meta.pop("slider_names", [])  # absent in files saved before sliders had play
        with np.load(stem.with_suffix(".npz"), allow_pickle=False) as z:
            return cls(
                times=z["times"],
                outputs={k: z[f"output/{k}"] for k in out_names},
                # a joint's optional series (a lubricated joint's film force) only where saved
                joints={j: JointResult.from_series(_joint_arrays(z, j)) for j in joint_names},
                drive_angle=z["drive_angle"],
                drive_speed=z["drive_speed"],
                drive_torque=z["drive_torque"],
                link_poses=z["link_poses"],
                closure_violation=z["closure_violation"],
                metadata=meta,
                energy={k: z[f"energy/{k}"] for k in energy_names},
                joint_reactions={k: z[f"reaction/{k}"] for k in reaction_names},
                body_poses=z["body_poses"] if "body_poses" in z.files else np.zeros((0, 0, 7)),
                sliders={j: SliderResult(*(z[f"slider/{j}/{f}"] for f in SLIDER_FIELDS)) for j in slider_names},
            )


def _joint_arrays(z: Any, joint: str) -> dict[str, np.ndarray]:
    """A saved joint's series by field name, from an open ``.npz`` (``joint/<joint>/<field>``)."""
    prefix = f"joint/{joint}/"
    return {k[len(prefix) :]: z[k] for k in z.files if k.startswith(prefix) and "/" not in k[len(prefix) :]}


def _json_default(o: object) -> object:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if hasattr(o, "value"):
        return o.value
    raise TypeError(f"not JSON-serialisable: {type(o).__name__}")
