"""`SimulationResult`: the one record every solver returns and every analysis reads.

A result saves to ``<stem>.npz`` (arrays) plus ``<stem>.json`` (metadata) and loads back
losslessly. Both files are written atomically (temporary file, then rename).
"""

from __future__ import annotations

import json
import os
import secrets
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["JointResult", "SimulationResult", "atomic_write_bytes", "atomic_write_text", "temporary_file_beside"]


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


@dataclass
class JointResult:
    """Per-clearance-joint series, all in the bearing frame.

    Attributes:
        eccentricity: (n, 2) journal-centre position relative to the bearing centre [m].
        eccentricity_rate: (n, 2) its time derivative [m/s].
        penetration: (n,) |e| - c [m]; positive means in contact.
        contact_force: (n, 2) net contact force on the journal [N].
    """

    eccentricity: np.ndarray
    eccentricity_rate: np.ndarray
    penetration: np.ndarray
    contact_force: np.ndarray

    @property
    def force_magnitude(self) -> np.ndarray:
        """(n,) magnitude of the contact force [N]."""
        return np.hypot(self.contact_force[:, 0], self.contact_force[:, 1])

    def sliced(self, sl: slice | np.ndarray) -> JointResult:
        """The same series restricted to ``sl`` (rows)."""
        return JointResult(
            self.eccentricity[sl],
            self.eccentricity_rate[sl],
            self.penetration[sl],
            self.contact_force[sl],
        )


_JOINT_FIELDS = ("eccentricity", "eccentricity_rate", "penetration", "contact_force")


@dataclass
class SimulationResult:
    """A simulated run of a mechanism (MuJoCo or the reference solver).

    Attributes:
        times: (n,) [s].
        outputs: name -> (n,) output position [m or rad]; ``<name>_vel`` and ``<name>_acc``
            hold its first and second time derivatives.
        joints: clearance joint name -> `JointResult`.
        drive_angle, drive_speed, drive_torque: (n, n_drives) [rad, rad/s, N m].
        link_poses: (n, n_links, 3) pose (x [m], y [m], theta [rad]) of each moving link.
        closure_violation: (n,) largest ideal loop-closure error [m] (zeros if none).
        metadata: mechanism name and parameters, solver, time step, segment count, geom
            types, contact mode and parameters, versions, wall time (JSON-serialisable).
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

    def __len__(self) -> int:
        return len(self.times)

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
            joints={
                k: JointResult(*(cat([getattr(p.joints[k], f) for p in parts]) for f in _JOINT_FIELDS))
                for k in first.joints
            },
            drive_angle=cat([p.drive_angle for p in parts]),
            drive_speed=cat([p.drive_speed for p in parts]),
            drive_torque=cat([p.drive_torque for p in parts]),
            link_poses=cat([p.link_poses for p in parts]),
            closure_violation=cat([p.closure_violation for p in parts]),
            metadata=first.metadata,
        )

    # -- persistence --------------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> tuple[Path, Path]:
        """Save to ``<stem>.npz`` and ``<stem>.json``; returns both paths.

        Args:
            path: file path; any suffix is replaced.
        """
        import io

        stem = Path(path).with_suffix("")
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
            for f in _JOINT_FIELDS:
                arrays[f"joint/{j}/{f}"] = getattr(jr, f)
        buf = io.BytesIO()
        # numpy's stubs type **kwds against the allow_pickle keyword (absent before numpy 2.1) too
        np.savez_compressed(buf, **arrays)  # type: ignore[arg-type]
        npz, js = stem.with_suffix(".npz"), stem.with_suffix(".json")
        meta = dict(self.metadata)
        meta["output_names"] = list(self.outputs)
        meta["joint_names"] = list(self.joints)
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
        with np.load(stem.with_suffix(".npz"), allow_pickle=False) as z:
            return cls(
                times=z["times"],
                outputs={k: z[f"output/{k}"] for k in out_names},
                joints={j: JointResult(*(z[f"joint/{j}/{f}"] for f in _JOINT_FIELDS)) for j in joint_names},
                drive_angle=z["drive_angle"],
                drive_speed=z["drive_speed"],
                drive_torque=z["drive_torque"],
                link_poses=z["link_poses"],
                closure_violation=z["closure_violation"],
                metadata=meta,
            )


def _json_default(o: object) -> object:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if hasattr(o, "value"):
        return o.value
    raise TypeError(f"not JSON-serialisable: {type(o).__name__}")
