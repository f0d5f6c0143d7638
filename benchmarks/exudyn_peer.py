"""Exudyn as a peer: the default slider-crank in Exudyn and in our compiled exact contact, one run.

Usage:  python benchmarks/exudyn_peer.py [--revolutions 1] [--repeat 5] [--exudyn-step-us 1]
                                         [--exudyn-module fast|regular] [--exudyn-newton-rtol R]
                                         [--ours-mode exact] [--ours-timestep-us 2] [--ours-also-us 1]
                                         [--out benchmarks/exudyn_peer.md | -]

Needs Exudyn 1.13.6, the ``bench`` extra:  pip install -e ".[bench]"

The same scenario three ways, in one process, one run at a time:

  * the reference solver (`clearance.reference.run_reference`, LSODA at rtol 1e-9, output
    every 1 µs), which defines the exact first impact;
  * Exudyn 1.13.6: planar rigid bodies (NodeRigidBody2D + ObjectRigidBody2D at each link's
    centre of mass), ObjectJointRevolute2D for the ideal revolute joints,
    ObjectJointPrismatic2D for the slider guide, the constant crank speed as a
    velocity-level ObjectConnectorCoordinate (crank angle rate = ω, no user function), and
    the clearance joint as its built-in ObjectContactSphereSphere: the journal a sphere of
    radius R_J on the journal link inside a hollow sphere of radius R_B on the bearing link,
    Hunt–Crossley impact model (``impactModel=1``), no Python user function anywhere;
    generalized-α (Exudyn's implicit second-order solver, its default spectral radius 0.9)
    at a fixed step h = 1 µs;
  * ours: `clearance.simulate` with ``ModelOptions(contact_mode="exact", timestep=2e-6)``.

The contact law. Exudyn's Hunt–Crossley model computes, with δ the overlap and δ̇ its rate
(> 0 approaching), f = k δⁿ + λ δⁿ v_n with v_n = −δ̇ and λ = k/δ̇⁻ · 3/2 (e − 1), i.e.

    f = k δⁿ [1 + 3(1 − e)/2 · δ̇/δ̇⁻],   δ̇⁻ = max(minimumImpactVelocity, approach speed)

(Exudyn's documentation of ObjectContactSphereSphere and CObjectContactSphereSphere.cpp; the
approach speed is recorded at the end of the step in which the gap closes). That is the family K δⁿ [1 + χ δ̇/δ̇⁻] of `contact_calibration.laws` with
χ = 3(1 − e)/2, so any law of the family is passed exactly by choosing Exudyn's
restitution coefficient e_X = 1 − 2χ/3: for Lankarani–Nikravesh χ = 3(1 − c_e²)/4 and
e_X = (1 + c_e²)/2 (0.905 for c_e = 0.9). We pass k = `laws.bearing_stiffness` (the
joint's K), n = 1.5, contactDamping = 0 and minimumImpactVelocity =
`laws.MIN_APPROACH_SPEED` (the reference's floor on δ̇⁻). The script checks this on
Exudyn's own trajectory (its reported force against the formula) and runs the reference a
second time with the law as Exudyn states it (Hunt–Crossley with c_e = e_X): both
references must agree.

Timing: CPU time (time.process_time) and wall time, best of ``--repeat`` runs, of (a) the
solve alone on a model built beforehand (Exudyn's SolveDynamic; our simulate_prepared) and
(b) the whole call (Exudyn: items, Assemble and SolveDynamic; ours: simulate, MJCF build
and compile included). Per revolution = time / revolutions simulated.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import scipy
from _clock import clock, since  # benchmarks/_clock.py
from _tables import write_keeping_reading  # benchmarks/_tables.py (scripts run from benchmarks/)

from clearance.analysis.metrics.accuracy import first_impact, first_impact_errors
from clearance.builders import slider_crank
from clearance.contact_calibration.laws import MIN_APPROACH_SPEED, bearing_stiffness, hysteresis_factor
from clearance.model import Clearance, ContactLaw, DriveKind, JointType, Mechanism
from clearance.reference import run_reference
from clearance.reference.system import ReferenceSystem
from clearance.results import JointResult, SimulationResult
from clearance.version import __version__

HERE = Path(__file__).resolve().parent
JOINT = "rod_slider"
EXUDYN_VERSION = "1.13.6"
INSTALL_HINT = 'pip install -e ".[bench]"  (the bench extra pins exudyn==' + EXUDYN_VERSION + ")"


# -- Exudyn ---------------------------------------------------------------------------------


def import_exudyn(module: str) -> Any:
    """Import Exudyn, its fast module (no range checks, AVX2) when ``module`` is "fast".

    Exits with status 2 and the install command when Exudyn is missing.
    """
    sys.exudynFast = module == "fast"  # type: ignore[attr-defined]  # read by exudyn/__init__.py
    try:
        import exudyn
    except ImportError:
        print(
            f"exudyn_peer: Exudyn is not installed. Install the benchmark extra:\n    {INSTALL_HINT}", file=sys.stderr
        )
        sys.exit(2)
    if exudyn.__version__ != EXUDYN_VERSION:
        print(f"exudyn_peer: warning: Exudyn {exudyn.__version__} is installed; this benchmark is for {EXUDYN_VERSION}")
    return exudyn


def exudyn_restitution(clearance: Clearance) -> float:
    """Exudyn's Hunt–Crossley restitution e_X that gives the joint's law exactly: 1 − 2χ/3.

    Raises:
        ValueError: a law outside the family K δⁿ [1 + χ δ̇/δ̇⁻] (IMPACT), or χ >= 1.5 (e_X
            would not be positive, which Exudyn refuses).
    """
    if clearance.law is ContactLaw.IMPACT:
        raise ValueError("the IMPACT law has no Hunt-Crossley form: Exudyn's sphere contact cannot express it")
    chi = hysteresis_factor(clearance.law, clearance.restitution)
    e = 1.0 - 2.0 * chi / 3.0
    if not 0.0 < e <= 1.0:
        raise ValueError(f"hysteresis factor {chi:g} needs Exudyn restitution {e:g}, outside (0, 1]")
    return e


@dataclass
class ExudynModel:
    """An Exudyn system of a mechanism, assembled, with its sensors and solver settings."""

    system_container: Any
    mbs: Any
    settings: Any
    sensors: dict[str, Any]
    restitution: float
    stiffness: float


def build_exudyn(
    exu: Any, mech: Mechanism, *, h: float, duration: float, newton_rtol: float | None = None, check: bool = False
) -> ExudynModel:
    """Build and assemble ``mech`` in Exudyn (planar rigid bodies, built-in items only).

    Args:
        exu: the exudyn module.
        mech: a mechanism with constant-speed drives, revolute and prismatic joints, and
            frictionless clearance joints.
        h: fixed time step [s].
        duration: simulated time [s].
        newton_rtol: Newton's relative tolerance (None: Exudyn's default, 1e-8).
        check: also record what the force-law check needs (relative velocity, normal,
            the contact's data coordinates).

    Raises:
        ValueError: a drive, friction or law Exudyn's built-in items cannot express here.
    """
    from exudyn.itemInterface import (
        MarkerBodyRigid,
        MarkerNodeCoordinate,
        NodeGenericData,
        NodePointGround,
        NodeRigidBody2D,
        ObjectConnectorCoordinate,
        ObjectContactSphereSphere,
        ObjectGround,
        ObjectJointPrismatic2D,
        ObjectJointRevolute2D,
        ObjectRigidBody2D,
        SensorNode,
        SensorObject,
    )

    ref = ReferenceSystem(mech)
    z0, zd0 = ref.to_com(*ref.initial_state())  # ideal positions and velocities, journals centred
    links = {lk.name: lk for lk in mech.links}
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    ground_coordinate = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    nodes, bodies = {}, {}
    for i, name in enumerate(ref.link_names):
        nodes[name] = mbs.AddNode(
            NodeRigidBody2D(
                referenceCoordinates=[float(v) for v in z0[3 * i : 3 * i + 3]],
                initialVelocities=[float(v) for v in zd0[3 * i : 3 * i + 3]],
            )
        )
        bodies[name] = mbs.AddObject(
            ObjectRigidBody2D(mass=links[name].mass, inertia=links[name].inertia, nodeNumber=nodes[name])
        )

    def marker(link: str, point: str) -> Any:
        lk = links[link]
        px, py = lk.point(point)
        if link == mech.ground:
            return mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[px, py, 0.0]))
        return mbs.AddMarker(
            MarkerBodyRigid(bodyNumber=bodies[link], localPosition=[px - lk.com[0], py - lk.com[1], 0.0])
        )

    def angle(link: str) -> Any:
        if link == mech.ground:
            return ground_coordinate
        return mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[link], coordinate=2))

    contact = data_node = None
    restitution = stiffness = math.nan
    for j in mech.joints:
        if j.clearance is not None:
            c = j.clearance
            if c.friction != 0.0:
                raise ValueError(
                    f"joint {j.name!r}: friction {c.friction} - Exudyn's regularised Coulomb law is not Ambrosio's"
                )
            ends = [(j.link_a, j.point_a), (j.link_b, j.point_b)]
            if c.journal_link != j.link_a:
                ends.reverse()
            restitution, stiffness = exudyn_restitution(c), bearing_stiffness(c)
            data_node = mbs.AddNode(
                NodeGenericData(initialCoordinates=[c.radial_clearance, 0.0, 0.0, 0.0], numberOfDataCoordinates=4)
            )
            contact = mbs.AddObject(
                ObjectContactSphereSphere(
                    markerNumbers=[marker(*ends[0]), marker(*ends[1])],  # journal, bearing
                    nodeNumber=data_node,
                    spheresRadii=[c.journal_radius, c.bearing_radius],
                    isHollowSphere1=True,
                    contactStiffness=stiffness,
                    contactStiffnessExponent=1.5,
                    contactDamping=0.0,
                    impactModel=1,  # Hunt-Crossley
                    restitutionCoefficient=restitution,
                    minimumImpactVelocity=MIN_APPROACH_SPEED,
                    dynamicFriction=0.0,
                )
            )
        elif j.kind is JointType.REVOLUTE:
            mbs.AddObject(
                ObjectJointRevolute2D(markerNumbers=[marker(j.link_a, j.point_a), marker(j.link_b, j.point_b)])
            )
        else:
            ax, ay = j.axis
            mbs.AddObject(
                ObjectJointPrismatic2D(
                    markerNumbers=[marker(j.link_a, j.point_a), marker(j.link_b, j.point_b)],
                    axisMarker0=[ax, ay, 0.0],
                    normalMarker1=[-ay, ax, 0.0],
                    constrainRotation=True,
                )
            )
    if contact is None:
        raise ValueError(f"mechanism {mech.name!r} has no clearance joint")
    for d in mech.drives:
        if d.kind is not DriveKind.CONSTANT_SPEED:
            raise ValueError(f"drive {d.name!r}: only constant-speed drives are built without a user function")
        j = mech.joint(d.joint)
        # velocity level: (link_b angle rate) - (link_a angle rate) = speed; the angle follows from it
        mbs.AddObject(
            ObjectConnectorCoordinate(
                markerNumbers=[angle(j.link_a), angle(j.link_b)], offset=d.speed, velocityLevel=True
            )
        )

    ovt = exu.OutputVariableType
    wanted = {"force": ovt.Force, "gap": ovt.DisplacementLocal}
    if check:
        wanted |= {"velocity": ovt.Velocity, "normal": ovt.Director1}
    sensors = {
        k: mbs.AddSensor(
            SensorObject(objectNumber=contact, storeInternal=True, writeToFile=False, outputVariableType=v)
        )
        for k, v in wanted.items()
    }
    if check:
        sensors["data"] = mbs.AddSensor(
            SensorNode(nodeNumber=data_node, storeInternal=True, writeToFile=False, outputVariableType=ovt.Coordinates)
        )
    mbs.Assemble()

    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.startTime, ti.endTime, ti.numberOfSteps = 0.0, duration, int(round(duration / h))
    ti.adaptiveStep = False  # a fixed step h
    ti.discontinuous.useRecommendedStepSize = False  # no step cut at contact onset (it would stop a fixed-step run)
    ti.verboseMode = 0
    if newton_rtol is not None:
        ti.newton.relativeTolerance = newton_rtol
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = h  # every step
    return ExudynModel(sc, mbs, ss, sensors, restitution, stiffness)


@dataclass
class Timing:
    """Best CPU and wall times [s] over repeats, and the revolutions they cover."""

    cpu: float = math.inf
    wall: float = math.inf
    revolutions: float = 1.0

    def add(self, cpu: float, wall: float) -> None:
        self.cpu, self.wall = min(self.cpu, cpu), min(self.wall, wall)

    def per_rev(self) -> tuple[float, float]:
        return self.cpu / self.revolutions, self.wall / self.revolutions


def _result(times: np.ndarray, penetration: np.ndarray, force: np.ndarray, **metadata: Any) -> SimulationResult:
    """A `SimulationResult` holding one clearance joint's penetration and force (what first impacts read).

    The force is (n, 2) in the world frame; eccentricities are not recorded (NaN).
    """
    n = len(times)
    nan2 = np.full((n, 2), np.nan)
    empty = np.zeros((n, 0))
    return SimulationResult(
        times=times,
        outputs={},
        joints={JOINT: JointResult(nan2, nan2.copy(), penetration, force)},
        drive_angle=empty,
        drive_speed=empty,
        drive_torque=empty,
        link_poses=np.zeros((n, 0, 3)),
        closure_violation=np.zeros(n),
        metadata=dict(metadata),
    )


@dataclass
class ExudynRun:
    """Exudyn's first-impact record, timings, solver statistics and force-law check."""

    result: SimulationResult
    solve: Timing
    whole: Timing
    statistics: dict[str, float] = field(default_factory=dict)
    law_check: dict[str, float] = field(default_factory=dict)
    restitution: float = math.nan
    stiffness: float = math.nan


def run_exudyn(
    exu: Any, mech: Mechanism, *, h: float, duration: float, repeat: int, revolutions: float, newton_rtol: float | None
) -> ExudynRun:
    """Time Exudyn (solve alone, and build + solve), read the contact of the last run (all runs are alike)
    and check its force law on a run with more sensors (`check_exudyn_law`)."""
    solve, whole = Timing(revolutions=revolutions), Timing(revolutions=revolutions)
    model = None
    for _ in range(repeat):
        start = clock()
        model = build_exudyn(exu, mech, h=h, duration=duration, newton_rtol=newton_rtol)
        mid = clock()
        exu.SolveDynamic(model.mbs, model.settings, solverType=exu.DynamicSolverType.GeneralizedAlpha, storeSolver=True)
        solve.add(*since(mid))
        whole.add(*since(start))
    assert model is not None
    it = model.mbs.sys["dynamicSolver"].it
    steps = int(round(duration / h))
    stats = {
        "steps": steps,
        "newton_per_step": it.newtonStepsCount / steps,
        "jacobians": it.newtonJacobiCount,
        "discontinuous_iterations": it.discontinuousIterationsCount,
    }
    force = model.mbs.GetSensorStoredData(model.sensors["force"])
    gap = model.mbs.GetSensorStoredData(model.sensors["gap"])
    result = _result(force[:, 0], -gap[:, 1], force[:, 1:3].copy(), solver="exudyn", time_step=h)
    run = ExudynRun(result, solve, whole, stats, restitution=model.restitution, stiffness=model.stiffness)
    run.law_check = check_exudyn_law(exu, mech, h=h, duration=duration, newton_rtol=newton_rtol)
    return run


def check_exudyn_law(
    exu: Any, mech: Mechanism, *, h: float, duration: float, newton_rtol: float | None
) -> dict[str, float]:
    """Exudyn's reported normal force against K δⁿ [1 + 3(1 − e_X)/2 · δ̇/δ̇⁻] on its own trajectory.

    Returns:
        ``max_rel_dev``: largest |F_exudyn − F_formula| / peak force over every sample in
        contact; ``min_force``: smallest normal force in contact (negative: Exudyn pulls,
        where our laws clip at 0); ``approach_speed``: the first impact's δ̇⁻ Exudyn recorded.
    """
    m = build_exudyn(exu, mech, h=h, duration=duration, newton_rtol=newton_rtol, check=True)
    exu.SolveDynamic(m.mbs, m.settings, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    get = m.mbs.GetSensorStoredData
    force, gap, vel, normal, data = (get(m.sensors[k])[:, 1:] for k in ("force", "gap", "velocity", "normal", "data"))
    delta = -gap[:, 0]
    inside = delta > 0
    # marker 1 (the bearing) gets f = -F n with n the normal: F = -(f . n)
    fn = -np.einsum("ij,ij->i", force, normal)
    delta_dot = -np.einsum("ij,ij->i", vel, normal)  # v_n = (v_1 - v_0) . n = -delta_dot
    approach = np.maximum(MIN_APPROACH_SPEED, data[:, 2])
    d = np.where(inside, delta, 0.0)
    formula = m.stiffness * d**1.5 * (1.0 + 1.5 * (1.0 - m.restitution) * delta_dot / approach)
    peak = float(np.max(np.abs(fn[inside])))
    first = int(np.argmax(inside))
    return {
        "max_rel_dev": float(np.max(np.abs(fn - formula)[inside]) / peak),
        "min_force": float(fn[inside].min()),
        "approach_speed": float(data[first, 2]),
    }


# -- ours -----------------------------------------------------------------------------------


@dataclass
class OursRun:
    """Our run's result (None if the contact mode was refused, with ``error`` saying why) and timings."""

    result: SimulationResult | None
    solve: Timing
    whole: Timing
    error: str = ""


def run_ours(mech: Mechanism, *, mode: str, h: float, duration: float, repeat: int, revolutions: float) -> OursRun:
    """Time `simulate` (whole call) and `simulate_prepared` (stepping alone) in contact mode ``mode``."""
    from clearance import ModelOptions, simulate

    solve, whole = Timing(revolutions=revolutions), Timing(revolutions=revolutions)
    try:
        options = ModelOptions(contact_mode=mode, timestep=h)
        simulate(mech, duration=min(duration, 10 * h), options=options)  # warm-up: plugin load, imports
    except (ValueError, TypeError) as exc:
        return OursRun(None, solve, whole, error=f"{type(exc).__name__}: {exc}")
    result = None
    for _ in range(repeat):
        start = clock()
        result = simulate(mech, duration=duration, options=options)
        whole.add(*since(start))
    try:  # the stepping alone, on a model prepared beforehand
        from clearance.run.preparation import prepare
        from clearance.run.simulation import simulate_prepared

        prepared = prepare(mech, options)
        for _ in range(repeat):
            start = clock()
            simulate_prepared(prepared, duration=duration)
            solve.add(*since(start))
    except (ImportError, TypeError) as exc:  # internals moved: only the whole call is timed
        print(f"exudyn_peer: our stepping is not timed alone ({type(exc).__name__}: {exc})", file=sys.stderr)
        solve = Timing(revolutions=revolutions)
    return OursRun(result, solve, whole)


# -- report ---------------------------------------------------------------------------------


def accuracy(run: SimulationResult, ref: SimulationResult) -> dict[str, float] | None:
    """First-impact errors of ``run`` against ``ref`` (None if either never touches).

    Returns:
        `first_impact_errors` (relative errors of ``peak_force``, ``max_penetration``,
        ``impulse``; ``onset`` difference [s]), ``peak`` (the run's first-impact peak [N])
        and ``force``: max |F_run - F_ref| over the reference's first impact, at the run's
        samples (the reference interpolated; exact on its 1 µs grid), over the reference's peak.
    """
    fi, fr = first_impact(run, JOINT), first_impact(ref, JOINT)
    if fi is None or fr is None:
        return None
    out = first_impact_errors(fi, fr)
    out["peak"] = fi.peak_force
    pad = float(ref.times[1] - ref.times[0])
    t = run.times
    sel = (t >= fr.onset - pad) & (t <= fr.end + pad)
    f_ref = np.interp(t[sel], ref.times, ref.joints[JOINT].force_magnitude)
    out["force"] = float(np.max(np.abs(run.joints[JOINT].force_magnitude[sel] - f_ref)) / fr.peak_force)
    return out


def _accuracy_cells(acc: dict[str, float] | None) -> list[str]:
    if acc is None:
        return ["no impact"] + ["-"] * 5
    return [
        f"{acc['peak']:.2f}",
        f"{acc['peak_force']:+.3e}",
        f"{acc['force']:.2e}",
        f"{acc['max_penetration']:+.2e}",
        f"{acc['impulse']:+.2e}",
        f"{acc['onset'] * 1e6:+.1f}",
    ]


def _time_cells(t: Timing) -> list[str]:
    if not math.isfinite(t.cpu):
        return ["-", "-"]
    cpu, wall = t.per_rev()
    return [f"{cpu * 1e3:.1f}", f"{wall * 1e3:.1f}"]


def _compare(ours: float, theirs: float) -> str:
    """Which error is smaller; within 1 % of each other counts as a tie (the third digit is sampling)."""
    if abs(ours - theirs) <= 0.01 * max(ours, theirs):
        return "a tie (within 1 % of each other)"
    return "ours better" if ours < theirs else "Exudyn better"


def _row(*cells: str) -> str:
    return "| " + " | ".join(cells) + " |"


COLUMNS = (
    "run",
    "step [µs]",
    "solve CPU / rev [ms]",
    "solve wall / rev [ms]",
    "whole call CPU / rev [ms]",
    "whole call wall / rev [ms]",
    "first-impact peak [N]",
    "peak error",
    "force error over the first impact",
    "max penetration error",
    "impulse error",
    "onset - ref [µs]",
)


def _machine(exu: Any) -> str:
    import mujoco

    module = getattr(exu, "_compiledModuleName", "?")  # the compiled module Exudyn loaded
    return (
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores (shared); Python "
        f"{platform.python_version()}, NumPy {np.__version__}, SciPy {scipy.__version__}, MuJoCo "
        f"{mujoco.__version__}, Exudyn {exu.__version__} ({module}), clearance {__version__}; "
        f"{datetime.now(UTC):%Y-%m-%d %H:%M} UTC"
    )


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        description="Exudyn 1.13.6 (ObjectContactSphereSphere, Hunt-Crossley, generalized-alpha) against "
        "our compiled exact contact on the default slider-crank, in one run; writes a Markdown table.",
        epilog="Needs the bench extra: " + INSTALL_HINT,
    )
    ap.add_argument("--revolutions", type=float, default=1.0, help="crank revolutions simulated (default 1: 12 ms)")
    ap.add_argument("--repeat", type=int, default=5, help="timed runs of each solver; the best counts (default 5)")
    ap.add_argument("--exudyn-step-us", type=float, default=1.0, help="Exudyn's fixed step [µs] (default 1)")
    ap.add_argument(
        "--exudyn-module",
        choices=("fast", "regular"),
        default="fast",
        help="Exudyn's compiled module: fast (no range checks, the faster) or regular (default fast)",
    )
    ap.add_argument(
        "--exudyn-newton-rtol",
        type=float,
        default=None,
        help="Exudyn's Newton relative tolerance (default: Exudyn's own, 1e-8)",
    )
    ap.add_argument("--ours-mode", default="exact", help="our ModelOptions.contact_mode (default exact)")
    ap.add_argument("--ours-timestep-us", type=float, default=2.0, help="our time step [µs] (default 2)")
    ap.add_argument(
        "--ours-also-us",
        type=float,
        nargs="*",
        default=[1.0],
        help="further time steps [µs] of ours, reported beside the main one (default 1; give none for none)",
    )
    ap.add_argument(
        "--out",
        default=str(HERE / "exudyn_peer.md"),
        help="Markdown file (default benchmarks/exudyn_peer.md; '-': print only)",
    )
    return ap


def main(argv: list[str] | None = None) -> int:
    ap = _parser()
    args = ap.parse_args(argv)
    if args.repeat < 1 or args.revolutions <= 0:
        ap.error("--repeat must be >= 1 and --revolutions > 0")
    exu = import_exudyn(args.exudyn_module)
    cmd = "python benchmarks/exudyn_peer.py " + " ".join(sys.argv[1:] if argv is None else argv)

    mech = slider_crank()
    clr = mech.joint(JOINT).require_clearance()
    revs = args.revolutions
    duration = revs * mech.drive_period
    k, e_x = bearing_stiffness(clr), exudyn_restitution(clr)

    print("reference ...", flush=True)
    start = clock()
    ref = run_reference(mech, duration, output_interval=1e-6, rtol=1e-9)
    ref_time = Timing(revolutions=revs)
    ref_time.add(*since(start))
    ref_fi = first_impact(ref, JOINT)
    if ref_fi is None:
        raise RuntimeError("the reference run has no impact: nothing to compare")
    # the same law written as Exudyn computes it: Hunt-Crossley with its restitution e_X
    ref_hc = run_reference(slider_crank(law=ContactLaw.HUNT_CROSSLEY, restitution=e_x), duration, output_interval=1e-6)
    hc_fi = first_impact(ref_hc, JOINT)
    hc_dev = abs(hc_fi.peak_force / ref_fi.peak_force - 1.0) if hc_fi is not None else math.nan
    # the reference's first impact sampled every 10 ns: what a 1 µs sampling of the peak loses
    fine = first_impact(run_reference(mech, ref_fi.end + 20e-6, output_interval=1e-8, rtol=1e-9), JOINT)
    fine_peak = fine.peak_force if fine is not None else math.nan

    print("Exudyn ...", flush=True)
    h_x = args.exudyn_step_us * 1e-6
    ex = run_exudyn(
        exu, mech, h=h_x, duration=duration, repeat=args.repeat, revolutions=revs, newton_rtol=args.exudyn_newton_rtol
    )
    ex_acc = accuracy(ex.result, ref)

    print("ours ...", flush=True)
    ours: dict[float, OursRun] = {}
    for us in [args.ours_timestep_us, *args.ours_also_us]:
        if us not in ours:
            ours[us] = run_ours(
                mech, mode=args.ours_mode, h=us * 1e-6, duration=duration, repeat=args.repeat, revolutions=revs
            )
    main_ours = ours[args.ours_timestep_us]

    rows = [_row(*COLUMNS), "|" + "---|" * len(COLUMNS)]
    rows.append(
        _row(
            "reference: LSODA, rtol 1e-9, output 1 µs (one run)",
            "adaptive",
            *_time_cells(ref_time),
            *_time_cells(ref_time),
            *_accuracy_cells(accuracy(ref, ref)),
        )
    )
    rows.append(
        _row(
            f"reference, the law as Exudyn writes it: Hunt-Crossley, c_e = {e_x:g}",
            "adaptive",
            *["-"] * 4,
            *_accuracy_cells(accuracy(ref_hc, ref)),
        )
    )
    rows.append(
        _row(
            f"Exudyn {exu.__version__}: generalized-alpha, ObjectContactSphereSphere",
            f"{args.exudyn_step_us:g}",
            *_time_cells(ex.solve),
            *_time_cells(ex.whole),
            *_accuracy_cells(ex_acc),
        )
    )
    for us, o in ours.items():
        label = f"ours: contact_mode={args.ours_mode}" + ("" if us == args.ours_timestep_us else " (extra row)")
        if o.result is None:
            rows.append(_row(label, f"{us:g}", f"not run: {o.error}", *[""] * (len(COLUMNS) - 3)))
        else:
            rows.append(
                _row(
                    label,
                    f"{us:g}",
                    *_time_cells(o.solve),
                    *_time_cells(o.whole),
                    *_accuracy_cells(accuracy(o.result, ref)),
                )
            )

    verdict = []
    if main_ours.result is not None and ex_acc is not None:
        o_acc = accuracy(main_ours.result, ref)
        assert o_acc is not None
        for what, a, b in (("solve alone", ex.solve, main_ours.solve), ("whole call", ex.whole, main_ours.whole)):
            if math.isfinite(b.cpu):
                verdict.append(
                    f"- Speed, {what}: Exudyn / ours = **{a.cpu / b.cpu:.1f}x** in CPU time, "
                    f"{a.wall / b.wall:.1f}x in wall time."
                )
        e_o, e_x_err = abs(o_acc["peak_force"]), abs(ex_acc["peak_force"])
        peak_verdict = _compare(e_o, e_x_err)
        verdict.append(
            f"- First-impact peak error (|peak / reference peak - 1|): ours {e_o:.3e}, Exudyn {e_x_err:.3e}: "
            f"{peak_verdict}. Force error over the first impact: ours {o_acc['force']:.2e}, Exudyn "
            f"{ex_acc['force']:.2e}: {_compare(o_acc['force'], ex_acc['force'])}."
        )
        timed = main_ours.solve if math.isfinite(main_ours.solve.cpu) else main_ours.whole
        speed = ex.solve.cpu / timed.cpu
        met = speed >= 20.0 and not peak_verdict.startswith("Exudyn")
        verdict.append(
            f"- Target, >= 20x faster (CPU, solve alone) at equal or better first-impact peak error: "
            f"**{'met' if met else 'not met'}** ({speed:.1f}x; peak error: {peak_verdict})."
        )
    else:
        verdict.append(f"- Ours not run ({main_ours.error}): no speed ratio in this run.")

    st, lc = ex.statistics, ex.law_check
    onset_speed = ref.metadata["contact_onsets"][JOINT][0][1]
    chi = hysteresis_factor(clr.law, clr.restitution)
    rtol_text = "1e-8 (its default)" if args.exudyn_newton_rtol is None else f"{args.exudyn_newton_rtol:g}"
    lines = [
        "# Exudyn as a peer: the default slider-crank, side by side",
        "",
        f"Command: `{cmd.strip()}`",
        "",
        f"Machine: {_machine(exu)}. Times are the best of {args.repeat} runs, one at a time, on a "
        "shared machine: CPU time is the steadier measure.",
        "",
        f"Scenario: `slider_crank()`: clearance {clr.radial_clearance * 1e3:g} mm at `{JOINT}` (R_B = "
        f"{clr.bearing_radius * 1e3:g} mm, R_J = {clr.journal_radius * 1e3:g} mm), crank at 5000 rpm constant "
        f"speed, no gravity, no friction, {clr.law.value} with c_e = {clr.restitution:g}, K = {k:.4g} N/m^1.5, "
        f"n = 1.5; ideal positions and velocities at t = 0 with the journal centred; {revs:g} revolution(s) "
        f"= {duration * 1e3:g} ms.",
        "",
        *rows,
        "",
        *verdict,
        "",
        "Notes:",
        "",
        "- Errors are against the first row, the project's reference, with the project's measure "
        "(`analysis.metrics.accuracy.first_impact`, `first_impact_errors`: the samples of the first contact "
        "event; reference and Exudyn sampled every 1 µs, ours every step). Force error over the first impact: "
        "max |F - F_ref| at the run's samples within the reference's first impact, over the reference's peak.",
        f"- Sampling: the reference's first-impact peak sampled every 10 ns is {fine_peak:.2f} N, "
        f"{fine_peak / ref_fi.peak_force - 1:+.2e} from its 1 µs samples (first row): peak errors of that size "
        "say where the samples fall, not how accurate the run is. The force error over the first impact "
        "compares the runs at common instants.",
        "- Solve alone: the run on a model built beforehand (Exudyn `SolveDynamic`, with two sensors storing "
        "force and gap every step; ours `simulate_prepared`, returning the full-rate `SimulationResult`). "
        "Whole call: Exudyn items + `Assemble` + `SolveDynamic`; ours `simulate` (MJCF build, compile and "
        "contact setup included). The reference row is one call of `run_reference`.",
        f"- Exudyn's contact law: `ObjectContactSphereSphere` with `impactModel=1` (Hunt-Crossley) computes "
        f"F = k d^n [1 + 3(1 - e)/2 * d'/v0], d the overlap, d' its rate, v0 = max(minimumImpactVelocity, "
        f"approach speed). We pass k = K = {k:.4g} N/m^1.5, n = 1.5, contactDamping = 0, "
        f"minimumImpactVelocity = {MIN_APPROACH_SPEED:g} m/s (the reference's floor on v0), dynamicFriction = 0 "
        f"and restitutionCoefficient e = (1 + c_e^2)/2 = {e_x:g}: its factor 3(1 - e)/2 = {1.5 * (1 - e_x):.6g} "
        f"equals Lankarani-Nikravesh's 3(1 - c_e^2)/4 = {chi:.6g}, so Exudyn computes the joint's own law. "
        f"The second row runs the reference with the law written Exudyn's way (Hunt-Crossley, c_e = e): its "
        f"peak differs from the first row's by {hc_dev:.1e}.",
        f"- Checked on Exudyn's own run: its reported normal force equals that formula to {lc['max_rel_dev']:.1e} "
        "of the peak at every sample in contact.",
        f"- What still differs: Exudyn records v0 at the end of the step in which the gap closes "
        f"({lc['approach_speed']:.6g} m/s at the first impact), the reference at the exact onset "
        f"({onset_speed:.6g} m/s); Exudyn does not clip the force at 0, our laws do (smallest force in contact "
        f"in Exudyn's run: {lc['min_force']:.3g} N"
        f"{', so the clip never acts here' if lc['min_force'] >= 0 else ', negative: Exudyn pulls there'}). "
        "Geometry: a sphere in a hollow sphere, all motion in the plane z = 0: the same circle-in-circle "
        "penetration |e| - c as ours.",
        f"- Exudyn model: NodeRigidBody2D + ObjectRigidBody2D per link (node at the centre of mass), "
        f"ObjectJointRevolute2D (crank pivot, crank-rod), ObjectJointPrismatic2D with the rotation constrained "
        f"(slider guide), the crank speed a velocity-level ObjectConnectorCoordinate (offset = 5000 rpm); "
        f"generalized-alpha with Exudyn's defaults (spectral radius 0.9, index 3, modified Newton, relative "
        f"tolerance {rtol_text}) at a fixed step: adaptiveStep off, and the discontinuous iteration's "
        f"recommended step off (with the step fixed it stops the run at the first contact). {st['steps']} "
        f"steps, {st['newton_per_step']:.2f} Newton iterations per step, {st['jacobians']} Jacobians, "
        f"{st['discontinuous_iterations']} discontinuous iterations.",
        f'- Ours: `simulate(mech, duration, options=ModelOptions(contact_mode="{args.ours_mode}", '
        f"timestep={args.ours_timestep_us:g}e-6))`: MuJoCo with the compiled exact-geometry contact plugin.",
        "",
    ]
    text = "\n".join(lines)
    if args.out != "-":
        text = write_keeping_reading(args.out, text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
