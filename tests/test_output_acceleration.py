"""Output accelerations are kinematic (gravity is not part of them)."""

from __future__ import annotations

import math

import numpy as np

from clearance import ModelOptions, simulate
from clearance.builders import seven_bar_press
from clearance.kinematics import solve_kinematics


def test_press_slider_acceleration_matches_kinematics_with_gravity_on():
    # the press runs with gravity 9.81 m/s^2 along the slider guide; its ideal slider
    # acceleration stays below 0.7 m/s^2 at pi rad/s (catalogue), so an accelerometer-type
    # reading (a - g) would be off by 14 times the signal
    m = seven_bar_press(clearance_at=())
    r = simulate(m, duration=0.5, options=ModelOptions(timestep=2e-5))
    kin = solve_kinematics(m, r.times)
    a, a_kin = r.outputs["slider_y_acc"], kin.outputs["slider_y_acc"]
    sel = r.times > 0.05  # after the drives' servo transient at t = 0
    err = np.max(np.abs(a[sel] - a_kin[sel]))
    # measured 3.4e-7 m/s^2 (soft loop closures, servo error); 1e-3 m/s^2 (0.15 % of the
    # peak) leaves room for other platforms while a reading that includes g is off by 9.81
    assert err < 1e-3, err
    assert math.isclose(m.gravity[1], -9.81)
