"""One candidate of a robot's play ranking: a hinge given radial play or backlash alone, run against its twin.

`PlayAtHinge` is the picklable callable a ranking hands to its executor: for a point
``{"joint", "play", "amplitude", "frequency"}`` it retrofits the user's model in memory
(`clearance.retrofit.retrofit` with the radial play, or `add_backlash` with the band, at that
one hinge), then runs the retrofitted model and its unmodified twin under the sinusoid of that
amplitude and frequency on every actuator (`SineControl`), both at the retrofit's time step
(`simulate_retrofitted`), and returns the two runs with the end effector's position.
A radial retrofit is sized from that same sinusoid.

`check_candidates` refuses, before any work, a hinge a ranking cannot give the play it asks
for; `actuated_hinges` lists the default candidates.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco

from clearance.options import ContactMode
from clearance.results import SimulationResult
from clearance.retrofit.play import Backlash, RadialPlay, RetrofitError, RetrofitOptions, SineControl
from clearance.run.retrofitted import Retrofitted, point_of, retrofitted, simulate_retrofitted

__all__ = ["floating_base", "PLAYS", "PlayAtHinge", "actuated_hinges", "check_candidates", "end_effector"]

PLAYS = ("radial", "backlash")
"""The kinds of play a candidate hinge is given."""

_JOINT_TRN = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))


def actuated_hinges(model: mujoco.MjModel) -> list[str]:
    """The named hinges with an actuator on them (``joint=``), in the model's order."""
    driven = {int(model.actuator_trnid[k, 0]) for k in range(model.nu) if int(model.actuator_trntype[k]) in _JOINT_TRN}
    return [
        model.joint(j).name
        for j in range(model.njnt)
        if j in driven and model.joint(j).name and int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_HINGE)
    ]


def end_effector(model: mujoco.MjModel, hinges: Sequence[str], *, avoid: Sequence[str] = ()) -> str:
    """The default point whose deviation is scored: the named body deepest below the hinges
    (the most ancestors; the last in the model's order among equals), not below a hinge of ``avoid``
    that is itself below them (hinges left out of the retrofit: a refused hinge's link may move on its own).

    Raises:
        RetrofitError: no named body moves with the hinges.
    """
    roots = {int(model.jnt_bodyid[model.joint(h).id]) for h in hinges}
    above = set()  # the hinges' bodies and their ancestors: an avoided hinge there moves every candidate alike
    for r in roots:
        while r:
            above.add(r)
            r = int(model.body_parentid[r])
    skipped = {int(model.jnt_bodyid[model.joint(h).id]) for h in avoid} - above
    best, depth = "", -1
    for b in range(1, model.nbody):
        chain, k = [], b
        while k:
            chain.append(k)
            k = int(model.body_parentid[k])
        name = model.body(b).name
        if name and roots & set(chain) and not skipped & set(chain) and len(chain) >= depth:
            best, depth = name, len(chain)
    if not best:
        raise RetrofitError(f"no named body moves with the hinges {list(hinges)}: name a site or body with --site")
    return best


def floating_base(model: mujoco.MjModel, point: str) -> str | None:
    """The floating base that carries ``point`` (a site or a body): the top body of its chain (a child of
    the world) where that body has a free joint or a slide (a mobile or planar base: gymnasium's runners'
    rootx/rootz, Fetch's base slides); None for a base fixed to the world (an arm whose first joint is a
    hinge). Its name, or ``#id``.

    Raises:
        KeyError: ``point`` is neither a site nor a body of ``model``.
    """
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, point)
    body = int(model.site_bodyid[sid]) if sid >= 0 else mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, point)
    if body < 0:
        raise KeyError(point)
    while body and model.body_parentid[body]:
        body = int(model.body_parentid[body])
    first, count = int(model.body_jntadr[body]), int(model.body_jntnum[body])
    kinds = {int(model.jnt_type[j]) for j in range(first, first + count)}
    if not kinds & {int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_SLIDE)}:
        return None
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or f"#{body}"


def check_candidates(model: mujoco.MjModel, joints: Sequence[str], plays: Sequence[str], where: str) -> None:
    """Refuse joints a ranking cannot give its plays (before any work).

    Args:
        model: the user's model, compiled.
        joints: the candidate hinges.
        plays: kinds of play asked for (`PLAYS`).
        where: the model file, for messages.

    Raises:
        RetrofitError: an unknown play, an unknown joint, a joint that is not a hinge, or, with
            backlash, a hinge with no actuator on it (backlash sits between a motor and its link).
    """
    for p in plays:
        if p not in PLAYS:
            raise RetrofitError(f"play {p!r} is not one of {', '.join(PLAYS)}")
    hinges = [
        model.joint(j).name for j in range(model.njnt) if int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_HINGE)
    ]
    actuated = actuated_hinges(model)
    for name in joints:
        if name not in hinges:
            what = (
                "is not a hinge" if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) >= 0 else "is not a joint"
            )
            raise RetrofitError(f"joint {name!r} {what} of {where} (its hinges: {', '.join(h for h in hinges if h)})")
        if "backlash" in plays and name not in actuated:
            raise RetrofitError(
                f"joint {name!r} of {where} has no actuator on it (joint=): backlash sits between a motor and its "
                f"link, so an unactuated hinge cannot take it (actuated hinges: {', '.join(actuated) or 'none'}); "
                "rank it with radial play alone"
            )


@dataclass(frozen=True)
class PlayAtHinge:
    """Picklable point -> (retrofitted run, twin run) for points ``{"joint", "play", "amplitude", "frequency"}``.

    Attributes:
        model: the user's MJCF file.
        site: the site (or body) whose world position the runs carry (`site_output_names`).
        duration: simulated time of each run [s].
        radial: the play of a hinge given radial play.
        backlash: the band of a hinge given backlash.
        contact_mode: the radial play's contact ('exact', 'calibrated' or 'nominal').
        accept_inaccurate: keep a ring that misses its stated accuracy (`RetrofitOptions`); not in
            the repr a ranking's manifest records: it changes no run's numbers, only whether the
            run of such a ring is refused.
    """

    model: str
    site: str
    duration: float
    radial: RadialPlay
    backlash: Backlash
    contact_mode: str = "exact"
    accept_inaccurate: bool = field(default=False, repr=False)

    def loaded(self, point: Mapping[str, Any]) -> Retrofitted:
        """The model retrofitted at the point's hinge with the point's play, in memory.

        Raises:
            RetrofitError: the hinge cannot take that play (a `ValueError`).
        """
        spec = mujoco.MjSpec.from_file(self.model)
        joint, play = str(point["joint"]), str(point["play"])
        control = SineControl(float(point["amplitude"]), float(point["frequency"]))
        folder = Path(self.model).parent
        if play == "radial":
            from clearance.retrofit.output import manifest_of
            from clearance.retrofit.pipeline import retrofit

            mode = ContactMode(self.contact_mode)
            options = RetrofitOptions(
                contact_mode=mode, control=control, measure_speed=False, accept_inaccurate=self.accept_inaccurate
            )
            done = retrofit(spec, {joint: self.radial}, options)
            return retrofitted(folder, manifest_of(done), done.model, done.twin)
        if play == "backlash":
            from clearance.retrofit.backlash import add_backlash
            from clearance.retrofit.output import backlash_manifest_of
            from clearance.run.backlash_readout import add_backlash_sensors

            edit = add_backlash(spec, {joint: self.backlash})
            manifest = backlash_manifest_of(edit)
            work = edit.spec.copy()
            add_backlash_sensors(work, manifest.backlash)
            return retrofitted(folder, manifest, work.compile(), edit.twin)
        raise RetrofitError(f"play {play!r} is not one of {', '.join(PLAYS)}")

    def __call__(self, point: Mapping[str, Any]) -> tuple[SimulationResult, SimulationResult]:
        """The retrofitted model's run and its twin's, both with the site's position.

        Raises:
            RetrofitError: the hinge cannot take the play; `SimulationError`: a run diverged.
        """
        loaded = self.loaded(point)
        point_of(loaded.twin, self.site)  # KeyError before any run for a point neither model has
        drive = SineControl(float(point["amplitude"]), float(point["frequency"]))
        result = simulate_retrofitted(loaded, drive, self.duration, sites=[self.site])
        twin = simulate_retrofitted(loaded, drive, self.duration, twin=True, sites=[self.site])
        return result, twin
