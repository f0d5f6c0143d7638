"""Mechanisms from TOML scenario files, and back.

A scenario either names a catalogue builder with keyword overrides::

    [mechanism]
    builder = "slider_crank"
    clearance_mm = 0.5            # alias of radial_clearance
    crank_speed_rpm = 1000
    clearance_at = ["crank_rod"]

or describes the whole mechanism: ``[mechanism]`` (name, ground, gravity_m_per_s2,
optional ``[mechanism.parameters]``), ``[[links]]`` (name, mass_kg, inertia_kg_m2, com_m,
position_guess_m, angle_guess_rad, ``points_m``), ``[[joints]]`` (name, kind, link_a,
point_a, link_b, point_b, axis, optional ``[joints.clearance]`` with radial_clearance_mm,
bearing_radius_mm, journal_link, restitution, friction, law, materials, bearing_length_mm and a
``[joints.clearance.lubrication]`` table for an oiled joint; a prismatic joint's optional
``[joints.translational_clearance]``, see `clearance.builders._translational_toml`),
``[[drives]]`` (name, joint, kind, speed_rpm, start_angle_deg, torque_n_m,
initial_speed_rad_per_s of a torque drive, optional ``[drives.motion]``)
and ``[[outputs]]`` (name, link, kind, point). Units are part of the key names; any
length, angle or speed unit of `clearance.units.UNITS` may be used. Files are
validated before a `Mechanism` is built; errors name the file, line, table and key. A
loaded mechanism is assembled once at t = 0, so that a loop that cannot close is reported
here. `dump_scenario` writes the full form in SI units, atomically; reading it back gives
an equal `Mechanism`.
"""

from __future__ import annotations

import os
import re
import tempfile
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import tomli_w

from clearance.builders._contact import lubrication_document
from clearance.builders._scenario_builder import from_builder, read_lubrication
from clearance.builders._toml_reader import Locator, ScenarioError, Table
from clearance.builders._translational_toml import read_translational, translational_document
from clearance.kinematics import AssemblyError, SingularPositionError, assemble
from clearance.model import (
    Clearance,
    ContactLaw,
    Drive,
    DriveKind,
    Joint,
    JointType,
    Link,
    Material,
    Mechanism,
    MotionLaw,
    Output,
    OutputKind,
)

__all__ = ["ScenarioError", "load_scenario", "loads_scenario", "dump_scenario", "dumps_scenario", "scenario_document"]

_HEADER = "# clearance mechanism scenario: SI values, units in the key names.\n"
_LAWS = [law.value for law in ContactLaw]
_T = TypeVar("_T")


def load_scenario(path: str | os.PathLike[str]) -> Mechanism:
    """Read a scenario file and return its `Mechanism`.

    Raises:
        ScenarioError: the file is not UTF-8 text or not valid TOML, a key is missing,
            unknown or has a bad unit, a name refers to nothing, the mechanism is invalid,
            or its loops cannot be closed at t = 0. The message names file, line, table
            and key.
        OSError: the file cannot be read.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as e:
        raise ScenarioError(f"not a TOML text file (not UTF-8: {e.reason} at byte {e.start})", path=str(p)) from None
    return loads_scenario(text, source=str(p))


def loads_scenario(text: str, *, source: str = "<string>") -> Mechanism:
    """Like `load_scenario`, from the text of a scenario."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(f"not valid TOML: {e}", path=source) from None
    loc = Locator(text, source)
    top = Table(doc, (), "", loc)
    mech = top.sub("mechanism", "[mechanism]", required=True)
    mech.label = "[mechanism]"
    if not mech.has("builder") and not any(top.has(k) for k in ("links", "joints")):
        from clearance.builders.catalogue import CATALOGUE

        raise mech.error(
            None,
            "missing key 'builder': a scenario names a catalogue builder (builder = \"slider_crank\"; one of: "
            f"{', '.join(CATALOGUE)}) with keyword overrides, or describes a whole mechanism with name, "
            "[[links]], [[joints]], [[drives]] and [[outputs]]",
        )
    if mech.has("builder"):
        others = [k for k in ("links", "joints", "drives", "outputs") if top.has(k)]
        if others:
            raise top.error(
                others[0], "a scenario that names a builder cannot also define links, joints, drives or outputs"
            )
        top.finish(["mechanism"])
        return from_builder(mech)
    try:
        mechanism = _read_full(top, mech)
        assemble(mechanism)
    except ArithmeticError as e:  # sizes that over- or underflow (a link of 1e300 m)
        raise ScenarioError(
            f"the mechanism's sizes cannot be computed with ({e}); check its numbers", path=source
        ) from None
    except SingularPositionError as e:
        raise ScenarioError(f"the mechanism starts in a singular position at t = 0: {e}", path=source) from None
    except AssemblyError as e:
        # name the [[joints]] entry (and its line) whose two sides stay farthest apart
        tables = [t for t in top.array("joints") if t.raw("name") == e.joint]
        if tables:
            raise tables[0].error(None, f"the loops cannot be closed at t = 0: {e}") from None
        raise ScenarioError(f"the loops cannot be closed at t = 0: {e}", path=source) from None
    return mechanism


def _material(t: Table | None) -> Material:
    if t is None:
        return Material()
    m = Material(
        t.number("youngs_modulus", "pressure", Material().youngs_modulus),
        t.plain("poisson_ratio", Material().poisson_ratio),
    )
    t.finish(["youngs_modulus_<pa|mpa|gpa>", "poisson_ratio"])
    return m


def _motion(t: Table) -> MotionLaw:
    speed = t.number("speed", "angular_speed")
    harmonics = []
    for key, factor in (("harmonics_rad", 1.0), ("harmonics_deg", 3.141592653589793 / 180.0)):
        for h in t.raw(key, []):
            harmonics.append(t.convert_pair(key, h, factor))
    period = t.number("period", "time", 0.0) or None
    t.finish(["speed_<rad_per_s|rpm>", "harmonics_<rad|deg> (list of [amplitude, phase])", "period_<s|ms>"])
    return MotionLaw(speed, tuple(harmonics), period)


def _read_link(t: Table, ground: str) -> Link:
    """One ``[[links]]`` table as a `Link`."""
    if t.has("points"):
        raise t.error("points", "needs a unit in its name: use points_m or points_mm")
    pts_t = t.sub("points_m", "points") if t.has("points_m") else t.sub("points_mm", "points")
    scale = 1e-3 if t.has("points_mm") else 1.0
    points = {}
    if pts_t is not None:
        for k, v in pts_t.data.items():
            points[k] = pts_t.convert_pair(k, v, scale)
            pts_t.check_range(k, "length", scale, points[k], unit="mm" if scale != 1.0 else "m")
    lk_name = t.text("name")
    pos = t.pair("position_guess", "length", (0.0, 0.0))
    link: Link = _wrap(
        t,
        None,
        lambda: Link(
            lk_name,
            t.number("mass", "mass", 0.0 if lk_name == ground else None),
            t.number("inertia", "inertia", 0.0 if lk_name == ground else None),
            com=t.pair("com", "length", (0.0, 0.0)),
            points=points,
            pose_guess=(pos[0], pos[1], t.number("angle_guess", "angle", 0.0)),
        ),
    )
    t.finish(
        [
            "name",
            "mass_<kg|g>",
            "inertia_<kg_m2|g_mm2>",
            "com_<m|mm>",
            "position_guess_<m|mm>",
            "angle_guess_<rad|deg>",
            "points_<m|mm>",
        ]
    )
    return link


def _read_full(top: Table, mech: Table) -> Mechanism:
    name = mech.text("name")
    ground = mech.text("ground", default="ground")
    gravity = mech.pair("gravity", "acceleration", (0.0, 0.0))
    params = mech.raw("parameters", {})
    mech.finish(["name", "ground", "gravity_m_per_s2", "parameters", "builder"])
    links, link_tables = [], {}
    for t in top.array("links"):
        link = _read_link(t, ground)
        links.append(link)
        link_tables[link.name] = link
    joints = [_joint(t, link_tables) for t in top.array("joints")]
    drives = [_drive(t, {j.name for j in joints}) for t in top.array("drives")]
    outputs = [_output(t, link_tables) for t in top.array("outputs")]
    top.finish(["mechanism", "links", "joints", "drives", "outputs"])
    return _wrap(
        mech,
        None,
        lambda: Mechanism(
            name,
            tuple(links),
            tuple(joints),
            tuple(drives),
            tuple(outputs),
            ground=ground,
            gravity=gravity,
            parameters=params,
        ),
    )


def _wrap(t: Table, key: str | None, make: Callable[[], _T]) -> _T:
    """``make()``, its ValueError or KeyError reported as a `ScenarioError` of ``t`` (and ``key``)."""
    try:
        return make()
    except ScenarioError:
        raise
    except (ValueError, KeyError) as e:
        raise t.error(key, str(e).strip("\"'")) from None


def _link_ref(t: Table, key: str, links: dict[str, Link]) -> str:
    name = t.text(key)
    if name not in links:
        raise t.error(key, f"unknown link '{name}' (links: {sorted(links)})")
    return name


def _point_ref(t: Table, key: str, link: Link) -> str:
    point = t.text(key)
    if point not in link.points:
        raise t.error(key, f"link '{link.name}' has no point '{point}' (points: {sorted(link.points)})")
    return point


def _joint(t: Table, links: dict[str, Link]) -> Joint:
    name = t.text("name")
    kind = JointType(t.text("kind", choices=[k.value for k in JointType]))
    la = _link_ref(t, "link_a", links)
    pa = _point_ref(t, "point_a", links[la])
    lb = _link_ref(t, "link_b", links)
    pb = _point_ref(t, "point_b", links[lb])
    axis = t.convert_pair("axis", t.raw("axis"), 1.0) if t.has("axis") else (1.0, 0.0)
    c = t.sub("clearance", "clearance")
    clearance = None
    if c is not None:
        journal = c.text("journal_link", default="") or None
        if journal is not None and journal not in (la, lb):
            raise c.error("journal_link", f"must be '{la}' or '{lb}' (got '{journal}')")
        length = c.number("bearing_length", "length", 0.0) or None
        oil = c.sub("lubrication", "lubrication")
        lubrication = None if oil is None else read_lubrication(oil)
        clearance = _wrap(
            c,
            None,
            lambda: Clearance(
                c.number("radial_clearance", "length"),
                c.number("bearing_radius", "length", 0.010),
                journal,
                _material(c.sub("bearing_material", "bearing_material")),
                _material(c.sub("journal_material", "journal_material")),
                c.plain("restitution", 0.9),
                c.plain("friction", 0.0),
                ContactLaw(c.text("law", default=ContactLaw.LANKARANI_NIKRAVESH.value, choices=_LAWS)),
                bearing_length=length,
                lubrication=lubrication,
            ),
        )
        c.finish(
            [
                "radial_clearance_<m|mm|um>",
                "bearing_radius_<m|mm>",
                "journal_link",
                "restitution",
                "friction",
                "law",
                "bearing_material",
                "journal_material",
                "bearing_length_<m|mm|um>",
                "lubrication",
            ]
        )
    tt = t.sub("translational_clearance", "translational_clearance")
    play = None if tt is None else read_translational(tt)
    t.finish(["name", "kind", "link_a", "point_a", "link_b", "point_b", "axis", "clearance", "translational_clearance"])
    return _wrap(
        t,
        None,
        lambda: Joint(name, kind, la, pa, lb, pb, axis=axis, clearance=clearance, translational_clearance=play),
    )


def _drive(t: Table, joints: set[str]) -> Drive:
    name = t.text("name")
    joint = t.text("joint")
    if joint not in joints:
        raise t.error("joint", f"unknown joint '{joint}' (joints: {sorted(joints)})")
    kind = DriveKind(t.text("kind", default="constant_speed", choices=[k.value for k in DriveKind]))
    m = t.sub("motion", "motion")
    motion = None if m is None else _motion(m)
    drive = _wrap(
        t,
        None,
        lambda: Drive(
            name,
            joint,
            kind,
            speed=t.number("speed", "angular_speed", 0.0),
            start_angle=t.number("start_angle", "angle", 0.0),
            motion=motion,
            torque=t.number("torque", "torque", 0.0),
            initial_speed=t.number("initial_speed", "angular_speed", 0.0),
        ),
    )
    t.finish(
        [
            "name",
            "joint",
            "kind",
            "speed_<rad_per_s|rpm|deg_per_s>",
            "start_angle_<rad|deg>",
            "torque_n_m",
            "initial_speed_<rad_per_s|rpm|deg_per_s>",
            "motion",
        ]
    )
    return drive


def _output(t: Table, links: dict[str, Link]) -> Output:
    name = t.text("name")
    kind = OutputKind(t.text("kind", choices=[k.value for k in OutputKind]))
    link = _link_ref(t, "link", links)
    point = _point_ref(t, "point", links[link]) if t.has("point") else None
    t.finish(["name", "link", "kind", "point"])
    return _wrap(t, None, lambda: Output(name, link, kind, point))


def _material_doc(m: Material) -> dict[str, Any]:
    return {"youngs_modulus_pa": m.youngs_modulus, "poisson_ratio": m.poisson_ratio}


def scenario_document(mechanism: Mechanism) -> dict[str, Any]:
    """The full-form scenario of a mechanism as a TOML-ready dict (SI units)."""
    mech: dict[str, Any] = {
        "name": mechanism.name,
        "ground": mechanism.ground,
        "gravity_m_per_s2": list(mechanism.gravity),
    }
    if mechanism.parameters:
        mech["parameters"] = dict(mechanism.parameters)
    links = [
        {
            "name": lk.name,
            "mass_kg": lk.mass,
            "inertia_kg_m2": lk.inertia,
            "com_m": list(lk.com),
            "position_guess_m": list(lk.pose_guess[:2]),
            "angle_guess_rad": lk.pose_guess[2],
            "points_m": {k: list(v) for k, v in lk.points.items()},
        }
        for lk in mechanism.links
    ]
    joints = []
    for j in mechanism.joints:
        d: dict[str, Any] = {
            "name": j.name,
            "kind": j.kind.value,
            "link_a": j.link_a,
            "point_a": j.point_a,
            "link_b": j.link_b,
            "point_b": j.point_b,
        }
        if j.kind is JointType.PRISMATIC:
            d["axis"] = list(j.axis)
        if j.translational_clearance is not None:
            d["translational_clearance"] = translational_document(j.translational_clearance)
        c = j.clearance
        if c is not None:
            d["clearance"] = {
                "radial_clearance_m": c.radial_clearance,
                "bearing_radius_m": c.bearing_radius,
                "journal_link": c.journal_link,
                "restitution": c.restitution,
                "friction": c.friction,
                "law": c.law.value,
                "bearing_material": _material_doc(c.bearing_material),
                "journal_material": _material_doc(c.journal_material),
            }
            if c.bearing_length is not None:
                d["clearance"]["bearing_length_m"] = c.bearing_length
            if c.lubrication is not None:
                d["clearance"]["lubrication"] = lubrication_document(c.lubrication)
        joints.append(d)
    drives = []
    for dr in mechanism.drives:
        d = {
            "name": dr.name,
            "joint": dr.joint,
            "kind": dr.kind.value,
            "speed_rad_per_s": dr.speed,
            "start_angle_rad": dr.start_angle,
            "torque_n_m": dr.torque,
        }
        if dr.initial_speed:
            d["initial_speed_rad_per_s"] = dr.initial_speed
        if dr.motion is not None:
            d["motion"] = {"speed_rad_per_s": dr.motion.speed, "harmonics_rad": [list(h) for h in dr.motion.harmonics]}
            if dr.motion.period is not None:
                d["motion"]["period_s"] = dr.motion.period
        drives.append(d)
    outputs = [
        {"name": o.name, "link": o.link, "kind": o.kind.value, **({"point": o.point} if o.point else {})}
        for o in mechanism.outputs
    ]
    return {"mechanism": mech, "links": links, "joints": joints, "drives": drives, "outputs": outputs}


def dumps_scenario(mechanism: Mechanism) -> str:
    """The full-form scenario text of a mechanism.

    Raises:
        ValueError: the mechanism's parameters hold a value TOML cannot store (e.g. None).
    """
    try:
        return _HEADER + _compact(tomli_w.dumps(scenario_document(mechanism)))
    except TypeError as e:
        raise ValueError(
            f"mechanism '{mechanism.name}' cannot be written as TOML: {e} "
            "(parameters must be strings, numbers, booleans, lists or tables)"
        ) from None


_ITEM = r'(?:-?(?:\d[\d_]*(?:\.\d*)?(?:[eE][+-]?\d+)?|inf|nan)|"[A-Za-z0-9_.\-]*"|true|false|\[[^\[\]\n]*\])'
_ARRAY = re.compile(rf"\[\n((?:[ ]+{_ITEM},\n)+)[ ]*\]")


def _compact(text: str) -> str:
    """Put arrays of plain values on one line (tomli_w writes one item per line)."""
    while True:
        new = _ARRAY.sub(lambda m: "[" + ", ".join(x.strip().rstrip(",") for x in m.group(1).splitlines()) + "]", text)
        if new == text:
            return text
        text = new


def dump_scenario(mechanism: Mechanism, path: str | os.PathLike[str]) -> None:
    """Write a mechanism as a full-form scenario file, atomically (temp file, then rename).

    Raises:
        ValueError: see `dumps_scenario`.
        OSError: the file cannot be written.
    """
    text = dumps_scenario(mechanism)
    p = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=p.parent if str(p.parent) else ".")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, p)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
