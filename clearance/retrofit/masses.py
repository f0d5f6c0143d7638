"""Mass properties across a retrofit: every link keeps its own, and a pin's mass is cut from its link.

Three rules, each checked on the compiled result (`check_masses`):

- A model whose compiler rescales masses (``<compiler settotalmass=...>`` over the bodies an
  edit adds, or ``inertiafromgeom="true"``, which overrides the explicit inertial of a pin's
  donor) would not weigh its links as before: `freeze_inertials` then writes every body's
  compiled mass, centre of mass and principal inertia as its explicit inertial and turns the
  rescaling off. (Written to a file, those inertials keep MuJoCo's 6 significant digits.)
- Elements a retrofit adds carry no mass (a backlash motor body has `MOTOR_MASS`, MuJoCo's floor
  for a moving body, far below any link; in a model with a fluid, the mass that keeps the fluid
  model's box for it 0.1 mm across: `clearance.retrofit.backlash.motor_body_mass`).
- A loop closure's pin (`clearance.retrofit.loop`) is a real share of its donor's mass: a point
  mass cut from the donor at the connect's anchor (`split_point_mass`), so donor + pin is the
  original body (mass, centre of mass and inertia; the pin's own isotropic inertia `PIN_INERTIA`
  is cut too, so it holds in any orientation).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.retrofit.play import RetrofitError

__all__ = [
    "FROZEN_NOTE",
    "MASS_RTOL",
    "PIN_INERTIA",
    "PIN_MASS_SHARE",
    "Inertial",
    "PointMassSplit",
    "body_label",
    "check_masses",
    "freeze_inertials",
    "rescales_masses",
    "split_point_mass",
]

PIN_MASS_SHARE = 0.1
"""Share of its donor's mass a pin takes [-] (halved until the donor's remainder is a physical
inertia): enough that the connect's row does not see a near-massless body, small enough that the
donor keeps most of its own inertia."""

PIN_INERTIA = 1e-12
"""Isotropic rotational inertia of a pin [kg m^2] (MuJoCo requires one; the pin does not turn on
its slides), cut from the donor with its mass."""

FROZEN_NOTE = (
    "the model's compiler rescales masses (settotalmass, or inertiafromgeom=\"true\" where a pin's donor needs its "
    "explicit inertial): every body's compiled mass, centre of mass and inertia are written as its explicit inertial "
    "and the rescaling is off, so the edit does not rescale the links (written to a file, 6 significant digits)"
)
"""The report's line on `freeze_inertials`."""

MIN_SHARE = 1e-4
"""Smallest share tried before `split_point_mass` gives up [-]."""

MASS_RTOL = 1e-9
"""Relative tolerance of the mass checks where a value is recomputed rather than copied: an
eigen-decomposition and MuJoCo's normalisation of a quaternion round at 1e-16 relative; 1e-9
leaves seven orders for the sums of a model's largest and smallest inertias."""

_FLOOR = 1e-12
"""Relative margin a remainder's principal inertias must keep (positive, triangle inequality)."""


def body_label(model: mujoco.MjModel, body: int) -> str:
    """A body's name, or ``#id`` if unnamed."""
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or f"#{body}"


def rescales_masses(spec: mujoco.MjSpec, *, adds_bodies: bool, cuts_pins: bool) -> bool:
    """Whether ``spec``'s compiler would rescale or recompute the masses of an edit that adds bodies
    (``adds_bodies``) or writes a donor's explicit inertial (``cuts_pins``).

    ``settotalmass`` rescales every body by the total, which an added body changes;
    ``inertiafromgeom="true"`` ignores explicit inertials (a body without geoms then weighs
    nothing: harmless for a backlash motor, whose inertia is its armature, not for a donor).
    """
    c = spec.compiler
    fromgeom = c.inertiafromgeom == mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    return bool(c.settotalmass > 0 and (adds_bodies or cuts_pins)) or (fromgeom and cuts_pins)


def _set_inertial(body: mujoco.MjsBody, mass: float, ipos: np.ndarray, iquat: np.ndarray, inertia: np.ndarray) -> None:
    body.explicitinertial = True
    body.mass = float(mass)
    body.ipos = [float(v) for v in ipos]
    body.iquat = [float(v) for v in iquat]
    body.inertia = [float(v) for v in inertia]
    body.fullinertia = [float("nan"), 0.0, 0.0, 0.0, 0.0, 0.0]  # unset: the principal inertia and iquat hold


def freeze_inertials(spec: mujoco.MjSpec, twin: mujoco.MjModel, *, adds_bodies: bool, cuts_pins: bool) -> bool:
    """Write each body's compiled mass properties as its explicit inertial and stop the compiler's rescaling.

    Does nothing unless `rescales_masses` (the usual model keeps its inertials as written).

    Args:
        spec: the spec being edited, compiled once so that its bodies carry the twin's ids.
        twin: the unmodified model compiled.
        adds_bodies: the edit adds bodies. cuts_pins: it cuts pins from donors (`split_point_mass`).

    Returns:
        Whether the inertials were frozen (the report says so).
    """
    if not rescales_masses(spec, adds_bodies=adds_bodies, cuts_pins=cuts_pins):
        return False
    for body in spec.bodies:
        b = int(body.id)
        if b <= 0 or (twin.body_mass[b] == 0 and not twin.body_inertia[b].any()):
            continue  # the world, or a body with nothing to rescale
        _set_inertial(body, twin.body_mass[b], twin.body_ipos[b], twin.body_iquat[b], twin.body_inertia[b])
    spec.compiler.settotalmass = -1.0
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_AUTO
    return True


def _parallel(mass: float, r: np.ndarray) -> np.ndarray:
    """Inertia tensor of a point mass at ``r`` about the origin [kg m^2]."""
    return mass * (float(r @ r) * np.eye(3) - np.outer(r, r))


def _tensor(model: mujoco.MjModel, b: int) -> np.ndarray:
    """Body ``b``'s inertia tensor about its centre of mass, in the body frame [kg m^2]."""
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.body_iquat[b])
    r = rot.reshape(3, 3)
    return r @ np.diag(model.body_inertia[b]) @ r.T


def _principal(tensor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(principal inertias (3,), the quaternion of their axes (4,)) of a symmetric tensor."""
    eig, vec = np.linalg.eigh(0.5 * (tensor + tensor.T))
    if np.linalg.det(vec) < 0:
        vec[:, 0] = -vec[:, 0]
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(vec).reshape(9))
    return eig, quat


def _physical(tensor: np.ndarray) -> bool:
    """Principal inertias positive and within the triangle inequality, with a relative margin."""
    a, b, c = np.sort(np.linalg.eigvalsh(0.5 * (tensor + tensor.T)))
    return bool(a > _FLOOR * c and a + b >= c * (1 + _FLOOR))


@dataclass(frozen=True)
class Inertial:
    """A body's mass properties in its own frame.

    Attributes:
        mass: [kg]. ipos: (3,) centre of mass [m]. tensor: (3, 3) inertia about it [kg m^2].
    """

    mass: float
    ipos: np.ndarray
    tensor: np.ndarray

    @classmethod
    def of_body(cls, model: mujoco.MjModel, b: int) -> Inertial:
        """Body ``b`` of a compiled model."""
        return cls(float(model.body_mass[b]), np.array(model.body_ipos[b], dtype=float), _tensor(model, b))

    def apply(self, body: mujoco.MjsBody) -> None:
        """Write as ``body``'s explicit inertial (principal inertias and their axes)."""
        eig, quat = _principal(self.tensor)
        _set_inertial(body, self.mass, self.ipos, quat, eig)


@dataclass(frozen=True)
class PointMassSplit:
    """A point mass cut from a donor body.

    Attributes:
        donor: the donor's body id (unmodified model). pin_mass: the point mass [kg].
        share: its share of the donor's mass before the cut [-]. remainder: the donor after it.
    """

    donor: int
    pin_mass: float
    share: float
    remainder: Inertial


def split_point_mass(
    donor: int, inertial: Inertial, point: np.ndarray, *, label: str, share: float = PIN_MASS_SHARE
) -> PointMassSplit:
    """Cut a point mass (with the isotropic `PIN_INERTIA`) from ``inertial`` at ``point`` [m] (body frame).

    The share starts at ``share`` and is halved until the remainder's principal inertias are
    positive and satisfy the triangle inequality.

    Args:
        donor: the donor's body id. inertial: its mass properties now (after earlier cuts).
        point: where the point mass sits. label: the body's name for a message. share: the first share tried.

    Raises:
        RetrofitError: no share down to `MIN_SHARE` leaves a physical remainder (the body's mass
            sits at the point), naming the body.
    """
    m, c, tensor = inertial.mass, inertial.ipos, inertial.tensor
    a = np.asarray(point, dtype=float)
    s = share
    while s >= MIN_SHARE:
        p = s * m
        c2 = (m * c - p * a) / (m - p)
        rest = tensor + _parallel(m, c - c2) - _parallel(p, a - c2) - PIN_INERTIA * np.eye(3)
        if _physical(rest):
            return PointMassSplit(donor, p, s, Inertial(m - p, c2, rest))
        s /= 2
    raise RetrofitError(
        f"body '{label}' cannot give a loop closure's pin a share of its mass: its inertia is concentrated at the "
        f"connect's anchor {a.tolist()}"
    )


def _world_inertia(
    model: mujoco.MjModel, data: mujoco.MjData, bodies: Sequence[int]
) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia tensor about it) of ``bodies`` together, world frame, at ``data``'s pose."""
    mass = float(sum(model.body_mass[b] for b in bodies))
    com = sum(model.body_mass[b] * data.xipos[b] for b in bodies) / mass
    out = np.zeros((3, 3))
    for b in bodies:
        r = data.ximat[b].reshape(3, 3)
        out += r @ np.diag(model.body_inertia[b]) @ r.T + _parallel(float(model.body_mass[b]), data.xipos[b] - com)
    return mass, np.asarray(com), out


def check_masses(
    twin: mujoco.MjModel,
    model: mujoco.MjModel,
    kept: Sequence[int],
    pins: Sequence[tuple[int, int]] = (),
    light: Sequence[int] = (),
    light_mass: float = 0.0,
) -> None:
    """Check that every link kept its mass properties across an edit.

    Args:
        twin: the unmodified model.
        model: the edited model.
        kept: for each body of ``twin`` (in order), its id in ``model``.
        pins: (donor's id in ``twin``, the pin's id in ``model``): a donor and its pins together
            must be the twin's donor (mass, centre of mass, inertia at qpos0, within `MASS_RTOL`).
        light: bodies the edit added that must weigh ``light_mass`` (backlash motor bodies).
        light_mass: their mass and largest principal inertia [kg, kg m^2].

    Raises:
        RuntimeError: a mass property moved (a defect of the edit, not of the model), naming the body.
    """
    donors = {d for d, _ in pins}
    for b, bm in enumerate(kept):
        if b in donors or b == 0:
            continue
        for field in ("body_mass", "body_inertia", "body_ipos"):
            if not np.allclose(getattr(model, field)[bm], getattr(twin, field)[b], rtol=MASS_RTOL, atol=0.0):
                raise RuntimeError(f"the edit changed the {field[5:]} of body '{body_label(twin, b)}'")
        if not np.allclose(_tensor(model, bm), _tensor(twin, b), rtol=0.0, atol=MASS_RTOL * max(twin.body_inertia[b])):
            raise RuntimeError(f"the edit changed the inertia axes of body '{body_label(twin, b)}'")
    for b in light:
        if model.body_mass[b] > light_mass or max(model.body_inertia[b]) > light_mass:
            raise RuntimeError(f"added body '{body_label(model, b)}' weighs more than {light_mass:g} kg")
    if not pins:
        return
    dt, dm = mujoco.MjData(twin), mujoco.MjData(model)
    mujoco.mj_kinematics(twin, dt)
    mujoco.mj_kinematics(model, dm)
    for donor in sorted(donors):
        mine = [pin for d, pin in pins if d == donor]
        m0, c0, i0 = _world_inertia(twin, dt, [donor])
        m1, c1, i1 = _world_inertia(model, dm, [kept[donor], *mine])
        scale = max(float(np.abs(i0).max()), m0 * float(np.max(np.abs(c0)) ** 2) if np.any(c0) else 0.0)
        if not (
            abs(m1 - m0) <= MASS_RTOL * m0
            and np.allclose(c1, c0, rtol=0.0, atol=MASS_RTOL * max(1.0, float(np.abs(c0).max())))
            and np.allclose(i1, i0, rtol=0.0, atol=MASS_RTOL * scale)
        ):
            names = ", ".join(f"'{body_label(model, pin)}'" for pin in mine)
            raise RuntimeError(
                f"body '{body_label(twin, donor)}' and its pins {names} together are not the original body"
            )
