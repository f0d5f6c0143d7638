"""The slider-crank with play in its guide (Flores, Leine and Glocker 2010) beside the siconos example.

Runs builders/scenarios/slider_crank_translational_flores2010.toml with the reference solver
over the examples' 0.2 s (what `clearance reference --scenario ... --duration-ms 200` runs) and
sets it beside the siconos example's own results (benchmarks/data/siconos_slider_crank.csv.gz:
two Moreau-Jean schemes with position projection, h = 1e-4 s, Newton impacts e_N = 0.4,
mu = 0.01): the crank speed, the slider's position across the guide and its tilt over time
(the example figure's quantities), the contact phases, and the mechanical energy. The same
run at corner stiffnesses 10 times lower and higher, and without friction, says how the
compliant stand-in for the impulsive law was chosen and what friction does. Writes
translational_clearance.md and translational_clearance.png next to this file.

    python benchmarks/translational_clearance.py
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path
from typing import Any

import numpy as np
from _tables import write_keeping_reading  # benchmarks/_tables.py (scripts run from benchmarks/)
from numpy.typing import NDArray

from clearance.analysis.figures.canvas import new_figure, save_png
from clearance.analysis.metrics.slider import Lines, contact_phases, touched_lines
from clearance.builders.scenario import load_scenario
from clearance.model import ContactLaw, Mechanism
from clearance.reference import run_reference
from clearance.results import SimulationResult
from clearance.translational import SliderContact, classify_contact

HERE = Path(__file__).resolve().parent
SCENARIO = HERE.parent / "builders" / "scenarios" / "slider_crank_translational_flores2010.toml"
SICONOS = HERE / "data" / "siconos_slider_crank.csv.gz"
DURATION = 0.2  # the examples' final time [s]
OUTPUT = 1e-5  # our output interval [s]: a tenth of the examples' step, so no contact falls between samples
JOINT = "slider_guide"
# the examples' parameters (their Table 1), by name; a and b are the block's half-sizes
L1, L2, M1, M2, M3, J1, J2, G = 0.153, 0.306, 0.038, 0.038, 0.076, 7.4e-5, 5.9e-4, 9.81
SCHEMES = ("combined projection", "direct projection")


def energy(q1: NDArray[Any], q2: NDArray[Any], w1: NDArray[Any], w2: NDArray[Any]) -> NDArray[Any]:
    """Kinetic plus gravity energy [J] of the examples' crank and rod coordinates (their eqs. 90-96).

    The slider's own turning (never in the examples' runs) and the contact's elastic energy are
    not included.
    """
    m11 = J1 + (M1 / 4 + M2 + M3) * L1**2
    m22 = J2 + (M2 / 4 + M3) * L2**2
    m12 = (M2 / 2 + M3) * L1 * L2 * np.cos(q2 - q1)
    kinetic = 0.5 * (m11 * w1**2 + 2 * m12 * w1 * w2 + m22 * w2**2)
    return kinetic + (M1 / 2 + M2 + M3) * G * L1 * np.sin(q1) + (M2 / 2 + M3) * G * L2 * np.sin(q2)


@dataclasses.dataclass
class Series:
    """One run's figure quantities on its own time grid."""

    name: str
    t: NDArray[Any]
    crank: NDArray[Any]  # crank angle [rad]
    speed: NDArray[Any]  # crank speed [rad/s]
    across: NDArray[Any]  # slider centre across the guide / c
    tilt: NDArray[Any]  # slider tilt [rad]
    cases: NDArray[Any]  # SliderContact codes
    lines: NDArray[Any]  # Lines codes
    energy: NDArray[Any]  # kinetic + gravity [J]
    events: NDArray[Any] = dataclasses.field(default_factory=lambda: np.zeros(0))  # contact switches [s]

    def touching_steps(self) -> NDArray[Any]:
        """(n - 1,) bool: a corner touches at either end of the step, or a contact starts or ends in it."""
        touch = (self.cases[1:] != SliderContact.FREE.value) | (self.cases[:-1] != SliderContact.FREE.value)
        if len(self.events):
            touch |= np.histogram(self.events, bins=self.t)[0] > 0
        return touch


def siconos_series() -> list[Series]:
    """The two siconos schemes' runs (tilt 0 throughout: the file says so)."""
    data = np.loadtxt(SICONOS, delimiter=",", comments="#", skiprows=11)
    out = []
    for k, name in enumerate(SCHEMES):
        d = data[data[:, 0] == k]
        t, q1, q2, w1, w2, mask = d[:, 1], d[:, 2], d[:, 3], d[:, 4], d[:, 5], d[:, 6].astype(int)
        touching = np.stack([(mask >> i) & 1 for i in range(4)], axis=1).astype(float)  # > 0: touching
        y = (L1 * np.sin(q1) + L2 * np.sin(q2)) / 1e-3
        cases, lines = classify_contact(touching), touched_lines(touching)
        out.append(Series(f"siconos, {name}", t, q1, w1, y, np.zeros_like(t), cases, lines, energy(q1, q2, w1, w2)))
    return out


def our_series(res: SimulationResult, name: str, c: float) -> Series:
    """A run's figure quantities (a MuJoCo run has no located contact switches: its samples' only)."""
    sr = res.sliders[JOINT]
    onsets = res.metadata.get("contact_onsets", {}).get(JOINT)
    events = [o[0] for o in onsets] + res.metadata["contact_ends"][JOINT] if onsets is not None else []
    q = res.link_poses
    kinetic_gravity = res.energy["kinetic"] + res.energy["gravity_potential"] if res.energy else np.full(len(q), np.nan)
    return Series(
        name,
        res.times,
        q[:, 0, 2],
        res.drive_speed[:, 0],
        sr.position[:, 1] / c,
        sr.tilt,
        sr.contact_case,
        touched_lines(sr.corner_penetration),
        kinetic_gravity,
        np.array(events, dtype=float),
    )


def episodes(s: Series) -> list[tuple[float, float, str, int]]:
    """Contact episodes: (first touch [s], last release [s], line, contact phases) of a run.

    An episode is every contact phase on one guide line until the slider touches the other:
    the impacts, bounces and sliding contact of one crossing of the clearance.
    """
    phases = [p for p in contact_phases(s.t, s.cases, s.lines) if p.case is not SliderContact.FREE]
    out: list[list[Any]] = []
    for p in phases:
        line = "+n" if p.lines is Lines.UPPER else "-n" if p.lines is Lines.LOWER else "both"
        if out and out[-1][2] in (line, "both"):
            out[-1][1] = p.end
            out[-1][3] += 1
        else:
            out.append([p.start, p.end, line, 1])
    return [(a, b, ln, n) for a, b, ln, n in out]


def dead_centre_speeds(s: Series, revolutions: int = 3) -> list[float]:
    """Crank speed [rad/s] as the crank passes 2 pi k (the slider's outer dead centre), k = 1..3."""
    out = []
    for k in range(1, revolutions + 1):
        i = int(np.searchsorted(s.crank, 2 * np.pi * k))
        if 0 < i < len(s.crank):
            f = (2 * np.pi * k - s.crank[i - 1]) / (s.crank[i] - s.crank[i - 1])
            out.append(float(s.speed[i - 1] + f * (s.speed[i] - s.speed[i - 1])))
        else:
            out.append(float("nan"))
    return out


def variant(mech: Mechanism, **changes: Any) -> Mechanism:
    """The scenario with its slider's play changed (stiffness, friction, law)."""
    tc = dataclasses.replace(mech.joint(JOINT).require_translational(), **changes)
    joints = tuple(dataclasses.replace(j, translational_clearance=tc) if j.name == JOINT else j for j in mech.joints)
    return dataclasses.replace(mech, joints=joints)


def figure(ours: Series, sic: list[Series], path: Path) -> None:
    """Crank speed, slider across / c, tilt, contact and energy against time: ours beside the examples'."""
    fig = new_figure(10.0, 10.5)
    ax = fig.subplots(5, 1, sharex=True, gridspec_kw={"height_ratios": [1, 1, 1, 0.8, 0.8]})
    styles = [{"color": "C0", "lw": 1.0}, {"color": "C3", "lw": 0.8, "ls": "--"}, {"color": "C2", "lw": 0.8, "ls": ":"}]
    for s, st in zip([ours, *sic], styles):
        ax[0].plot(s.t * 1e3, s.speed, label=s.name, **st)
        ax[1].plot(s.t * 1e3, s.across, **st)
        ax[2].plot(s.t * 1e3, s.tilt * 1e3, **st)
        ax[4].plot(s.t * 1e3, s.energy, **st)
    ax[0].set_ylabel("crank speed [rad/s]")
    ax[0].legend(fontsize=8, loc="upper right")
    ax[1].set_ylabel("slider across / c")
    ax[2].set_ylabel("slider tilt [mrad]")
    for k, s in enumerate([ours, *sic]):
        for code, colour in ((Lines.UPPER, "C2"), (Lines.LOWER, "C3"), (Lines.BOTH, "C4")):
            hit = s.lines == code.value
            ax[3].plot(s.t[hit] * 1e3, np.full(hit.sum(), -k), "|", ms=6, color=colour)
    ax[3].set_yticks([0, -1, -2], ["ours", "siconos\ncombined", "siconos\ndirect"])
    ax[3].set_ylim(-2.6, 0.6)
    ax[3].set_ylabel("touching\n(green +n line,\nred -n line)")
    ax[4].set_ylabel("kinetic + gravity\nenergy [J]")
    ax[4].set_xlabel("time [ms]")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("Slider-crank with play in the guide (Flores, Leine and Glocker 2010): reference vs siconos")
    fig.tight_layout()
    save_png(fig, path)


def _episode_rows(runs: list[Series], count: int) -> list[str]:
    eps = [episodes(s) for s in runs]
    lines = ["| episode | " + " | ".join(s.name for s in runs) + " |", "|---|" + "---|" * len(runs)]
    for i in range(count):
        cells = []
        for e in eps:
            if i < len(e):
                a, b, line, n = e[i]
                cells.append(f"{a * 1e3:.1f}-{b * 1e3:.1f} ms, {line} line, {n} phase{'s' if n > 1 else ''}")
            else:
                cells.append("")
        lines.append(f"| {i + 1} | " + " | ".join(cells) + " |")
    lines.append("| episodes in 0.2 s | " + " | ".join(str(len(e)) for e in eps) + " |")
    return lines


def main() -> None:
    mech = load_scenario(SCENARIO)
    tc = mech.joint(JOINT).require_translational()
    c = tc.clearance
    sic = siconos_series()
    runs: dict[str, tuple[SimulationResult, float]] = {}
    for label, changes in (
        ("K = 1e10 (scenario)", {}),
        ("K = 1e9", {"stiffness": 1e9}),
        ("K = 1e11", {"stiffness": 1e11}),
        ("K = 1e10, mu = 0", {"friction": 0.0}),
        ("K = 1e10, Gonthier law", {"law": ContactLaw.GONTHIER}),
    ):
        t0 = time.perf_counter()
        res = run_reference(variant(mech, **changes), DURATION, output_interval=OUTPUT, track_work=True)
        runs[label] = (res, time.perf_counter() - t0)
    ours = {k: our_series(r, f"reference, {k}", c) for k, (r, _) in runs.items()}
    main_run = ours["K = 1e10 (scenario)"]
    figure(main_run, sic, HERE / "translational_clearance.png")
    # on the examples' own grid
    dw = np.abs(np.interp(sic[0].t, main_run.t, main_run.speed) - sic[0].speed)
    dw_sic = np.abs(sic[0].speed - sic[1].speed)
    load = os.getloadavg()[0]
    text = [
        "# Slider-crank with play in its guide: the reference beside the siconos example",
        "",
        f"`python benchmarks/translational_clearance.py` (load {load:.1f} on 2 shared cores). Our run is "
        "`clearance reference --scenario builders/scenarios/slider_crank_translational_flores2010.toml "
        "--duration-ms 200` (reference solver, rtol 1e-9, sampled every 10 us); the comparison is the siconos "
        "example's own results for Flores, Leine and Glocker (2010) "
        "(`benchmarks/data/siconos_slider_crank.csv.gz`, its header says where they come from).",
        "",
        "![translational clearance](translational_clearance.png)",
        "",
        "## Parameters, checked in the examples",
        "",
        "| quantity | siconos `SliderCrankPlugin.cpp` and the `.cpp` drivers; cardillo `SliderCrankFlores` | ours |",
        "|---|---|---|",
        "| crank, rod length | l1 = 0.1530 m, l2 = 0.3060 m | 153 mm, 306 mm |",
        "| slider | a = 0.05 m, b = 0.025 m, guide d = 2 (b + c): half-sizes | block 100 mm by 50 mm |",
        "| clearance | c = 0.001 m | 1 mm each side |",
        "| masses | m1 = m2 = 0.038 kg, m3 = 0.076 kg | same |",
        "| inertias | J1 = 7.4e-5, J2 = 5.9e-4, J3 = 2.7e-6 kg m^2 (centres of mass) | same |",
        "| start | q = 0, crank 150 rad/s, rod -75 rad/s, no drive | free crank from 150 rad/s, ideal velocities |",
        "| gravity | 9.81 m/s^2 along -y (in FInt; the issue text omits it) | 9.81 m/s^2 along -y |",
        "| contact | Newton e_N = 0.4, e_T = 0, Coulomb mu = 0.01 (the projection drivers; the plain "
        "Moreau-Jean driver overrides e_N to 0.1 and has no friction) | Flores et al. (2011) law, "
        f"c_e = 0.4, K = {tc.stiffness:.0e} N/m^1.5; Ambrosio friction mu = 0.01 |",
        "| time | T = 0.2 s, h = 1e-4 s (projection drivers) | 0.2 s, adaptive steps |",
        "",
        "## Contact episodes side by side",
        "",
        "An episode is every contact phase on one guide line until the slider touches the other one (the "
        "impacts, bounces and sliding contact of one crossing of the clearance), from its first touch to its last "
        "release; a phase is a stretch of samples in one contact case.",
        "",
        *_episode_rows([main_run, *sic], 12),
        "",
        "## The crank's speed and the energy",
        "",
        "Kinetic plus gravity energy (the contacts' elastic energy is under 1 mJ); its change over the run split "
        "into the steps of free flight and those where a corner touches at either end or a contact starts or ends "
        "(the reference's located switches; the examples' steps are their own time steps).",
        "",
        "| run | crank speed at 1, 2, 3 revolutions [rad/s] | energy at 0, 2.5, 50, 100, 200 ms [J] | "
        "change in free flight | change in contact |",
        "|---|---|---|---|---|",
    ]
    for s in [*ours.values(), *sic]:
        at = np.interp([0.0, 0.0025, 0.05, 0.1, 0.2], s.t, s.energy)
        speeds = ", ".join("not reached" if np.isnan(w) else f"{w:.2f}" for w in dead_centre_speeds(s))
        de, touch = np.diff(s.energy), s.touching_steps()
        text.append(
            f"| {s.name} | {speeds} | {', '.join(f'{e:.4f}' for e in at)} | {de[~touch].sum():+.4f} J | "
            f"{de[touch].sum():+.4f} J |"
        )
    text += [
        "",
        "Largest |crank speed difference|, ours against siconos combined projection: "
        + ", ".join(f"{dw[sic[0].t <= t].max():.2f} rad/s to {t * 1e3:g} ms" for t in (0.02, 0.05, 0.1, 0.2))
        + f"; the two siconos schemes against each other: {dw_sic[sic[0].t <= 0.05].max():.2f} rad/s to 50 ms, "
        f"{dw_sic.max():.2f} rad/s to 200 ms.",
        "",
        "## The compliant stand-in: stiffness and friction",
        "",
        "| run | first 4 episodes' starts moved by | deepest corner penetration | peak corner force | "
        "time in contact | contact phases | largest tilt | energy at 200 ms | wall time |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    base_starts = [e[0] for e in episodes(main_run)]

    def contact_cells(s: Series) -> tuple[str, str, str]:
        """(episode starts moved, time in contact, contact phases) of a run against ours."""
        shift = max(abs(e[0] - b) for e, b in zip(episodes(s)[:4], base_starts[:4]))
        share = float(np.mean(s.cases != SliderContact.FREE.value))
        phases = sum(1 for p in contact_phases(s.t, s.cases, s.lines) if p.case is not SliderContact.FREE)
        return f"{shift * 1e3:.1f} ms", f"{share:.1%}", str(phases)

    for label, (res, wall) in runs.items():
        sr, s = res.sliders[JOINT], ours[label]
        moved, share, phases = contact_cells(s)
        pen = sr.corner_penetration.max()
        text.append(
            f"| {label} | {moved} | {pen * 1e6:.1f} um ({pen / c:.1%} of c) | {sr.corner_force.max():.0f} N | {share} | "
            f"{phases} | {np.abs(sr.tilt).max() * 1e3:.2f} mrad | {s.energy[-1]:.4f} J | {wall:.1f} s |"
        )
    for s in sic:
        moved, share, phases = contact_cells(s)
        text.append(f"| {s.name} | {moved} | (rigid) | (impulses) | {share} | {phases} | 0 | {s.energy[-1]:.4f} J | |")
    from clearance.contact_calibration.impact import law_impact

    rebounds = {
        law: law_impact(law, mass=0.1, speed=0.84, stiffness=tc.stiffness, restitution=0.4).restitution
        for law in (ContactLaw.FLORES, ContactLaw.GONTHIER, ContactLaw.LANKARANI_NIKRAVESH)
    }
    text += [
        "",
        "Restitution of one impact at c_e = 0.4 (the calibration's impact reference: 0.1 kg at 0.84 m/s, the "
        "first impact's approach speed, K as the scenario's): "
        + ", ".join(f"{law.value} {e:.3f}" for law, e in rebounds.items())
        + ".",
        "",
    ]
    print(write_keeping_reading(HERE / "translational_clearance.md", "\n".join(text)))


if __name__ == "__main__":
    main()
