"""The map of docs/architecture.md, kept true: every import of the package goes down the floors.

Every ``import`` and ``from ... import`` of every module (those inside functions too) is
read from the source with `ast`, resolved to the module it names, and checked against the
allowed edges between floors. A module on a floor may import its own floor and the floors
listed for it, nothing else; nothing imports the command line.
"""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

FLOORS: dict[str, str] = {
    "clearance": "front door",
    "clearance.model": "data model",
    "clearance.options": "data model",
    "clearance.results": "data model",
    "clearance.joint_result": "data model",
    "clearance.constraints": "data model",
    "clearance.kinematics": "data model",
    "clearance.units": "data model",
    "clearance.version": "data model",
    "clearance.checks": "data model",
    "clearance.progress": "data model",
    "clearance.result_units": "data model",
    "clearance.lubrication": "data model",
    "clearance.translational": "data model",
    "clearance.loads": "inverse dynamics",
    "clearance.builders": "builders",
    "clearance.mjcf": "mjcf",
    "clearance.contact_calibration.laws": "contact laws",
    "clearance.contact_calibration.film": "contact laws",
    "clearance.contact_calibration.cylindrical_laws": "contact laws",
    "clearance.contact_calibration": "contact",
    "clearance.contact_plugin": "contact",
    "clearance.retrofit": "retrofit",
    "clearance.reference": "reference",
    "clearance.run": "run",
    "clearance.analysis": "analysis",
    "clearance.analysis.design": "analysis",
    "clearance.bench": "bench",
    "clearance.cli": "command line",
}
"""Module (or package prefix) -> floor; the longest prefix wins. `clearance` alone is the
package's ``__init__``: its front door."""

_BELOW_CLI = {
    "data model",
    "inverse dynamics",
    "builders",
    "mjcf",
    "contact laws",
    "contact",
    "retrofit",
    "reference",
    "run",
    "analysis",
}

ALLOWED: dict[str, set[str]] = {
    "data model": set(),
    "inverse dynamics": {"data model"},
    "builders": {"data model"},
    "mjcf": {"data model"},
    "contact laws": {"data model"},
    "contact": {"data model", "mjcf", "inverse dynamics", "contact laws"},
    "retrofit": {"data model", "mjcf", "contact laws", "contact"},
    "reference": {"data model", "contact laws"},
    "run": {"data model", "inverse dynamics", "mjcf", "contact laws", "contact", "retrofit"},
    "analysis": {"data model", "run"},
    "bench": _BELOW_CLI,
    "command line": _BELOW_CLI | {"bench", "front door"},
    "front door": {"data model", "run"},
}
"""Floor -> the other floors it may import (see docs/architecture.md)."""


def package_modules() -> dict[str, Path]:
    """Every module of the installed package: dotted name -> source file (from pyproject's package-dir)."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    dirs = config["package-dir"]
    modules: dict[str, Path] = {}
    for package in config["packages"]:
        folder = ROOT / dirs.get(package, package.replace(".", "/"))
        for file in folder.glob("*.py"):
            name = package if file.stem == "__init__" else f"{package}.{file.stem}"
            modules[name] = file
    return modules


def floor_of(module: str) -> str | None:
    """The floor of a module of ours (longest matching prefix), None for another package's."""
    best = None
    for prefix in FLOORS:
        if (module == prefix or module.startswith(prefix + ".")) and (best is None or len(prefix) > len(best)):
            best = prefix
    if best == "clearance" and module != "clearance":
        raise AssertionError(f"module {module} is on no floor: add it to FLOORS and to docs/architecture.md")
    return FLOORS[best] if best else None


def imports_of(module: str, source: str, known: set[str], is_package: bool) -> list[tuple[int, str]]:
    """(line, imported module of ours) for every import statement in ``source``."""
    out = []
    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names if a.name.split(".")[0] == "clearance"]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[: len(parts) - node.level + 1] + ([base] if base else []))
            if base.split(".")[0] != "clearance":
                continue
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                out.append((node.lineno, sub if sub in known else base))
    return out


def violations(modules: dict[str, Path]) -> list[str]:
    """Every import that the map does not allow, as 'file:line: a (floor) -> b (floor)'."""
    known = set(modules)
    bad = []
    for name, file in sorted(modules.items()):
        mine = floor_of(name)
        assert mine is not None
        for line, target in imports_of(name, file.read_text(), known, file.stem == "__init__"):
            theirs = floor_of(target)
            if theirs is None or theirs == mine or theirs in ALLOWED[mine]:
                continue
            bad.append(f"{file.relative_to(ROOT)}:{line}: {name} ({mine}) -> {target} ({theirs})")
    return bad


def test_every_module_is_on_a_floor():
    modules = package_modules()
    assert len(modules) > 50  # the package's own modules were found (a wrong path would find none)
    for name in modules:
        assert floor_of(name) is not None


def test_no_import_goes_up_the_floors():
    bad = violations(package_modules())
    assert not bad, "imports the map forbids (docs/architecture.md):\n" + "\n".join(bad)


@pytest.mark.parametrize(
    ("source", "module", "expected"),
    [
        ("from clearance.cli import main", "clearance.analysis.x", "clearance.cli"),
        ("def f():\n    from clearance.run.simulation import simulate", "clearance.mjcf.x", "clearance.run.simulation"),
        ("from ..builders import catalogue", "clearance.analysis.x", "clearance.builders.catalogue"),
        ("import clearance.bench.scenarios", "clearance.run.x", "clearance.bench.scenarios"),
    ],
)
def test_the_checker_sees_every_kind_of_import(source, module, expected):
    """A function-level, relative or plain import that goes up is found (the check can fail)."""
    known = {"clearance.builders.catalogue", "clearance.run.simulation", "clearance.bench.scenarios", "clearance.cli"}
    found = imports_of(module, source, known, is_package=False)
    assert [t for _, t in found] == [expected]
    assert floor_of(expected) not in ALLOWED[floor_of(module) or ""] | {floor_of(module)}
