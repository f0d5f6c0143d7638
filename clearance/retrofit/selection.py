"""Which hinges a retrofit edits, checked before any work.

A hinge can be given radial play when it exists, is a hinge (not a ball, slide or free
joint), is the only joint of its body (`shared_body`: a hinge beside others is part of a
compound joint, or turns a planar floating base), and the model lets contacts act (the bearing is a
ring of contact pairs); a loop closure (a `connect` equality between two bodies) when one of
its bodies has a hinge to take the axis from (`clearance.retrofit.loop`). A model that does
not compile, or that already holds names with the retrofit's prefix, is refused too. Every
refusal is one `RetrofitError` naming the joint and what was expected.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco

from clearance.retrofit.loop import check_connect
from clearance.retrofit.play import DEFAULT_CLASS, PREFIX, Refusal, RetrofitError

__all__ = ["Hinge", "compile_model", "hinge_names", "joint_kind", "select_hinges", "shared_body"]

_OBJ = mujoco.mjtObj
_JOINT_KIND = {
    mujoco.mjtJoint.mjJNT_FREE: "a free joint",
    mujoco.mjtJoint.mjJNT_BALL: "a ball joint",
    mujoco.mjtJoint.mjJNT_SLIDE: "a slide joint",
    mujoco.mjtJoint.mjJNT_HINGE: "a hinge",
}
_NAMED = (
    _OBJ.mjOBJ_BODY,
    _OBJ.mjOBJ_JOINT,
    _OBJ.mjOBJ_GEOM,
    _OBJ.mjOBJ_SITE,
    _OBJ.mjOBJ_SENSOR,
    _OBJ.mjOBJ_PAIR,
    _OBJ.mjOBJ_ACTUATOR,
    _OBJ.mjOBJ_EQUALITY,
    _OBJ.mjOBJ_TENDON,
    _OBJ.mjOBJ_KEY,
)


@dataclass(frozen=True)
class Hinge:
    """A hinge chosen for radial play, located in the compiled unmodified model.

    A loop closure (a `connect` equality) is one too: its journal is a pin that follows
    body1's anchor (`clearance.retrofit.loop`), its bearing on body2.

    Attributes:
        name: the joint's (or the connect's) name.
        joint_id: its id in the unmodified model (-1 for a connect).
        child_id: the body it moves (the journal's body; a connect's body1).
        parent_id: that body's parent in the compiled model (the bearing's body; 0 for the
            world; a connect's body2).
        equality_id: the connect's id (-1 for a hinge).
        axis_joint: the hinge whose axis a connect's play is normal to (-1 for a hinge).
    """

    name: str
    joint_id: int
    child_id: int
    parent_id: int
    equality_id: int = -1
    axis_joint: int = -1

    @property
    def is_connect(self) -> bool:
        """Whether this is a loop closure rather than a hinge."""
        return self.equality_id >= 0


def joint_kind(model: mujoco.MjModel, joint: int) -> str:
    """How a message names a joint's type: 'a hinge', 'a slide joint', 'a ball joint' or 'a free joint'."""
    return _JOINT_KIND[mujoco.mjtJoint(int(model.jnt_type[joint]))]


def shared_body(model: mujoco.MjModel, joint: int) -> Refusal | None:
    """Why a hinge that shares its body with other joints cannot take play, or None where it is alone.

    `Refusal.FLOATING_BASE` where the body hangs from the world and two or more of its other joints
    are slides: the hinge turns a planar floating base (gymnasium's runners' ``rooty`` beside
    ``rootx`` and ``rootz``, the swimmer's ``free_body_rot``), one of the base's freedoms relative to
    the world, with no bearing to give radial play and no gear to give backlash, as a free joint has
    none. `Refusal.SHARED_BODY` otherwise: a compound joint (the humanoid's hips, hinges through one
    point; a swivel on a carriage's rail), whose axes have no body between them to carry a bearing.
    """
    body = int(model.jnt_bodyid[joint])
    if model.body_jntnum[body] == 1:
        return None
    first = int(model.body_jntadr[body])
    kinds = [int(model.jnt_type[k]) for k in range(first, first + int(model.body_jntnum[body])) if k != joint]
    if model.body_parentid[body] == 0 and kinds.count(int(mujoco.mjtJoint.mjJNT_SLIDE)) >= 2:
        return Refusal.FLOATING_BASE
    return Refusal.SHARED_BODY


def model_label(spec: mujoco.MjSpec) -> str:
    """How messages name a model: its name, or 'the model'."""
    return f"model '{spec.modelname}'" if spec.modelname else "the model"


def compile_model(spec: mujoco.MjSpec) -> mujoco.MjModel:
    """Compile ``spec``; a MuJoCo error becomes a `RetrofitError` carrying MuJoCo's message."""
    try:
        return spec.compile()
    except ValueError as err:
        raise RetrofitError(f"{model_label(spec)} does not compile in MuJoCo: {err}") from None


def hinge_names(model: mujoco.MjModel) -> list[str]:
    """Names of the model's named hinges that can take radial play (each the only joint of its body), in
    joint order: what a refusal lists as the hinges there are."""
    out = []
    for j in range(model.njnt):
        name = mujoco.mj_id2name(model, _OBJ.mjOBJ_JOINT, j)
        alone = model.body_jntnum[model.jnt_bodyid[j]] == 1
        if name and alone and model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            out.append(name)
    return out


def _prefixed_names(model: mujoco.MjModel) -> list[str]:
    found = []
    for objtype in _NAMED:
        count = {
            _OBJ.mjOBJ_BODY: model.nbody,
            _OBJ.mjOBJ_JOINT: model.njnt,
            _OBJ.mjOBJ_GEOM: model.ngeom,
            _OBJ.mjOBJ_SITE: model.nsite,
            _OBJ.mjOBJ_SENSOR: model.nsensor,
            _OBJ.mjOBJ_PAIR: model.npair,
            _OBJ.mjOBJ_ACTUATOR: model.nu,
            _OBJ.mjOBJ_EQUALITY: model.neq,
            _OBJ.mjOBJ_TENDON: model.ntendon,
            _OBJ.mjOBJ_KEY: model.nkey,
        }[objtype]
        for i in range(count):
            name = mujoco.mj_id2name(model, objtype, i)
            if name and name.startswith(PREFIX):
                found.append(name)
    return found


def check_not_retrofitted(spec: mujoco.MjSpec, model: mujoco.MjModel) -> None:
    """Refuse a model that already carries a retrofit (radial play or backlash).

    Args:
        spec: the model's spec (for its name and default classes).
        model: ``spec`` compiled.

    Raises:
        RetrofitError: names with the retrofit's prefix (or its default class) are in the
            model; the message names some of them and asks for the unmodified model.
    """
    clash = _prefixed_names(model) + ([DEFAULT_CLASS] if spec.find_default(DEFAULT_CLASS) is not None else [])
    if clash:
        some = ", ".join(sorted(set(clash))[:5])
        raise RetrofitError(
            f"{model_label(spec)} already has names starting with '{PREFIX}' ({some}), the "
            "prefix of what a retrofit adds: is it retrofitted already? Retrofit the unmodified model (one "
            "command gives one kind of play: radial play and backlash cannot be stacked)"
        )


def select_hinges(spec: mujoco.MjSpec, model: mujoco.MjModel, names: Sequence[str]) -> list[Hinge]:
    """Check the request and locate each hinge.

    Args:
        spec: the unmodified spec (for messages: its model name and default classes).
        model: ``spec`` compiled.
        names: the hinges to give play, in the user's order.

    Returns:
        One `Hinge` per name, in the order given.

    Raises:
        RetrofitError: no name, a name given twice, a joint that does not exist (the
            message lists the hinges there are), a connect between sites or between two
            bodies without a hinge (no axis), a joint that is not a hinge, a hinge sharing its body with
            other joints, contacts or constraints disabled, or names with the retrofit's
            prefix already in the model.
    """
    label = model_label(spec)
    if not names:
        raise RetrofitError("name at least one hinge to give radial play")
    seen: set[str] = set()
    for n in names:
        if n in seen:
            raise RetrofitError(f"joint '{n}' is named twice")
        seen.add(n)
    flags = int(model.opt.disableflags)
    for bit, what in (
        (mujoco.mjtDisableBit.mjDSBL_CONSTRAINT, "constraint"),
        (mujoco.mjtDisableBit.mjDSBL_CONTACT, "contact"),
    ):
        if flags & int(bit):
            raise RetrofitError(
                f'{label} disables {what}s (<option><flag {what}="disable"/>): the bearing ring is a set of '
                "contact pairs and needs them; enable them to retrofit"
            )
    check_not_retrofitted(spec, model)
    hinges = hinge_names(model)
    out = []
    for n in names:
        jid = mujoco.mj_name2id(model, _OBJ.mjOBJ_JOINT, n)
        if jid < 0:
            eq = mujoco.mj_name2id(model, _OBJ.mjOBJ_EQUALITY, n)
            if eq >= 0 and model.eq_type[eq] == mujoco.mjtEq.mjEQ_CONNECT:
                b1, b2, axis = check_connect(model, eq, n, label)
                out.append(Hinge(n, -1, b1, b2, eq, axis))
                continue
            listed = ", ".join(hinges) if hinges else "none"
            raise RetrofitError(
                f"joint '{n}' does not exist in {label}; its hinges that can take radial play are: {listed} (a "
                "connect equality can be named too)"
            )
        kind = mujoco.mjtJoint(int(model.jnt_type[jid]))
        if kind != mujoco.mjtJoint.mjJNT_HINGE:
            raise RetrofitError(
                f"joint '{n}' is {_JOINT_KIND[kind]}: only a hinge can be given radial play "
                f"(hinges of {label} that can: {', '.join(hinges) or 'none'})",
                reason=Refusal.NOT_A_HINGE,
                hinge=n,
            )
        body = int(model.jnt_bodyid[jid])
        shared = shared_body(model, jid)
        if shared is not None:
            first = int(model.body_jntadr[body])
            others = [
                mujoco.mj_id2name(model, _OBJ.mjOBJ_JOINT, k) or f"#{k}"
                for k in range(first, first + int(model.body_jntnum[body]))
                if k != jid
            ]
            bname = mujoco.mj_id2name(model, _OBJ.mjOBJ_BODY, body) or f"#{body}"
            what = "and turns a floating base" if shared is Refusal.FLOATING_BASE else "(a compound joint)"
            raise RetrofitError(
                f"hinge '{n}' shares body '{bname}' with other joints ({', '.join(others)}) {what}: radial "
                f"play needs a body whose only joint is the hinge (hinges of {label} that can: "
                f"{', '.join(hinges) or 'none'})",
                reason=shared,
                hinge=n,
            )
        out.append(Hinge(n, jid, body, int(model.body_parentid[body])))
    return out
