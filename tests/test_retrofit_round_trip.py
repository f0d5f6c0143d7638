"""Round trip on our own slider-crank: retrofit the ideal twin's crank_rod hinge and compare with
the native run with clearance at crank_rod (calibrated ring, 104 segments, the same 2 µs step).

The two models differ in structure, not in physics: the native model cuts the loop at the
clearance joint (the rod hangs from the slider, no equality), the retrofitted twin keeps
crank_rod in the tree and closes the loop with the twin's `connect` at rod_slider (a soft
constraint of time constant 2h). Each calibrates its own ring at its own effective mass
(0.3356 and 0.3361 kg), and the fit lands 11 % apart in stiffness for that 0.15 %.

Measured (benchmarks/retrofit_round_trip.md): the first impact at the same step (0.238 ms),
the orbits within 1.8 % of c through the first two impacts (0.8 ms), 5 % at 1.0 ms; the
native model against itself at half the step is already 28 % of c apart at 2 ms and 105 % at
5 ms, so over 5 ms no two discretizations of this motion agree to 5 % of c. The orbit is
compared where the motion is still predictable: the first 0.8 ms.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from clearance.builders import slider_crank
from clearance.options import ModelOptions
from clearance.retrofit import ControlTable, RadialPlay, RetrofitOptions, retrofit, write_retrofit
from clearance.run.preparation import prepare
from clearance.run.retrofitted import load_retrofitted, simulate_retrofitted
from clearance.run.simulation import simulate_prepared

WINDOW = 0.8e-3
"""Orbit comparison window [s]: through the first two impacts (0.238 and 0.698 ms)."""


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(native result, retrofitted result, radial clearance, the retrofit) over the window."""
    mech = slider_crank(clearance_at=("crank_rod",))
    options = ModelOptions(contact_mode="calibrated")
    native = prepare(mech, options)
    segments = native.metadata["segments"]["crank_rod"]
    ideal = prepare(mech.ideal_twin(), options)
    spec = mujoco.MjSpec.from_string(ideal.to_xml())  # the ring-free model a user would hand us
    clearance = mech.joint("crank_rod").require_clearance()
    play = RadialPlay(dataclasses.replace(clearance, journal_link=None))
    drive = ControlTable(np.array([0.0]), ideal.model.key_ctrl[:1], "the crank's speed set point")
    r = retrofit(
        spec,
        {"crank_rod": play},
        RetrofitOptions(
            segments=segments,
            timestep=options.timestep,
            control=drive,
            sizing_duration=0.012,  # one crank revolution at 5000 rpm
            measure_speed=False,
            # the native model's own calibrated ring misses the fit's restitution goal (0.02) by about 0.01 at
            # the ends of its speed decade; the round trip compares the same ring both ways, so it is kept
            accept_inaccurate=True,
        ),
    )
    out = tmp_path_factory.mktemp("slider_crank_retrofit")
    write_retrofit(r, out)
    loaded = load_retrofitted(out)
    a = simulate_prepared(native, duration=WINDOW)
    b = simulate_retrofitted(loaded, drive, WINDOW)
    return a, b, clearance.radial_clearance, r


def test_the_retrofit_sizes_the_bearing_as_the_native_model_does(runs):
    a, _, _, r = runs
    native = a.metadata["sizing"]["crank_rod"]
    s = r.hinges["crank_rod"].sizing
    # both read the same ideal motion's loads; the effective masses come from two methods
    # (the cycle's kinematics, the compiled model's constraint rows): 1 % is their agreement
    assert s.effective_mass == pytest.approx(native["effective_mass"], rel=1e-2)
    assert s.peak_load == pytest.approx(native["peak_load"], rel=1e-2)
    assert r.timestep == 2e-6 and s.segments == 104


def test_first_impact_and_orbit_match_the_native_clearance_run(runs):
    a, b, c, _ = runs
    ja, jb = a.joints["crank_rod"], b.joints["crank_rod"]
    assert len(a.times) == len(b.times)  # the same step and window
    first_a = a.times[np.argmax(ja.penetration > 0)]
    first_b = b.times[np.argmax(jb.penetration > 0)]
    assert ja.penetration.max() > 0 and (ja.penetration > 0).any()
    assert first_b == pytest.approx(first_a, rel=1e-2)  # the goal: first impact within 1 %
    # the goal: the journal orbit within 5 % of c (here over the predictable window, see above)
    gap = np.hypot(*(ja.eccentricity - jb.eccentricity).T)
    assert gap.max() < 0.05 * c
    # both impacts of the window happen in both runs
    starts = [np.nonzero(np.diff((j.penetration > 0).astype(int)) == 1)[0] for j in (ja, jb)]
    assert len(starts[0]) == len(starts[1]) >= 2


def test_cli_sizes_from_a_control_file(runs, tmp_path, capsys):
    """`--sizing-control`: the slider-crank's ideal twin sized under its speed set point from a CSV, as the
    native model sizes its bearing (the sinusoid would hold the servo near 0 rad/s)."""
    from clearance.cli import main

    a, _, _, r = runs
    model = tmp_path / "slider_crank_ideal.xml"
    model.write_text(r.twin_spec.to_xml())
    ctrl = tmp_path / "ctrl.csv"
    ctrl.write_text(f"time_s,crank\n0,{float(r.twin.key_ctrl[0, 0])!r}\n")
    argv = ["retrofit", str(model), "--joint", "crank_rod:clearance_mm=0.5", "--out", str(tmp_path / "out")]
    argv += ["--contact-mode", "nominal", "--segments", "104", "--timestep-us", "2", "--no-speed"]
    argv += ["--sizing-control", str(ctrl), "--sizing-duration-s", "0.012"]
    assert main(argv) == 0
    stdout = capsys.readouterr().out
    assert "crank_rod: c = 500 µm" in stdout
    lines = (tmp_path / "out" / "retrofit.md").read_text().splitlines()
    table = next(i for i, x in enumerate(lines) if x.startswith("| hinge | median load [N] | peak load [N] |"))
    row = next(x for x in lines[table:] if x.startswith("| crank_rod |"))
    peak = float(row.split("|")[3])  # the sizing table's peak load [N], 4 significant digits
    # the same motion as the native sizing's: its peak load to the table's 4 digits (half a unit: 5e-4)
    assert peak == pytest.approx(a.metadata["sizing"]["crank_rod"]["peak_load"], rel=5e-4)
    ctrl.write_text("time_s,crank,extra\n0,1,2\n")
    assert main([*argv[:4], "--out", str(tmp_path / "never"), "--sizing-control", str(ctrl)]) == 2
    assert "unknown actuator 'extra'" in capsys.readouterr().err
    assert not (tmp_path / "never").exists()


def test_a_ring_is_refused_exactly_when_its_calibration_misses_the_fit_goals(runs):
    """Fits that missed their goals passed as notes, exit 0. The same retrofit without accept_inaccurate (its
    calibration comes from the session's cache) is refused if and only if a fitted speed misses `GOALS`."""
    from clearance.retrofit.accuracy import InaccurateRetrofitError

    _, _, _, r = runs
    missed = [row for row in r.hinges["crank_rod"].contact.calibration.rows if not row.meets_goals()]
    assert bool(r.warnings) == bool(missed)  # kept with a warning: one per missing ring
    options = dataclasses.replace(r.options, accept_inaccurate=False)
    plays = {h.name: h.play for h in r.hinges.values()}
    if not missed:
        assert not retrofit(r.twin_spec, plays, options).warnings
        return
    with pytest.raises(InaccurateRetrofitError) as caught:
        retrofit(r.twin_spec, plays, options)
    text = str(caught.value)
    assert (
        f"misses the fit's goals at {len(missed)} of" in text
        and "restitution" in text
        and "--contact-mode exact" in text
    )
