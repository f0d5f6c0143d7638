"""Gymnasium's MuJoCo models, found without importing gymnasium (its wheel ships the XML assets)."""

from __future__ import annotations

import importlib.util
from pathlib import Path


def gym_model(name: str) -> Path:
    """Path of gymnasium's ``<name>.xml`` (reacher, pusher, half_cheetah, ...).

    Raises:
        SystemExit: gymnasium is not installed.
    """
    spec = importlib.util.find_spec("gymnasium")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("gymnasium is not installed (pip install -e '.[test]')")
    return Path(next(iter(spec.submodule_search_locations))) / "envs" / "mujoco" / "assets" / f"{name}.xml"
