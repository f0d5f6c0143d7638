"""From a mechanism and options to a compiled MuJoCo model ready to run.

Sizing is done from the ideal mechanism's joint loads over one drive cycle (inverse
dynamics): the median load of a clearance joint gives its typical Hertz penetration (for
the segment-count rule), the peak load an estimate of impact speed and the divergence
bound. In the ring modes, contact parameters come from `clearance.contact_calibration`
(nominal formulas, or a fitted calibration) and are written into the pairs' direct-mode
solref and solimp; in the exact mode each clearance joint gets an instance of the compiled
contact plugin. Every run's model carries the energy meter when the compiled library is
installed (the spec, which `to_xml` writes, does not).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from clearance.checks import of_type
from clearance.contact_calibration.effective_mass import cycle_effective_mass
from clearance.contact_calibration.laws import bearing_stiffness, contact_omega
from clearance.contact_plugin import PLUGIN_NAME, is_available
from clearance.contact_plugin import require as require_plugin
from clearance.contact_plugin.attributes import add_for_clearance, require_compiled_law
from clearance.contact_plugin.energy import add_energy_meter
from clearance.mjcf import (
    BuiltModel,
    add_initial_keyframe,
    apply_contact,
    build_spec,
    choose_segments,
)
from clearance.model import CYLINDRICAL_LAWS, ContactLaw, DriveKind, Joint, Mechanism
from clearance.options import ContactMode, ContactParameters, GeomType, ModelOptions
from clearance.run.cycle_cache import ideal_cycle
from clearance.run.sizing import JointSizing as JointSizing
from clearance.run.sizing import load_penetration, size_joint
from clearance.run.slider_contact import add_slider_contacts, corner_loads, guide_metadata, slider_sizing

if TYPE_CHECKING:
    from clearance.run.reactions import ReactionLayout

__all__ = ["JointSizing", "PreparedModel", "prepare", "initial_controls", "exact_contact_name", "TimeStepError"]


class TimeStepError(ValueError):
    """The time step is too large for a contact's stiffness (explicit stability limit)."""


@dataclass
class PreparedModel:
    """A compiled model and everything `simulate` needs to run and read it.

    ``slices`` (sensor name -> slice of a sensor row) and ``reactions`` (the joint reactions'
    readout layout) are filled by the first readout of the model.
    """

    mechanism: Mechanism
    options: ModelOptions
    built: BuiltModel
    model: mujoco.MjModel
    sizing: dict[str, JointSizing]
    contact: dict[str, ContactParameters]
    metadata: dict[str, Any] = field(default_factory=dict)
    slices: dict[str, slice] | None = None
    reactions: ReactionLayout | None = None

    def to_xml(self) -> str:
        """MJCF text of the model (with contact parameters and the initial keyframe)."""
        return self.built.spec.to_xml()


def _refuse_lubricated(mechanism: Mechanism, mode: ContactMode) -> None:
    """Refuse a lubricated joint, with the reason, in a mode that cannot carry its film (the rings).

    Raises:
        ValueError: a clearance joint of the mechanism carries a `Lubrication` and ``mode`` is a
            ring mode; more than one joint is lubricated in the exact contact.
    """
    oiled = [j.name for j in mechanism.clearance_joints if j.require_clearance().lubrication is not None]
    if len(oiled) > 1 and mode is ContactMode.EXACT:
        # benchmarks/lubricated_bearing.md, "Two lubricated joints": each film's damping is taken in
        # the step with its own joint's response only, so two films diverge (the slider-crank with
        # both rod joints oiled within 0.09 ms at 3, 1 and 0.5 us; the press's A and C spike to
        # 312 kN at 3 us against the reference's 27.5 N)
        raise ValueError(
            f"joints {oiled} are all lubricated, and the exact contact runs one lubricated joint per mechanism: "
            "it takes each film's damping in the step with its own joint alone, and two films on one mechanism "
            "diverge at any practical step; run it in the reference solver (clearance reference), or keep one "
            "joint lubricated"
        )
    if not oiled or mode is ContactMode.EXACT:
        return
    raise ValueError(
        f"joint(s) {oiled} are lubricated and contact mode '{mode.value}' (the ring of contact segments) cannot "
        "carry the film: ring contacts push only where a segment touches the journal, while the film pushes "
        "across the whole clearance from the journal's speed; run them with contact_mode 'exact' or the "
        "reference solver (clearance reference)"
    )


def _refuse_slider(mechanism: Mechanism, mode: ContactMode) -> None:
    """Refuse a slider with play whose law or friction its corners cannot take in ``mode``, with the reason.

    Raises:
        ValueError: a cylindrical law (a pin in a hole) on a slider's corners; the IMPACT law
            (the run passes no c_max and d_max); friction in a ring mode (the portable corners).
    """
    for j in mechanism.translational_joints:
        play = j.require_translational()
        if play.law in CYLINDRICAL_LAWS:
            raise ValueError(
                f"joint '{j.name}': law '{play.law.value}' is a law of a pin in a hole; a slider's corners take the "
                "point laws (hertz, lankarani_nikravesh, flores, ...)"
            )
        if play.law is ContactLaw.IMPACT:
            raise ValueError(
                f"joint '{j.name}': law 'impact' needs c_max and d_max, which contact_mode '{mode.value}' does not "
                "take for a slider's corners; run it in the reference solver (clearance reference)"
            )
        if play.friction > 0 and mode is not ContactMode.EXACT:
            raise ValueError(
                f"joint '{j.name}': friction {play.friction:g} cannot run in contact_mode '{mode.value}' (a slider's "
                "portable corners): MuJoCo's friction cone lifts a sliding contact off its line at about mu |v_t| "
                "(0.1 m/s for mu = 0.01 at 10 m/s of sliding), so the slider bounces along its guide where it "
                "slides on it; run it with contact_mode 'exact' (Ambrosio's friction), in the reference solver "
                "(clearance reference), or without friction"
            )


def check_run_arguments(mechanism: object, options: object) -> None:
    """Refuse a mechanism or options of the wrong type, naming the argument (before any work).

    Raises:
        clearance.checks.WrongTypeError: ``mechanism`` is not a `Mechanism`, or ``options`` is
            neither a `ModelOptions` nor None (a `TypeError` and a `ValueError`).
    """
    of_type("mechanism", mechanism, Mechanism, "a Mechanism (from a builder, e.g. clearance.builders.slider_crank())")
    of_type("options", options, (ModelOptions, type(None)), "a ModelOptions (e.g. ModelOptions(timestep=1e-6)) or None")


def prepare(
    mechanism: Mechanism,
    options: ModelOptions | None = None,
    *,
    contact: dict[str, ContactParameters] | None = None,
) -> PreparedModel:
    """Size, build, compile and parametrise the MuJoCo model of a mechanism.

    Args:
        mechanism: the mechanism.
        options: numerical options (default `ModelOptions()`).
        contact: per-joint contact parameters overriding the ones ``options.contact_mode``
            would choose.

    Returns:
        The prepared model.

    Raises:
        AssemblyError: the mechanism cannot be assembled.
        TimeStepError: the time step is too large for some contact's stiffness.
        ValueError: bad options; a slider with play whose law or friction its contact cannot take.
        CalibrationStabilityError: a calibrated or nominal contact is unstable at the time step.
    """
    check_run_arguments(mechanism, options)
    options = options or ModelOptions()
    cjoints = mechanism.clearance_joints
    sliders = mechanism.translational_joints
    slider_names = {j.name for j in sliders}
    exact = options.contact_mode is ContactMode.EXACT
    _refuse_lubricated(mechanism, options.contact_mode)
    _refuse_slider(mechanism, options.contact_mode)
    if exact and contact:  # before any work
        raise ValueError(
            f"contact parameters were given for {sorted(contact)}, but contact_mode 'exact' computes each joint's "
            "own contact law and takes no ring parameters; use contact_mode 'nominal' or 'calibrated'"
        )
    if exact and (cjoints or sliders):
        require_plugin()  # before any work: without the compiled plugin this mode cannot run
        for j in cjoints:
            require_compiled_law(j.require_clearance().law, j.name)
    # the ideal cycle's loads and bearings' effective masses, their pose-dependent parts cached per mechanism
    cycle = ideal_cycle(mechanism) if cjoints or sliders else None
    pairs = cycle.loads if cycle is not None else {}
    loads = {name: np.hypot(v[:, 0], v[:, 1]) for name, v in pairs.items()}
    segs: dict[str, int] = {}
    for j in cjoints:
        c = j.require_clearance()
        dtyp = load_penetration(loads[j.name], bearing_stiffness(c))[2]
        # the compiled exact contact has no ring: 0 segments
        segs[j.name] = (
            0
            if exact
            else options.segments
            or choose_segments(
                c.bearing_radius,
                c.radial_clearance,
                dtyp,
                ripple_limit=options.ripple_limit,
                flat=options.segment_geom is GeomType.BOX,
            )
        )
    built = build_spec(mechanism, options, segs)
    model = built.spec.compile()
    masses = dict(cycle.masses) if cycle is not None else {}
    if sliders:  # a slider's corners' masses from the compiled guide (not cached)
        masses |= {k: v for k, v in cycle_effective_mass(model, built, mechanism).items() if k in slider_names}
    sizing = {
        j.name: size_joint(
            stiffness=bearing_stiffness(j.require_clearance()),
            loads=loads[j.name],
            clearance=j.require_clearance().radial_clearance,
            mass=masses[j.name],
            segments=segs[j.name],
        )
        for j in cjoints
    }
    sizing |= slider_sizing(mechanism, corner_loads(mechanism, pairs), masses)
    for name, s in sizing.items():
        # before any calibration: a fit at an unstable step fails with a less useful message
        lightest = s.effective_mass_range[0] if name in slider_names else s.effective_mass
        _check_time_step(name, s, options.timestep, lightest)
    params = dict(contact or {})
    slider_params = {k: params.pop(k) for k in sorted(slider_names) if k in params}
    if exact:
        contact_meta = {j.name: _add_exact_contact(built, j) for j in cjoints}
    else:
        for j in cjoints:
            if j.name not in params:
                params[j.name] = _contact_for(j, built, sizing[j.name], options)
        apply_contact(built, model, params)
        contact_meta = {
            k: {
                "stiffness_per_row": p.stiffness,
                "damping_per_row": p.damping,
                "impedance_rise": p.impedance_rise,
                "source": p.source,
            }
            for k, p in params.items()
        }
    contact_meta |= add_slider_contacts(built, model, mechanism, sizing, options, slider_params, exact_contact_name)
    params |= slider_params
    add_initial_keyframe(built, model, initial_controls(mechanism))
    # the run's model carries the energy meter; the spec (what to_xml writes) stays portable
    run_spec = built.spec
    if is_available():
        run_spec = built.spec.copy()
        add_energy_meter(run_spec)
    model = run_spec.compile()
    meta = {
        "segments": {} if exact else segs,
        "journal_geom": options.journal_geom.value,
        "segment_geom": options.segment_geom.value,
        "time_step": options.timestep,
        "integrator": options.integrator,
        "contact_mode": options.contact_mode.value,
        "contact": contact_meta,
        "sizing": {k: vars(s) for k, s in sizing.items()},
        "translational_joints": [j.name for j in sliders],
        "guides": guide_metadata(mechanism),
        "stiffness_formula": "K = 4/(3(sigma_B+sigma_J)) sqrt(R_B R_J/(R_B-R_J)), sigma=(1-nu^2)/E",
    }
    return PreparedModel(mechanism, options, built, model, sizing, params, meta)


def initial_controls(mechanism: Mechanism) -> np.ndarray:
    """Actuator controls at t = 0: drive speed [rad/s], or torque [N m] for torque drives."""
    return np.array([d.torque if d.kind is DriveKind.TORQUE else float(d.rate(0.0)) for d in mechanism.drives])


def exact_contact_name(joint: str) -> str:
    """Name of a clearance joint's compiled contact (plugin instance and sensor)."""
    return f"{joint}__contact"


def _add_exact_contact(built: BuiltModel, joint: Joint) -> dict[str, Any]:
    """Add the joint's compiled exact contact to the spec; return its metadata."""
    c = joint.require_clearance()
    add_for_clearance(
        built.spec,
        c,
        name=exact_contact_name(joint.name),
        journal_site=f"{joint.name}__journal",
        bearing_site=f"{joint.name}__bearing",
    )
    if c.law in CYLINDRICAL_LAWS:  # the law's own constants, not the point laws' Hertz K
        from dataclasses import asdict

        from clearance.contact_calibration.cylindrical_laws import cylinder_law

        law_meta: dict[str, Any] = {k: v for k, v in asdict(cylinder_law(c)).items() if k != "law"}
    else:
        law_meta = {"stiffness": bearing_stiffness(c), "exponent": 1.5}
    return {
        "law": c.law.value,
        **law_meta,
        "restitution": c.restitution,
        "friction": c.friction,
        "source": f"exact: compiled plugin {PLUGIN_NAME}",
    }


def _contact_for(joint: Joint, built: BuiltModel, sizing: JointSizing, options: ModelOptions) -> ContactParameters:
    from clearance.contact_calibration.nominal import nominal_parameters

    ring = built.rings[joint.name]
    if options.contact_mode is ContactMode.CALIBRATED:
        try:
            from clearance.contact_calibration.store import calibrated_parameters
        except ImportError:
            raise ValueError("contact_mode 'calibrated' is not available in this version; use 'nominal'") from None
        return calibrated_parameters(joint, ring, sizing, options)
    return nominal_parameters(joint.require_clearance(), ring, effective_mass=sizing.effective_mass)


def _check_time_step(name: str, s: JointSizing, h: float, mass: float) -> None:
    """Explicit contact stability needs omega h < 2, omega = sqrt(k_t / m) (docs/mujoco_notes.md), m the
    effective mass [kg] (a slider's lightest corner alone)."""
    k_t = 1.5 * s.stiffness * math.sqrt(s.penetration_limit)
    omega = contact_omega(s.stiffness, s.penetration_limit, mass)
    if omega * h >= 2.0:
        h_max = 2.0 / omega
        raise TimeStepError(
            f"time step {h:g} s is too large for the contact stiffness at joint '{name}': "
            f"omega*h = {omega * h:.2f} >= 2 at the largest expected penetration "
            f"({s.penetration_limit * 1e6:.1f} um, tangent stiffness {k_t:.3g} N/m, effective mass "
            f"{mass:.3g} kg), so the contact would blow up. Use a time step below "
            f"{h_max:.3g} s (largest stable for the contact spring; damping lowers it, so stay well below), "
            f"and below {0.1 / omega:.3g} s (omega*h <= 0.1) to resolve that deepest impact's force peak exactly."
        )
