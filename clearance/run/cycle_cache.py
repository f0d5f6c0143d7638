"""A cache of the ideal cycle's pose-dependent parts (`clearance.run.cycle.CycleShape`).

The parts depend on the mechanism's links, joints, drives and gravity, but not on its drive's
speed (they are kept at unit speed when the loads scale with it), its clearances' sizes or their
contact properties (laws, materials, restitution, friction, lubrication), nor on the model
options: every point of a sweep over speed or clearance shares one shape. `cycle_key` writes
what they depend on as canonical JSON.

Two levels: a dictionary in the process (`MEMORY_ENTRIES` shapes, oldest dropped first) and
JSON files in ``<cache>/sizing/`` beside the calibration store (`clearance.contact_calibration.
store.cache_dir`), shared by the processes of a sweep. A file is named
``cycle-<first 24 hex digits of the SHA-256 of its key>.json`` and stores the key, so a hash
collision or an edited file is detected; floats are written as Python's shortest round-trip
repr, so a shape read back is bitwise the one computed. Writes are atomic (a temporary file, then
`os.replace`). A file that cannot be read, parsed or checked is reported with a
`CycleCacheWarning` naming it, and computed again and rewritten; a folder that cannot be written
is reported the same way and the shape is used without being stored.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import json
import warnings
from collections import OrderedDict
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from clearance.contact_calibration.store import cache_dir
from clearance.model import Mechanism
from clearance.results import atomic_write_bytes
from clearance.run.cycle import (
    CYCLE_TIMES,
    MASS_POSES,
    CycleShape,
    IdealCycle,
    canonical_mechanism,
    cycle_shape,
    scale_cycle,
)

__all__ = [
    "CYCLE_VERSION",
    "MEMORY_ENTRIES",
    "CycleCacheWarning",
    "clear_memory",
    "cycle_key",
    "cycle_path",
    "ideal_cycle",
]

CYCLE_VERSION = 1
"""Version of the shape's computation; a change makes every stored shape a miss."""

MEMORY_ENTRIES = 64
"""Shapes kept in the process."""

_MEMORY: OrderedDict[str, CycleShape] = OrderedDict()


class CycleCacheWarning(UserWarning):
    """A stored cycle shape was unreadable or inconsistent (it is computed again), or could not be
    written (it is used without being stored)."""


def _plain(value: Any) -> Any:
    """A JSON-ready copy of a data-model value: dataclasses as dicts, enums as their values."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in sorted(value.items())}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def cycle_key(mechanism: Mechanism) -> str:
    """What a mechanism's cycle shape depends on, as canonical JSON (module docstring).

    A clearance enters as the journal's side only; a slider's play whole (the guide's geometry
    enters its model); the drive as `clearance.run.cycle.canonical_mechanism` has it.
    """
    canon = canonical_mechanism(mechanism)
    joints = []
    for j in canon.joints:
        d = _plain(dataclasses.replace(j, clearance=None))
        d["clearance"] = None if j.clearance is None else {"journal_link": j.clearance.journal_link}
        joints.append(d)
    key = {
        "version": CYCLE_VERSION,
        "times": CYCLE_TIMES,
        "poses": MASS_POSES,
        "links": _plain(canon.links),
        "joints": joints,
        "drives": _plain(canon.drives),
        "ground": canon.ground,
        "gravity": _plain(canon.gravity),
        "numpy": np.__version__,
        "mujoco": mujoco.__version__,
    }
    return json.dumps(key, sort_keys=True, separators=(",", ":"))


def cycle_path(key: str, directory: Path | None = None) -> Path:
    """File of a key's shape (``directory``: default ``<cache>/sizing``)."""
    folder = directory if directory is not None else cache_dir().parent / "sizing"
    return folder / f"cycle-{hashlib.sha256(key.encode('utf-8')).hexdigest()[:24]}.json"


def clear_memory() -> None:
    """Forget the shapes kept in this process (the files stay)."""
    _MEMORY.clear()


def _to_json(key: str, shape: CycleShape) -> bytes:
    arrays = lambda d: {k: v.tolist() for k, v in d.items()}  # noqa: E731
    doc = {
        "key": json.loads(key),
        "shape": {
            "times": shape.times.tolist(),
            "unit_speed": shape.unit_speed,
            "inertial": arrays(shape.inertial),
            "gravity": arrays(shape.gravity),
            "mobility": arrays(shape.mobility),
        },
    }
    return json.dumps(doc, sort_keys=True).encode("utf-8")


def _from_json(key: str, raw: bytes) -> CycleShape:
    """The shape a file holds; ValueError, KeyError or TypeError when it is not a shape of ``key``."""
    doc = json.loads(raw.decode("utf-8"))
    if json.dumps(doc["key"], sort_keys=True, separators=(",", ":")) != key:
        raise ValueError("its key does not match the mechanism")
    s = doc["shape"]
    arrays = lambda d, shape: {k: _array(v, shape, k) for k, v in d.items()}  # noqa: E731
    shape = CycleShape(
        _array(s["times"], (CYCLE_TIMES,), "times"),
        bool(s["unit_speed"]),
        arrays(s["inertial"], (CYCLE_TIMES, 2)),
        arrays(s["gravity"], (CYCLE_TIMES, 2)),
        arrays(s["mobility"], (MASS_POSES, 2, 2)),
    )
    if set(shape.inertial) != set(shape.gravity) or not set(shape.mobility) <= set(shape.inertial):
        raise ValueError("its loads and mobilities name different joints")
    return shape


def _array(value: Any, shape: tuple[int, ...], what: str) -> np.ndarray:
    out = np.asarray(value, dtype=float)
    if out.shape != shape or not np.isfinite(out).all():
        raise ValueError(f"'{what}' is not a finite array of shape {shape}")
    return out


def _load(key: str, path: Path) -> CycleShape | None:
    try:
        raw = path.read_bytes()
    except (FileNotFoundError, NotADirectoryError):
        return None
    try:
        return _from_json(key, raw)
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        warnings.warn(
            f"cycle cache file {path} is corrupt or inconsistent ({type(exc).__name__}: {exc}); "
            "ignoring it and computing the cycle again",
            CycleCacheWarning,
            stacklevel=3,
        )
        return None


def _store(key: str, shape: CycleShape, path: Path) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(path, _to_json(key, shape))
    except OSError as exc:
        warnings.warn(
            f"cannot write the cycle cache file {path} ({type(exc).__name__}: {exc}); the cycle is used "
            "without being stored",
            CycleCacheWarning,
            stacklevel=3,
        )


def ideal_cycle(mechanism: Mechanism, *, directory: Path | None = None) -> IdealCycle:
    """The mechanism's ideal cycle at its own speed, its shape from the cache when there.

    A shape computed here is the one stored: a point that finds it in the cache gets bitwise the
    cycle it would compute.

    Args:
        mechanism: the mechanism.
        directory: folder of the shape files (default ``<cache>/sizing``).

    Returns:
        `clearance.run.cycle.scale_cycle` of the shape.

    Raises:
        AssemblyError: the mechanism cannot be assembled, or reaches a singular position, over
            the cycle (on a miss).
    """
    key = cycle_key(mechanism)
    shape = _MEMORY.get(key)
    if shape is None:
        path = cycle_path(key, directory)
        shape = _load(key, path)
        if shape is None:
            shape = cycle_shape(mechanism)
            _store(key, shape, path)
        _MEMORY[key] = shape
        while len(_MEMORY) > MEMORY_ENTRIES:
            _MEMORY.popitem(last=False)
    else:
        _MEMORY.move_to_end(key)
    return scale_cycle(shape, mechanism)
