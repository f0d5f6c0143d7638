"""``clearance optimise --scenario``: a scenario file that names a builder, with an ``[optimise]`` section.

The file is an ordinary scenario (``[mechanism]`` with ``builder = "..."`` and keyword
overrides, units in the key names) plus a section of the optimisation's settings::

    [optimise]
    objective = "rms_deviation"
    stroke = [95, 105]            # mm for a position output, deg for an angle output
    rpm = [2000]
    runs = 20
    budget = 30

    [optimise.vary]
    rod_length_mm = [100, 200]            # [low, high] or [low, high, start]
    slider_mass_kg = [0.05, 0.4]
    "crank7_pivot_mm[1]" = [-30, 30]      # one component of a pair

Every key of ``[optimise]`` is an option of the command without its dashes (``confirm_seed``,
``timestep_us``, ``contact_mode``, ``output``, ``samples``, ``periods``, ``seed``); an option
given on the command line wins over the file, and ``--vary`` adds to the file's variables.
The mechanism is read by `clearance.builders.load_scenario` with the section blanked out
(so its errors keep their line numbers), and its builder keywords are converted to SI for
the design factory, which must rebuild exactly the mechanism the file describes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from clearance.cli.scenario_sections import split_section
from clearance.cli.sweep_common import UsageError
from clearance.model import ContactLaw, Mechanism
from clearance.units import UNITS, quantity_of

__all__ = ["SECTION_KEYS", "ScenarioDesign", "read_scenario_design", "section_vary"]

SECTION_KEYS = (
    "vary",
    "objective",
    "output",
    "stroke",
    "rpm",
    "runs",
    "periods",
    "samples",
    "budget",
    "seed",
    "confirm_seed",
    "timestep_us",
    "contact_mode",
)
"""Keys an ``[optimise]`` section may hold."""


@dataclass(frozen=True)
class ScenarioDesign:
    """A scenario file read for ``clearance optimise``.

    Attributes:
        path: the file.
        builder_name: the catalogue builder it names.
        keywords: its builder keywords in SI (``clearance_mm`` as ``radial_clearance``).
        section: the ``[optimise]`` table (empty when absent).
        mechanism: the mechanism the file describes.
    """

    path: Path
    builder_name: str
    keywords: dict[str, Any]
    section: dict[str, Any]
    mechanism: Mechanism


def _keyword(key: str, params: list[str]) -> tuple[str, float]:
    """(builder keyword, factor to SI) of a ``[mechanism]`` key (the scenario reader has accepted it)."""
    if key in params:
        return key, 1.0
    for alias, target in (("clearance_", "radial_clearance_"),):
        if key.startswith(alias) and not key.startswith("radial_"):
            key = target + key[len(alias) :]
    for p in sorted(params, key=len, reverse=True):
        q = quantity_of(p)
        if q is not None and key.startswith(p + "_") and key[len(p) + 1 :] in UNITS[q]:
            return p, UNITS[q][key[len(p) + 1 :]]
    raise UsageError(f"--scenario: key {key!r} of [mechanism] names no keyword of the builder")


def _si(keyword: str, value: Any, factor: float) -> Any:
    if keyword == "law":
        return ContactLaw(value)
    if keyword == "clearance_at":
        return tuple(value)
    if isinstance(value, list) and all(isinstance(v, (int, float)) for v in value):
        return tuple(float(v) * factor for v in value)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value) * factor
    if isinstance(value, str):
        return value
    raise UsageError(
        f"--scenario: [mechanism] {keyword} is a table or a list the design factory cannot take; optimise a "
        "scenario whose builder keywords are numbers, pairs, names and joint lists"
    )


def read_scenario_design(path: str) -> ScenarioDesign:
    """Read a scenario for ``clearance optimise``: its mechanism, builder keywords and ``[optimise]`` section.

    Raises:
        UsageError: the file cannot be read, does not name a catalogue builder, has an
            unknown key in ``[optimise]``, or keywords the design factory cannot rebuild.
        ScenarioError: the scenario itself is bad (a `ValueError` naming file, line and key).
    """
    import inspect

    from clearance.builders import CATALOGUE
    from clearance.builders.scenario import loads_scenario

    p = Path(path)
    split = split_section(p, "optimise")
    doc, section = split.document, split.section
    unknown = sorted(set(section) - set(SECTION_KEYS))
    if unknown:
        raise UsageError(f"--scenario {p}: [optimise] has unknown key(s) {unknown}; it takes {', '.join(SECTION_KEYS)}")
    mechanism = loads_scenario(split.scenario_text, source=str(p))
    table = doc.get("mechanism", {})
    name = table.get("builder") if isinstance(table, dict) else None
    if not isinstance(name, str) or name not in CATALOGUE:
        raise UsageError(
            f"--scenario {p}: optimise needs a scenario that names a catalogue builder ([mechanism] builder = ...), "
            "whose keywords are the design variables"
        )
    builder = CATALOGUE[name].builder
    params = list(inspect.signature(builder).parameters)
    keywords = {}
    for key, value in table.items():
        if key == "builder":
            continue
        keyword, factor = _keyword(key, params)
        keywords[keyword] = _si(keyword, value, factor)
    try:
        rebuilt = builder(**keywords)
    except (TypeError, ValueError, ArithmeticError) as err:
        raise UsageError(
            f"--scenario {p}: its builder keywords cannot be rebuilt for the design factory ({err})"
        ) from None
    if rebuilt != mechanism:
        raise UsageError(f"--scenario {p}: its builder keywords do not rebuild the mechanism the file describes")
    return ScenarioDesign(p, name, keywords, section, mechanism)


def section_vary(section: dict[str, Any], path: Path) -> list[str]:
    """The ``[optimise.vary]`` entries as ``--vary`` values (``key=low:high[:start]``).

    Raises:
        UsageError: an entry that is not a list of two or three finite numbers.
    """
    vary = section.get("vary", {})
    if not isinstance(vary, dict):
        raise UsageError(f"--scenario {path}: [optimise.vary] must be a table of KEY = [LOW, HIGH(, START)]")
    out = []
    for key, value in vary.items():
        ok = isinstance(value, list) and len(value) in (2, 3)
        ok = ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)
        if not ok:
            raise UsageError(
                f"--scenario {path}: [optimise.vary] {key} must be [LOW, HIGH] or [LOW, HIGH, START] (got {value!r})"
            )
        out.append(f"{key}=" + ":".join(f"{v!r}" for v in value))
    return out
