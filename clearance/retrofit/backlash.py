"""Backlash at actuated hinges: a motor side and a load side with a dead band of +-b.

The hinge keeps its name, its body and its meaning (the link's angle relative to its
parent), so its sensors, limits, damping and keyframe values are untouched: the load side.
A motor body ``clr_<hinge>__motor`` is added beside the link (a child of the link's parent,
at the link's frame) with a hinge ``<hinge>__motor`` on the same axis; the model's actuators
on the hinge are moved to it. The dead band is a fixed tendon
``clr_<hinge>__backlash`` = q_load - q_motor, limited to [-b, b]: the two coincident hinges
and a limit of MuJoCo's recipe, with the limit on their difference so neither angle changes
meaning. The stop at either end of the band is calibrated (`Backlash.stop` = 'calibrated'):
the tendon limit's solreflimit and solimplimit fitted to the gear mesh's impact law at the
band's effective inertia, and the model's time step lowered where the stop needs it
(`clearance.retrofit.backlash_stop`); or MuJoCo's default limit at the model's step, the
recipe as users write it ('recipe'); or the mesh law itself ('exact'): the tendon is then left
unlimited (it still reads the band's angle) and a `clearance.backlash_stop` plugin instance
``clr_<hinge>__stop`` (`clearance.contact_plugin.backlash_stop`) applies the law's torque to the
two hinges, at the time step a calibrated stop would ask for.

A limited hinge's limit is copied to its motor hinge (range, solref, solimp, margin): the
twin's limit stopped the link with the rotor's inertia behind it, and MuJoCo's limit is
normalised by the inertia it acts on, so on the light link alone it would let the motor push
the link far through its range; on the motor side it stops the drive where the twin's joint
stopped, and the load stays within +-b of it.

The motor body carries no mass (`MOTOR_MASS`, MuJoCo's floor requires some; in a model with a
fluid, `motor_body_mass`); the motor's inertia is its hinge's armature: the hinge's own armature
moved to the motor side (the rotor's reflected inertia is what a joint armature models), or
`MOTOR_ARMATURE_FRACTION` of the hinge's inertia at the reference pose where it has none, or the
value the user gives.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import mujoco
import numpy as np

from clearance.checks import of_type
from clearance.contact_calibration.torsional_stop import OMEGA_H
from clearance.contact_plugin import require
from clearance.contact_plugin.backlash_stop import add_backlash_stop
from clearance.retrofit.backlash_stop import Band, BandStop, calibrate_stops, stop_note
from clearance.retrofit.contact_softness import keep_contact_softness
from clearance.retrofit.conventions import check_conventions
from clearance.retrofit.coordinates import extend_paired_keyframes, joint_index_map
from clearance.retrofit.elements import add_builtin_class
from clearance.retrofit.masses import FROZEN_NOTE, check_masses, freeze_inertials
from clearance.retrofit.play import PREFIX, Backlash, Refusal, RetrofitError
from clearance.retrofit.selection import check_not_retrofitted, compile_model, joint_kind, model_label, shared_body
from clearance.retrofit.softness import keep_constraint_softness, softness_note

__all__ = [
    "MOTOR_ARMATURE_FRACTION",
    "FLUID_MOTOR_BOX",
    "MOTOR_MASS",
    "BacklashHinge",
    "BacklashRetrofit",
    "add_backlash",
    "motor_body_mass",
    "motor_joint_name",
    "stop_plugin_name",
]

MOTOR_MASS = 1e-12
"""Mass and each principal inertia of a motor body [kg, kg m^2]: none to speak of (MuJoCo
refuses a moving body without mass); the motor's inertia is its hinge's armature."""

FLUID_MOTOR_BOX = 1e-4
"""Side of the box MuJoCo's inertia-box fluid model sees in a motor body [m], in a model with a
fluid (``<option density>`` or ``viscosity`` > 0). The model sizes a body's box from its principal
inertias over its mass (side sqrt(6 I / m)) and applies the fluid's drag to every body with mass,
so a motor body of `MOTOR_MASS` and inertia `MOTOR_MASS` is a 2.4 m box: in gymnasium's swimmer
(density 4000) its drag moved the tail by 1.5 mm in 0.1 s against the twin, 5x the zero-play
bound of a 0.1 arc-minute band. At 0.1 mm the drag is below 1e-5 of a link's a tenth of a metre
across (force ~ side^2, torque ~ side^5)."""

MOTOR_ARMATURE_FRACTION = 1e-4
"""Motor armature, where the hinge has none and none is given, as a fraction of the hinge's
diagonal mass-matrix entry at the model's reference pose [-]. A model without armature drives
its hinges with an ideal, massless motor; the motor side invented for it must not change what
the model does, yet MuJoCo needs it to have some inertia. At 1e-4 a 0.1 arc-minute band follows
the twin within 0.07 of the zero-play bound on the hand-written arms (tests/retrofit_models.py;
1 % moved the end effector by 5x the bound: the rotor's inertia, not the band); the stop's time
step scales with its square root (10x smaller than at 1 %). Give ``Backlash.motor_armature`` for
a real rotor's reflected inertia."""

_HINGE = mujoco.mjtJoint.mjJNT_HINGE
_ACTUATOR_SENSORS = (mujoco.mjtSensor.mjSENS_JOINTACTFRC,)
_STATE_SENSORS = (mujoco.mjtSensor.mjSENS_JOINTPOS, mujoco.mjtSensor.mjSENS_JOINTVEL)
_TRN_JOINT = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))


def motor_body_mass(twin: mujoco.MjModel) -> tuple[float, float]:
    """A motor body's mass [kg] and each of its principal inertias [kg m^2] in ``twin``.

    `MOTOR_MASS` for both, except in a model with a fluid: there MuJoCo's smallest inertia
    (``mjMINVAL``) and the mass that makes the fluid model's box `FLUID_MOTOR_BOX` across
    (6e-7 kg), so that the fluid does not drag on a body the twin does not have.
    """
    if twin.opt.density > 0 or twin.opt.viscosity > 0:
        inertia = mujoco.mjMINVAL
        return max(MOTOR_MASS, 6.0 * inertia / FLUID_MOTOR_BOX**2), inertia
    return MOTOR_MASS, MOTOR_MASS


def motor_joint_name(hinge: str) -> str:
    """The motor side's hinge of ``hinge``."""
    return f"{hinge}__motor"


def stop_plugin_name(hinge: str) -> str:
    """The plugin instance (and its sensor) of ``hinge``'s exact stop."""
    return f"{PREFIX}{hinge}__stop"


@dataclass(frozen=True)
class BacklashHinge:
    """One hinge given backlash.

    Attributes:
        name: the hinge (the load side, name kept).
        backlash: what was asked.
        motor_joint: the motor side's hinge.
        motor_body: the motor body.
        tendon: the dead band's tendon (q_load - q_motor; limited to +-b unless the stop is 'exact').
        actuators: names (or ``#k``) of the actuators moved to the motor side.
        motor_armature: the motor hinge's armature [kg m^2].
        armature_source: where it came from ('the hinge's armature (moved)', 'given', or the
            fraction of the hinge's inertia).
        stop: the stop at the ends of the band (its inertia, impact speed and fit).
        moved_sensors: names (or ``#k``) of the hinge's sensors now on the motor side: its
            jointactuatorfrc sensors (they follow the actuators), and its jointpos and
            jointvel sensors where ``backlash.sensors`` is 'motor'.
    """

    name: str
    backlash: Backlash
    motor_joint: str
    motor_body: str
    tendon: str
    actuators: tuple[str, ...]
    motor_armature: float
    armature_source: str
    stop: BandStop
    moved_sensors: tuple[str, ...] = ()


@dataclass
class BacklashRetrofit:
    """A model with backlash at hinges, its unmodified twin, and what changed.

    Attributes:
        spec: the edited spec. model: it compiled.
        twin_spec: the unmodified spec (a copy). twin: it compiled.
        hinges: hinge name -> what was added for it, in the order given.
        keyframes: keyframes extended (each motor angle and speed = its load's: the band centred).
        notes: remarks for a report.
        timestep: the model's time step [s] (the twin's, or lower where a calibrated stop needs it).
        motor_mass: each motor body's mass [kg] (`motor_body_mass`).
    """

    spec: mujoco.MjSpec
    model: mujoco.MjModel
    twin_spec: mujoco.MjSpec
    twin: mujoco.MjModel
    hinges: dict[str, BacklashHinge]
    keyframes: int
    notes: list[str] = field(default_factory=list)
    timestep: float = 0.0
    motor_mass: float = MOTOR_MASS


def _actuator_label(model: mujoco.MjModel, k: int) -> str:
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, k) or f"#{k}"


def _check(twin: mujoco.MjModel, spec: mujoco.MjSpec, joints: Mapping[str, Backlash]) -> dict[str, list[int]]:
    """Hinge name -> ids of the actuators on it; raises `RetrofitError` for a hinge that cannot take backlash."""
    where = model_label(spec)
    check_not_retrofitted(spec, twin)
    actuated: dict[str, list[int]] = {}
    for name, play in joints.items():
        of_type(f"joints[{name!r}]", play, Backlash, f"a Backlash (the backlash of hinge '{name}')")
        j = mujoco.mj_name2id(twin, mujoco.mjtObj.mjOBJ_JOINT, name) if isinstance(name, str) and name else -1
        if j < 0:
            raise RetrofitError(f"hinge '{name}': no joint of that name in {where}")
        if int(twin.jnt_type[j]) != int(_HINGE):
            raise RetrofitError(
                f"joint '{name}' is {joint_kind(twin, j)}: only a hinge can be given backlash",
                reason=Refusal.NOT_A_HINGE,
                hinge=name,
            )
        if play.stop == "exact":
            for obj in (mujoco.mjtObj.mjOBJ_PLUGIN, mujoco.mjtObj.mjOBJ_SENSOR):
                if mujoco.mj_name2id(twin, obj, stop_plugin_name(name)) >= 0:
                    raise RetrofitError(
                        f"hinge '{name}': {where} already has an element named '{stop_plugin_name(name)}'"
                    )
        for clash in (motor_joint_name(name), f"{PREFIX}{name}__motor", f"{PREFIX}{name}__backlash"):
            for obj in (mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_TENDON):
                if mujoco.mj_name2id(twin, obj, clash) >= 0:
                    raise RetrofitError(f"hinge '{name}': {where} already has an element named '{clash}'")
        on_joint = [
            k for k in range(twin.nu) if int(twin.actuator_trntype[k]) in _TRN_JOINT and twin.actuator_trnid[k, 0] == j
        ]
        dof = int(twin.jnt_dofadr[j])
        for k in range(twin.nu):
            if k in on_joint or int(twin.actuator_trntype[k]) != int(mujoco.mjtTrn.mjTRN_TENDON):
                continue
            t = int(twin.actuator_trnid[k, 0])
            adr, num = int(twin.tendon_adr[t]), int(twin.tendon_num[t])
            if any(
                int(twin.wrap_type[adr + i]) == int(mujoco.mjtWrap.mjWRAP_JOINT) and twin.wrap_objid[adr + i] == j
                for i in range(num)
            ):
                raise RetrofitError(
                    f"hinge '{name}': actuator '{_actuator_label(twin, k)}' drives it through a tendon; backlash moves "
                    "only actuators with joint= to the motor side",
                    reason=Refusal.TENDON_DRIVEN,
                    hinge=name,
                )
        if not on_joint:
            raise RetrofitError(
                f"hinge '{name}' (dof {dof}) has no actuator with joint= on it: backlash sits between a motor and its "
                "link, and an unactuated hinge has no motor side",
                reason=Refusal.NO_ACTUATOR,
                hinge=name,
            )
        body = int(twin.jnt_bodyid[j])
        shared = shared_body(twin, j)
        if shared is not None:
            what = "it turns a floating base" if shared is Refusal.FLOATING_BASE else "a compound joint"
            raise RetrofitError(
                f"hinge '{name}': its body has {twin.body_jntnum[body]} joints ({what}); backlash needs the hinge "
                "alone in its body",
                reason=shared,
                hinge=name,
            )
        actuated[name] = on_joint
    if any(play.stop == "exact" for play in joints.values()):
        require()  # the exact stop is the compiled plugin: say how to get it before any work
    return actuated


def _move_sensors(spec: mujoco.MjSpec, hinge: str, play: Backlash) -> dict[int, str]:
    """Point the hinge's sensors that belong on the motor side at its motor hinge; their ids -> labels.

    jointactuatorfrc always moves (the actuators are on the motor hinge now; on the link it
    would read 0); jointpos and jointvel move where ``play.sensors`` is 'motor'.
    """
    kinds = _ACTUATOR_SENSORS + (_STATE_SENSORS if play.sensors == "motor" else ())
    moved = {}
    for k, sensor in enumerate(spec.sensors):
        if sensor.objtype == mujoco.mjtObj.mjOBJ_JOINT and sensor.objname == hinge and sensor.type in kinds:
            sensor.objname = motor_joint_name(hinge)
            moved[k] = sensor.name or f"#{k}"
    return moved


def _reference_inertia(twin: mujoco.MjModel, dof: int) -> float:
    """The hinge's diagonal mass-matrix entry at the reference pose [kg m^2]."""
    data = mujoco.MjData(twin)
    mujoco.mj_forward(twin, data)
    full = np.zeros((twin.nv, twin.nv))
    mujoco.mj_fullM(twin, data, full)
    return float(full[dof, dof])


def add_backlash(spec: mujoco.MjSpec, joints: Mapping[str, Backlash]) -> BacklashRetrofit:
    """Give each named actuated hinge of ``spec`` backlash: a motor side, a load side, a dead band of +-b.

    Args:
        spec: the user's model (not changed: the edit is on a copy).
        joints: hinge name -> its backlash.

    Returns:
        The edited model, its twin and what was added.

    Raises:
        TypeError: ``spec``, ``joints`` or a backlash of the wrong type, naming it
            (`clearance.checks.WrongTypeError`, also a ValueError).
        RetrofitError: before any work, for a joint that does not exist, is not a hinge, shares
            its body with another joint, has no actuator with ``joint=`` on it, or is driven
            through a tendon; a model that does not compile.
    """
    of_type("spec", spec, mujoco.MjSpec, "a mujoco.MjSpec (read a model file with mujoco.MjSpec.from_file(path))")
    of_type("joints", joints, Mapping, "a mapping hinge name -> Backlash (e.g. {'elbow': Backlash.from_arcmin(5)})")
    twin_spec = spec.copy()
    twin = compile_model(twin_spec)
    actuated = _check(twin, twin_spec, joints)

    work = spec.copy()
    compile_model(work)  # the work spec's elements get the twin's ids
    frozen = freeze_inertials(work, twin, adds_bodies=True, cuts_pins=False)
    old_joints = list(work.joints)
    bodies = {int(b.id): b for b in work.bodies}
    geoms = {int(g.id): g for g in work.geoms}  # by the twin's ids, as bodies
    old_bodies = sorted(bodies)
    actuators = {int(a.id): a for a in work.actuators}
    cls = add_builtin_class(work)
    motor_mass, motor_inertia = motor_body_mass(twin)
    pending: dict[str, tuple[str, Backlash, str, str, str, tuple[str, ...], float, str]] = {}
    sensors: dict[str, dict[int, str]] = {}
    for name, play in joints.items():
        j = mujoco.mj_name2id(twin, mujoco.mjtObj.mjOBJ_JOINT, name)
        body = int(twin.jnt_bodyid[j])
        hinge = work.joint(name)
        dof = int(twin.jnt_dofadr[j])
        own, damping = float(twin.dof_armature[dof]), np.array(hinge.damping, dtype=float)
        hinge.armature, hinge.damping = 0.0, np.zeros_like(damping)
        if play.motor_armature is not None:
            armature, source = play.motor_armature, "given"
        elif own > 0:
            armature, source = own, "the hinge's armature (moved)"
        else:
            armature = MOTOR_ARMATURE_FRACTION * _reference_inertia(twin, dof)
            source = f"{MOTOR_ARMATURE_FRACTION:g} x the hinge's inertia at the reference pose"
        motor_body = f"{PREFIX}{name}__motor"
        motor = bodies[int(twin.body_parentid[body])].add_body(
            name=motor_body,
            pos=twin.body_pos[body],
            quat=twin.body_quat[body],
            mass=motor_mass,
            inertia=[motor_inertia] * 3,
            explicitinertial=True,
            ipos=[0.0, 0.0, 0.0],
            iquat=[1.0, 0.0, 0.0, 0.0],  # set, so the MJCF writer writes the inertial
        )
        # angles as the hinge's own spec holds them, in the model's units (degrees under
        # <compiler angle="degree"/>): the motor's range and reference angle compile as the hinge's
        motor.add_joint(
            cls,
            name=motor_joint_name(name),
            type=_HINGE,
            pos=twin.jnt_pos[j],
            axis=twin.jnt_axis[j],
            ref=hinge.ref,
            armature=armature,
            damping=damping,
            limited=mujoco.mjtLimited.mjLIMITED_TRUE if twin.jnt_limited[j] else mujoco.mjtLimited.mjLIMITED_FALSE,
            range=list(hinge.range),
            solref_limit=twin.jnt_solref[j],
            solimp_limit=twin.jnt_solimp[j],
            margin=twin.jnt_margin[j],
        )
        tendon = f"{PREFIX}{name}__backlash"
        limited = mujoco.mjtLimited.mjLIMITED_FALSE if play.stop == "exact" else mujoco.mjtLimited.mjLIMITED_TRUE
        band = work.add_tendon(name=tendon, limited=limited, range=[-play.half_width, play.half_width])
        band.wrap_joint(name, 1.0)
        band.wrap_joint(motor_joint_name(name), -1.0)
        if play.stop == "exact":
            add_backlash_stop(
                work,
                name=stop_plugin_name(name),
                load_joint=name,
                motor_joint=motor_joint_name(name),
                half_width=play.half_width,
                stiffness=play.mesh_stiffness,
                restitution=play.restitution,
                exponent=play.mesh_exponent,
            )
        for k in actuated[name]:
            actuators[k].target = motor_joint_name(name)
        sensors[name] = _move_sensors(work, name, play)
        pending[name] = (
            name,
            play,
            motor_joint_name(name),
            motor_body,
            tendon,
            tuple(_actuator_label(twin, k) for k in actuated[name]),
            armature,
            source,
        )
    kinematic = compile_model(work)
    bands = {
        name: Band(
            tendon=int(kinematic.tendon(f"{PREFIX}{name}__backlash").id),
            load_dof=int(kinematic.joint(name).dofadr[0]),
            motor_dof=int(kinematic.joint(motor_joint_name(name)).dofadr[0]),
            actuators=tuple(int(k) for k in actuated[name]),
            backlash=play,
        )
        for name, play in joints.items()
    }
    timestep, stops = calibrate_stops(kinematic, bands)
    for name, stop in stops.items():
        if stop.solref is not None and stop.solimp is not None:
            tendon = work.tendon(f"{PREFIX}{name}__backlash")
            tendon.solref_limit = list(stop.solref)
            tendon.solimp_limit = list(stop.solimp)
    work.option.timestep = timestep
    backlashed = {int(twin.joint(name).id) for name in joints}  # their limits go to the motor side: not kept
    same_joints = [(j, int(s.id)) for j, s in enumerate(old_joints) if j not in backlashed]
    kept = keep_constraint_softness(work, twin, kinematic, same_joints, timestep)
    contacts = keep_contact_softness(work, twin, kinematic, geoms, timestep, cls)
    done = {name: BacklashHinge(*pending[name], stops[name], tuple(sensors[name].values())) for name in joints}
    qmap, vmap = joint_index_map(twin, kinematic, [int(j.id) for j in old_joints])
    pairs = [(int(kinematic.joint(h.name).id), int(kinematic.joint(h.motor_joint).id)) for h in done.values()]
    nkeys = extend_paired_keyframes(work, twin, kinematic, qmap, vmap, pairs)
    model = compile_model(work)
    motor_ids = [int(model.body(h.motor_body).id) for h in done.values()]
    check_masses(twin, model, [int(bodies[b].id) for b in old_bodies], light=motor_ids, light_mass=motor_mass)
    motors = {int(twin.joint(n).id): int(model.joint(h.motor_joint).id) for n, h in done.items()}
    check_conventions(twin, model, qmap, vmap, motors=motors, moved_sensors=[k for s in sensors.values() for k in s])
    notes = [
        f"hinge '{h.name}': actuators {', '.join(h.actuators)} moved to '{h.motor_joint}' (armature "
        f"{h.motor_armature:.4g} kg m^2, {h.armature_source}); dead band +-{h.backlash.half_width:.4g} rad by the "
        f"{_band_note(h)}, {stop_note(h.stop)}; "
        + (
            f"sensors on the motor side: {', '.join(h.moved_sensors)}"
            if h.moved_sensors
            else "sensors on the load side"
        )
        for h in done.values()
    ]
    if kept or contacts:
        notes.append(softness_note([(k.label, k.softness) for k in kept] + [(c.label, c.softness) for c in contacts]))
    if frozen:
        notes.append(FROZEN_NOTE)
    if timestep < twin.opt.timestep:
        notes.append(
            f"time step lowered from {twin.opt.timestep:g} s to {timestep:g} s for the calibrated or exact stops "
            f"(omega*h <= {OMEGA_H:g} with omega = sqrt(K/J) at the lightest pose sampled); run the twin at this step "
            "to compare"
        )
    return BacklashRetrofit(work, model, twin_spec, twin, done, nkeys, notes, timestep, motor_mass)


def _band_note(h: BacklashHinge) -> str:
    """What closes a band: the tendon's limit, or the exact stop's plugin."""
    if h.stop.kind == "exact":
        return f"tendon '{h.tendon}' (unlimited, the band's angle) closed by plugin '{stop_plugin_name(h.name)}'"
    return f"limit of tendon '{h.tendon}'"
