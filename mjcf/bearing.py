"""Bearing geometry: a ring of N convex segments around the bearing centre.

Each segment's in-plane cross-section is a circle of radius ``segment_radius`` whose
centre lies at ``bearing_radius + segment_radius`` from the bearing centre, so its inner
edge touches the bearing circle. (A box segment is the limit of an infinite radius: a flat
face tangent to the bearing circle.) The journal is a circle of radius R_J = R_B - c.

This module also holds the ring's force model in closed form (pure NumPy): with a linear
spring of stiffness k on every journal-segment contact row, pushing the journal a depth
delta into the ring engages every segment within about sqrt(2 delta / c) of the journal
direction and the summed force grows like delta^1.5 (docs/mujoco_notes.md). From it come the
per-segment stiffness that reproduces a Hertz-type stiffness K, the force ripple with
journal direction, and the segment-count rule.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "RingGeometry",
    "segment_centres",
    "ring_force",
    "ring_stiffness_coefficient",
    "ring_damping_coefficient",
    "force_ripple",
    "band_ripple",
    "choose_segments",
    "RIPPLE_BAND",
    "SEGMENT_RADIUS_FRACTION",
    "SEGMENT_CANDIDATES",
]

SEGMENT_RADIUS_FRACTION = 0.25
"""Segment radius as a fraction of the bearing radius (round segments)."""

SEGMENT_CANDIDATES = tuple(range(16, 513, 8))
"""Segment counts the ripple rule chooses from."""

_FLAT = 1e3  # a box face: segment radius this many bearing radii


@dataclass(frozen=True)
class RingGeometry:
    """In-plane geometry of one bearing ring.

    Attributes:
        bearing_radius: R_B [m].
        radial_clearance: c [m].
        segments: N.
        segment_radius: in-plane radius of one segment [m] (a very large value for flat
            box faces).
        contacts_per_pair: contact rows MuJoCo creates per touching journal-segment pair
            (2 for parallel capsules, else 1).
    """

    bearing_radius: float
    radial_clearance: float
    segments: int
    segment_radius: float
    contacts_per_pair: int = 1

    @classmethod
    def make(
        cls,
        bearing_radius: float,
        radial_clearance: float,
        segments: int,
        *,
        flat: bool = False,
        contacts_per_pair: int = 1,
    ) -> RingGeometry:
        """Ring with round segments of the default radius, or flat (box) faces."""
        rs = bearing_radius * (_FLAT if flat else SEGMENT_RADIUS_FRACTION)
        return cls(bearing_radius, radial_clearance, segments, rs, contacts_per_pair)

    @property
    def journal_radius(self) -> float:
        """R_J [m]."""
        return self.bearing_radius - self.radial_clearance

    @property
    def polygon_error(self) -> float:
        """Largest radial error of the journal-centre boundary [m], c (pi/N)^2 / 2 for flat faces."""
        return self.radial_clearance * (math.pi / self.segments) ** 2 / 2


def segment_centres(geom: RingGeometry) -> np.ndarray:
    """Segment centres in the bearing frame, shape (N, 2) [m]; segment 0 on +x."""
    phi = 2 * np.pi * np.arange(geom.segments) / geom.segments
    r = geom.bearing_radius + geom.segment_radius
    return r * np.stack([np.cos(phi), np.sin(phi)], axis=1)


def _impedance_factor(geom: RingGeometry, pen: np.ndarray, impedance_rise: float) -> np.ndarray | float:
    """d(r)/d of rows at penetrations ``pen`` [m]: 1 − ε + ε min(r/c, 1) (1 for ε = 0)."""
    if not impedance_rise:
        return 1.0
    return 1.0 - impedance_rise + impedance_rise * np.minimum(pen / geom.radial_clearance, 1.0)


def ring_force(
    geom: RingGeometry,
    eccentricity: np.ndarray,
    *,
    stiffness: float = 1.0,
    damping: float = 0.0,
    eccentricity_rate: np.ndarray | None = None,
    impedance_rise: float = 0.0,
) -> np.ndarray:
    """Net force on the journal from a ring of linear spring-dampers.

    Args:
        geom: ring geometry.
        eccentricity: (..., 2) journal centre in the bearing frame [m].
        stiffness: per contact row [N/m] (at full impedance).
        damping: per contact row [N s/m] (at full impedance).
        eccentricity_rate: (..., 2) journal-centre velocity [m/s] (needed with damping).
        impedance_rise: ε of `ContactParameters.impedance_rise`: a row at penetration r
            pushes with g² k r + g b ṙ, g = 1 − ε + ε min(r/c, 1) (MuJoCo's direct-mode row
            with solimp (d(1 − ε), d, c, 0.5, 1)); 0: plain linear rows.

    Returns:
        (..., 2) force on the journal [N] (each row pushes only: no adhesion).
    """
    e = np.asarray(eccentricity, dtype=float)
    s = segment_centres(geom)
    d = e[..., None, :] - s  # (..., N, 2) from segment to journal centre
    dist = np.linalg.norm(d, axis=-1)
    n = d / dist[..., None]
    pen = geom.journal_radius + geom.segment_radius - dist
    active = pen > 0
    g = _impedance_factor(geom, np.where(active, pen, 0.0), impedance_rise)
    f = g**2 * stiffness * np.where(active, pen, 0.0)
    if damping and eccentricity_rate is not None:
        v = np.asarray(eccentricity_rate, dtype=float)
        pen_rate = -(n * v[..., None, :]).sum(-1)
        f = f + np.where(active, g * damping * pen_rate, 0.0)
        f = np.maximum(f, 0.0)
    f = f * geom.contacts_per_pair
    return (f[..., None] * n).sum(-2)


def _radial_force(geom: RingGeometry, delta: np.ndarray, n_dir: int) -> np.ndarray:
    """Inward radial ring force for unit row stiffness, shape (len(delta), n_dir)."""
    psi = np.linspace(0.0, 2 * np.pi / geom.segments, n_dir, endpoint=False)
    u = np.stack([np.cos(psi), np.sin(psi)], axis=1)
    r = geom.radial_clearance + np.asarray(delta, dtype=float)
    e = r[:, None, None] * u[None]
    f = ring_force(geom, e)
    return -(f * u[None]).sum(-1)


def ring_stiffness_coefficient(
    geom: RingGeometry, delta_range: tuple[float, float], *, n: int = 24, n_dir: int = 32
) -> float:
    """C such that the ring force ~ C * k * delta^1.5 for unit row stiffness k.

    Fitted in log space over ``delta_range`` [m] and averaged over journal direction, so a
    per-row stiffness k = K / C reproduces a journal-bearing stiffness K [N/m^1.5].
    """
    lo, hi = delta_range
    if not 0 < lo < hi:
        raise ValueError(f"delta_range must satisfy 0 < lo < hi (got {delta_range!r})")
    deltas = np.geomspace(lo, hi, n)
    f = _radial_force(geom, deltas, n_dir).mean(axis=1)
    return float(np.exp(np.mean(np.log(f) - 1.5 * np.log(deltas))))


def ring_damping_coefficient(geom: RingGeometry, delta: float, *, impedance_rise: float = 0.0) -> float:
    """Radial damping of the ring at depth ``delta`` for unit row damping [N s/m per N s/m].

    Sum of cos^2 of the active rows' normals about the radial direction (averaged over
    journal direction): the ring's damping grows like sqrt(delta) while LN's grows like
    delta^1.5, which is why one constant row damping matches LN restitution at one impact
    speed only. With ``impedance_rise`` ε each row's term is weighted by its d(r)/d (see
    `ring_force`).
    """
    psi = np.linspace(0.0, 2 * np.pi / geom.segments, 16, endpoint=False)
    s = segment_centres(geom)
    tot = 0.0
    for p in psi:
        u = np.array([math.cos(p), math.sin(p)])
        e = (geom.radial_clearance + delta) * u
        d = e - s
        dist = np.linalg.norm(d, axis=1)
        pen = geom.journal_radius + geom.segment_radius - dist
        act = pen > 0
        cos = (d[act] / dist[act, None]) @ u
        tot += float(np.sum(_impedance_factor(geom, pen[act], impedance_rise) * cos**2))
    return tot / len(psi) * geom.contacts_per_pair


def force_ripple(geom: RingGeometry, delta: float, *, n_dir: int = 256) -> float:
    """(max - min) / mean of the radial ring force over journal direction at depth delta."""
    f = _radial_force(geom, np.array([delta]), n_dir)[0]
    mean = float(f.mean())
    if mean <= 0:
        return math.inf
    return float((f.max() - f.min()) / mean)


RIPPLE_BAND = (0.5, 0.71, 1.0, 1.41, 2.0)
"""Depths, as multiples of the typical penetration, over which a ring's force ripple is judged
(the ripple is not monotonic in N or depth: one depth can hide a bad count)."""


def band_ripple(geom: RingGeometry, typical_penetration: float) -> float:
    """Largest force ripple of ``geom`` over `RIPPLE_BAND` x ``typical_penetration`` [m] (`force_ripple`,
    at 96 directions, every depth in one pass)."""
    f = _radial_force(geom, typical_penetration * np.asarray(RIPPLE_BAND), 96)
    mean = f.mean(axis=1)
    if not (mean > 0).all():
        return math.inf
    return float(np.max((f.max(axis=1) - f.min(axis=1)) / mean))


def choose_segments(
    bearing_radius: float,
    radial_clearance: float,
    typical_penetration: float,
    *,
    ripple_limit: float = 0.02,
    flat: bool = False,
    candidates: tuple[int, ...] = SEGMENT_CANDIDATES,
    fallback_max: int = 288,
) -> int:
    """Smallest N whose force ripple stays under ``ripple_limit`` at the typical depth.

    The ripple of a ring of linear rows is not monotonic in N (engagement patterns
    repeat), so the rule asks for the limit to hold over a band of depths, from half to
    twice ``typical_penetration`` [m], not at one depth (`band_ripple`).

    When no candidate meets the limit (light loads: the journal barely touches, as in a
    slow mechanism), the candidate up to ``fallback_max`` with the smallest ripple is
    returned and a `RuntimeWarning` says so.

    Raises:
        ValueError: a non-positive typical penetration.
    """
    if typical_penetration <= 0:
        raise ValueError(f"typical_penetration must be > 0 (got {typical_penetration!r} m)")
    best = (math.inf, candidates[0])
    for n in candidates:
        ripple = band_ripple(RingGeometry.make(bearing_radius, radial_clearance, n, flat=flat), typical_penetration)
        if ripple < ripple_limit:
            return n
        if n <= fallback_max and ripple < best[0]:
            best = (ripple, n)
    import warnings

    warnings.warn(
        f"no segment count up to {candidates[-1]} keeps the force ripple under {ripple_limit:.1%} at "
        f"penetration {typical_penetration:.3g} m (clearance {radial_clearance:.3g} m); using N = {best[1]} "
        f"(ripple {best[0]:.1%}); give ModelOptions(segments=...) to choose",
        RuntimeWarning,
        stacklevel=2,
    )
    return best[1]
