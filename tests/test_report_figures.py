"""What the report and its figures show: the steady state's scale with the start-up marked, one
contact figure and a distinct contact-mode figure, Poincaré sections with integer periods and the
clearance circle, no section at all below the minimum of points (the report says why and how many
revolutions give one), envelopes that keep every peak, and the report's start-up window.

The runs are synthetic (a journal that strikes hard in the first drive period and lightly
after it), so every number asserted is known by construction.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from clearance.analysis.chaos.poincare import MIN_SECTION_POINTS, section_warning
from clearance.analysis.figures.analysis_figures import plot_contact_modes, plot_poincare
from clearance.analysis.figures.canvas import thin_path, thin_series
from clearance.analysis.figures.density import column_envelope, crowded_columns
from clearance.analysis.figures.plots import plot_contact_force, plot_response
from clearance.analysis.figures.report import write_report
from clearance.analysis.figures.report_sections import revolutions_for_sections, section_points
from clearance.analysis.metrics.response import ContactMode, contact_modes
from clearance.results import JointResult, SimulationResult
from clearance.units import format_quantity

T = 0.1  # drive period of the synthetic runs [s]
W = 2 * np.pi / T
H = 1e-4  # sample interval [s]
C = 5e-4  # radial clearance [m]
STARTUP_FORCE = 40e3  # the start-up impact [N]
STEADY_FORCE = 6e3  # the steady state's largest impact [N]
STARTUP_ACC = 5e4  # the start-up acceleration spike [m/s^2]
STEADY_ACC = 2e3  # the steady state's largest acceleration spike [m/s^2]


def _runs(periods: float = 3.0) -> tuple[SimulationResult, SimulationResult]:
    """A run with clearance and its ideal twin: output x = 0.05 sin(W t), a journal that
    strikes at 5 ms (40 kN, 5e4 m/s^2) and then at 0.5 T into each later period (6 kN, 2e3
    m/s^2), and rests on the wall for 30 ms of each period (continuous contact)."""
    t = np.arange(0.0, periods * T, H)
    n = len(t)
    y0 = 0.05 * np.sin(W * t)
    v0 = 0.05 * W * np.cos(W * t)
    a0 = -0.05 * W**2 * np.sin(W * t)
    pen = np.full(n, -1e-5)
    force = np.zeros(n)
    acc = a0.copy()
    k = int(round(0.005 / H))
    pen[k : k + 3], force[k : k + 3], acc[k] = 1e-6, [STARTUP_FORCE / 2, STARTUP_FORCE, STARTUP_FORCE / 2], STARTUP_ACC
    for p in range(1, int(periods)):
        k = int(round((p + 0.5) * T / H))
        pen[k : k + 3], force[k : k + 3], acc[k] = 1e-6, [STEADY_FORCE / 2, STEADY_FORCE, 1e3], STEADY_ACC
        rest = slice(int(round((p + 0.6) * T / H)), int(round((p + 0.9) * T / H)))
        pen[rest], force[rest] = 1e-7, 500.0
    ang = W * t
    r = C + pen
    ecc = np.column_stack([r * np.cos(ang), r * np.sin(ang)])
    common = {
        "drive_angle": ang[:, None],
        "drive_speed": np.full((n, 1), W),
        "drive_torque": np.zeros((n, 1)),
        "link_poses": np.zeros((n, 1, 3)),
        "closure_violation": np.zeros(n),
    }
    joint = JointResult(ecc, np.gradient(ecc, t, axis=0), pen, np.column_stack([force, np.zeros(n)]))
    result = SimulationResult(
        times=t,
        outputs={"x": y0 + 1e-4 * np.sin(3 * W * t), "x_vel": v0, "x_acc": acc},
        joints={"j": joint},
        metadata={"mechanism": "synthetic"},
        **common,
    )
    ideal = SimulationResult(times=t, outputs={"x": y0, "x_vel": v0, "x_acc": a0}, joints={}, **common)
    return result, ideal


def _axes(fig, label):
    return next(ax for ax in fig.axes if ax.get_label() == label)


def _startup_panels(fig):
    return [ax for ax in fig.axes if ax.get_title().startswith("start-up, full scale")]


def test_response_acceleration_is_scaled_to_the_steady_state_with_the_start_up_beside():
    result, ideal = _runs()
    fig = plot_response(result, ideal, "x", startup=T)
    acc = _axes(fig, "acceleration")
    # the unit chosen by the steady peak (2e3 m/s^2 reads 2 km/s^2)
    assert acc.get_ylabel() == "acceleration [km/s²]"
    lo, hi = np.array(acc.get_ylim()) * 1e3
    # the axis holds every steady-state sample (the spike of 2e3 m/s^2 and the ideal's +-987)
    # with its 6 % margin, and stops far below the start-up spike of 5e4 m/s^2
    assert STEADY_ACC <= hi < 0.1 * STARTUP_ACC
    assert lo <= -0.05 * W**2
    # the start-up at full scale beside it, the spike inside its limits, its axes labelled
    (panel,) = _startup_panels(fig)  # only the acceleration row is clipped
    assert panel.get_ylim()[1] * 1e3 >= STARTUP_ACC
    assert panel.get_ylabel() == "acceleration [km/s²]" and panel.get_xlabel() == "time [ms]"
    # the displacement's steady scale holds its whole range: nothing clipped there
    assert _axes(fig, "displacement").get_ylim()[1] >= 50.0  # 0.05 m in mm


def test_contact_force_is_the_one_contact_figure_at_the_steady_scale_with_modes_shaded():
    result, _ = _runs()
    fig = plot_contact_force(result, startup=T)
    ax = _axes(fig, "j")
    lo, hi = ax.get_ylim()
    # kN (the steady peak is 6 kN); from 0 (a magnitude) to just above the steady peak
    assert "kN" in ax.get_ylabel()
    assert lo <= 0 and STEADY_FORCE / 1e3 <= hi < STARTUP_FORCE / 1e3
    assert _startup_panels(fig)[0].get_ylim()[1] >= STARTUP_FORCE / 1e3
    # the contact modes shaded beneath: one bar collection for impacts, one for continuous
    # contact (broken_barh); the start-up window is a PolyCollection-free axvspan
    bars = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert len(bars) == 2
    modes = contact_modes(result, "j")
    n_impacts = sum(e.mode is ContactMode.IMPACT for e in modes.events)
    assert {len(b.get_paths()) for b in bars} == {n_impacts, len(modes.events) - n_impacts}


def test_contact_modes_figure_is_the_share_of_time_per_window_not_a_time_series():
    result, _ = _runs()
    first = contact_modes(result, "j", end=T)
    steady = contact_modes(result, "j", skip=T)
    fig = plot_contact_modes({"start-up": [first], "steady state": [steady]})
    (ax,) = fig.axes
    assert ax.get_xlim() == (0.0, 100.0)  # shares in %, no time axis
    # one stacked bar per window and mode: their widths are the fractions (exact arithmetic)
    widths = sorted(round(p.get_width(), 9) for p in ax.patches)
    expected = sorted(round(m.fractions[mode] * 100, 9) for m in (first, steady) for mode in ContactMode)
    assert widths == expected
    # by construction: the start-up has only the 5 ms impact (3 of 1000 samples), the steady
    # state 30 ms of rest on the wall per period (continuous, 300 of 1000 samples)
    assert first.fractions[ContactMode.CONTINUOUS] == 0.0
    assert steady.fractions[ContactMode.CONTINUOUS] == pytest.approx(0.3, abs=0.002)  # one sample of 1000


def test_poincare_section_has_integer_periods_the_clearance_circle_and_a_warning():
    rng = np.random.default_rng(0)
    pts = C * 0.9 * np.column_stack([np.cos(rng.uniform(0, 6, 3)), np.sin(rng.uniform(0, 6, 3))])
    fig = plot_poincare(pts, ("j.ex", "j.ey"), periods=np.array([1, 2, 3]), clearance=C)
    cbar = fig.axes[1]
    ticks = cbar.get_yticks()
    np.testing.assert_array_equal(ticks, [1, 2, 3])  # integer drive periods, not a 0-1 bar
    ax = fig.axes[0]
    radii = [np.hypot(*line.get_data()).max() for line in ax.get_lines()]
    assert any(r == pytest.approx(C * 1e6, rel=1e-9) for r in radii)  # the circle, in µm
    texts = " ".join(t.get_text() for t in ax.texts)
    assert f"fewer than {MIN_SECTION_POINTS}" in texts.replace("\n", " ")
    many = plot_poincare(np.zeros((MIN_SECTION_POINTS, 2)) + pts[0], ("j.ex", "j.ey"), periods=np.arange(1, 21))
    assert not many.axes[0].texts  # enough points: no warning
    assert section_warning(MIN_SECTION_POINTS) is None and "only 19" in (section_warning(19) or "")


def test_report_names_the_start_up_window_and_keeps_it_apart(tmp_path):
    result, ideal = _runs()
    text = write_report(tmp_path, result, ideal, skip=T).read_text()
    assert "**Start-up window**: 0–100 ms, the first period of the slowest prescribed drive" in text
    # peaks: the start-up row has the 5e4 spike, the steady-state row the 2e3 one
    acc = [line for line in text.splitlines() if line.startswith("| x_acc |")]
    assert "| start-up |" in acc[0] and "| 50 km/s² |" in acc[0]  # each value in the unit its size calls for
    assert "| steady state |" in acc[1] and "50 km/s²" not in acc[1] and "| 2 km/s² |" in acc[1]
    # contact statistics side by side: start-up peak 40 kN, steady peak 6 kN
    assert "| statistic | j, start-up, 0–100 ms | j, steady state, 100–300 ms |" in text
    assert "| peak force | 40 kN | 6 kN |" in text
    # 3 periods, the first the start-up: a point at t = T, 2T (and 3T, where arange's rounding
    # puts a last sample there); no section drawn; the report says why and that 21 periods
    # (1 start-up + 20 points) give one
    ks, _ = section_points(result, ["x"], T, T)
    assert 2 <= len(ks) < MIN_SECTION_POINTS
    assert "**No Poincaré section: too few drive periods.**" in text
    assert f"from {MIN_SECTION_POINTS} points or more; this run gives {len(ks)} (k = 1–{ks[-1]})" in text
    assert "`clearance run --revolutions 21`" in text and "poincare_1.png" not in text
    assert not (tmp_path / "poincare_1.png").exists()
    for png in ("response_vs_ideal", "contact_force", "contact_modes", "orbit_j", "deviation", "phase_0"):
        assert (tmp_path / f"{png}.png").stat().st_size > 10_000


def test_a_run_within_its_start_up_window_says_so(tmp_path):
    result, ideal = _runs(periods=1.0)
    text = write_report(tmp_path, result, ideal, skip=T).read_text()
    assert "**No steady state**" in text
    assert "not estimated: the run has no whole drive period after its start-up window" in text
    # every figure but the sections is still written; no section point at all
    for png in ("response_vs_ideal", "contact_force", "contact_modes", "orbit_j", "deviation", "phase_0"):
        assert (tmp_path / f"{png}.png").exists()
    assert "this run gives no section point" in text


def test_a_run_long_enough_gets_its_sections_named_by_number(tmp_path):
    need = revolutions_for_sections(_runs(1.0)[0], T, T)
    assert need == MIN_SECTION_POINTS + 1  # the start-up period, then one point per period
    assert revolutions_for_sections(_runs(1.0)[0], T, 0.0) == MIN_SECTION_POINTS  # t = 0 is a point
    result, ideal = _runs(periods=float(need))
    text = write_report(tmp_path, result, ideal, skip=T).read_text()
    assert "No Poincaré section" not in text
    # the table names each section's figure: section 0 the output's phase portrait, 1 the joint's
    assert f"| 0: x / x_vel | phase_0.png | {MIN_SECTION_POINTS} |" in text
    assert f"| 1: j.ex / j.ey | poincare_1.png | {MIN_SECTION_POINTS} |" in text
    assert (tmp_path / "poincare_1.png").stat().st_size > 10_000


def test_thinning_keeps_every_peak_and_the_ends():
    x = np.arange(100_000, dtype=float)
    y = np.sin(x / 5000)
    y[12_345] = 50.0  # a one-sample spike
    y[77_777] = -40.0
    tx, ty = thin_series(x, y, columns=500)
    assert len(tx) <= 2 * 500 + 2 and ty.max() == 50.0 and ty.min() == -40.0
    assert tx[0] == 0 and tx[-1] == x[-1] and np.all(np.diff(tx) > 0)
    keep = thin_path(np.cos(x / 1e4), np.sin(x / 1e4), resolution=1e-3)
    assert keep[0] == 0 and keep[-1] == len(x) - 1 and len(keep) < len(x) / 10


@pytest.mark.parametrize("n, columns", [(1_000_003, 640), (4_001, 640), (999, 1500)])
def test_the_envelope_keeps_every_peak_and_the_column_means(n, columns):
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.uniform(0.5, 1.5, n))  # uneven steps: columns of unequal counts
    y = rng.normal(size=n) + 5 * np.sin(x / x[-1] * 20)
    k_max, k_min = int(rng.integers(n)), int(rng.integers(n))
    y[k_max], y[k_min] = 1e3, -1e3  # one-sample peaks anywhere
    env = column_envelope(x, y, columns=columns)
    # peaks preserved exactly: the envelope's max is the data's max (the same float, no arithmetic)
    assert env.high.max() == y.max() == 1e3 and env.low.min() == y.min() == -1e3
    assert len(env.x) <= columns and env.counts.sum() == n  # every sample in one column
    # each column: its own samples' min, max and mean (the mean to summation rounding, 1e-12)
    edges = np.concatenate([[0], np.cumsum(env.counts)])
    for c in rng.integers(len(env.counts), size=20):
        part = y[edges[c] : edges[c + 1]]
        assert env.low[c] == part.min() and env.high[c] == part.max()
        assert env.mean[c] == pytest.approx(part.mean(), rel=1e-12, abs=1e-12)
    # a stretch: only its samples, its peaks
    env = column_envelope(x, y, columns=50, start=x[n // 4], end=x[n // 2])
    assert env.counts.sum() == n // 2 - n // 4 + 1 and env.high.max() == y[n // 4 : n // 2 + 1].max()


def test_a_fast_oscillation_is_crowded_and_drawn_as_a_band_a_slow_one_as_a_line():
    x = np.linspace(0.0, 6000.0, 600_001)  # ms, as the press's 3 revolutions
    fast = 30 + 6 * np.sin(2 * np.pi * 0.277 * x)  # 277 Hz: about 5 reversals per pixel column
    slow = 30 + 6 * np.sin(2 * np.pi * x / 2000)  # the drive's 0.5 Hz
    pixel = 14.0 / 190  # the axis's range over its height in pixels
    assert crowded_columns(x, fast, columns=640, pixel=pixel).all()
    assert not crowded_columns(x, slow, columns=640, pixel=pixel).any()
    result, ideal = _runs()
    fig = plot_response(result, ideal, "x", startup=T)
    # the synthetic run's lone spikes are sparse: lines, no band
    assert not any(c for ax in fig.axes for c in ax.collections if type(c).__name__ == "FillBetweenPolyCollection")


def test_report_figures_do_not_import_pyplot(tmp_path):
    code = (
        "import sys\n"
        "sys.path.insert(0, {tests!r})\n"
        "from test_report_figures import _runs\n"
        "from clearance.analysis.figures.report import write_report\n"
        "r, i = _runs()\n"
        "write_report({out!r}, r, i, skip=0.1)\n"
        "print('matplotlib.pyplot' in sys.modules)\n"
    ).format(tests=str(__import__("pathlib").Path(__file__).parent), out=str(tmp_path))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "False"


@pytest.mark.parametrize(
    "value, unit, text",
    [
        (44.3, "N", "44.3 N"),  # not "0.0443 kN"
        (1334.0, "N", "1.33 kN"),
        (-1013.0, "N m", "-1.01 kN m"),
        (6.0, "s", "6 s"),  # not "6e+03 ms"
        (2.5e-4, "s", "250 µs"),
        (999.7, "N", "1 kN"),  # rounding reaches 1000: one prefix up
        (6000.0, "s", "6000 s"),  # no prefix above the second
        (1.6e5, "m/s²", "160 km/s²"),
        (float("nan"), "N", "n/a"),
    ],
)
def test_numbers_are_written_for_people(value, unit, text):
    assert format_quantity(value, unit) == text


def test_eleven_joints_fill_two_columns_each_with_its_time_axis_at_the_foot():
    """The ten-bar with a clearance at every joint that can carry one: 11 contact rows."""
    from dataclasses import replace

    result, _ = _runs()
    joints = {f"j{i}": result.joints["j"] for i in range(11)}
    fig = plot_contact_force(replace(result, joints=joints), startup=T)
    rows = [ax for ax in fig.axes if ax.get_label() in joints]
    assert len(rows) == 11 and len({round(ax.get_position().x0, 3) for ax in rows}) == 2
    # rows fill the first column first (6 of them); the foot of each column carries the time axis
    assert [ax.get_label() for ax in rows if ax.get_xlabel() == "time [ms]"] == ["j5", "j10"]


def test_a_comb_of_strokes_is_a_solid_block_lone_spikes_are_not():
    from clearance.analysis.figures.density import SOLID_RUN, solid_columns

    x = np.arange(64_000, dtype=float)  # 640 columns of 100 samples
    y = np.zeros_like(x)
    y[np.arange(50, 6_000, 200)] = 10.0  # a stroke to the top every second column, columns 0-59
    y[np.arange(30_050, 64_000, 1_200)] = 10.0  # lone spikes, 12 columns apart
    env = column_envelope(x, y, columns=640)
    solid = solid_columns(env, (0.0, 10.0))
    assert solid[:59].all() and not solid[60 + SOLID_RUN :].any()
