"""Where gymnasium's MuJoCo models lie (a test-only dependency: its wheel ships the XML assets)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest


def gym_model(name: str) -> Path:
    """Path of gymnasium's ``<name>.xml`` (found without importing gymnasium); skips the test without it."""
    spec = importlib.util.find_spec("gymnasium")
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("gymnasium is not installed (pip install -e '.[test]' installs it)")
    return Path(next(iter(spec.submodule_search_locations))) / "envs" / "mujoco" / "assets" / f"{name}.xml"
