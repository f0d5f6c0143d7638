"""Exudyn as a peer: the default slider-crank in Exudyn and in our compiled exact contact, one run.

Usage:  python benchmarks/exudyn_peer.py [--revolutions 1] [--repeat 3]
                                         [--ours-mode exact] [--ours-timestep-us 2]
                                         [--out benchmarks/exudyn_peer.md]

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

(CObjectContactSphereSphere.cpp; the approach speed is recorded in the step where the gap
first closes). That is the family K δⁿ [1 + χ δ̇/δ̇⁻] of `contact_calibration.laws` with
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
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import scipy
from _tables import write_keeping_reading  # benchmarks/_tables.py (scripts run from benchmarks/)

from clearance.analysis.metrics.accuracy import FirstImpact, first_impact, first_impact_errors
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
        sys.exit(f"exudyn_peer: Exudyn is not installed. Install the benchmark extra:\n    {INSTALL_HINT}")
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


def _clock() -> tuple[float, float]:
    return time.process_time(), time.perf_counter()


def _since(start: tuple[float, float]) -> tuple[float, float]:
    c, w = _clock()
    return c - start[0], w - start[1]


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
    """Time Exudyn (solve alone, and build + solve) and read its first run's contact force."""
    solve, whole = Timing(revolutions=revolutions), Timing(revolutions=revolutions)
    model = None
    for _ in range(repeat):
        start = _clock()
        model = build_exudyn(exu, mech, h=h, duration=duration, newton_rtol=newton_rtol)
        mid = _clock()
        exu.SolveDynamic(model.mbs, model.settings, solverType=exu.DynamicSolverType.GeneralizedAlpha, storeSolver=True)
        solve.add(*_since(mid))
        whole.add(*_since(start))
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
        start = _clock()
        result = simulate(mech, duration=duration, options=options)
        whole.add(*_since(start))
    try:
        from clearance.run.preparation import prepare
        from clearance.run.simulation import simulate_prepared
    except ImportError:
        pass
    else:
        prepared = prepare(mech, options)
        for _ in range(repeat):
            start = _clock()
            simulate_prepared(prepared, duration=duration)
            solve.add(*_since(start))
    return OursRun(result, solve, whole)


