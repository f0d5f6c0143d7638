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
    """The default scenario's calibrated ring model (the ring's tests; the exact contact has its own)."""
    from clearance.options import ModelOptions
    from clearance.run.preparation import prepare

    return prepare(default_mechanism, ModelOptions(contact_mode="calibrated"))


@pytest.fixture(scope="session", autouse=True)
def _calibration_cache(tmp_path_factory):
    """Tests never touch the user's calibration cache; they share one for the session.

    Session-scoped and autouse, so it is set before any other session- or module-scoped
    fixture prepares a model. Ring runs are calibrated, so a shared cache fits each joint
    setup once per session. Tests about the cache itself set their own folder.
    """
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("CLEARANCE_CACHE_DIR", str(tmp_path_factory.mktemp("calibration-cache")))
        yield
