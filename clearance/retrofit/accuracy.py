"""Whether each ring meets the accuracy it states, and what happens when one does not.

A ring states two accuracies: its force ripple with journal direction stays under the ripple
bound (`RetrofitOptions.ripple_limit`, 2 % unless given) over half to twice the typical
penetration (`clearance.mjcf.bearing.band_ripple`), and a calibrated ring reproduces the
contact law's impacts within `clearance.contact_calibration.fit.GOALS` at every fitted speed.
A ring that misses either is refused (`InaccurateRetrofitError`, naming every miss with its
numbers and a remedy: a finer ring where one exists, the exact contact otherwise) unless
`RetrofitOptions.accept_inaccurate` keeps it, with the same lines as warnings for the console
and the report. The exact contact states neither (no ring, the law itself).
"""

from __future__ import annotations

from dataclasses import dataclass

from clearance.contact_calibration.fit import GOALS
from clearance.mjcf.bearing import SEGMENT_CANDIDATES, RingGeometry, band_ripple
from clearance.retrofit.contact import PlayContact
from clearance.retrofit.play import Refusal, RetrofitError
from clearance.retrofit.sizing import PlaySizing

__all__ = ["ACCEPT_HINT", "InaccurateRetrofitError", "Miss", "fit_miss", "refuse_or_warn", "ripple_miss"]

ACCEPT_HINT = "--accept-inaccurate (RetrofitOptions(accept_inaccurate=True)) keeps such a ring, with a warning"
"""How a refused ring can still be kept."""

EXACT_HINT = "the exact contact (--contact-mode exact) has no ring and computes the law itself"


class InaccurateRetrofitError(RetrofitError):
    """A ring misses its stated accuracy (ripple bound or calibration goals); the message says by how much."""


@dataclass(frozen=True)
class Miss:
    """One hinge's ring missing one of its stated accuracies.

    Attributes:
        hinge: the hinge. what: the accuracy missed, with its numbers. remedy: what would meet it.
    """

    hinge: str
    what: str
    remedy: str

    def line(self) -> str:
        """One line for a message, the console or the report."""
        return f"hinge '{self.hinge}': {self.what}; remedy: {self.remedy}"


def _finer(ring: RingGeometry, typical: float, limit: float, flat: bool) -> int | None:
    """The smallest segment count above ``ring``'s that meets the ripple bound, or None."""
    for n in SEGMENT_CANDIDATES:
        if n > ring.segments:
            geom = RingGeometry.make(ring.bearing_radius, ring.radial_clearance, n, flat=flat)
            if band_ripple(geom, typical) < limit:
                return n
    return None


def ripple_miss(
    name: str, ring: RingGeometry, sizing: PlaySizing, limit: float, *, flat: bool, chosen: bool
) -> Miss | None:
    """The miss of a ring whose force ripple (``sizing.ripple``) reaches the bound ``limit``, or None.

    Args:
        name: the hinge. ring: its ring. sizing: its sizing. limit: the ripple bound [-].
        flat: box segments. chosen: the segment rule chose the count (it then tried every finer one).
    """
    if not sizing.ripple >= limit:  # NaN (no ring) never misses
        return None
    finer = None if chosen else _finer(ring, sizing.typical_penetration, limit, flat)
    ring_fix = (
        f"a finer ring, --segments {finer}"
        if finer is not None
        else f"no ring up to {SEGMENT_CANDIDATES[-1]} segments meets it at this light a load"
    )
    return Miss(
        name,
        f"the ring of {ring.segments} segments has a force ripple of {sizing.ripple:.1%} with journal direction at "
        f"{sizing.typical_penetration * 1e6:.3g} um typical penetration (bound {limit:.1%})",
        f"{ring_fix}; or {EXACT_HINT}",
    )


def fit_miss(name: str, contact: PlayContact, ring: RingGeometry, sizing: PlaySizing) -> Miss | None:
    """The miss of a calibrated ring whose fit misses `GOALS` at some impact speed, or None."""
    cal = contact.calibration
    if cal is None:
        return None
    missed = [row for row in cal.rows if not row.meets_goals()]
    if not missed:
        return None
    worst = {
        key: max((getattr(row, f"{key}_worst") for row in cal.rows), key=abs)
        for key in ("peak_force", "max_penetration", "duration", "restitution")
    }
    speeds = ", ".join(f"{row.speed:.3g}" for row in missed)
    polygon = ring.polygon_error
    finer = (
        f"a finer ring (its polygon error c (pi/N)^2 / 2 is {polygon * 1e6:.3g} um against "
        f"{sizing.typical_penetration * 1e6:.3g} um typical penetration: --segments {2 * ring.segments}); or "
        if polygon > 0.1 * sizing.typical_penetration and 2 * ring.segments <= SEGMENT_CANDIDATES[-1]
        else ""
    )
    return Miss(
        name,
        f"the calibrated ring misses the fit's goals at {len(missed)} of {len(cal.rows)} impact speeds ({speeds} m/s): "
        f"worst peak force {worst['peak_force']:+.1%}, penetration {worst['max_penetration']:+.1%}, duration "
        f"{worst['duration']:+.1%}, restitution {worst['restitution']:+.3f} (goals {GOALS['peak_force']:.0%}, "
        f"{GOALS['max_penetration']:.0%}, {GOALS['duration']:.0%}, {GOALS['restitution']:g})",
        f"{finer}{EXACT_HINT}",
    )


def refuse_or_warn(misses: list[Miss], accept: bool) -> list[str]:
    """The warnings for ``misses`` when ``accept``; otherwise refuse them (none: no warnings).

    Raises:
        InaccurateRetrofitError: some ring misses and ``accept`` is off; the message lists each miss.
    """
    if not misses:
        return []
    lines = [m.line() for m in misses]
    if not accept:
        raise InaccurateRetrofitError(
            f"{len(misses)} ring{'s' * (len(misses) > 1)} would miss {'their' if len(misses) > 1 else 'its'} stated "
            f"accuracy: {' | '.join(lines)}. {ACCEPT_HINT}",
            reason=Refusal.INACCURATE,
            hinge=misses[0].hinge if len(misses) == 1 else None,
        )
    return [f"accuracy not met, kept with --accept-inaccurate: {line}" for line in lines]
