"""Play randomised per world: copies of one compiled model whose play differs, for training.

A policy trained over many worlds with randomised dynamics needs its play randomised too. The
robot-step play a retrofit writes is stock MJCF held in tendon limits:

- a backlash band: the fixed tendon ``clr_<hinge>__backlash`` = q_load - q_motor, limited to
  [-b, b] (`clearance.retrofit.backlash`);
- a radial stop: the spatial tendon ``clr_<hinge>__radial`` from the bearing's centre to the
  journal's, whose length is |e|, limited above at the radial clearance c
  (`clearance.retrofit.radial_stop`).

MuJoCo reads a tendon's range (``tendon_range``) and its limit's solref (``tendon_solref_lim``)
afresh at every step, so a copy of the compiled model (`copy.copy`: MuJoCo's ``mj_copyModel``)
holding its own values is another world with the same structure: the copies step together in
one `mujoco.rollout` call (`clearance.run.world_batch`), and nothing is recompiled.

The stop's stiffness K and damping B are physical [N m/rad and N m s/rad at a band; N/m and
N s/m at a radial stop]. They are written in direct mode, solref = (-K Â, -B Â) with Â the
tendon's inverse weight at qpos0 (``tendon_invweight0``): at the reference pose the limit row's
force is then -K r - B ṙ - (d/Â) a₀ (r the distance past the limit, a₀ the unconstrained
acceleration along the tendon, d the limit's impedance, solimp's dmax where it varies; see
`clearance.retrofit.softness`). A model's own stop in MuJoCo's time-constant form is read the
same way (`stop_spring`), so the worlds a randomisation leaves alone keep their stop exactly.

Every range is checked before anything is drawn: a band within (0, `MAX_BACKLASH`], a clearance
> 0, and the stiffest, most damped stop of the ranges stable at the model's step at the tendon's
lightest pose (h²ω² + 2hγ < `STABLE_BOUND`: MuJoCo's semi-implicit Euler on the limit's spring
and damper, the bound `clearance.contact_calibration.torsional_stop` checks a fitted stop with).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import dataclass

import mujoco
import numpy as np

from clearance.checks import finite, of_type
from clearance.retrofit.play import MAX_BACKLASH, RetrofitError
from clearance.retrofit.play_tendons import PlayKind, PlayTendon, lightest_invweights, play_tendons
from clearance.retrofit.softness import refsafe, stiffness_damping

__all__ = [
    "STABLE_BOUND",
    "PlayDistribution",
    "PlayKind",
    "PlayTendon",
    "PlayWorlds",
    "Uniform",
    "play_tendons",
    "randomise_play",
    "stop_bound",
    "stop_spring",
]

STABLE_BOUND = 4.0
"""Largest h²ω² + 2hγ [-] of a stop at the model's step (semi-implicit Euler's stability limit
on a spring-damper; ω² = K A_eff, γ = B A_eff at the lightest pose)."""


@dataclass(frozen=True)
class Uniform:
    """Values drawn uniformly in [low, high] (in log space where ``log``).

    Attributes:
        low, high: the bounds [the parameter's unit], finite, 0 < low <= high.
        log: draw log-uniformly (for a stiffness spread over decades).

    Raises:
        ValueError: a bound not finite or not > 0, or low > high.
    """

    low: float
    high: float
    log: bool = False

    def __post_init__(self) -> None:
        lo, hi = finite("Uniform.low", self.low), finite("Uniform.high", self.high)
        if not 0 < lo <= hi:
            raise ValueError(f"Uniform bounds must satisfy 0 < low <= high (got low={self.low!r}, high={self.high!r})")
        object.__setattr__(self, "low", lo)
        object.__setattr__(self, "high", hi)

    def draw(self, rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
        """``shape`` values from ``rng``."""
        if self.log:
            return np.exp(rng.uniform(math.log(self.low), math.log(self.high), shape))
        return rng.uniform(self.low, self.high, shape)


@dataclass(frozen=True)
class PlayDistribution:
    """What to randomise at a play tendon; None keeps the model's own value in every world.

    Attributes:
        size: the band's half-width b [rad] (backlash) or the radial clearance c [m] (radial).
        stiffness: the stop's spring K [N m/rad or N/m].
        damping: the stop's damper B [N m s/rad or N s/m].
    """

    size: Uniform | None = None
    stiffness: Uniform | None = None
    damping: Uniform | None = None

    def __post_init__(self) -> None:
        for name in ("size", "stiffness", "damping"):
            value = getattr(self, name)
            if value is not None:
                of_type(f"PlayDistribution.{name}", value, Uniform, "a Uniform(low, high) or None")


@dataclass
class PlayWorlds:
    """Copies of one model whose play differs, and what each holds.

    Attributes:
        models: one compiled model per world (same structure: they step in one rollout).
        tendons: the play tendons, the columns of the arrays below.
        size: (n_worlds, n_tendons) b [rad] or c [m] of each world's stop.
        stiffness: (n_worlds, n_tendons) K of each stop [N m/rad or N/m].
        damping: (n_worlds, n_tendons) B of each stop [N m s/rad or N s/m].
        seed: the random seed drawn with.
    """

    models: list[mujoco.MjModel]
    tendons: tuple[PlayTendon, ...]
    size: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    seed: int

    def world(self, k: int) -> dict[str, tuple[float, float, float]]:
        """``'<kind> <hinge>'`` -> (size, K, B) of world ``k``."""
        return {
            f"{t.kind.value} {t.hinge}": (
                float(self.size[k, i]),
                float(self.stiffness[k, i]),
                float(self.damping[k, i]),
            )
            for i, t in enumerate(self.tendons)
        }


def _size(model: mujoco.MjModel, t: PlayTendon) -> float:
    """b or c of the tendon's limit [rad or m]."""
    return float(model.tendon_range[t.tendon, 1])


def _set_size(model: mujoco.MjModel, t: PlayTendon, value: float) -> None:
    """Set b (the band [-b, b]) or c (the radial stop's upper limit; its lower one stays)."""
    low = -value if t.kind is PlayKind.BACKLASH else float(model.tendon_range[t.tendon, 0])
    model.tendon_range[t.tendon] = (low, value)


def stop_spring(model: mujoco.MjModel, tendon: int) -> tuple[float, float]:
    """(K, B) of a tendon limit's stop at the reference pose [N m/rad, N m s/rad or N/m, N s/m].

    The mass-normalised spring and damper of its solref (direct or time-constant form, with
    MuJoCo's refsafe where it applies) at solimp's dmax, times the tendon's inverse weight's
    reciprocal (module docstring); `randomise_play` writes them back as (-K Â, -B Â). (nan, nan) where Â is 0:
    a radial stop whose bearing plane is normal to the world's x axis (its size can still be randomised).
    """
    dmax = float(model.tendon_solimp_lim[tendon, 1])
    k, b = stiffness_damping(dmax, model.tendon_solref_lim[tendon], float(model.opt.timestep), refsafe(model))
    a = float(model.tendon_invweight0[tendon])
    if a <= 0.0:  # a radial stop whose bearing plane is normal to x (a zero-length tendon points along x)
        return math.nan, math.nan
    return k * dmax**2 / a, b * dmax / a


def stop_bound(
    *, stiffness: float, damping: float, invweight: float, lightest: float, impedance: float, h: float
) -> float:
    """h²ω² + 2hγ of a tendon-limit stop at its lightest pose (< `STABLE_BOUND`: stable).

    The row's acceleration response is A(aref - a₀)/(A + R) with R = (1 - d)/d Â, so along the
    tendon ω² = c K Â/d and γ = c B Â/d with c = A d/(A d + (1 - d) Â) (c = d at A = Â: ω² = K Â).

    Args:
        stiffness, damping: K, B (physical, module docstring).
        invweight: Â at qpos0. lightest: the largest inverse weight A over the poses [same unit].
        impedance: the limit's dmax [-]. h: the time step [s].
    """
    d = impedance
    c = lightest * d / (lightest * d + (1.0 - d) * invweight)
    omega2, gamma = c * stiffness * invweight / d, c * damping * invweight / d
    return h * h * omega2 + 2.0 * h * gamma


def _distributions(
    tendons: tuple[PlayTendon, ...],
    kind: PlayKind,
    given: PlayDistribution | Mapping[str, PlayDistribution] | None,
    where: str,
) -> dict[int, PlayDistribution]:
    """Column index -> its distribution, for the tendons of ``kind``."""
    if given is None:
        return {}
    mine = {t.hinge: i for i, t in enumerate(tendons) if t.kind is kind}
    name = kind.value
    if not mine:
        how = "add_backlash" if kind is PlayKind.BACKLASH else "retrofit with a robot-step radial stop"
        raise RetrofitError(f"{name}: {where} has no limited {name} tendon (clr_<hinge>__{name}); {how} first")
    if isinstance(given, PlayDistribution):
        return {i: given for i in mine.values()}
    of_type(name, given, Mapping, f"a PlayDistribution or a mapping hinge -> PlayDistribution ({name})")
    out = {}
    for hinge, dist in given.items():
        if hinge not in mine:
            raise RetrofitError(f"{name}: hinge {hinge!r} has no {name} tendon in {where} (it has: {', '.join(mine)})")
        of_type(f"{name}[{hinge!r}]", dist, PlayDistribution, "a PlayDistribution")
        out[mine[hinge]] = dist
    return out


def _check_ranges(
    model: mujoco.MjModel, tendons: tuple[PlayTendon, ...], plan: dict[int, PlayDistribution], lightest: np.ndarray
) -> None:
    """Refuse a size outside its kind's range or a stop unstable at the step (module docstring)."""
    h = float(model.opt.timestep)
    for i, dist in plan.items():
        t = tendons[i]
        size_u, k_u, b_u = t.kind.units
        if dist.size is not None and t.kind is PlayKind.BACKLASH and dist.size.high > MAX_BACKLASH:
            raise RetrofitError(
                f"backlash size for hinge {t.hinge!r}: high {dist.size.high:g} rad is beyond {MAX_BACKLASH:.6g} rad "
                "(10 degrees)"
            )
        if dist.stiffness is None and dist.damping is None:
            continue  # the stop as compiled: its size does not change its stability
        if t.invweight <= 0.0:
            raise RetrofitError(
                f"{t.kind.value} stop of hinge {t.hinge!r}: its tendon has no inverse weight at qpos0 (its bearing "
                "plane is normal to the world's x axis, the direction MuJoCo gives a zero-length tendon), so its "
                "stiffness and damping have no value in N/m and N s/m there; randomise its size only",
                hinge=t.hinge,
            )
        k0, b0 = stop_spring(model, t.tendon)
        k = dist.stiffness.high if dist.stiffness is not None else k0
        b = dist.damping.high if dist.damping is not None else b0
        d = float(model.tendon_solimp_lim[t.tendon, 1])
        bound = stop_bound(stiffness=k, damping=b, invweight=t.invweight, lightest=float(lightest[i]), impedance=d, h=h)
        if not bound < STABLE_BOUND:
            raise RetrofitError(
                f"{t.kind.value} stop of hinge {t.hinge!r}: K = {k:.4g} {k_u} with B = {b:.4g} {b_u} is unstable at "
                f"the step {h:g} s at its lightest pose (h^2 omega^2 + 2 h gamma = {bound:.3g}, must be < "
                f"{STABLE_BOUND:g}); lower the stiffness or damping range's high end",
                hinge=t.hinge,
            )


def randomise_play(
    model: mujoco.MjModel,
    *,
    n_worlds: int,
    backlash: PlayDistribution | Mapping[str, PlayDistribution] | None = None,
    radial: PlayDistribution | Mapping[str, PlayDistribution] | None = None,
    seed: int = 0,
) -> PlayWorlds:
    """``n_worlds`` copies of ``model``, each with its play drawn from the distributions.

    Args:
        model: a compiled model with play tendons (a robot-step retrofit, or `add_backlash`'s
            'calibrated' or 'recipe' stops).
        n_worlds: how many worlds, >= 1.
        backlash: one distribution for every band, or hinge -> its own; None: bands as compiled.
        radial: the same for the radial stops.
        seed: the draws' seed (the same seed draws the same worlds).

    Returns:
        The worlds and each one's play. Draws are independent per world and tendon; world k's
        values are row k of the arrays.

    Raises:
        WrongTypeError: an argument of the wrong type (also a ValueError).
        RetrofitError: before any draw, for a kind the model has no tendon of, a hinge without
            one, a band range beyond `MAX_BACKLASH`, or a stop range unstable at the model's step.
    """
    of_type("model", model, mujoco.MjModel, "a compiled mujoco.MjModel (spec.compile())")
    if isinstance(n_worlds, bool) or not isinstance(n_worlds, int) or n_worlds < 1:
        raise RetrofitError(f"n_worlds must be an integer >= 1 (got {n_worlds!r})")
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise RetrofitError(f"seed must be an integer (got {seed!r})")
    where = "the model"
    tendons = play_tendons(model)
    plan = {
        **_distributions(tendons, PlayKind.BACKLASH, backlash, where),
        **_distributions(tendons, PlayKind.RADIAL, radial, where),
    }
    _check_ranges(model, tendons, plan, lightest_invweights(model, tendons))
    n = len(tendons)
    nominal = np.array([[_size(model, t), *stop_spring(model, t.tendon)] for t in tendons]).reshape(n, 3)
    values = np.repeat(nominal.T[:, None, :], n_worlds, axis=1)  # (3, n_worlds, n)
    rng = np.random.default_rng(seed)
    for i in sorted(plan):
        for p, u in enumerate((plan[i].size, plan[i].stiffness, plan[i].damping)):
            if u is not None:
                values[p, :, i] = u.draw(rng, (n_worlds,))
    models = []
    for w in range(n_worlds):
        m = copy.copy(model)
        for i in plan:
            t = tendons[i]
            if plan[i].size is not None:
                _set_size(m, t, float(values[0, w, i]))
            if plan[i].stiffness is not None or plan[i].damping is not None:
                m.tendon_solref_lim[t.tendon] = (-values[1, w, i] * t.invweight, -values[2, w, i] * t.invweight)
        models.append(m)
    return PlayWorlds(models, tendons, values[0], values[1], values[2], seed)
