"""Shared fixtures: canonical mechanisms and one prepared default model per session."""

from __future__ import annotations

import pytest

from clearance.builders import slider_crank


@pytest.fixture(scope="session")
def default_mechanism():
    """The default scenario: classic slider-crank, c = 0.5 mm at rod_slider, 5000 rpm."""
    return slider_crank()


@pytest.fixture(scope="session")
def default_prepared(default_mechanism):
    from clearance.options import ModelOptions
    from clearance.preparation import prepare

    return prepare(default_mechanism, ModelOptions())


@pytest.fixture(autouse=True)
def _calibration_cache(tmp_path, monkeypatch):
    """Tests never touch the user's calibration cache."""
    monkeypatch.setenv("CLEARANCE_CACHE_DIR", str(tmp_path / "cache"))
