"""The keywords that end every catalogue builder's signature, declared once.

After its own dimensions and drives, every builder takes where its clearances are
(``clearance_at``: revolute joints, and the prismatic joints of its sliders), their contact
properties (``radial_clearance``, ``bearing_radius``, ``restitution``, ``friction``, ``law``,
``material``; a slider's block ``slider_length`` by ``slider_height`` and its corners'
``guide_stiffness``), ``gravity`` and the mechanism's ``name``. `ContactKeywords` declares
them for the type checker (a builder ends with ``**contact: Unpack[ContactKeywords]``);
`contact_keywords` gives a builder their defaults and writes them into its signature one by
one, so that `inspect.signature` (the command line, scenario files) and ``help`` list every
keyword and an unknown one raises TypeError; `ClearanceFactory` turns them into `Clearance`
and `TranslationalClearance` records.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Sequence
from typing import Any, ForwardRef, TypedDict, TypeVar, Unpack, cast

from clearance.lubrication import Lubrication
from clearance.model import (
    STEEL,
    Clearance,
    ContactLaw,
    Joint,
    JointType,
    Material,
    Mechanism,
)
from clearance.translational import DEFAULT_GUIDE_STIFFNESS, TranslationalClearance

__all__ = [
    "DEFAULT_RADIAL_CLEARANCE",
    "ContactKeywords",
    "CONTACT_DEFAULTS",
    "contact_keywords",
    "ClearanceFactory",
    "lubrication_document",
]

DEFAULT_RADIAL_CLEARANCE = 0.1e-3
"""Default radial clearance of the catalogue's mechanisms [m] (mid-range of 0.02-1 mm)."""


class ContactKeywords(TypedDict, total=False):
    """The keywords every catalogue builder takes after its own dimensions and drives.

    Attributes:
        clearance_at: joints with clearance (any of the builder's clearable joints: revolute
            joints get a radial clearance, a slider's prismatic joint a translational one);
            empty for the ideal mechanism.
        radial_clearance: c [m] at every clearance joint (a slider: the gap on each side of
            its block in the guide).
        bearing_radius: R_B [m].
        restitution: coefficient of restitution of every clearance joint.
        friction: Coulomb friction coefficient of every clearance joint.
        law: normal contact force law of every clearance joint.
        material: journal and bearing material.
        gravity: gravitational acceleration [m/s^2] along -y (0 for none).
        name: mechanism name (default: the builder's name).
        bearing_length: axial length L [m] of every clearance joint's bearing, or None.
        lubrication: the oil film of every clearance joint (`Lubrication`), or None for
            dry joints; needs ``bearing_length``.
        slider_length: length [m] of a slider's block along its guide (translational
            clearance only).
        slider_height: height [m] of a slider's block across its guide (translational
            clearance only).
        guide_stiffness: K [N/m^1.5] of a slider's corners against its guide (translational
            clearance only).
    """

    clearance_at: Sequence[str]
    radial_clearance: float
    bearing_radius: float
    restitution: float
    friction: float
    law: ContactLaw
    material: Material
    gravity: float
    name: str
    bearing_length: float | None
    lubrication: Lubrication | None
    slider_length: float
    slider_height: float
    guide_stiffness: float


CONTACT_DEFAULTS: ContactKeywords = {
    "radial_clearance": DEFAULT_RADIAL_CLEARANCE,
    "bearing_radius": 0.010,
    "restitution": 0.9,
    "friction": 0.0,
    "law": ContactLaw.LANKARANI_NIKRAVESH,
    "material": STEEL,
    "gravity": 0.0,
    "bearing_length": None,
    "lubrication": None,
    "slider_length": 0.040,
    "slider_height": 0.020,
    "guide_stiffness": DEFAULT_GUIDE_STIFFNESS,
}
"""The catalogue's defaults of the contact keywords; ``clearance_at`` and ``name`` are each builder's own.

The catalogue's sliders are the project's own 40 mm by 20 mm blocks (the papers give none)."""

_Builder = TypeVar("_Builder", bound=Callable[..., Mechanism])


def _annotation(hint: object) -> object:
    """A `ContactKeywords` annotation as the builders' own are written (a string)."""
    return hint.__forward_arg__ if isinstance(hint, ForwardRef) else hint


def contact_keywords(**defaults: Unpack[ContactKeywords]) -> Callable[[_Builder], _Builder]:
    """Decorate a builder that ends with ``**contact: Unpack[ContactKeywords]``.

    The decorated builder's signature lists the contact keywords one by one after the
    builder's own, with the defaults of `CONTACT_DEFAULTS` overridden by ``defaults``
    (``clearance_at`` is required; ``name`` defaults to the builder's name). A call is
    bound to that signature: an unknown keyword raises TypeError as for any function, and
    the builder receives every keyword, given or defaulted.

    Args:
        defaults: the builder's own defaults of contact keywords; must include ``clearance_at``.

    Returns:
        The decorator.

    Raises:
        TypeError: ``clearance_at`` is not given, or the builder does not end with a
            ``**`` parameter.
    """
    if "clearance_at" not in defaults:
        raise TypeError("contact_keywords needs the builder's default clearance_at")

    def decorate(build: _Builder) -> _Builder:
        own = list(inspect.signature(build).parameters.values())
        if not own or own[-1].kind is not inspect.Parameter.VAR_KEYWORD:
            raise TypeError(f"{build.__name__} must end with **contact: Unpack[ContactKeywords]")
        values: dict[str, Any] = {**CONTACT_DEFAULTS, "name": build.__name__, **defaults}
        signature = inspect.signature(build).replace(
            parameters=[
                *own[:-1],
                *(
                    inspect.Parameter(
                        key, inspect.Parameter.KEYWORD_ONLY, default=values[key], annotation=_annotation(t)
                    )
                    for key, t in ContactKeywords.__annotations__.items()
                ),
            ]
        )

        @functools.wraps(build)
        def builder(*args: Any, **kwargs: Any) -> Mechanism:
            try:
                bound = signature.bind(*args, **kwargs)
            except TypeError as e:
                raise TypeError(f"{build.__name__}() {e}") from None
            bound.apply_defaults()
            return build(**bound.arguments)

        # what `inspect.signature` reports; set through __dict__ as functools.update_wrapper sets attributes
        builder.__dict__["__signature__"] = signature
        return cast(_Builder, builder)

    return decorate


class ClearanceFactory:
    """The contact keywords of one builder call: `Clearance` records by joint name, gravity, name.

    Args:
        clearable: revolute joints that may carry a clearance (the others are driven).
        contact: the call's contact keywords, every one present (as a builder decorated
            with `contact_keywords` receives them).
        sliders: prismatic joints whose slider may have play in its guide.

    Raises:
        ValueError: an unknown or non-clearable joint in ``clearance_at``, or a bad value.
    """

    def __init__(self, clearable: Sequence[str], contact: ContactKeywords, *, sliders: Sequence[str] = ()) -> None:
        clearance_at, law, material = contact["clearance_at"], contact["law"], contact["material"]
        if isinstance(clearance_at, str):
            raise ValueError(f"clearance_at must be a sequence of joint names (got the string {clearance_at!r})")
        self.joints = tuple(clearance_at)
        unknown = [j for j in self.joints if j not in (*clearable, *sliders)]
        if unknown:
            raise ValueError(f"clearance_at: unknown joint(s) {unknown}; expected any of {[*clearable, *sliders]}")
        if not isinstance(law, ContactLaw):
            raise ValueError(f"law must be a ContactLaw (got {law!r})")
        if not isinstance(material, Material):
            raise ValueError(f"material must be a Material (got {material!r})")
        self.template = Clearance(
            radial_clearance=contact["radial_clearance"],
            bearing_radius=contact["bearing_radius"],
            bearing_material=material,
            journal_material=material,
            restitution=contact["restitution"],
            friction=contact["friction"],
            law=law,
            bearing_length=contact["bearing_length"],
            lubrication=contact["lubrication"],
        )
        self.slider: TranslationalClearance | None = None
        """The translational clearance of the sliders in ``clearance_at`` (None if there are none)."""
        if any(j in sliders for j in self.joints):
            self.slider = TranslationalClearance(
                clearance=contact["radial_clearance"],
                slider_length=contact["slider_length"],
                slider_height=contact["slider_height"],
                stiffness=contact["guide_stiffness"],
                restitution=contact["restitution"],
                friction=contact["friction"],
                law=law,
            )
        self.slider_keywords = {k: contact[k] for k in ("slider_length", "slider_height", "guide_stiffness")}
        self.gravity = contact["gravity"]
        self.name = contact["name"]

    def __call__(self, joint: str) -> Clearance | None:
        """The clearance of ``joint``, or None for an ideal joint."""
        return self.template if joint in self.joints else None

    def revolute(self, name: str, link_a: str, point_a: str, link_b: str, point_b: str) -> Joint:
        """A revolute joint, with clearance when ``name`` is in ``clearance_at``."""
        return Joint(name, JointType.REVOLUTE, link_a, point_a, link_b, point_b, clearance=self(name))

    def prismatic(
        self, name: str, link_a: str, point_a: str, link_b: str, point_b: str, *, axis: tuple[float, float]
    ) -> Joint:
        """A prismatic joint (guide ``link_a``, slider ``link_b``), with play when ``name`` is in ``clearance_at``."""
        play = self.slider if name in self.joints else None
        return Joint(
            name, JointType.PRISMATIC, link_a, point_a, link_b, point_b, axis=axis, translational_clearance=play
        )

    def pin(self, name: str, link_a: str, link_b: str) -> Joint:
        """A revolute joint between points named ``name`` of both links, with clearance as `revolute`."""
        return self.revolute(name, link_a, name, link_b, name)

    def parameters(self) -> dict[str, Any]:
        """The contact keywords but ``name`` as JSON-friendly builder parameters (the slider keywords
        only where a slider has play)."""
        c = self.template
        extra: dict[str, Any] = {}
        if c.bearing_length is not None:
            extra["bearing_length"] = c.bearing_length
        if c.lubrication is not None:
            extra["lubrication"] = lubrication_document(c.lubrication)
        return {
            "clearance_at": list(self.joints),
            "radial_clearance": c.radial_clearance,
            "bearing_radius": c.bearing_radius,
            "restitution": c.restitution,
            "friction": c.friction,
            "law": c.law.value,
            "material": {
                "youngs_modulus": c.bearing_material.youngs_modulus,
                "poisson_ratio": c.bearing_material.poisson_ratio,
            },
            # a slider's block and stiffness, where a slider has play
            **({k: float(v) for k, v in self.slider_keywords.items()} if self.slider else {}),
            "gravity": float(self.gravity),
            **extra,
        }


def lubrication_document(lubrication: Lubrication) -> dict[str, Any]:
    """A `Lubrication` as a TOML-ready table in SI units (the keys a scenario file reads)."""
    return {
        "viscosity_pa_s": lubrication.viscosity,
        "film": lubrication.film.value,
        "transition_thickness_m": lubrication.transition_thickness,
    }
