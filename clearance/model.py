"""The mechanism data model: frozen dataclasses in SI units (m, kg, s, rad, N, Pa).

A `Mechanism` is pure data. It knows nothing of MuJoCo or of any solver; `clearance.mjcf`
turns it into a MuJoCo model and `clearance.reference` integrates it directly. Every record
validates itself in ``__post_init__`` and names the field, the value and what was expected.

Conventions:
  * The mechanism moves in the x-y plane. A link's pose is (x, y, theta): the position of
    its frame origin in the world and the rotation of its frame about z.
  * Points (joint locations, centre of mass) are given in the link frame.
  * A revolute joint pins ``point_a`` of ``link_a`` to ``point_b`` of ``link_b``.
  * A prismatic joint keeps ``theta_b - theta_a`` equal to its value in the pose guesses and
    lets ``point_b`` slide along the line through ``point_a`` with direction ``axis``
    (given in the frame of ``link_a``).
  * A drive sets the relative angle ``theta_b - theta_a`` of a revolute joint: the
    drive angle.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from clearance.checks import finite, positive
from clearance.lubrication import Lubrication

if TYPE_CHECKING:  # numpy is imported where it is used: `import clearance` stays cheap
    import numpy as np
    from numpy.typing import ArrayLike, NDArray

    from clearance.translational import TranslationalClearance

__all__ = [
    "ContactLaw",
    "CYLINDRICAL_LAWS",
    "JointType",
    "DriveKind",
    "OutputKind",
    "Material",
    "Clearance",
    "Link",
    "Joint",
    "MotionLaw",
    "Drive",
    "Output",
    "Mechanism",
    "STEEL",
]


class ContactLaw(enum.Enum):
    """Normal contact force law of a clearance joint (docs/references.md: contact laws)."""

    HERTZ = "hertz"
    LANKARANI_NIKRAVESH = "lankarani_nikravesh"
    HUNT_CROSSLEY = "hunt_crossley"
    FLORES = "flores"
    GONTHIER = "gonthier"
    HU_GUO = "hu_guo"
    IMPACT = "impact"
    # The cylindrical (conformal) laws of a pin in a hole (`contact_calibration.cylindrical_laws`;
    # appended last: the compiled contact's law codes follow this order)
    JOHNSON = "johnson"
    RADZIMOVSKY = "radzimovsky"
    GOLDSMITH = "goldsmith"
    DUBOWSKY_FREUDENSTEIN = "dubowsky_freudenstein"
    ESDU_78035 = "esdu_78035"
    LIU = "liu"
    PEREIRA = "pereira"
    PERSSON = "persson"


CYLINDRICAL_LAWS = frozenset(
    (
        ContactLaw.JOHNSON,
        ContactLaw.RADZIMOVSKY,
        ContactLaw.GOLDSMITH,
        ContactLaw.DUBOWSKY_FREUDENSTEIN,
        ContactLaw.ESDU_78035,
        ContactLaw.LIU,
        ContactLaw.PEREIRA,
        ContactLaw.PERSSON,
    )
)
"""The laws of a pin in a hole's line contact: they need the bearing length L
(`Clearance.bearing_length`) and take Lankarani–Nikravesh's hysteresis damping."""


class JointType(enum.Enum):
    """Kinematic pair type."""

    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"


class DriveKind(enum.Enum):
    """How a drive moves its joint."""

    CONSTANT_SPEED = "constant_speed"
    MOTION_LAW = "motion_law"
    TORQUE = "torque"


class OutputKind(enum.Enum):
    """What a named output measures."""

    POSITION_X = "position_x"
    POSITION_Y = "position_y"
    ANGLE = "angle"


def _point(name: str, value: Any) -> tuple[float, float]:
    try:
        x, y = value
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a pair (x, y) in metres (got {value!r})") from None
    return (finite(f"{name}[0]", x), finite(f"{name}[1]", y))


def _name(field_name: str, value: object) -> str:
    if not isinstance(value, str) or not value or not value.replace("_", "").replace("-", "").isalnum():
        raise ValueError(f"{field_name} must be a non-empty name of letters, digits, '_' or '-' (got {value!r})")
    return value


@dataclass(frozen=True)
class Material:
    """Elastic material of a journal or bearing.

    Attributes:
        youngs_modulus: Young's modulus E [Pa].
        poisson_ratio: Poisson's ratio nu [-], in [0, 0.5).
    """

    youngs_modulus: float = 207e9
    poisson_ratio: float = 0.3

    def __post_init__(self) -> None:
        positive("youngs_modulus", self.youngs_modulus, "Pa")
        nu = finite("poisson_ratio", self.poisson_ratio)
        if not 0.0 <= nu < 0.5:
            raise ValueError(f"poisson_ratio must be in [0, 0.5) (got {self.poisson_ratio!r})")


STEEL = Material(207e9, 0.3)
"""Steel as used throughout the clearance-joint literature (docs/references.md)."""


@dataclass(frozen=True)
class Clearance:
    """Radial clearance of a revolute joint: a journal inside a bearing. Physics only.

    Numerical choices (segment count, geom types, time step, contact mode) live in the
    options passed to `clearance.mjcf` and `clearance.simulate`, not here.

    Attributes:
        radial_clearance: c = R_B - R_J [m], > 0 and < bearing_radius.
        bearing_radius: R_B [m].
        journal_link: name of the link that holds the journal; None means the link of the
            joint that is farther from ground (resolved by `Mechanism`).
        bearing_material, journal_material: elastic materials.
        restitution: coefficient of restitution c_e in (0, 1].
        friction: Coulomb friction coefficient mu >= 0.
        law: normal contact force law.
        bearing_length: axial length L of the bearing [m], > 0, or None where nothing
            needs it (a lubricated joint does). The cylindrical laws (`CYLINDRICAL_LAWS`)
            take None as L = 2 R_B, a bearing as long as its bore
            (`contact_calibration.cylindrical_laws.bearing_length`).
        lubrication: the oil film of a lubricated joint (`clearance.lubrication`), or None
            for a dry joint.
    """

    radial_clearance: float
    bearing_radius: float = 0.010
    journal_link: str | None = None
    bearing_material: Material = STEEL
    journal_material: Material = STEEL
    restitution: float = 0.9
    friction: float = 0.0
    law: ContactLaw = ContactLaw.LANKARANI_NIKRAVESH
    bearing_length: float | None = None
    lubrication: Lubrication | None = None

    def __post_init__(self) -> None:
        rb = positive("bearing_radius", self.bearing_radius, "m")
        c = finite("radial_clearance", self.radial_clearance)
        if not 0.0 < c < rb:
            raise ValueError(f"radial_clearance must be > 0 and < bearing_radius = {rb} m (got {c!r} m)")
        e = finite("restitution", self.restitution)
        if not 0.0 < e <= 1.0:
            raise ValueError(f"restitution must be in (0, 1] (got {self.restitution!r})")
        mu = finite("friction", self.friction)
        if mu < 0:
            raise ValueError(f"friction must be >= 0 (got {self.friction!r})")
        if not isinstance(self.law, ContactLaw):
            raise ValueError(f"law must be a ContactLaw (got {self.law!r})")
        if self.journal_link is not None:
            _name("journal_link", self.journal_link)
        if self.bearing_length is not None:
            positive("bearing_length", self.bearing_length, "m")
        if self.lubrication is not None:
            if not isinstance(self.lubrication, Lubrication):
                raise ValueError(f"lubrication must be a Lubrication (got {self.lubrication!r})")
            if self.bearing_length is None:
                raise ValueError("a lubricated joint needs bearing_length, the bearing's axial length [m] > 0")
            ht = self.lubrication.transition_thickness
            if ht >= c:
                raise ValueError(f"lubrication transition_thickness must be < radial_clearance = {c} m (got {ht!r} m)")

    @property
    def journal_radius(self) -> float:
        """R_J = R_B - c [m]."""
        return self.bearing_radius - self.radial_clearance


@dataclass(frozen=True)
class Link:
    """A rigid link.

    Attributes:
        name: unique link name.
        mass: mass [kg]; 0 only for the ground link.
        inertia: moment of inertia about the centre of mass, z axis [kg m^2].
        com: centre of mass in the link frame [m].
        points: named points in the link frame [m] (joint locations, output points).
        pose_guess: (x [m], y [m], theta [rad]) guess of the pose at t = 0; assembly picks
            the branch nearest these guesses.
    """

    name: str
    mass: float
    inertia: float
    com: tuple[float, float] = (0.0, 0.0)
    points: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    pose_guess: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        _name("Link.name", self.name)
        m = finite(f"link '{self.name}' mass", self.mass)
        j = finite(f"link '{self.name}' inertia", self.inertia)
        if m < 0 or j < 0:
            raise ValueError(
                f"link '{self.name}': mass and inertia must be >= 0 (got {self.mass!r} kg, {self.inertia!r} kg m^2)"
            )
        object.__setattr__(self, "com", _point(f"link '{self.name}' com", self.com))
        pts = {}
        for k, v in dict(self.points).items():
            pts[_name(f"link '{self.name}' point name", k)] = _point(f"link '{self.name}' point '{k}'", v)
        object.__setattr__(self, "points", MappingProxyType(pts))
        try:
            x, y, th = self.pose_guess
        except (TypeError, ValueError):
            raise ValueError(f"link '{self.name}' pose_guess must be (x, y, theta) (got {self.pose_guess!r})") from None
        object.__setattr__(
            self,
            "pose_guess",
            tuple(finite(f"link '{self.name}' pose_guess", v) for v in (x, y, th)),
        )

    def point(self, name: str) -> tuple[float, float]:
        """Return a named point, or raise KeyError naming the link and its points."""
        try:
            return self.points[name]
        except KeyError:
            raise KeyError(f"link '{self.name}' has no point '{name}' (it has: {sorted(self.points)})") from None


@dataclass(frozen=True)
class Joint:
    """A kinematic pair between two links.

    Attributes:
        name: unique joint name.
        kind: revolute or prismatic.
        link_a, point_a: first link and its point (for a prismatic joint: the guide).
        link_b, point_b: second link and its point (for a prismatic joint: the slider).
        axis: prismatic sliding direction in the frame of link_a (normalised here).
        clearance: radial clearance of a revolute joint, or None for an ideal joint.
        translational_clearance: play of a prismatic joint's slider in its guide
            (`clearance.translational.TranslationalClearance`), or None for an ideal slider.
    """

    name: str
    kind: JointType
    link_a: str
    point_a: str
    link_b: str
    point_b: str
    axis: tuple[float, float] = (1.0, 0.0)
    clearance: Clearance | None = None
    translational_clearance: TranslationalClearance | None = None

    def __post_init__(self) -> None:
        _name("Joint.name", self.name)
        if not isinstance(self.kind, JointType):
            raise ValueError(f"joint '{self.name}' kind must be a JointType (got {self.kind!r})")
        for f in ("link_a", "point_a", "link_b", "point_b"):
            _name(f"joint '{self.name}' {f}", getattr(self, f))
        if self.link_a == self.link_b:
            raise ValueError(f"joint '{self.name}' joins link '{self.link_a}' to itself")
        ax = _point(f"joint '{self.name}' axis", self.axis)
        n = math.hypot(*ax)
        if n == 0:
            raise ValueError(f"joint '{self.name}' axis must be non-zero (got {self.axis!r})")
        object.__setattr__(self, "axis", (ax[0] / n, ax[1] / n))
        if self.clearance is not None:
            if self.kind is not JointType.REVOLUTE:
                raise ValueError(
                    f"joint '{self.name}': clearance is only supported on revolute joints (got kind={self.kind.value})"
                )
            if not isinstance(self.clearance, Clearance):
                raise ValueError(f"joint '{self.name}' clearance must be a Clearance (got {self.clearance!r})")
            jl = self.clearance.journal_link
            if jl is not None and jl not in (self.link_a, self.link_b):
                raise ValueError(
                    f"joint '{self.name}' clearance journal_link must be '{self.link_a}' or "
                    f"'{self.link_b}' (got '{jl}')"
                )
        if self.translational_clearance is not None:
            from clearance.translational import TranslationalClearance

            if self.kind is not JointType.PRISMATIC:
                raise ValueError(
                    f"joint '{self.name}': translational_clearance is only supported on prismatic joints "
                    f"(got kind={self.kind.value})"
                )
            if not isinstance(self.translational_clearance, TranslationalClearance):
                raise ValueError(
                    f"joint '{self.name}' translational_clearance must be a TranslationalClearance "
                    f"(got {self.translational_clearance!r})"
                )

    @property
    def has_play(self) -> bool:
        """Whether the joint has a clearance of either kind (radial or translational)."""
        return self.clearance is not None or self.translational_clearance is not None

    def require_translational(self) -> TranslationalClearance:
        """The joint's translational clearance, for code that handles sliders with play only.

        Raises:
            ValueError: the joint has no translational clearance.
        """
        if self.translational_clearance is None:
            raise ValueError(f"joint '{self.name}' has no translational clearance")
        return self.translational_clearance

    def require_clearance(self) -> Clearance:
        """The joint's clearance, for code that handles clearance joints only.

        Raises:
            ValueError: the joint is ideal (it has no clearance).
        """
        if self.clearance is None:
            raise ValueError(f"joint '{self.name}' is an ideal joint: it has no clearance")
        return self.clearance


@dataclass(frozen=True)
class MotionLaw:
    """A servo motion law theta(t) = theta0 + speed * t + sum_k a_k sin(k w t + phi_k).

    Attributes:
        speed: mean angular speed [rad/s] (also sets the fundamental w = speed; with zero
            speed, ``period`` must be given).
        harmonics: ((amplitude [rad], phase [rad]), ...) for k = 1, 2, ...
        period: fundamental period [s]; default 2 pi / |speed|.
    """

    speed: float
    harmonics: tuple[tuple[float, float], ...] = ()
    period: float | None = None

    def __post_init__(self) -> None:
        finite("MotionLaw.speed", self.speed)
        hs = tuple(_point(f"MotionLaw.harmonics[{i}]", h) for i, h in enumerate(self.harmonics))
        object.__setattr__(self, "harmonics", hs)
        if self.period is None:
            if self.speed == 0:
                raise ValueError("MotionLaw.period must be given when speed is 0")
        else:
            positive("MotionLaw.period", self.period, "s")

    @property
    def fundamental(self) -> float:
        """Fundamental angular frequency [rad/s]."""
        return 2 * math.pi / self.period if self.period is not None else abs(self.speed)

    def offset(self, t: ArrayLike) -> NDArray[np.float64]:
        """theta(t) - theta0 [rad] for scalar or array t [s]."""
        import numpy as np

        t = np.asarray(t, dtype=float)
        w = self.fundamental
        out: NDArray[np.float64] = self.speed * t
        for k, (a, ph) in enumerate(self.harmonics, start=1):
            out = out + a * (np.sin(k * w * t + ph) - math.sin(ph))
        return out

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        """theta'(t) [rad/s]."""
        import numpy as np

        t = np.asarray(t, dtype=float)
        w = self.fundamental
        out = np.full_like(t, self.speed)
        for k, (a, ph) in enumerate(self.harmonics, start=1):
            out = out + a * k * w * np.cos(k * w * t + ph)
        return out

    def acceleration(self, t: ArrayLike) -> NDArray[np.float64]:
        """theta''(t) [rad/s^2]."""
        import numpy as np

        t = np.asarray(t, dtype=float)
        w = self.fundamental
        out = np.zeros_like(t)
        for k, (a, ph) in enumerate(self.harmonics, start=1):
            out = out - a * (k * w) ** 2 * np.sin(k * w * t + ph)
        return out


@dataclass(frozen=True)
class Drive:
    """A drive on an ideal revolute joint; it sets the joint's relative angle theta_b - theta_a.

    Attributes:
        name: unique drive name.
        joint: name of the driven revolute joint (must be ideal).
        kind: constant speed, motion law or torque.
        speed: constant speed [rad/s] (CONSTANT_SPEED).
        start_angle: drive angle at t = 0 [rad].
        motion: the motion law (MOTION_LAW).
        torque: constant torque [N m] (TORQUE).
        initial_speed: speed of the joint at t = 0 [rad/s] (TORQUE; a crank that turns
            freely from a given speed is a torque drive of 0 N m with this speed).
    """

    name: str
    joint: str
    kind: DriveKind = DriveKind.CONSTANT_SPEED
    speed: float = 0.0
    start_angle: float = 0.0
    motion: MotionLaw | None = None
    torque: float = 0.0
    initial_speed: float = 0.0

    def __post_init__(self) -> None:
        _name("Drive.name", self.name)
        _name(f"drive '{self.name}' joint", self.joint)
        if not isinstance(self.kind, DriveKind):
            raise ValueError(f"drive '{self.name}' kind must be a DriveKind (got {self.kind!r})")
        finite(f"drive '{self.name}' speed", self.speed)
        finite(f"drive '{self.name}' start_angle", self.start_angle)
        finite(f"drive '{self.name}' torque", self.torque)
        finite(f"drive '{self.name}' initial_speed", self.initial_speed)
        if self.initial_speed != 0 and self.kind is not DriveKind.TORQUE:
            raise ValueError(
                f"drive '{self.name}' initial_speed is for torque drives (a {self.kind.value} drive starts at "
                f"its prescribed speed; got {self.initial_speed!r} rad/s)"
            )
        if self.kind is DriveKind.CONSTANT_SPEED and self.speed == 0:
            raise ValueError(f"drive '{self.name}' speed must be non-zero for a constant-speed drive")
        if self.kind is DriveKind.MOTION_LAW and not isinstance(self.motion, MotionLaw):
            raise ValueError(f"drive '{self.name}' needs a MotionLaw in 'motion' (got {self.motion!r})")

    def require_motion(self) -> MotionLaw:
        """The drive's motion law, for code that handles motion-law drives only.

        Raises:
            ValueError: the drive has no motion law (it is not a MOTION_LAW drive).
        """
        if self.motion is None:
            raise ValueError(f"drive '{self.name}' ({self.kind.value}) has no motion law")
        return self.motion

    def angle(self, t: ArrayLike) -> NDArray[np.float64]:
        """Prescribed drive angle [rad] at time(s) t [s] (not defined for torque drives)."""
        import numpy as np

        if self.kind is DriveKind.MOTION_LAW:
            return self.start_angle + self.require_motion().offset(t)
        if self.kind is DriveKind.CONSTANT_SPEED:
            return self.start_angle + self.speed * np.asarray(t, dtype=float)
        raise ValueError(f"drive '{self.name}' is a torque drive: its angle is not prescribed")

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        """Prescribed drive speed [rad/s] at time(s) t [s]."""
        import numpy as np

        if self.kind is DriveKind.MOTION_LAW:
            return self.require_motion().rate(t)
        if self.kind is DriveKind.CONSTANT_SPEED:
            return np.full_like(np.asarray(t, dtype=float), self.speed)
        raise ValueError(f"drive '{self.name}' is a torque drive: its speed is not prescribed")

    def acceleration(self, t: ArrayLike) -> NDArray[np.float64]:
        """Prescribed drive acceleration [rad/s^2] at time(s) t [s]."""
        import numpy as np

        if self.kind is DriveKind.MOTION_LAW:
            return self.require_motion().acceleration(t)
        return np.zeros_like(np.asarray(t, dtype=float))

    @property
    def period(self) -> float:
        """Drive period [s]: one revolution at the drive's (mean) speed, or the law's period."""
        if self.kind is DriveKind.MOTION_LAW:
            return 2 * math.pi / self.require_motion().fundamental
        if self.kind is DriveKind.CONSTANT_SPEED:
            return 2 * math.pi / abs(self.speed)
        raise ValueError(f"drive '{self.name}' is a torque drive: it has no set period")


@dataclass(frozen=True)
class Output:
    """A named output quantity: a point's x or y position, or a link angle.

    Attributes:
        name: unique output name (e.g. ``slider_x``).
        link: link it is measured on.
        kind: POSITION_X, POSITION_Y or ANGLE.
        point: named point of the link (positions only).
    """

    name: str
    link: str
    kind: OutputKind
    point: str | None = None

    def __post_init__(self) -> None:
        _name("Output.name", self.name)
        _name(f"output '{self.name}' link", self.link)
        if not isinstance(self.kind, OutputKind):
            raise ValueError(f"output '{self.name}' kind must be an OutputKind (got {self.kind!r})")
        if self.kind is not OutputKind.ANGLE and self.point is None:
            raise ValueError(f"output '{self.name}' ({self.kind.value}) needs a point")

    def require_point(self) -> str:
        """The point of a position output.

        Raises:
            ValueError: the output has no point (an ANGLE output).
        """
        if self.point is None:
            raise ValueError(f"output '{self.name}' ({self.kind.value}) has no point")
        return self.point


def _unique(kind: str, names: list[str]) -> None:
    seen = set()
    for n in names:
        if n in seen:
            raise ValueError(f"{kind} names must be unique ('{n}' appears twice)")
        seen.add(n)


@dataclass(frozen=True)
class Mechanism:
    """A planar mechanism: links, joints, drives and outputs, in SI units.

    Attributes:
        name: mechanism name.
        links: all links, ground included.
        joints: all kinematic pairs.
        drives: one per degree of freedom of the ideal mechanism.
        outputs: named outputs.
        ground: name of the fixed link.
        gravity: (g_x, g_y) [m/s^2] in the plane; (0, 0) for none.
        parameters: the builder parameters (for metadata and reports), JSON-serialisable.
    """

    name: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    drives: tuple[Drive, ...]
    outputs: tuple[Output, ...] = ()
    ground: str = "ground"
    gravity: tuple[float, float] = (0.0, 0.0)
    parameters: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        _name("Mechanism.name", self.name)
        for attr in ("links", "joints", "drives", "outputs"):
            object.__setattr__(self, attr, tuple(getattr(self, attr)))
        object.__setattr__(self, "gravity", _point("gravity", self.gravity))
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        _unique("link", [lk.name for lk in self.links])
        _unique("joint", [j.name for j in self.joints])
        _unique("drive", [d.name for d in self.drives])
        _unique("output", [o.name for o in self.outputs])
        links = {lk.name: lk for lk in self.links}
        if self.ground not in links:
            raise ValueError(f"ground link '{self.ground}' is not among the links {sorted(links)}")
        for lk in self.links:
            if lk.name != self.ground and (lk.mass <= 0 or lk.inertia <= 0):
                raise ValueError(
                    f"link '{lk.name}': mass and inertia must be > 0 for a moving link "
                    f"(got {lk.mass!r} kg, {lk.inertia!r} kg m^2)"
                )
        for j in self.joints:
            for side in ("a", "b"):
                ln, pn = getattr(j, f"link_{side}"), getattr(j, f"point_{side}")
                if ln not in links:
                    raise ValueError(
                        f"joint '{j.name}' link_{side} = '{ln}' is not a link of the mechanism (links: {sorted(links)})"
                    )
                if pn not in links[ln].points:
                    raise ValueError(
                        f"joint '{j.name}' point_{side} = '{pn}' is not a point of link '{ln}' "
                        f"(points: {sorted(links[ln].points)})"
                    )
        joints = {j.name: j for j in self.joints}
        driven = set()
        for d in self.drives:
            if d.joint not in joints:
                raise ValueError(f"drive '{d.name}' joint '{d.joint}' is not a joint of the mechanism")
            jt = joints[d.joint]
            if jt.kind is not JointType.REVOLUTE or jt.clearance is not None:
                raise ValueError(
                    f"drive '{d.name}' must act on an ideal revolute joint ('{d.joint}' is "
                    f"{'a clearance' if jt.clearance is not None else jt.kind.value} joint)"
                )
            if d.joint in driven:
                raise ValueError(f"joint '{d.joint}' has two drives")
            driven.add(d.joint)
        for o in self.outputs:
            if o.link not in links:
                raise ValueError(f"output '{o.name}' link '{o.link}' is not a link of the mechanism")
            if o.point is not None and o.point not in links[o.link].points:
                raise ValueError(f"output '{o.name}' point '{o.point}' is not a point of link '{o.link}'")
        # connectivity
        adj: dict[str, set[str]] = {n: set() for n in links}
        for j in self.joints:
            adj[j.link_a].add(j.link_b)
            adj[j.link_b].add(j.link_a)
        seen, stack = {self.ground}, [self.ground]
        while stack:
            for nb in adj[stack.pop()]:
                if nb not in seen:
                    seen.add(nb)
                    stack.append(nb)
        if seen != set(links):
            raise ValueError(f"links {sorted(set(links) - seen)} are not connected to ground")
        dof = self.degrees_of_freedom
        if dof != len(self.drives):
            raise ValueError(
                f"the ideal mechanism has {dof} degree(s) of freedom (Gruebler) but "
                f"{len(self.drives)} drive(s); give one drive per degree of freedom"
            )
        # resolve the journal side of each clearance
        depth = self._depths(adj)
        new_joints = []
        for j in self.joints:
            c = j.clearance
            if c is not None and c.journal_link is None:
                far = j.link_b if depth[j.link_b] >= depth[j.link_a] else j.link_a
                j = dataclasses.replace(j, clearance=dataclasses.replace(c, journal_link=far))
            new_joints.append(j)
        object.__setattr__(self, "joints", tuple(new_joints))

    def _depths(self, adj: Mapping[str, set[str]]) -> dict[str, int]:
        depth = {self.ground: 0}
        frontier = [self.ground]
        while frontier:
            nxt = []
            for n in frontier:
                for nb in sorted(adj[n]):
                    if nb not in depth:
                        depth[nb] = depth[n] + 1
                        nxt.append(nb)
            frontier = nxt
        return depth

    @property
    def degrees_of_freedom(self) -> int:
        """Gruebler count of the ideal mechanism: 3 (n - 1) - 2 j."""
        return 3 * (len(self.links) - 1) - 2 * len(self.joints)

    def link(self, name: str) -> Link:
        """Return the link called ``name``."""
        for lk in self.links:
            if lk.name == name:
                return lk
        raise KeyError(f"no link '{name}' (links: {[lk.name for lk in self.links]})")

    def joint(self, name: str) -> Joint:
        """Return the joint called ``name``."""
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(f"no joint '{name}' (joints: {[j.name for j in self.joints]})")

    @property
    def moving_links(self) -> tuple[Link, ...]:
        """All links but ground, in declaration order."""
        return tuple(lk for lk in self.links if lk.name != self.ground)

    @property
    def drive_period(self) -> float | None:
        """Period [s] of the slowest prescribed drive (constant speed or motion law).

        The one time scale every run, statistic and figure of a mechanism uses: default
        durations are counted in it, the start-up window is one of it. None when every drive
        is a torque (no set period).
        """
        periods = [d.period for d in self.drives if d.kind is not DriveKind.TORQUE]
        return max(periods) if periods else None

    @property
    def clearance_joints(self) -> tuple[Joint, ...]:
        """Revolute joints that carry a (radial) clearance, in declaration order."""
        return tuple(j for j in self.joints if j.clearance is not None)

    @property
    def translational_joints(self) -> tuple[Joint, ...]:
        """Prismatic joints whose slider has play in its guide, in declaration order."""
        return tuple(j for j in self.joints if j.translational_clearance is not None)

    def ideal_twin(self) -> Mechanism:
        """The same mechanism with every clearance replaced by an ideal hinge or slider."""
        return dataclasses.replace(
            self,
            name=self.name if self.name.endswith("_ideal") else f"{self.name}_ideal",
            joints=tuple(dataclasses.replace(j, clearance=None, translational_clearance=None) for j in self.joints),
        )
