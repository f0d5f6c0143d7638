"""What a run reads at a hinge with backlash: the angle in the band and the torque at its ends.

A backlash retrofit (`clearance.retrofit.backlash`) puts a dead band between a motor side and
the hinge (the load side): a fixed tendon q_load - q_motor limited to +-b, or, for an 'exact'
stop, unlimited and closed by a `clearance.backlash_stop` plugin instance. Per row of a run
this module reads

- the backlash angle q_load - q_motor [rad] (the tendon's length), from the row's qpos;
- the stop's torque [N m]: the tendon limit's constraint force (a ``tendonlimitfrc`` sensor,
  which `add_backlash_sensors` adds to the model before it is compiled for the run; MuJoCo
  gives it as a magnitude, zero while the angle is inside the band); for an exact stop, the
  law's torque T >= 0 from the plugin's own sensor (its first value), which the retrofit
  already put in the model.

They become the outputs ``backlash/<hinge>/angle`` and ``backlash/<hinge>/torque`` of the run's
`SimulationResult`.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from clearance.retrofit.backlash import stop_plugin_name
from clearance.retrofit.manifest import BacklashRecord

__all__ = ["BacklashReader", "add_backlash_sensors", "backlash_output_names", "torque_sensor_name"]


def torque_sensor_name(hinge: str, stop: str = "calibrated") -> str:
    """The name of the sensor of ``hinge``'s stop torque (the plugin's sensor for an 'exact' ``stop``)."""
    return stop_plugin_name(hinge) if stop == "exact" else f"clr_{hinge}__backlash_torque"


def backlash_output_names(hinge: str) -> tuple[str, str]:
    """Output names of a backlashed hinge's angle [rad] and stop torque [N m]."""
    return f"backlash/{hinge}/angle", f"backlash/{hinge}/torque"


def add_backlash_sensors(spec: mujoco.MjSpec, records: Sequence[BacklashRecord]) -> None:
    """Add to ``spec`` a ``tendonlimitfrc`` sensor on each record's dead-band tendon (none already there).

    An exact stop's record gets none: its plugin's sensor is in the model already.
    """
    have = {s.name for s in spec.sensors}
    for r in records:
        if r.stop == "exact":
            continue
        name = torque_sensor_name(r.name)
        if name not in have:
            spec.add_sensor(
                name=name,
                type=mujoco.mjtSensor.mjSENS_TENDONLIMITFRC,
                objtype=mujoco.mjtObj.mjOBJ_TENDON,
                objname=r.tendon,
            )


class BacklashReader:
    """Rows of a run (sensor rows and qpos) -> the backlash outputs of each hinge."""

    def __init__(self, model: mujoco.MjModel, records: Sequence[BacklashRecord]) -> None:
        """Index the hinges' coordinates and torque sensors in ``model``.

        Raises:
            KeyError: a hinge, motor hinge or torque sensor ``model`` lacks.
        """
        self.records = list(records)
        self.load = [int(model.joint(r.name).qposadr[0]) for r in self.records]
        self.motor = [int(model.joint(r.motor_joint).qposadr[0]) for r in self.records]
        self.sensor = [int(model.sensor(torque_sensor_name(r.name, r.stop)).adr[0]) for r in self.records]

    def read(self, sens: np.ndarray, q: np.ndarray) -> dict[str, np.ndarray]:
        """Output name -> (n,) series for sensor rows ``sens`` (n, nsensordata) and positions ``q`` (n, nq)."""
        out: dict[str, np.ndarray] = {}
        for r, load, motor, adr in zip(self.records, self.load, self.motor, self.sensor):
            angle, torque = backlash_output_names(r.name)
            out[angle] = q[:, load] - q[:, motor]
            out[torque] = np.abs(sens[:, adr])
        return out
