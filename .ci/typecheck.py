"""mypy over the package as it installs, with errors reported against the source files.

pyproject.toml maps the subpackages onto top-level folders (``clearance.builders`` is
``builders/``), which an editable install resolves through an import hook that mypy cannot
follow. This script lays the package out as it installs, as a tree of links to the source
files, runs mypy on it with the project's configuration, and prints the source paths.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    setup = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    dirs = setup["package-dir"]
    with tempfile.TemporaryDirectory() as tmp:
        where: dict[str, str] = {}
        for package in setup["packages"]:
            source = ROOT / dirs.get(package, package.replace(".", "/"))
            target = Path(tmp, *package.split("."))
            target.mkdir(parents=True, exist_ok=True)
            for file in source.glob("*.py"):
                (target / file.name).symlink_to(file)
                where[str((target / file.name).relative_to(tmp))] = str(file.relative_to(ROOT))
        cmd = [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"), "-p", "clearance"]
        run = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True)
    for line in (run.stdout + run.stderr).splitlines():
        path, sep, rest = line.partition(":")
        print(where.get(path, path) + sep + rest)
    return run.returncode


if __name__ == "__main__":
    sys.exit(main())
