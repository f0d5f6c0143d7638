"""The unit of every series and number a saved run holds: the ``units`` entry of ``result.json``.

Everything a `SimulationResult` saves is in SI; the names do not always say which SI unit
(``time_step``, ``drive_torque``, ``output/slider_x_acc``). `result_units` lists them: each
array of the ``.npz`` by its name, and the metadata's numbers at the top level, so a script
reading the files needs no other document.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable

__all__ = ["METADATA_UNITS", "array_unit", "result_units"]

METADATA_UNITS: dict[str, str] = {
    "time_step": "s",
    "wall_time_s": "s",
    "steps": "-",
    "steps_per_second": "1/s",
    "output_every_steps": "-",
    "parameters": "SI: lengths m, masses kg, inertias kg m^2, speeds rad/s, angles rad, moduli Pa",
    "sizing.effective_mass": "kg",
    "sizing.impact_speed": "m/s",
    "sizing.median_load": "N",
    "sizing.peak_load": "N",
    "sizing.penetration_limit": "m",
    "sizing.stiffness": "N/m^1.5",
    "sizing.typical_penetration": "m",
    "contact.stiffness": "N/m^1.5",
    "contact.stiffness_per_row": "N/m (MuJoCo's solref direct mode, per row)",
    "contact.damping_per_row": "N s/m (MuJoCo's solref direct mode, per row)",
    "energy_balance": "J",
}
"""Units of the metadata's numbers (``sizing.<key>``: a key of each joint's sizing record)."""

_JOINT_ARRAYS = {
    "eccentricity": "m",
    "eccentricity_rate": "m/s",
    "penetration": "m",
    "contact_force": "N",
    "film_force": "N",
    "approach_speed": "m/s",
    "friction_force": "N",
    "contact_torque": "N m",
}
_TOP_ARRAYS = {
    "times": "s",
    "drive_angle": "rad",
    "drive_speed": "rad/s",
    "drive_torque": "N m",
    "link_poses": "m, m, rad (x, y, theta of each moving link)",
    "closure_violation": "m",
    "body_poses": "m, m, m, - (position, then the orientation quaternion)",
}


def array_unit(name: str, angular_outputs: Collection[str] = ()) -> str:
    """The unit of one array of a saved run, by its name in the ``.npz``.

    Args:
        name: the array's name (``times``, ``output/slider_x_acc``, ``joint/rod_slider/penetration``,
            ``energy/kinetic``, ``reaction/crank_pivot``).
        angular_outputs: the outputs that are angles (their series are in rad, rad/s, rad/s²);
            the others are positions (m, m/s, m/s²).

    Returns:
        The unit, ``-`` for a dimensionless array, or ``see the metadata`` for one not known here.
    """
    if name in _TOP_ARRAYS:
        return _TOP_ARRAYS[name]
    kind, _, rest = name.partition("/")
    if kind == "output":
        base = rest.removesuffix("_vel").removesuffix("_acc")
        length = "rad" if base in angular_outputs else "m"
        return length + ("/s" if rest.endswith("_vel") else "/s^2" if rest.endswith("_acc") else "")
    if kind == "joint":
        return _JOINT_ARRAYS.get(rest.rpartition("/")[2], "see the metadata")
    if kind == "energy":
        return "J"
    if kind == "reaction":
        return "N"
    return "see the metadata"


def result_units(array_names: Iterable[str], angular_outputs: Collection[str] = ()) -> dict[str, object]:
    """The ``units`` entry of a saved run: every array's unit and the metadata's.

    Args:
        array_names: the names of the arrays saved (`SimulationResult.arrays`' keys).
        angular_outputs: the outputs that are angles.

    Returns:
        ``{"arrays": {name: unit}, "metadata": METADATA_UNITS}``.
    """
    return {
        "arrays": {name: array_unit(name, angular_outputs) for name in array_names},
        "metadata": dict(METADATA_UNITS),
    }
