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


@pytest.fixture(scope="session")
def _session_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("calibration-cache")


@pytest.fixture(autouse=True)
def _calibration_cache(_session_cache, monkeypatch):
    """Tests never touch the user's calibration cache; they share one for the session.

    Default runs are calibrated, so a shared cache fits each joint setup once per session.
    Tests about the cache itself set their own folder.
    """
    monkeypatch.setenv("CLEARANCE_CACHE_DIR", str(_session_cache))
