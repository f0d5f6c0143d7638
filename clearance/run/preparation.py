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
from clearance.loads import joint_reactions
from clearance.mjcf import (
    BuiltModel,
    add_initial_keyframe,
    apply_contact,
    build_spec,
    choose_segments,
    refuse_translational_clearance,
)
from clearance.model import CYLINDRICAL_LAWS, DriveKind, Joint, Mechanism
from clearance.options import ContactMode, ContactParameters, GeomType, ModelOptions

if TYPE_CHECKING:
    from clearance.run.reactions import ReactionLayout

__all__ = ["JointSizing", "PreparedModel", "prepare", "initial_controls", "exact_contact_name", "TimeStepError"]


class TimeStepError(ValueError):
    """The time step is too large for a contact's stiffness (explicit stability limit)."""


@dataclass(frozen=True)
class JointSizing:
    """Loads and sizes of one clearance joint.

    Attributes:
        stiffness: journal-bearing stiffness K [N/m^1.5].
        median_load, peak_load: ideal-mechanism reaction force over one cycle [N].
        typical_penetration: (median_load / K)^(2/3) [m].
        impact_speed: sqrt(2 peak_load c / m_eff), the speed gained crossing the clearance
            under the peak load [m/s].
        effective_mass: mass seen along the contact normal [kg]: median over the ideal
            cycle of the mass along the ideal joint's load (loop closures and velocity
            drives held), as `clearance.contact_calibration.cycle_effective_mass` measures it.
        effective_mass_range: (min, max) of that mass over the cycle [kg], the range a
            calibration is valid for.
        penetration_limit: divergence bound [m]: 4 x the Hertz penetration of an impact at
            ``impact_speed``, at least 4 x that under the peak load.
        segments: ring segment count N (0 for the exact contact, which has no ring).
    """

    stiffness: float
    median_load: float
    peak_load: float
    typical_penetration: float
    impact_speed: float
    effective_mass: float
    penetration_limit: float
    segments: int
    effective_mass_range: tuple[float, float] = (0.0, 0.0)


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


def _cycle_times(mechanism: Mechanism, n: int = 181) -> np.ndarray:
    return np.linspace(0.0, mechanism.drive_period or 1.0, n)


def _refuse_lubricated(mechanism: Mechanism, mode: ContactMode) -> None:
    """Refuse a lubricated joint, with the reason, in a mode that cannot carry its film (the rings).

    Raises:
        ValueError: a clearance joint of the mechanism carries a `Lubrication` and ``mode`` is a
            ring mode.
    """
    oiled = [j.name for j in mechanism.clearance_joints if j.require_clearance().lubrication is not None]
    if not oiled or mode is ContactMode.EXACT:
        return
    raise ValueError(
        f"joint(s) {oiled} are lubricated and contact mode '{mode.value}' (the ring of contact segments) cannot "
        "carry the film: ring contacts push only where a segment touches the journal, while the film pushes "
        "across the whole clearance from the journal's speed; run them with contact_mode 'exact' or the "
        "reference solver (clearance reference)"
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
        ValueError: bad options; a slider with play (translational clearance runs in the
            reference solver only so far).
    """
    check_run_arguments(mechanism, options)
    refuse_translational_clearance(mechanism)  # before any work: MuJoCo has no slider with play yet
    options = options or ModelOptions()
    cjoints = mechanism.clearance_joints
    exact = options.contact_mode is ContactMode.EXACT
    _refuse_lubricated(mechanism, options.contact_mode)
    if exact and cjoints:
        require_plugin()  # before any work: without the compiled plugin this mode cannot run
        for j in cjoints:
            require_compiled_law(j.require_clearance().law, j.name)
    loads = joint_reactions(mechanism, _cycle_times(mechanism)) if cjoints else {}
    segs: dict[str, int] = {}
    pre: dict[str, tuple[float, float, float, float]] = {}
    for j in cjoints:
        c = j.require_clearance()
        K = bearing_stiffness(c)
        f = loads[j.name]
        fmed, fmax = float(np.median(f)), float(np.max(f))
        dtyp = (max(fmed, 1e-3 * max(fmax, 1e-9)) / K) ** (2 / 3) if fmax > 0 else 1e-7
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
        pre[j.name] = (K, fmed, fmax, dtyp)
    built = build_spec(mechanism, options, segs)
    model = built.spec.compile()
    masses = cycle_effective_mass(model, built, mechanism) if cjoints else {}
    sizing: dict[str, JointSizing] = {}
    for j in cjoints:
        K, fmed, fmax, dtyp = pre[j.name]
        m = masses[j.name].median
        v = math.sqrt(2 * max(fmax, 1e-9) * j.require_clearance().radial_clearance / m)
        d_imp = (5 * m * v**2 / (4 * K)) ** 0.4
        lim = 4 * max(d_imp, (max(fmax, 1e-9) / K) ** (2 / 3))
        sizing[j.name] = JointSizing(K, fmed, fmax, dtyp, v, m, lim, segs[j.name], masses[j.name].valid_range)
        # before any calibration: a fit at an unstable step fails with a less useful message
        _check_time_step(j.name, sizing[j.name], options.timestep)
    params = dict(contact or {})
    if exact:
        if params:
            raise ValueError(
                f"contact parameters were given for {sorted(params)}, but contact_mode 'exact' computes each "
                "joint's own contact law and takes no ring parameters; use contact_mode 'nominal' or 'calibrated'"
            )
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


def _check_time_step(name: str, s: JointSizing, h: float) -> None:
    """Explicit contact stability needs omega h < 2, omega = sqrt(k_t / m_eff) (docs/mujoco_notes.md)."""
    k_t = 1.5 * s.stiffness * math.sqrt(s.penetration_limit)
    omega = contact_omega(s.stiffness, s.penetration_limit, s.effective_mass)
    if omega * h >= 2.0:
        h_max = 2.0 / omega
        raise TimeStepError(
            f"time step {h:g} s is too large for the contact stiffness at joint '{name}': "
            f"omega*h = {omega * h:.2f} >= 2 at the largest expected penetration "
            f"({s.penetration_limit * 1e6:.1f} um, tangent stiffness {k_t:.3g} N/m, effective mass "
            f"{s.effective_mass:.3g} kg), so the contact would blow up. Use a time step below "
            f"{h_max:.3g} s (largest stable for the contact spring; damping lowers it, so stay well below), "
            f"and below {0.1 / omega:.3g} s (omega*h <= 0.1) to resolve that deepest impact's force peak exactly."
        )
