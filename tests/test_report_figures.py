"""What the report and its figures show: the steady state's scale with the start-up marked, one
contact figure and a distinct contact-mode figure, Poincaré sections with integer periods, the
clearance circle and a warning when too few, and the report's start-up window.

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
from clearance.analysis.figures.canvas import envelope, thin_path
from clearance.analysis.figures.plots import plot_contact_force, plot_response
from clearance.analysis.figures.report import write_report
from clearance.analysis.metrics.response import ContactMode, contact_modes
from clearance.results import JointResult, SimulationResult

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
    lo, hi = _axes(fig, "acceleration").get_ylim()
    # the axis holds every steady-state sample (the spike of 2e3 m/s^2 and the ideal's +-987)
    # with its 6 % margin, and stops far below the start-up spike of 5e4 m/s^2
    assert STEADY_ACC <= hi < 0.1 * STARTUP_ACC
    assert lo <= -0.05 * W**2
    # the start-up at full scale beside it, the spike inside its limits
    (panel,) = _startup_panels(fig)  # only the acceleration row is clipped
    assert panel.get_ylim()[1] >= STARTUP_ACC
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
    assert "| start-up |" in acc[0] and "5e+04" in acc[0]
    assert "| steady state |" in acc[1] and "5e+04" not in acc[1] and "| 2000 |" in acc[1]
    # contact statistics side by side: start-up peak 40 kN, steady peak 6 kN
    assert "| statistic | j, start-up, 0–100 ms | j, steady state, 100–300 ms |" in text
    assert "| peak force [N] | 4e+04 | 6000 |" in text
    # the Poincaré warning with its threshold
    assert "**Too few drive periods for a regime.**" in text and f"fewer than {MIN_SECTION_POINTS}" in text
    for png in ("response_vs_ideal", "contact_force", "contact_modes", "orbit_j", "deviation", "phase_0", "poincare_1"):
        assert (tmp_path / f"{png}.png").stat().st_size > 10_000


def test_a_run_within_its_start_up_window_says_so(tmp_path):
    result, ideal = _runs(periods=1.0)
    text = write_report(tmp_path, result, ideal, skip=T).read_text()
    assert "**No steady state**" in text
    assert "not estimated: the run has no whole drive period after its start-up window" in text
    # every output file is still written (the names a run's folder always has)
    for png in ("response_vs_ideal", "contact_force", "contact_modes", "orbit_j", "deviation", "phase_0", "poincare_1"):
        assert (tmp_path / f"{png}.png").exists()


def test_thinning_keeps_every_peak_and_the_ends():
    x = np.arange(100_000, dtype=float)
    y = np.sin(x / 5000)
    y[12_345] = 50.0  # a one-sample spike
    y[77_777] = -40.0
    tx, ty = envelope(x, y, columns=500)
    assert len(tx) <= 2 * 500 + 2 and ty.max() == 50.0 and ty.min() == -40.0
    assert tx[0] == 0 and tx[-1] == x[-1] and np.all(np.diff(tx) > 0)
    keep = thin_path(np.cos(x / 1e4), np.sin(x / 1e4), resolution=1e-3)
    assert keep[0] == 0 and keep[-1] == len(x) - 1 and len(keep) < len(x) / 10


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
