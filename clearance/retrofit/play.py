"""What a retrofit is asked for: the radial play of each hinge, and the numerical choices.

`RadialPlay` holds the physics of one hinge's play (a `clearance.model.Clearance`: radial
clearance, bearing radius, materials, restitution, friction, contact law) and where the
journal starts in its bearing. `RetrofitOptions` holds the choices that are not physics:
contact mode, segments and geoms of the ring, the time step (chosen by the stability rule
unless given), and the motion the loads and masses are sized from.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np

from clearance.checks import finite, positive
from clearance.model import STEEL, Clearance, ContactLaw, Material
from clearance.options import ContactMode, GeomType

__all__ = [
    "Backlash",
    "DEFAULT_MESH_RESTITUTION",
    "DEFAULT_MESH_STIFFNESS",
    "MAX_BACKLASH",
    "SENSOR_SIDES",
    "STOPS",
    "DEFAULT_BEARING_RADIUS",
    "DEFAULT_CLASS",
    "DEFAULT_RADIAL_CLEARANCE",
    "PREFIX",
    "RadialPlay",
    "Refusal",
    "RetrofitError",
    "RetrofitOptions",
    "SineControl",
    "ControlTable",
]

PREFIX = "clr_"
"""Every element a retrofit adds is named ``clr_<hinge>__...``."""

DEFAULT_CLASS = "clr_retrofit"
"""The default class of every element a retrofit adds: MuJoCo's built-in values, so that the
model's own defaults (a joint damping, a geom margin or density) do not reach them."""

DEFAULT_RADIAL_CLEARANCE = 1e-4
"""Radial clearance c when none is given [m] (0.1 mm)."""

DEFAULT_BEARING_RADIUS = 0.010
"""Bearing radius R_B when none is given [m] (10 mm, the catalogue's)."""


class Refusal(enum.Enum):
    """Why a hinge cannot take a kind of play: the reasons a refusal lists (`RetrofitError.reason`)."""

    NOT_A_HINGE = "not a hinge (a slide, ball or free joint)"
    SHARED_BODY = "shares its body with other joints (a compound joint: hinges through one point)"
    FLOATING_BASE = "turns a planar floating base (beside slides, on the world: no bearing, no gear)"
    NO_ACTUATOR = "no actuator of its own (backlash sits between a motor and its link)"
    TENDON_DRIVEN = "driven through a tendon (backlash moves only actuators with joint=)"
    TOO_LIGHT = "too light for its bearing or stop: it needs a time step below 1e-7 s"
    INACCURATE = "its ring misses its stated accuracy (ripple bound or calibration goals)"


class RetrofitError(ValueError):
    """A model or a request that cannot be retrofitted; the message names the joint, file or value.

    Attributes:
        reason: the listed reason where the refusal is about one hinge's nature (`Refusal`), else None.
        hinge: that hinge, or None.
    """

    def __init__(self, message: str, *, reason: Refusal | None = None, hinge: str | None = None) -> None:
        super().__init__(message)
        self.reason = reason
        self.hinge = hinge


@dataclass(frozen=True)
class RadialPlay:
    """Radial play of one hinge: a journal on the child body inside a bearing on the parent.

    Attributes:
        clearance: physics of the play (its ``journal_link`` must be None: the hinge's child
            body always holds the journal). Defaults: c = 0.1 mm, R_B = 10 mm, steel on
            steel, restitution 0.9, no friction, Lankarani-Nikravesh.
        initial_eccentricity: the journal centre in the bearing frame (x, y) [m] that the
            model's keyframes start from; (0, 0): centred. Its size must be below c; a loop
            closure's (a connect's) must be (0, 0).
    """

    clearance: Clearance = field(default_factory=lambda: Clearance(DEFAULT_RADIAL_CLEARANCE, DEFAULT_BEARING_RADIUS))
    initial_eccentricity: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if not isinstance(self.clearance, Clearance):
            raise RetrofitError(f"clearance must be a clearance.model.Clearance (got {self.clearance!r})")
        if self.clearance.journal_link is not None:
            raise RetrofitError(
                f"clearance.journal_link must be None in a retrofit: the hinge's child body holds the journal "
                f"(got {self.clearance.journal_link!r})"
            )
        try:
            ex, ey = self.initial_eccentricity
        except (TypeError, ValueError):
            raise RetrofitError(
                f"initial_eccentricity must be a pair (x, y) in metres (got {self.initial_eccentricity!r})"
            ) from None
        e = (finite("initial_eccentricity[0]", ex), finite("initial_eccentricity[1]", ey))
        c = self.clearance.radial_clearance
        size = math.hypot(*e)
        if size >= c:
            raise RetrofitError(
                f"initial_eccentricity must be smaller than the radial clearance {c:g} m (got |e| = {size:g} m)"
            )
        object.__setattr__(self, "initial_eccentricity", e)

    @classmethod
    def make(
        cls,
        radial_clearance: float = DEFAULT_RADIAL_CLEARANCE,
        bearing_radius: float = DEFAULT_BEARING_RADIUS,
        *,
        bearing_material: Material = STEEL,
        journal_material: Material = STEEL,
        restitution: float = 0.9,
        friction: float = 0.0,
        law: ContactLaw = ContactLaw.LANKARANI_NIKRAVESH,
        bearing_length: float | None = None,
        initial_eccentricity: tuple[float, float] = (0.0, 0.0),
    ) -> RadialPlay:
        """A play from its numbers (SI units; ``bearing_length`` None: the bore, 2 R_B, for a
        cylindrical law); raises `ValueError` naming a bad one."""
        c = Clearance(
            radial_clearance,
            bearing_radius,
            bearing_material=bearing_material,
            journal_material=journal_material,
            restitution=restitution,
            friction=friction,
            law=law,
            bearing_length=bearing_length,
        )
        return cls(c, initial_eccentricity)


MAX_BACKLASH = math.radians(10.0)
"""Largest backlash half-width a hinge accepts [rad] (10 degrees): beyond it the dead band is
a loose coupling rather than gear play."""


DEFAULT_MESH_STIFFNESS = 1e4
"""Torsional mesh stiffness K of a backlash stop when none is given [N m/rad]: the order of a
small robot gearbox's torsional stiffness (strain-wave gear catalogues give about 0.3e4 to
2.5e4 N m/rad for sizes 14 to 20 at low load; recalled, not checked)."""

DEFAULT_MESH_RESTITUTION = 0.8
"""Coefficient of restitution cₑ of a backlash stop when none is given [-]: lubricated steel
teeth, as gear-rattle models take it (about 0.6 to 0.9; recalled, not checked), in the range
where Lankarani–Nikravesh holds (cₑ >= 0.7)."""

STOPS = ("calibrated", "recipe", "exact")
"""What closes a dead band: 'calibrated' (the tendon limit fitted to the mesh law,
`clearance.contact_calibration.torsional_stop`), 'recipe' (the same limit at MuJoCo's
default solref and solimp, the two-hinges-and-a-limit recipe, and the model's time step) or
'exact' (no limit: the mesh law itself, computed by the compiled plugin
`clearance.backlash_stop`, `clearance.contact_plugin.backlash_stop`; the written model then
needs the plugin)."""

SENSOR_SIDES = ("load", "motor")
"""Where a backlashed hinge's jointpos and jointvel sensors read: 'load' (the link, the
hinge's own angle: the default) or 'motor' (the motor side's hinge). Its jointactuatorfrc
sensors follow the actuators to the motor side either way (on the link they would read 0)."""


@dataclass(frozen=True)
class Backlash:
    """Angular play (gear backlash) of one actuated hinge: a dead band of +-b between motor and link.

    The hinge keeps its name and its body (the link, the load side); a motor side on the same
    axis takes the model's actuators, and the load may turn within +-b of the motor
    (`clearance.retrofit.backlash`). At either end of the band the teeth meet: the stop
    follows Lankarani–Nikravesh in angular form, T = K δⁿ [1 + 3(1 − cₑ²)/4 · δ̇/δ̇⁻],
    δ = |q_load − q_motor| − b (`clearance.contact_calibration.laws.mesh_torque`).

    Attributes:
        half_width: b [rad], in (0, `MAX_BACKLASH`].
        motor_armature: the motor side's inertia about the axis [kg m^2] (the rotor's reflected
            inertia); None: the hinge's own ``armature`` moves to the motor side, or where the
            hinge has none, `clearance.retrofit.backlash.MOTOR_ARMATURE_FRACTION` of the
            hinge's inertia at the model's reference pose.
        mesh_stiffness: K [N m/rad^n], > 0 (`DEFAULT_MESH_STIFFNESS`, 1e4 N m/rad).
        restitution: cₑ [-], in (0, 1] (`DEFAULT_MESH_RESTITUTION`, 0.8).
        mesh_exponent: n [-], >= 1 (1: a gear mesh is a linear spring).
        impact_speed: the closing speed the stop is fitted around [rad/s] (a decade about it);
            None: estimated from the model (`clearance.retrofit.backlash.impact_speed`).
        stop: one of `STOPS` ('calibrated' unless 'recipe' or 'exact' is asked for).
        sensors: one of `SENSOR_SIDES`: where the hinge's position and velocity sensors
            read ('load', the default: the link's angle, as before the edit; 'motor': the
            motor side's, as an encoder on the motor reads it).
    """

    half_width: float
    motor_armature: float | None = None
    mesh_stiffness: float = DEFAULT_MESH_STIFFNESS
    restitution: float = DEFAULT_MESH_RESTITUTION
    mesh_exponent: float = 1.0
    impact_speed: float | None = None
    stop: str = "calibrated"
    sensors: str = "load"

    def __post_init__(self) -> None:
        b = finite("backlash half_width", self.half_width)
        if not 0 < b <= MAX_BACKLASH:
            raise RetrofitError(
                f"backlash half_width must be in (0, {MAX_BACKLASH:.6g}] rad (10 degrees) (got {self.half_width!r})"
            )
        if self.motor_armature is not None:
            positive("motor_armature", self.motor_armature, "kg m^2")
        positive("mesh_stiffness", self.mesh_stiffness, "N m/rad")
        if not finite("mesh_exponent", self.mesh_exponent) >= 1:
            raise RetrofitError(
                f"backlash mesh_exponent must be >= 1 (got {self.mesh_exponent!r}): below 1 the stop K d^n is "
                "infinitely stiff at first touch"
            )
        e = finite("restitution", self.restitution)
        if not 0 < e <= 1:
            raise RetrofitError(f"backlash restitution must be in (0, 1] (got {self.restitution!r})")
        if self.impact_speed is not None:
            positive("impact_speed", self.impact_speed, "rad/s")
        if self.stop not in STOPS:
            raise RetrofitError(f"backlash stop must be one of {', '.join(STOPS)} (got {self.stop!r})")
        if self.sensors not in SENSOR_SIDES:
            raise RetrofitError(f"backlash sensors must be one of {', '.join(SENSOR_SIDES)} (got {self.sensors!r})")

    @classmethod
    def from_arcmin(
        cls,
        half_width_arcmin: float,
        motor_armature: float | None = None,
        *,
        mesh_stiffness: float = DEFAULT_MESH_STIFFNESS,
        restitution: float = DEFAULT_MESH_RESTITUTION,
        stop: str = "calibrated",
        sensors: str = "load",
    ) -> Backlash:
        """A backlash from its half-width in arc-minutes."""
        b = math.radians(finite("backlash_arcmin", half_width_arcmin) / 60.0)
        return cls(
            b, motor_armature, mesh_stiffness=mesh_stiffness, restitution=restitution, stop=stop, sensors=sensors
        )


@dataclass(frozen=True)
class SineControl:
    """A sinusoid on every actuator: the motion a retrofit sizes its bearings from.

    Actuator k gets ``mid_k + a_k sin(2π f t + 2π k / nu)``: for an actuator with a control
    range, mid_k is the range's middle and a_k = ``amplitude`` x its half-width; without a
    range, mid_k = 0 and a_k = ``amplitude`` in the actuator's own units. The phases are
    spread so the actuators do not all push at once.

    Attributes:
        amplitude: fraction of each control range's half-width [-] (or the control's own units).
        frequency: f [Hz].
    """

    amplitude: float = 0.5
    frequency: float = 1.0

    def __post_init__(self) -> None:
        a = finite("amplitude", self.amplitude)
        if a < 0:
            raise RetrofitError(f"amplitude must be >= 0 (got {self.amplitude!r})")
        positive("frequency", self.frequency, "Hz")


@dataclass(frozen=True)
class ControlTable:
    """A control sequence: ``values[i, k]`` is actuator k's ctrl at ``times[i]``; linear in
    between, held before the first row and after the last (`clearance.retrofit.drive` reads
    one from a CSV file).

    Attributes:
        times: (n,) strictly increasing [s].
        values: (n, nu) controls, columns in the model's actuator order.
        source: where it came from (for messages and reports).
    """

    times: np.ndarray
    values: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        t = np.asarray(self.times, dtype=float)
        v = np.asarray(self.values, dtype=float)
        if t.ndim != 1 or len(t) < 1 or v.ndim != 2 or v.shape[0] != len(t):
            raise RetrofitError(f"a control table needs (n,) times and (n, nu) values (got {t.shape}, {v.shape})")
        where = f"control table {self.source}" if self.source else "a control table"
        if not (np.isfinite(t).all() and np.isfinite(v).all()):
            raise RetrofitError(f"{where}: times and values must be finite")
        if len(t) > 1 and not (np.diff(t) > 0).all():
            raise RetrofitError(f"{where}: times must increase strictly")
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "values", v)


@dataclass(frozen=True)
class RetrofitOptions:
    """Numerical choices of a retrofit (not physics).

    Attributes:
        contact_mode: CALIBRATED (default: the ring's soft contact fitted to the contact law
            at each bearing's own effective mass and impact speeds), NOMINAL (the ring with
            formula parameters) or EXACT (no ring: the compiled plugin's exact journal-bearing
            contact, `clearance.contact_plugin`; the written model then needs the plugin).
        segments: ring segments N per bearing; None: the ripple rule
            (`clearance.mjcf.choose_segments`) at each bearing's typical penetration.
        journal_geom, segment_geom: geom types of journal and segments.
        timestep: the retrofitted model's time step [s]; None: chosen by the stability rule
            (`clearance.retrofit.sizing.choose_time_step`), never above the model's own.
        ripple_limit: largest ring force ripple the segment rule allows [-].
        impedance: constant solimp impedance d of the contact rows [-].
        control: the motion of the unmodified model that loads, masses and impact speeds
            are sized from, and that the speed cost is measured on: a `SineControl` or a
            `ControlTable` (a servo's set point, a measured sequence).
        sizing_duration: how long that motion is run [s].
        measure_speed: measure steps per second of both models (the speed cost).
        use_cache: read and write stored calibrations.
        accept_inaccurate: keep a ring that misses its stated accuracy (the ripple bound, the
            calibration's goals: `clearance.retrofit.accuracy`) with a warning instead of refusing it.
        robot_step: radial play at the robot's own time step [s], in (0, 0.01]: each journal is held
            within c by a step-limited tendon stop (`clearance.retrofit.radial_stop`: stock MJCF, no
            ring, no friction) and the model runs at this step; a clearance the step cannot
            represent is refused. ``contact_mode``, ``segments``, the geoms and ``timestep`` do not
            apply. None (the default): the ring or the exact contact at the contact's own µs step.
    """

    contact_mode: ContactMode = ContactMode.CALIBRATED
    segments: int | None = None
    journal_geom: GeomType = GeomType.SPHERE
    segment_geom: GeomType = GeomType.SPHERE
    timestep: float | None = None
    ripple_limit: float = 0.02
    impedance: float = 1e-3
    control: SineControl | ControlTable = field(default_factory=SineControl)
    sizing_duration: float = 1.0
    measure_speed: bool = True
    use_cache: bool = True
    accept_inaccurate: bool = False
    robot_step: float | None = None

    def __post_init__(self) -> None:
        try:
            mode = ContactMode(self.contact_mode)
        except ValueError:
            raise RetrofitError(
                f"contact_mode must be 'calibrated', 'nominal' or 'exact' (got {self.contact_mode!r})"
            ) from None
        object.__setattr__(self, "contact_mode", mode)
        if self.segments is not None:
            if not isinstance(self.segments, int) or isinstance(self.segments, bool) or self.segments < 8:
                raise RetrofitError(f"segments must be an integer >= 8 (got {self.segments!r})")
        for name in ("journal_geom", "segment_geom"):
            try:
                object.__setattr__(self, name, GeomType(getattr(self, name)))
            except ValueError:
                raise RetrofitError(
                    f"{name} must be one of {[g.value for g in GeomType]} (got {getattr(self, name)!r})"
                ) from None
        if self.journal_geom is GeomType.BOX:
            raise RetrofitError("journal_geom must be sphere, capsule or cylinder (got 'box')")
        if self.timestep is not None:
            h = positive("timestep", self.timestep, "s")
            if h > 1e-2:
                raise RetrofitError(f"timestep must be in (0, 0.01] s (got {self.timestep!r})")
        if not 0 < finite("ripple_limit", self.ripple_limit) < 1:
            raise RetrofitError(f"ripple_limit must be in (0, 1) (got {self.ripple_limit!r})")
        if not 0 < finite("impedance", self.impedance) < 0.5:
            raise RetrofitError(f"impedance must be in (0, 0.5) (got {self.impedance!r})")
        if not isinstance(self.control, (SineControl, ControlTable)):
            raise RetrofitError(f"control must be a SineControl or a ControlTable (got {self.control!r})")
        positive("sizing_duration", self.sizing_duration, "s")
        if self.robot_step is not None:
            if not 0 < positive("robot_step", self.robot_step, "s") <= 1e-2:
                raise RetrofitError(f"robot_step must be in (0, 0.01] s (got {self.robot_step!r})")
            if self.timestep is not None:
                raise RetrofitError(
                    f"timestep {self.timestep!r} and robot_step {self.robot_step!r} both given: the robot step is the "
                    "model's time step; give one"
                )
