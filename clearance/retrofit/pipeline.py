"""`retrofit`: give hinges of any MuJoCo model radial play, in ring mode.

Steps (each in its own module): check the request (`selection`); run the unmodified model
under the sizing control and read its hinge loads (`motion`); put two slides before each
hinge and the centre sites (`insertion`, `elements`, `frames`), extend the keyframes
(`coordinates`); measure each bearing's effective mass along its load and size it, choose
the segment count and the time step (`sizing`); calibrate its contact (`contact`); add the
ring, pairs and sensors; compile; check that no body's mass or inertia moved; measure the
speed cost (`speed`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field

import mujoco

from clearance.checks import of_type
from clearance.mjcf.bearing import RingGeometry
from clearance.mjcf.spec import ring_geometry
from clearance.model import Joint, JointType
from clearance.options import ContactMode, ContactParameters, GeomType, ModelOptions
from clearance.retrofit.accuracy import Miss, fit_miss, refuse_or_warn, ripple_miss
from clearance.retrofit.contact import PlayContact, play_contact, row_inverse_weight, write_pair_contact
from clearance.retrofit.contact_softness import keep_contact_softness
from clearance.retrofit.conventions import check_conventions, joint_ids
from clearance.retrofit.coordinates import CoordinateMap, check_map, coordinate_map, extend_keyframes
from clearance.retrofit.elements import add_builtin_class
from clearance.retrofit.frames import BearingFrame, bearing_frame
from clearance.retrofit.insertion import PlayElements, add_bearing, add_exact_contact, add_slides_and_sites
from clearance.retrofit.loop import Pin, add_pin, connect_frame, pin_insertion_joint, pin_share, soften_like_twin
from clearance.retrofit.masses import FROZEN_NOTE, Inertial, PointMassSplit, check_masses, freeze_inertials
from clearance.retrofit.motion import Motion, twin_motion
from clearance.retrofit.play import RadialPlay, RetrofitError, RetrofitOptions
from clearance.retrofit.radial_stop import RadialStop, add_radial_stop, fit_radial_stop, stop_parameters
from clearance.retrofit.selection import Hinge, compile_model, model_label, select_hinges
from clearance.retrofit.sizing import (
    PlayMass,
    PlaySizing,
    check_time_step,
    choose_time_step,
    effective_masses,
    size_play,
)
from clearance.retrofit.softness import keep_constraint_softness, softness_note
from clearance.retrofit.speed import Clock, SpeedCost, measure_speed

__all__ = ["RetrofittedHinge", "Retrofit", "retrofit", "INTEGRATORS", "EXACT_SOURCE"]

EXACT_SOURCE = "exact: compiled plugin clearance.journal_bearing"
"""The contact source of a hinge in the exact mode (its stiffness is the Hertz-type K)."""

INTEGRATORS = {
    mujoco.mjtIntegrator.mjINT_EULER: "euler",
    mujoco.mjtIntegrator.mjINT_RK4: "rk4",
    mujoco.mjtIntegrator.mjINT_IMPLICIT: "implicit",
    mujoco.mjtIntegrator.mjINT_IMPLICITFAST: "implicitfast",
}
"""MuJoCo integrators by the names `ModelOptions` uses."""


@dataclass
class RetrofittedHinge:
    """One hinge with radial play.

    Attributes:
        name: the hinge.
        play: its play (physics).
        hinge: where it sits (joint and body ids, the same in both models).
        frame: its bearing frame.
        elements: names of what was added for it.
        ring: the ring's geometry (None in the exact mode: no ring).
        mass: effective mass over the motion.
        sizing: loads, sizes, segment count and contact frequency.
        contact: contact parameters and their source (exact mode: the law's stiffness K
            [N/m^1.5] and no damping parameter; the plugin computes the law's own).
        model_options: the options its ring was built and calibrated with (segments, geoms,
            time step, integrator, impedance, contact mode).
        pin: a loop closure's pin (its share of the donor's mass, its connect's softness); None
            for a hinge.
        stop: the step-limited radial stop at the robot's step (`RetrofitOptions.robot_step`);
            None for a ring or the exact contact.
    """

    name: str
    play: RadialPlay
    hinge: Hinge
    frame: BearingFrame
    elements: PlayElements
    ring: RingGeometry | None
    mass: PlayMass
    sizing: PlaySizing
    contact: PlayContact
    model_options: ModelOptions
    pin: Pin | None = None
    stop: RadialStop | None = None


@dataclass
class Retrofit:
    """A retrofitted model, its unmodified twin and everything a report needs.

    Attributes:
        spec: the retrofitted spec (ring mode: stock MuJoCo compiles it).
        model: ``spec`` compiled.
        twin_spec: the unmodified spec (a copy: the caller's spec is not changed).
        twin: ``twin_spec`` compiled.
        hinges: hinge name -> its play, elements, sizing and contact, in the order given.
        options: the numerical choices.
        integrator: the model's integrator (kept), by `ModelOptions`' name.
        timestep: the retrofitted model's time step [s].
        cmap: where the unmodified coordinates sit in the retrofitted model.
        motion: the unmodified model's sizing motion.
        keyframes: keyframes extended.
        speed: the speed cost (None when not measured).
        notes: remarks for the report (warnings of the motion, frozen inertials).
        timings: wall time per phase [s]: 'checks', 'sizing motion', 'spec edit and
            compiles', 'effective masses', 'segment rule', 'contact parameters', 'speed'.
        warnings: rings kept although they miss their stated accuracy (with
            ``options.accept_inaccurate``; `clearance.retrofit.accuracy`), one line each.
    """

    spec: mujoco.MjSpec
    model: mujoco.MjModel
    twin_spec: mujoco.MjSpec
    twin: mujoco.MjModel
    hinges: dict[str, RetrofittedHinge]
    options: RetrofitOptions
    integrator: str
    timestep: float
    cmap: CoordinateMap
    motion: Motion
    keyframes: int
    speed: SpeedCost | None = None
    notes: list[str] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)

    @property
    def wall_time(self) -> float:
        """Wall time of the retrofit without the speed measurement [s]."""
        return sum(t for phase, t in self.timings.items() if phase != "speed")


def _check_plays(joints: Mapping[str, RadialPlay]) -> None:
    of_type("joints", joints, Mapping, "a mapping hinge name -> RadialPlay (e.g. {'elbow': RadialPlay()})")
    for name, play in joints.items():
        if not isinstance(name, str) or not name:
            raise RetrofitError(f"hinge names must be non-empty strings (got {name!r})")
        of_type(f"joints[{name!r}]", play, RadialPlay, f"a RadialPlay (the play of hinge '{name}')")


def _spec_bodies(spec: mujoco.MjSpec) -> dict[int, mujoco.MjsBody]:
    """Spec bodies by the id the last compile gave them."""
    return {int(b.id): b for b in spec.bodies}


def _in_model(hinge: Hinge, bodies: Mapping[int, mujoco.MjsBody], spec: mujoco.MjSpec, added: PlayElements) -> Hinge:
    """``hinge`` with the body ids of the last compile of ``spec`` (a pin shifts the bodies after it); a
    connect's journal body is its pin."""
    child = spec.body(added.journal_body).id if hinge.is_connect else bodies[hinge.child_id].id
    return dataclasses.replace(hinge, child_id=int(child), parent_id=int(bodies[hinge.parent_id].id))


def _ring(play: RadialPlay, segments: int, options: ModelOptions) -> RingGeometry:
    joint = Joint("hinge", JointType.REVOLUTE, "parent", "centre", "child", "centre", clearance=play.clearance)
    return ring_geometry(joint, segments, options)


def retrofit(
    spec: mujoco.MjSpec,
    joints: Mapping[str, RadialPlay],
    options: RetrofitOptions | None = None,
) -> Retrofit:
    """Give each named hinge of ``spec`` radial play: a journal in a calibrated ring bearing.

    The child body of each hinge keeps its hinge and gains two slides before it, in the
    plane normal to the hinge axis through the hinge position (the bearing frame); the
    parent body gets the ring, the child the journal, with explicit contact pairs between
    them only. Everything else of the model is kept: bodies, masses and inertias, actuators,
    sensors (new ones are appended), keyframes (extended for the slides), defaults, assets,
    equality constraints, the integrator. The time step becomes the one the stability rule
    chooses (`clearance.retrofit.sizing`) unless ``options.timestep`` is given. A `connect`
    equality named instead of a hinge gets a pin on its body2 that the connect ties to body1's
    anchor, the journal on the pin (`clearance.retrofit.loop`): the one body a retrofit adds.

    Args:
        spec: the user's model (not changed: the retrofit edits a copy).
        joints: hinge name -> its play, in the order the report lists them.
        options: numerical choices (default `RetrofitOptions()`).

    Returns:
        The retrofitted model, its twin and what was measured and added.

    Raises:
        TypeError: ``spec``, ``joints`` or a play of the wrong type, naming it
            (`clearance.checks.WrongTypeError`, also a ValueError).
        RetrofitError: a bad request or model, before any work (see `select_hinges`); a
            time step too large for a bearing.
        CalibrationStabilityError: a fitted contact unstable at the time step.
    """
    of_type("spec", spec, mujoco.MjSpec, "a mujoco.MjSpec (read a model file with mujoco.MjSpec.from_file(path))")
    of_type("options", options, (RetrofitOptions, type(None)), "a RetrofitOptions or None")
    options = options or RetrofitOptions()
    robot = options.robot_step is not None
    exact = options.contact_mode is ContactMode.EXACT and not robot
    clock = Clock()
    with clock("checks"):
        _check_plays(joints)
        if exact:
            from clearance.contact_plugin import require as require_plugin

            require_plugin()  # before any work: without the compiled plugin this mode cannot run
        twin_spec = spec.copy()
        twin = compile_model(twin_spec)
        hinges = select_hinges(twin_spec, twin, list(joints))
        for h in hinges:
            if h.is_connect and any(joints[h.name].initial_eccentricity):
                raise RetrofitError(
                    f"connect '{h.name}': a loop closure's journal starts centred (its pin sits at body1's anchor, "
                    f"which the keyframes place); got initial_eccentricity {joints[h.name].initial_eccentricity}"
                )
    notes: list[str] = []
    with clock("sizing motion"):
        data = mujoco.MjData(twin)
        mujoco.mj_kinematics(twin, data)
        frames = {
            h.name: connect_frame(twin, data, h.equality_id, h.axis_joint)
            if h.is_connect
            else bearing_frame(twin, data, h.joint_id)
            for h in hinges
        }
        motion = twin_motion(twin, hinges, frames, options.control, options.sizing_duration)
    if motion.warnings:
        notes.append(
            f"the unmodified model raised MuJoCo warnings {motion.warnings} during the sizing motion "
            f"({len(motion.times)} steps kept)"
        )

    with clock("spec edit and compiles"):
        work = spec.copy()
        compile_model(work)  # gives the work spec's elements the compiled ids the twin has
        pinned = any(h.is_connect for h in hinges)  # a pin is the one body, and the one inertial, a retrofit adds
        if freeze_inertials(work, twin, adds_bodies=pinned, cuts_pins=pinned):
            notes.append(FROZEN_NOTE)
        bodies = _spec_bodies(work)
        geoms = {int(g.id): g for g in work.geoms}  # by the twin's ids, as bodies
        cls = add_builtin_class(work)
        elements: dict[str, PlayElements] = {}
        donors: dict[int, Inertial] = {}
        shares: dict[str, PointMassSplit] = {}
        for h in hinges:
            if h.parent_id not in bodies:
                raise RetrofitError(f"the parent body of hinge '{h.name}' is not in the spec of {model_label(spec)}")
            if h.is_connect:
                shares[h.name] = pin_share(twin, h.equality_id, donors)
                elements[h.name] = add_pin(work, h.name, bodies[h.parent_id], frames[h.name], shares[h.name], cls)
                continue
            elements[h.name] = add_slides_and_sites(work, work.joint(h.name), bodies[h.parent_id], frames[h.name], cls)
        for donor, remainder in donors.items():
            remainder.apply(bodies[donor])
        cmap = coordinate_map(
            twin,
            {h.name: h.joint_id for h in hinges if not h.is_connect},
            {h.name: pin_insertion_joint(twin, h.parent_id) for h in hinges if h.is_connect},
        )
        offsets = {h.name: joints[h.name].initial_eccentricity for h in hinges}
        nkeys = extend_keyframes(work, twin, cmap, offsets)
        kinematic = compile_model(work)
        check_map(cmap, kinematic, {n: e.slides for n, e in elements.items()})
        in_model = {h.name: _in_model(h, bodies, work, elements[h.name]) for h in hinges}

    with clock("effective masses"):
        masses = effective_masses(kinematic, cmap, list(in_model.values()), frames, motion)
    sizings: dict[str, PlaySizing] = {}
    flat = options.segment_geom is GeomType.BOX
    with clock("segment rule"):
        for h in hinges:
            sizings[h.name] = size_play(
                joints[h.name].clearance,
                motion.load_size(h.name),
                masses[h.name],
                segments=0 if exact or robot else options.segments,  # the exact contact and the stop have no ring
                ripple_limit=options.ripple_limit,
                flat=flat,
            )
    h_model = float(twin.opt.timestep)
    step = options.robot_step or options.timestep or choose_time_step(sizings, h_model)
    for name, s in sizings.items():
        if not robot:  # the step-limited stop is checked where it is fitted
            check_time_step(name, s, step)
    pins = {n: soften_like_twin(work, twin, kinematic, n, share, step) for n, share in shares.items()}
    same_joints = list(enumerate(joint_ids(twin, kinematic, cmap.qpos)))
    kept = keep_constraint_softness(work, twin, kinematic, same_joints, step, skip=set(shares))
    contacts = keep_contact_softness(work, twin, kinematic, geoms, step, cls)
    if kept or contacts:
        notes.append(softness_note([(k.label, k.softness) for k in kept] + [(c.label, c.softness) for c in contacts]))

    integrator = INTEGRATORS.get(mujoco.mjtIntegrator(int(twin.opt.integrator)), "implicitfast")
    if options.contact_mode is ContactMode.CALIBRATED and integrator not in ("implicitfast", "euler"):
        notes.append(
            f"the model integrates with {integrator}; the ring's contact is fitted in the one-bearing impact scene, "
            "which integrates with implicitfast (its explicit contact step is Euler's and implicitfast's alike)"
        )
    options_of = {h.name: _model_options(options, sizings[h.name], step, integrator) for h in hinges}
    rings = {
        h.name: _ring(joints[h.name], sizings[h.name].segments, options_of[h.name])
        for h in hinges
        if not (exact or robot)
    }
    chosen = options.segments is None  # the rule has tried every finer count already
    found = [
        ripple_miss(n, ring, sizings[n], options.ripple_limit, flat=flat, chosen=chosen) for n, ring in rings.items()
    ]
    misses = [m for m in found if m is not None]
    warnings = refuse_or_warn(misses, options.accept_inaccurate)  # before the fits: refusing costs nothing
    done: dict[str, RetrofittedHinge] = {}
    fit_misses: list[Miss] = []
    for h in hinges:
        play, sizing, model_options = joints[h.name], sizings[h.name], options_of[h.name]
        ring, stop, added = rings.get(h.name), None, elements[h.name]
        with clock("contact parameters"):
            if robot:
                stop = fit_radial_stop(
                    h.name, play.clearance, sizing, timestep=step, integrator=int(twin.opt.integrator)
                )
                contact = PlayContact(stop_parameters(stop))
            elif ring is None:
                contact = PlayContact(ContactParameters(sizing.stiffness, 0.0, source=EXACT_SOURCE))
            else:
                contact = play_contact(play.clearance, ring, sizing, model_options, use_cache=options.use_cache)
                if (miss := fit_miss(h.name, contact, ring, sizing)) is not None:
                    fit_misses.append(miss)
        with clock("spec edit and compiles"):
            if stop is not None:
                add_radial_stop(work, added, stop, cls)
            elif ring is None:
                add_exact_contact(work, added, play.clearance)
            else:
                journal = work.body(added.journal_body) if h.is_connect else work.joint(h.name).parent
                pairs = add_bearing(
                    work, added, journal, frames[h.name], ring, model_options, play.clearance.friction, cls
                ).pairs
                a_hat = row_inverse_weight(kinematic, in_model[h.name].child_id, in_model[h.name].parent_id)
                write_pair_contact(pairs, contact.parameters, a_hat, play.clearance.radial_clearance)
        done[h.name] = RetrofittedHinge(
            h.name,
            play,
            h,
            frames[h.name],
            added,
            ring,
            masses[h.name],
            sizing,
            contact,
            model_options,
            pins.get(h.name),
            stop,
        )
    warnings += refuse_or_warn(fit_misses, options.accept_inaccurate)
    with clock("spec edit and compiles"):
        work.option.timestep = step
        model = compile_model(work)
    check_masses(
        twin,
        model,
        [int(b.id) for _, b in sorted(bodies.items())],
        [(p.share.donor, int(model.body(elements[name].journal_body).id)) for name, p in pins.items()],
    )
    check_conventions(twin, model, cmap.qpos, cmap.qvel)
    speed = None
    if options.measure_speed:
        with clock("speed"):
            speed = SpeedCost(measure_speed(twin, options.control), measure_speed(model, options.control))
    return Retrofit(
        work,
        model,
        twin_spec,
        twin,
        done,
        options,
        integrator,
        step,
        cmap,
        motion,
        nkeys,
        speed,
        notes,
        clock.times,
        warnings,
    )


def _model_options(options: RetrofitOptions, sizing: PlaySizing, step: float, integrator: str) -> ModelOptions:
    """The options one bearing's ring is built and calibrated with."""
    return ModelOptions(
        segments=sizing.segments or None,  # None: the exact contact, no ring
        journal_geom=options.journal_geom,
        segment_geom=options.segment_geom,
        timestep=step,
        integrator=integrator,
        contact_mode=options.contact_mode,
        ripple_limit=options.ripple_limit,
        impedance=options.impedance,
    )
