"""A point mass hitting a rigid wall under a contact law: the calibration's impact test.

The mass m arrives with normal speed v > 0. Penetration δ starts at 0 with δ̇ = v and obeys
m δ̈ = −F(δ, δ̇, v), integrated with `scipy.integrate.solve_ivp` (DOP853) until separation.

Separation is defined as δ returning to 0 with δ̇ < 0. Where a law's damping term outgrows
the elastic one during restitution the laws clip at 0 instead of pulling, and the mass flies
free inside the penetration zone at constant δ̇, so the restitution is the speed at which
the mass finally leaves the zone. For the laws K δⁿ [1 + χ δ̇/δ̇⁻] the force only tends to 0
as |δ̇| nears δ̇⁻/χ (so cₑ_eff <= 1/χ); the IMPACT law releases in finite time and, as its
damping fades like δ² while K δⁿ fades like δ^1.5, pushes again just before δ = 0 (below
0.77 µm = 0.028 δ_s at C_max = 1e4 N s/m, d_max = 10 µm, 0.21 kg, 1 m/s, K = 6.6e10 N/m^1.5).

Switches: the force has a kink where the law lets go of a receding mass and another at
δ = 0, and one step can straddle a kink, or a whole thin region of contact, without its
error estimate noticing (a 0.5 t_s coasting step over that IMPACT re-push region lost
1.5e-4 of the restitution at rtol 1e-10). So:

- letting go (F turning 0 with δ > 0, δ̇ < 0) and separation are terminal events, and the
  step that carried one is taken again, from its start, to end on the located switch
  (integration goes on from there if the re-taken step has not switched yet);
- the flight with F = 0 is a straight line and is followed exactly. The force is sampled
  along it, at 1/512 steps of the penetration at release and then halving towards δ = 0
  (down to 2^-52 of it); the first pushing sample is bracketed, bisected to rounding, and
  integration restarts there. A region of contact narrower than 1/512 of that penetration
  and away from δ = 0 can be missed.

Scales: the integration runs in units of a Hertz-type penetration δ_s (where the
elastic work F(δ_s, 0, v) δ_s / 2.5 equals the kinetic energy ½ m v²) and of v, with time
in t_s = δ_s / v. Tolerances therefore mean the same across stiffness 1e9..1e12 N/m^1.5,
mass 0.01..10 kg and speed 0.001..20 m/s (the scaled Hertz and LN problems are identical
over that whole range).

Solver: DOP853 with max_step 0.5 t_s. Measured on an LN impact (cₑ = 0.9) against a
rtol = 1e-13 run: DOP853 at rtol 1e-10 gives a restitution error of 2e-10 in 610 force
calls (about 3.5 ms of integration; 530 calls and 4e-10 before the last step was re-taken);
without the re-take, LSODA 3e-9 in 340; RK45 4e-9 in 610; Radau 8e-12 in 3000 calls
(47 ms). A heavily damped IMPACT law (C_max >~ 1e6 N s/m at 0.2 kg) is stiff and takes tens
to hundreds of ms, but remains accurate.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypedDict, Unpack

import numpy as np
from scipy.integrate import DenseOutput, OdeSolution, solve_ivp
from scipy.optimize import minimize_scalar
from scipy.special import beta

from clearance.checks import positive
from clearance.contact_calibration import laws
from clearance.contact_calibration.cylindrical_laws import CylinderLaw, cylinder_law, damped_force, elastic_energy
from clearance.model import CYLINDRICAL_LAWS, Clearance, ContactLaw

__all__ = [
    "ImpactResult",
    "HertzImpact",
    "hertz_impact",
    "simulate_impact",
    "simulate_oblique_impact",
    "law_impact",
    "cylinder_impact",
    "clearance_impact",
    "SolverOptions",
    "LawOptions",
]

ForceLaw = Callable[[Any, Any, float], Any]
"""force(δ [m], δ̇ [m/s], approach speed [m/s]) -> normal force [N] >= 0."""


class SolverOptions(TypedDict, total=False):
    """The solver keywords of `simulate_impact` (see there) that `law_impact` passes on."""

    rtol: float
    atol: float | None
    max_duration: float | None
    n_samples: int


class LawOptions(SolverOptions, total=False):
    """The keywords `clearance_impact` passes on to `law_impact` (see there)."""

    exponent: float
    c_max: float | None
    d_max: float | None


_MAX_STEP = 0.5  # in units of t_s; the Hertz contact lasts about 3 t_s
_FIRST_STEP = 1e-4  # in units of t_s
_MAX_PHASES = 100  # integration runs per impact, each ended by a release or a re-take
# Where a coasting mass is tested for renewed contact, as fractions of the penetration at
# release: uniformly in steps of 1/512, then halving down to 2^-52 towards δ = 0.
_COAST_GRID = np.concatenate((np.arange(511, 0, -1) / 512, 2.0 ** -np.arange(10, 53)))


@dataclass(frozen=True)
class ImpactResult:
    """One simulated impact, sampled uniformly from contact onset to separation.

    Attributes:
        times: (n,) array [s], from 0 (onset) to ``duration`` (separation).
        penetration: (n,) array δ [m].
        penetration_rate: (n,) array δ̇ [m/s] (> 0 approaching).
        force: (n,) array normal force [N].
        peak_force: maximum normal force [N] (refined on the dense solution).
        max_penetration: maximum δ [m] (at δ̇ = 0, located by an event).
        duration: contact start to separation [s].
        restitution: separation speed / approach speed [-].
        approach_speed: normal approach speed v [m/s].
        mass: impacting mass m [kg].
        tangential_velocity: (n,) array [m/s]; constant 0 for normal impacts.
        tangential_force: (n,) array [N], opposing the tangential velocity; 0 for normal
            impacts.
    """

    times: np.ndarray
    penetration: np.ndarray
    penetration_rate: np.ndarray
    force: np.ndarray
    peak_force: float
    max_penetration: float
    duration: float
    restitution: float
    approach_speed: float
    mass: float
    tangential_velocity: np.ndarray
    tangential_force: np.ndarray


@dataclass(frozen=True)
class HertzImpact:
    """Closed-form Hertz impact of a point mass on a wall (see `hertz_impact`).

    Attributes:
        max_penetration: δ_max [m].
        peak_force: K δ_max^n [N].
        duration: contact duration [s].
    """

    max_penetration: float
    peak_force: float
    duration: float


def hertz_impact(*, mass: float, speed: float, stiffness: float, exponent: float = 1.5) -> HertzImpact:
    """Closed-form impact of a point mass on a wall under F = K δⁿ (no dissipation).

    Energy gives δ_max = ((n + 1) m v² / (2K))^(1/(n+1)); for n = 1.5 that is the standard
    (5 m v² / (4K))^(2/5). The duration is 2 δ_max/v ∫₀¹ dx / sqrt(1 − x^(n+1)) =
    2 δ_max/v · B(1/(n+1), 1/2)/(n+1), i.e. 2.9433 δ_max/v = 3.2181 (m²/(K² v))^(1/5)
    for n = 1.5 (the often-quoted 3.21 rounds this).

    Args:
        mass: m [kg], > 0.
        speed: approach speed v [m/s], > 0.
        stiffness: K [N/m^n], > 0.
        exponent: n [-], > 0.

    Returns:
        The peak penetration, peak force and duration.

    Raises:
        ValueError: if an argument is not positive and finite.
    """
    m = positive("mass", mass, "kg")
    v = positive("speed", speed, "m/s")
    k = positive("stiffness", stiffness, "N/m^n")
    n = positive("exponent", exponent, "")
    dmax = ((n + 1) * m * v * v / (2 * k)) ** (1 / (n + 1))
    duration = 2 * dmax / v * beta(1 / (n + 1), 0.5) / (n + 1)
    return HertzImpact(dmax, k * dmax**n, float(duration))


def _penetration_scale(force: ForceLaw, mass: float, speed: float) -> float:
    """δ_s with F(δ_s, 0, v) δ_s / 2.5 = ½ m v², by bisection in log δ over [1e-15, 1] m."""
    energy = 0.5 * mass * speed * speed

    def excess(d: float) -> float:
        return float(force(d, 0.0, speed)) * d / 2.5 - energy

    lo, hi = math.log(1e-15), 0.0
    if excess(1.0) <= 0:
        raise ValueError(
            "the contact law is too soft: its elastic force at zero rate does not stop the "
            f"mass (m = {mass} kg, v = {speed} m/s) within 1 m of penetration"
        )
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(math.exp(mid)) < 0 else (lo, mid)
    return math.exp(hi)


def _eval_force(force: ForceLaw, d: np.ndarray, dd: np.ndarray, v: float) -> np.ndarray:
    try:
        out = np.asarray(force(d, dd, v), dtype=float)
        if out.shape == d.shape:
            return out
    except (TypeError, ValueError):
        pass
    return np.array([float(force(a, b, v)) for a, b in zip(d, dd)])


class _Coast(DenseOutput):
    """Force-free flight from state y0 at t_old: δ moves at the constant rate δ̇."""

    def __init__(self, t_old: float, t: float, y0: np.ndarray) -> None:
        super().__init__(t_old, t)
        self.y0 = np.array(y0, dtype=float)
        self.rate = np.zeros_like(self.y0)
        self.rate[0] = self.y0[1]

    def _call_impl(self, t: np.ndarray) -> np.ndarray:
        dt = np.asarray(t, dtype=float) - self.t_old
        if dt.ndim == 0:
            return self.y0 + self.rate * dt
        return self.y0[:, None] + self.rate[:, None] * dt


@dataclass(frozen=True)
class _Event:
    """A `solve_ivp` event function with the ``terminal`` and ``direction`` scipy reads from it."""

    fn: Callable[[float, np.ndarray], float]
    terminal: bool
    direction: float

    def __call__(self, t: float, y: np.ndarray) -> float:
        return self.fn(t, y)


def _reengagement(force: ForceLaw, delta: float, rate: float, v: float) -> float:
    """Fraction u in [0, 1) of ``delta`` at which a mass coasting at ``rate`` < 0 is pushed.

    The first grid point (from u = 1 down) where the force is non-zero brackets, with the
    one before it, a switch that bisection narrows to rounding; the returned u is on the
    pushing side. 0 if the force stays 0 all the way to δ = 0.
    """
    f = _eval_force(force, delta * _COAST_GRID, np.full(_COAST_GRID.shape, rate), v)
    hit = np.flatnonzero(f > 0)
    if not hit.size:
        return 0.0
    k = int(hit[0])
    lo, hi = float(_COAST_GRID[k]), (1.0 if k == 0 else float(_COAST_GRID[k - 1]))
    while hi - lo > 4 * np.finfo(float).eps * hi:
        mid = 0.5 * (lo + hi)
        if float(force(delta * mid, rate, v)) > 0:
            lo = mid
        else:
            hi = mid
    return lo


def _simulate(
    force: ForceLaw,
    mass: float,
    speed: float,
    tangential_speed: float | None,
    friction: float,
    v0: float,
    v1: float,
    rtol: float,
    atol: float | None,
    max_duration: float | None,
    n_samples: int,
) -> ImpactResult:
    if not callable(force):
        raise ValueError(f"force must be callable as force(delta, delta_dot, approach_speed) (got {force!r})")
    m = positive("mass", mass, "kg")
    v = positive("speed", speed, "m/s")
    rtol = positive("rtol", rtol, "")
    atol = rtol if atol is None else positive("atol", atol, "(scaled state)")
    if not isinstance(n_samples, (int, np.integer)) or isinstance(n_samples, bool) or n_samples < 2:
        raise ValueError(f"n_samples must be an integer >= 2 (got {n_samples!r})")
    oblique = tangential_speed is not None
    if tangential_speed is not None:
        w0 = float(tangential_speed)
        if not math.isfinite(w0):
            raise ValueError(f"tangential_speed must be finite (got {tangential_speed!r} m/s)")
        laws.ambrosio_friction(0.0, 0.0, friction=friction, v0=v0, v1=v1)  # validates

    d_s = _penetration_scale(force, m, v)
    t_s = d_s / v
    gain = t_s / (m * v)  # force [N] -> d(δ̇/v)/d(t/t_s)
    t_end = 1e3 if max_duration is None else positive("max_duration", max_duration, "s") / t_s

    def rhs(_: float, y: np.ndarray) -> list[float]:
        f = float(force(d_s * y[0], v * y[1], v))
        if not oblique:
            return [y[1], -gain * f]
        ft = float(laws._friction(f, v * y[2], friction, v0, v1))
        return [y[1], -gain * f, gain * ft]

    def separation(_: float, y: np.ndarray) -> float:
        return float(y[0])

    def turning(_: float, y: np.ndarray) -> float:
        return float(y[1])

    def released(_: float, y: np.ndarray) -> float:
        # > 0 while the law pushes; -1 once it has let go of a receding mass inside the
        # zone. The jump is a sign change that brentq locates to rounding.
        f = float(force(d_s * y[0], v * y[1], v))
        if f > 0:
            return gain * f
        return -1.0 if y[0] > 0 and y[1] < 0 else 1.0

    events = (_Event(separation, True, -1), _Event(turning, False, -1), _Event(released, True, -1))

    def no_separation(message: str) -> RuntimeError:
        return RuntimeError(
            f"no separation within {t_end * t_s:.3g} s ({message}); raise max_duration for a strongly damped law"
        )

    def integrate(t0: float, t1: float, y0: np.ndarray, first_step: float | None) -> Any:
        return solve_ivp(
            rhs,
            (t0, t1),
            y0,
            method="DOP853",
            rtol=rtol,
            atol=atol,
            dense_output=True,
            events=events,
            max_step=_MAX_STEP,
            first_step=first_step,
        )

    ts: list[float] = [0.0]
    pieces: list[DenseOutput] = []
    turns: list[tuple[float, float]] = []  # (τ, δ/δ_s) where δ̇ turns negative

    def keep(sol: Any, n: int) -> None:
        """Keep the first n steps of a run: its interpolants and turning points."""
        for t1, piece in zip(sol.t[1 : n + 1], sol.sol.interpolants[:n]):
            if t1 > ts[-1]:  # a switch found where a run starts ends it with a null step
                ts.append(t1)
                pieces.append(piece)
        turns.extend((te, ye[0]) for te, ye in zip(sol.t_events[1], sol.y_events[1]) if te <= sol.t[n])

    t, y = 0.0, np.array([0.0, 1.0] + ([w0 / v] if oblique else []))
    first: float | None = _FIRST_STEP
    redone = math.nan
    for _ in range(_MAX_PHASES):
        sol = integrate(t, t_end, y, first)
        if sol.status == 1 and sol.t[-2] != redone and sol.t[-1] > sol.t[-2]:
            # The step that carried the switch (separation or release) can straddle a force
            # kink its error estimate does not see; take that step again so it ends on the
            # switch as located, and go on from there if it has not switched yet.
            keep(sol, len(sol.t) - 2)
            sol = integrate(sol.t[-2], sol.t[-1], sol.y[:, -2], None)
            if sol.status == 0:
                keep(sol, len(sol.t) - 1)
                t, y, first, redone = sol.t[-1], sol.y[:, -1], None, sol.t[-1]
                continue
        if sol.status != 1:
            raise no_separation(f"solver: {sol.message}")
        keep(sol, len(sol.t) - 1)
        if len(sol.t_events[0]):
            tau_sep, y_sep = float(sol.t_events[0][0]), sol.y_events[0][0]
            break
        # Released: coast in a straight line to where the law pushes again, or to δ = 0.
        t_rel, y_rel = float(sol.t_events[2][0]), sol.y_events[2][0]
        u = _reengagement(force, d_s * y_rel[0], v * y_rel[1], v)
        t = t_rel + y_rel[0] * (1.0 - u) / -y_rel[1]
        if t > t_end:
            raise no_separation("coasting")
        pieces.append(_Coast(t_rel, t, y_rel))
        ts.append(t)
        y = pieces[-1](t)
        y[0] = y_rel[0] * u
        if u == 0.0:
            tau_sep, y_sep = t, y
            break
        first, redone = None, math.nan
    else:
        raise RuntimeError(f"no separation after {_MAX_PHASES} switches between pushing and coasting")
    dmax = d_s * min(turns)[1] if turns else 0.0
    traj = OdeSolution(ts, pieces)

    tau = np.linspace(0.0, tau_sep, n_samples)
    y = traj(tau)
    y[:, -1] = y_sep
    delta, rate = d_s * y[0], v * y[1]
    f = _eval_force(force, delta, rate, v)

    def neg_force(t: float) -> float:
        yy = traj(t)
        return -float(force(d_s * yy[0], v * yy[1], v))

    i = int(np.argmax(f))
    lo, hi = tau[max(i - 1, 0)], tau[min(i + 1, n_samples - 1)]
    best = minimize_scalar(neg_force, bounds=(lo, hi), method="bounded", options={"xatol": 1e-12 * tau_sep})
    peak = max(float(f[i]), -float(best.fun))
    if oblique:
        wt = v * y[2]
        ft = laws._friction(f, wt, friction, v0, v1)
    else:
        wt, ft = np.zeros(n_samples), np.zeros(n_samples)
    return ImpactResult(
        times=tau * t_s,
        penetration=delta,
        penetration_rate=rate,
        force=f,
        peak_force=peak,
        max_penetration=dmax,
        duration=tau_sep * t_s,
        restitution=-float(y_sep[1]),
        approach_speed=v,
        mass=m,
        tangential_velocity=wt,
        tangential_force=ft,
    )


def simulate_impact(
    force: ForceLaw,
    *,
    mass: float,
    speed: float,
    rtol: float = 1e-10,
    atol: float | None = None,
    max_duration: float | None = None,
    n_samples: int = 2000,
) -> ImpactResult:
    """Normal impact of a point mass on a wall under a contact law.

    Integrates m δ̈ = −F(δ, δ̇, v) from δ = 0, δ̇ = v to separation (δ back to 0 with
    δ̇ < 0; see the module docstring for laws that release before δ = 0).

    Args:
        force: force(δ [m], δ̇ [m/s], approach speed [m/s]) -> normal force [N] >= 0; it
            should return 0 for δ <= 0. Called with floats during integration and tried
            with arrays for the output samples (falling back to one call per sample).
        mass: m [kg], > 0.
        speed: approach speed v [m/s], > 0.
        rtol: relative tolerance of DOP853 on the scaled state.
        atol: absolute tolerance on the scaled state (δ/δ_s, δ̇/v); default ``rtol``.
        max_duration: give up (RuntimeError) if there is no separation by then [s];
            default 1000 t_s (about 300 Hertz contact durations).
        n_samples: number of uniform output samples over the contact, >= 2.

    Returns:
        The sampled impact with exact peak values and restitution.

    Raises:
        ValueError: if an argument is out of range, or the law cannot stop the mass.
        RuntimeError: if the mass has not separated after ``max_duration``.
    """
    return _simulate(force, mass, speed, None, 0.0, 1e-4, 1e-3, rtol, atol, max_duration, n_samples)


def simulate_oblique_impact(
    force: ForceLaw,
    *,
    mass: float,
    normal_speed: float,
    tangential_speed: float,
    friction: float,
    v0: float = 1e-4,
    v1: float = 1e-3,
    rtol: float = 1e-10,
    atol: float | None = None,
    max_duration: float | None = None,
    n_samples: int = 2000,
) -> ImpactResult:
    """Oblique impact: `simulate_impact` plus sliding along the wall.

    The tangential velocity v_T obeys m v̇_T = F_T with F_T = Ambrósio friction on the
    normal force (`laws.ambrosio_friction`). The normal motion does not depend on it.

    Args:
        force: normal law force(δ, δ̇, approach speed) -> N, as in `simulate_impact`.
        mass: m [kg], > 0.
        normal_speed: normal approach speed v [m/s], > 0.
        tangential_speed: tangential velocity at onset [m/s], any sign.
        friction: Coulomb coefficient μ [-], >= 0.
        v0: Ambrósio's no-friction speed [m/s] (default 1e-4, a recalled value).
        v1: Ambrósio's full-friction speed [m/s] (default 1e-3, a recalled value).
        rtol: relative tolerance of DOP853 on the scaled state.
        atol: absolute tolerance on the scaled state (δ/δ_s, δ̇/v); default ``rtol``.
        max_duration: give up (RuntimeError) if there is no separation by then [s];
            default 1000 t_s (about 300 Hertz contact durations).
        n_samples: number of uniform output samples over the contact, >= 2.

    Returns:
        The sampled impact, with ``tangential_velocity`` and ``tangential_force`` filled.

    Raises:
        ValueError: if an argument is out of range.
        RuntimeError: if the mass has not separated after ``max_duration``.
    """
    return _simulate(force, mass, normal_speed, tangential_speed, friction, v0, v1, rtol, atol, max_duration, n_samples)


def law_impact(
    law: ContactLaw,
    *,
    mass: float,
    speed: float,
    stiffness: float,
    restitution: float,
    exponent: float = 1.5,
    c_max: float | None = None,
    d_max: float | None = None,
    **kw: Unpack[SolverOptions],
) -> ImpactResult:
    """`simulate_impact` under one of the laws of `clearance.contact_calibration.laws`.

    Args:
        law: the normal contact law.
        mass: m [kg], > 0.
        speed: approach speed v [m/s], > 0.
        stiffness: K [N/m^n], > 0.
        restitution: cₑ [-] of the dissipative laws.
        exponent: n [-], > 0.
        c_max: IMPACT's maximum damping [N s/m] (IMPACT only).
        d_max: IMPACT's full-damping penetration [m] (IMPACT only).
        **kw: ``rtol``, ``atol``, ``max_duration``, ``n_samples`` of `simulate_impact`;
            anything else raises TypeError.

    Returns:
        The simulated impact.

    Raises:
        ValueError: if a law parameter is out of range (checked once, up front).
    """
    # Validate once through the public law, then integrate with the unchecked kernels.
    laws.normal_force(
        law, 1e-6, 0.0, 1.0, stiffness=stiffness, restitution=restitution, exponent=exponent, c_max=c_max, d_max=d_max
    )
    k, n = float(stiffness), float(exponent)
    if law is ContactLaw.IMPACT:
        c, dm = laws._impact_params(c_max, d_max)

        def force(d: Any, dd: Any, vin: float) -> Any:
            return laws._impact(d, dd, k, n, c, dm)
    else:
        chi = laws.hysteresis_factor(law, restitution)

        def force(d: Any, dd: Any, vin: float) -> Any:
            if isinstance(d, float):
                return 0.0 if d <= 0 else max(k * d**n * (1.0 + chi * dd / vin), 0.0)
            return laws._dissipative(d, dd, vin, k, chi, n)

    return simulate_impact(force, mass=mass, speed=speed, **kw)


def cylinder_impact(
    cyl: CylinderLaw, *, restitution: float, mass: float, speed: float, **kw: Unpack[SolverOptions]
) -> ImpactResult:
    """`simulate_impact` under a cylindrical law with LN hysteresis (`cylindrical_laws.damped_force`).

    Args:
        cyl: the law (`cylindrical_laws.cylinder_law`).
        restitution: cₑ [-] in [0, 1].
        mass: m [kg], > 0.
        speed: approach speed v [m/s], > 0.
        **kw: the solver options of `simulate_impact`.

    Returns:
        The simulated impact.

    Raises:
        ValueError: an argument out of range, or an impact whose kinetic energy exceeds the
            elastic energy the law stores up to its deepest penetration δ* (it would reach δ*).
    """
    chi = laws.hysteresis_factor(cyl.law, restitution)
    m = positive("mass", mass, "kg")
    v = positive("speed", speed, "m/s")
    capacity = elastic_energy(cyl, cyl.max_penetration)
    if 0.5 * m * v * v >= capacity:
        raise ValueError(
            f"an impact of {m:g} kg at {v:g} m/s ({0.5 * m * v * v:.3g} J) would reach the '{cyl.law.value}' law's "
            f"deepest penetration {cyl.max_penetration:.3g} m (it stores {capacity:.3g} J there)"
        )

    def force(d: Any, dd: Any, vin: float) -> Any:
        if np.ndim(d) == 0 and np.ndim(dd) == 0:
            return damped_force(cyl, chi, float(d), float(dd), vin)
        b = np.broadcast(d, dd)
        return np.array([damped_force(cyl, chi, float(x), float(y), vin) for x, y in b]).reshape(b.shape)

    return simulate_impact(force, mass=m, speed=v, **kw)


def clearance_impact(clearance: Clearance, *, mass: float, speed: float, **kw: Unpack[LawOptions]) -> ImpactResult:
    """The impact under a joint's law and cₑ: `law_impact` with K = `laws.bearing_stiffness`,
    or for a cylindrical law `cylinder_impact` with its radii, materials and bearing length.

    Args:
        clearance: the clearance joint (radii, materials, law, restitution, bearing length).
        mass: m [kg], > 0.
        speed: approach speed v [m/s], > 0.
        **kw: ``exponent``, ``c_max``, ``d_max`` of `law_impact` (not for a cylindrical law)
            and the solver options of `simulate_impact`.

    Returns:
        The simulated impact.

    Raises:
        ValueError: as `law_impact` or `cylinder_impact`; ``exponent``, ``c_max`` or
            ``d_max`` with a cylindrical law.
    """
    if clearance.law in CYLINDRICAL_LAWS:
        extra = sorted(k for k in ("exponent", "c_max", "d_max") if k in kw)
        if extra:
            raise ValueError(f"{extra} do not apply to the cylindrical law '{clearance.law.value}'")
        opts: SolverOptions = {k: v for k, v in kw.items() if k not in ("exponent", "c_max", "d_max")}  # type: ignore[assignment]
        return cylinder_impact(
            cylinder_law(clearance), restitution=clearance.restitution, mass=mass, speed=speed, **opts
        )
    return law_impact(
        clearance.law,
        mass=mass,
        speed=speed,
        stiffness=laws.bearing_stiffness(clearance),
        restitution=clearance.restitution,
        **kw,
    )
