"""retrofit.json: what a run of a written retrofit needs, machine-readable.

`retrofit.md` is for people; `retrofit.json` beside it is for `clearance run --model DIR`:
the model files, the time step the stability rule chose, and per hinge the names of its
slides, sites and sensors, its clearance and its divergence bound, and where the unmodified
model's coordinates sit in the retrofitted one. A backlash retrofit records, per hinge, its
motor side and dead-band tendon (`BacklashRecord`) and no radial hinges; files written
before backlash existed have no ``backlash`` field and read as none.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from clearance.retrofit.play import RetrofitError

__all__ = [
    "MANIFEST_FILE",
    "FORMAT",
    "ROBOT_STEP_BOUND",
    "ROBOT_STEP_MODE",
    "BacklashRecord",
    "HingeRecord",
    "RetrofitManifest",
    "read_manifest",
]

MANIFEST_FILE = "retrofit.json"

ROBOT_STEP_MODE = "robot step"
"""The manifest's contact mode of radial play held by tendon-limit stops at the robot's step."""

ROBOT_STEP_BOUND = 4.0
"""A robot-step stop's divergence bound over its deepest penetration at the sized closing speed [-]
(as a ring's is 4 x the Hertz penetration of the sized impact)."""
FORMAT = 1
"""Version of the file's layout."""


@dataclass(frozen=True)
class HingeRecord:
    """One retrofitted hinge as a run reads it.

    Attributes:
        name: the hinge.
        slides: its x and y slides (their coordinates are the journal centre in the bearing frame).
        journal_site, bearing_site: sites at the journal and bearing centres (bearing-frame axes).
        journal_body, bearing_body: child and parent body names (``#id`` if unnamed).
        eccentricity_sensor, force_sensor: the sensors added for it.
        radial_clearance: c [m].
        bearing_radius: R_B [m].
        penetration_limit: divergence bound [m] (4 x the Hertz penetration of the sized impact).
        segments: ring segments (0: the compiled exact contact, whose sensor is ``force_sensor``).
    """

    name: str
    slides: tuple[str, str]
    journal_site: str
    bearing_site: str
    journal_body: str
    bearing_body: str
    eccentricity_sensor: str
    force_sensor: str
    radial_clearance: float
    bearing_radius: float
    penetration_limit: float
    segments: int


@dataclass(frozen=True)
class BacklashRecord:
    """One hinge with backlash as a run reads it.

    Attributes:
        name: the hinge (the load side, the link).
        motor_joint: the motor side's hinge on the same axis (it takes the actuators).
        motor_body: the motor body.
        tendon: the dead band's fixed tendon, q_load - q_motor, limited to +-``half_width``
            (unlimited for an 'exact' stop).
        half_width: b [rad].
        actuators: the actuators moved to the motor side (names, or ``#k``).
        stop: what closes the band, one of `clearance.retrofit.play.STOPS`; records written
            before the exact stop existed have none and read as 'calibrated' (a tendon limit,
            which is all a run needs to know of a 'recipe' stop too).
    """

    name: str
    motor_joint: str
    motor_body: str
    tendon: str
    half_width: float
    actuators: tuple[str, ...]
    stop: str = "calibrated"


@dataclass(frozen=True)
class RetrofitManifest:
    """The machine-readable record of a written retrofit.

    Attributes:
        model: the retrofitted model's file name (in the same folder).
        original: the unmodified twin's file name.
        timestep: the retrofitted model's time step [s] (the twin is run at it too).
        original_timestep: the unmodified model's own time step [s].
        contact_mode: 'calibrated', 'nominal', 'exact', 'robot step' (`ROBOT_STEP_MODE`: radial play held by
            tendon-limit stops at the robot's step) or 'backlash'.
        hinges: the retrofitted hinges, in the order given.
        qpos_map, qvel_map: index in the retrofitted qpos / qvel of each unmodified entry.
        backlash: the hinges given backlash, in the order given (empty for radial play).
    """

    model: str
    original: str
    timestep: float
    original_timestep: float
    contact_mode: str
    hinges: tuple[HingeRecord, ...]
    qpos_map: tuple[int, ...]
    qvel_map: tuple[int, ...]
    backlash: tuple[BacklashRecord, ...] = ()

    def __post_init__(self) -> None:
        for name in ("timestep", "original_timestep"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise RetrofitError(f"{name} must be a finite time step > 0 [s] (got {v!r})")

    def to_json(self) -> str:
        """The file's text."""
        body: dict[str, Any] = {"format": FORMAT, **asdict(self)}
        return json.dumps(body, indent=2)

    @classmethod
    def from_json(cls, text: str, where: str = "retrofit.json") -> RetrofitManifest:
        """Parse the file's text; `RetrofitError` naming ``where`` and the field when it is not one."""
        try:
            raw = json.loads(text)
            if raw.get("format") != FORMAT:
                raise RetrofitError(f"{where}: format {raw.get('format')!r} is not {FORMAT}")
            hinges = tuple(HingeRecord(**{**h, "slides": tuple(h["slides"])}) for h in raw["hinges"])
            return cls(
                model=str(raw["model"]),
                original=str(raw["original"]),
                timestep=float(raw["timestep"]),
                original_timestep=float(raw["original_timestep"]),
                contact_mode=str(raw["contact_mode"]),
                hinges=hinges,
                qpos_map=tuple(int(i) for i in raw["qpos_map"]),
                qvel_map=tuple(int(i) for i in raw["qvel_map"]),
                backlash=tuple(
                    BacklashRecord(**{**b, "actuators": tuple(b["actuators"])}) for b in raw.get("backlash", [])
                ),
            )
        except RetrofitError as err:
            if str(err).startswith(where):
                raise
            raise RetrofitError(f"{where}: {err}; write it again with clearance retrofit") from None
        except (ValueError, KeyError, TypeError, AttributeError) as err:
            raise RetrofitError(
                f"{where} is not a retrofit record ({type(err).__name__}: {err}); "
                "write it again with clearance retrofit"
            ) from None

    def hinge(self, name: str) -> HingeRecord:
        """The record of hinge ``name``."""
        for h in self.hinges:
            if h.name == name:
                return h
        raise KeyError(name)


def read_manifest(folder: str | os.PathLike[str]) -> RetrofitManifest:
    """The manifest of the retrofit written in ``folder``.

    Raises:
        RetrofitError: no ``retrofit.json`` there (naming the folder), or one that is not a record.
    """
    path = Path(folder) / MANIFEST_FILE
    if not path.is_file():
        raise RetrofitError(
            f"{folder}: no {MANIFEST_FILE} (expected a folder written by clearance retrofit, with model.xml, "
            f"original.xml and {MANIFEST_FILE})"
        )
    return RetrofitManifest.from_json(path.read_text(), str(path))
