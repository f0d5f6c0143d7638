"""Scenario files with a design tool's own section (``[allocation]``, ``[optimise]``).

A scenario TOML describes a mechanism; `clearance allocate` and `clearance optimise` read
their settings from a section of the same file that the scenario reader does not know.
`split_section` reads the file once and hands back the text with that section's lines
blanked (so the scenario reader's line numbers still point into the file) and the section.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from clearance.cli.sweep_common import UsageError

__all__ = ["DESIGN_SECTIONS", "ScenarioSection", "split_section"]

DESIGN_SECTIONS = {"allocation": "clearance allocate", "optimise": "clearance optimise"}
"""The design tools' sections a scenario file may hold beside its mechanism, and the command of each."""

_HEADER = re.compile(r"^\s*\[\[?\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")
"""A table or array-of-tables header line; group 1 is its dotted name."""


@dataclass(frozen=True)
class ScenarioSection:
    """A scenario file split for a design tool.

    Attributes:
        scenario_text: the file's text with the section and its sub-tables blanked.
        document: the whole file, parsed.
        section: the section's table ({} where the file has none).
    """

    scenario_text: str
    document: dict[str, Any]
    section: dict[str, Any]


def _top_name(header: str) -> str:
    return header.split(".")[0].strip().strip("\"' ")


def split_section(path: str | Path, section: str) -> ScenarioSection:
    """Read ``path`` and split off its ``[section]`` (and ``[section.*]``) tables.

    Every design tool's section (`DESIGN_SECTIONS`) is blanked in the scenario text, so one file
    may carry the settings of several tools beside its mechanism.

    Args:
        path: the scenario file (``--scenario``).
        section: the design tool's section name, e.g. "allocation".

    Raises:
        UsageError: the path is a folder, cannot be read, is not valid TOML, or its section
            is not a table; the message names ``--scenario`` and the file.
    """
    p = Path(path)
    if p.is_dir():
        raise UsageError(f"--scenario {p}: is a folder; give a scenario file (.toml)")
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise UsageError(f"--scenario {p}: cannot read it ({err})") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise UsageError(f"--scenario {p}: not valid TOML: {err}") from None
    table = doc.get(section, {})
    if not isinstance(table, dict):
        raise UsageError(f"--scenario {p}: [{section}] must be a table")
    lines, inside = [], False
    for line in text.splitlines():
        m = _HEADER.match(line)
        if m:
            inside = _top_name(m.group(1)) in (section, *DESIGN_SECTIONS)
        lines.append("" if inside else line)
    return ScenarioSection("\n".join(lines) + "\n", doc, table)
