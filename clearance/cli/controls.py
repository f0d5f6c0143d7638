"""Control files on the command line: read, and refused where MuJoCo would clamp them silently.

An actuator with a ``ctrlrange`` (``ctrllimited``) has its control clamped into the range by
MuJoCo, so a control file asking for more would run a different motion than it says, without a
word. `read_controls` refuses such a file before any work, naming the file, the column, the
time, the value and the range.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco

    from clearance.retrofit.play import ControlTable

__all__ = ["check_sine_amplitude", "read_controls"]


def read_controls(path: str, model: mujoco.MjModel, option: str) -> ControlTable:
    """The control file ``path`` for ``model``'s actuators, every value inside its actuator's range.

    Args:
        path: the CSV file (``time_s`` and one column per actuator, `clearance.retrofit.drive`).
        model: the model whose actuators it drives.
        option: the option that gave it, for the message (``--control``, ``--sizing-control``).

    Returns:
        The control table.

    Raises:
        ValueError: the file cannot be read as a control file (`read_control_file`'s message),
            or a value lies outside its actuator's ``ctrlrange``.
    """
    import numpy as np

    from clearance.retrofit.drive import actuator_labels, read_control_file

    labels = actuator_labels(model)
    try:
        table = read_control_file(path, labels)
    except ValueError as err:
        raise ValueError(f"{option} {path}: {err}") from None
    for k, label in enumerate(labels):
        if not model.actuator_ctrllimited[k]:
            continue
        lo, hi = (float(v) for v in model.actuator_ctrlrange[k])
        column = table.values[:, k]
        outside = np.flatnonzero((column < lo) | (column > hi))
        if len(outside):
            i = int(outside[0])
            raise ValueError(
                f"{option} {path}, column {label!r}: {column[i]:g} at t = {table.times[i]:g} s lies outside the "
                f"actuator's ctrlrange [{lo:g}, {hi:g}], where MuJoCo would clamp it ({len(outside)} such "
                "row(s)); scale the column into the range, or widen the model's ctrlrange"
            )
    return table


def check_sine_amplitude(amplitude: float, model: mujoco.MjModel, option: str) -> None:
    """Refuse a sinusoid that would drive a range-limited actuator beyond its ``ctrlrange``.

    The amplitude is a fraction of each limited actuator's half-range (above 1 MuJoCo would
    clamp the peaks), and a control in the actuator's own units for one without a range.

    Args:
        amplitude: the ``--sine-amplitude``.
        model: the model driven.
        option: the option, for the message.

    Raises:
        ValueError: ``amplitude`` > 1 while some actuator has a ``ctrlrange``.
    """
    if amplitude <= 1:
        return
    limited = [k for k in range(model.nu) if model.actuator_ctrllimited[k]]
    if limited:
        from clearance.retrofit.drive import actuator_labels

        names = [actuator_labels(model)[k] for k in limited]
        raise ValueError(
            f"{option} {amplitude:g}: above 1 the sinusoid leaves the ctrlrange of {', '.join(names)} (the amplitude "
            "is a fraction of each limited actuator's half-range) and MuJoCo would clamp its peaks; give at most 1"
        )
