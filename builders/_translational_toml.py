"""A slider's play in a full-form scenario: the ``[joints.translational_clearance]`` table.

Read by `clearance.builders.scenario` for a ``[[joints]]`` entry of kind "prismatic" and
written back by `dump_scenario`: clearance_<m|mm|um> (the gap on each side of the block),
slider_length_<m|mm>, slider_height_<m|mm>, stiffness_n_per_m1_5, restitution, friction, law.
"""

from __future__ import annotations

from typing import Any

from clearance.builders._toml_reader import Table
from clearance.model import ContactLaw
from clearance.translational import DEFAULT_GUIDE_STIFFNESS, TranslationalClearance

__all__ = ["read_translational", "translational_document"]

_KEYS = [
    "clearance_<m|mm|um>",
    "slider_length_<m|mm|cm|um>",
    "slider_height_<m|mm|cm|um>",
    "stiffness_n_per_m1_5",
    "restitution",
    "friction",
    "law",
]


def read_translational(t: Table) -> TranslationalClearance:
    """The ``translational_clearance`` table of a prismatic joint as a `TranslationalClearance`.

    Raises:
        ScenarioError: a missing key, a bad unit or value, an unknown law or key (naming file,
            line, table and key).
    """
    law = ContactLaw(
        t.text("law", default=ContactLaw.LANKARANI_NIKRAVESH.value, choices=[law.value for law in ContactLaw])
    )
    values = (
        t.number("clearance", "length"),
        t.number("slider_length", "length"),
        t.number("slider_height", "length"),
        t.number("stiffness", "contact_stiffness", DEFAULT_GUIDE_STIFFNESS),
        t.plain("restitution", 0.9),
        t.plain("friction", 0.0),
    )
    t.finish(_KEYS)
    try:
        return TranslationalClearance(*values, law=law)
    except ValueError as e:
        raise t.error(None, str(e)) from None


def translational_document(tc: TranslationalClearance) -> dict[str, Any]:
    """The ``translational_clearance`` table of `read_translational`, in SI units."""
    return {
        "clearance_m": tc.clearance,
        "slider_length_m": tc.slider_length,
        "slider_height_m": tc.slider_height,
        "stiffness_n_per_m1_5": tc.stiffness,
        "restitution": tc.restitution,
        "friction": tc.friction,
        "law": tc.law.value,
    }
