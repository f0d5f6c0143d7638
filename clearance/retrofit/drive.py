"""Driving a retrofitted model and its twin: a control sequence from a CSV file, or a sinusoid.

A control file is a CSV table: a header row ``time_s,<actuator>,<actuator>,...`` naming
every actuator of the model once (an unnamed actuator is ``#k``, its index), then one row
per time [s], strictly increasing and finite. Controls between rows are interpolated
linearly; before the first row and after the last they hold the row's values. The sinusoid
is `SineControl` (`clearance.retrofit.motion.control_signal`), the motion the retrofit was
sized from. Both models get the same controls at the same times.
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path

import mujoco
import numpy as np

from clearance.retrofit.motion import control_signal
from clearance.retrofit.play import ControlTable, RetrofitError, SineControl

__all__ = ["TIME_COLUMN", "ControlTable", "Drive", "actuator_labels", "read_control_file", "drive_controls"]

TIME_COLUMN = "time_s"


def actuator_labels(model: mujoco.MjModel) -> list[str]:
    """Each actuator's name in a control file: its name, or ``#k`` when it has none."""
    return [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, k) or f"#{k}" for k in range(model.nu)]


Drive = ControlTable | SineControl
"""What drives a run: a control sequence or the sinusoid on every actuator."""


def read_control_file(path: str | os.PathLike[str], labels: list[str]) -> ControlTable:
    """Read a control file for a model whose actuators are ``labels`` (`actuator_labels`).

    Raises:
        RetrofitError: a missing or unreadable file, a header that does not start with
            ``time_s`` or does not name every actuator once (an unknown one named), a row of
            the wrong column count, a value that is not a finite number, times that do not
            increase; the message names the file, line and column.
    """
    p = Path(path)
    where = f"control file {p}"
    if not p.is_file():
        raise RetrofitError(f"{where} does not exist" if not p.exists() else f"{where} is not a file")
    try:
        with p.open(newline="") as f:
            rows = [r for r in csv.reader(f) if r and any(c.strip() for c in r)]
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise RetrofitError(f"{where} cannot be read: {err}") from None
    if len(rows) < 2:
        raise RetrofitError(f"{where}: expected a header row and at least one row of controls")
    header = [c.strip() for c in rows[0]]
    if header[0] != TIME_COLUMN:
        raise RetrofitError(f"{where}: the first column must be '{TIME_COLUMN}' (got {header[0]!r})")
    names = header[1:]
    unknown = [n for n in names if n not in labels]
    if unknown:
        raise RetrofitError(
            f"{where}: unknown actuator {unknown[0]!r} in the header (the model's: {', '.join(labels)})"
        )
    twice = sorted({n for n in names if names.count(n) > 1})
    missing = [n for n in labels if n not in names]
    if twice or missing:
        what = f"names {twice[0]!r} twice" if twice else f"lacks actuator {missing[0]!r}"
        raise RetrofitError(
            f"{where}: the header {what}; expected {TIME_COLUMN} and one column per actuator ({', '.join(labels)})"
        )
    table = np.empty((len(rows) - 1, len(header)))
    for i, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise RetrofitError(f"{where}, line {i}: {len(row)} columns, expected {len(header)} (as the header)")
        for k, cell in enumerate(row):
            try:
                v = float(cell)
            except ValueError:
                v = math.nan
            if not math.isfinite(v):
                raise RetrofitError(f"{where}, line {i}, column {header[k]!r}: {cell.strip()!r} is not a finite number")
            table[i - 2, k] = v
    times = table[:, 0]
    if len(times) > 1 and not (np.diff(times) > 0).all():
        i = int(np.argmin(np.diff(times) > 0)) + 3
        raise RetrofitError(f"{where}, line {i}: the times must increase strictly")
    order = [names.index(n) + 1 for n in labels]
    return ControlTable(times, table[:, order], str(p))


def drive_controls(model: mujoco.MjModel, drive: Drive, times: np.ndarray) -> np.ndarray:
    """(len(times), nu) controls of ``drive`` at ``times`` [s] for ``model``'s actuators
    (`clearance.retrofit.motion.control_signal`)."""
    return control_signal(model, drive, times)
