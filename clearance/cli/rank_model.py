"""``clearance rank --model MODEL.xml``: which hinge's play costs a robot's end effector most (resumable).

    clearance rank --model MODEL.xml [--joints NAME ...] [--plays radial backlash] [--site NAME]
                   [--clearance-mm C] [--backlash-arcmin B] [--amplitudes A ...] [--frequencies-hz F ...]
                   [--duration-ms T] [--startup-ms S] [--out DIR] [--scheduler ADDRESS] [--workers N]

Every candidate hinge (default: every hinge with an actuator on it) is given radial play alone
(c = 0.1 mm steel in a 10 mm bearing, the compiled exact contact) and backlash alone (b = 5
arc-minutes, MuJoCo's stop as `clearance retrofit` makes it), and runs against the unmodified
twin under a sinusoid on every actuator for each control amplitude and frequency of the grid
(default amplitudes 0.25 and 0.5 of each control half-range, 2 and 4 Hz, 1.25 s per run);
each run is scored by the end effector's mean distance from the twin's over whole control
periods after the first 0.25 s (`clearance.analysis.sweeps.robot_ranking`), and the hinges are
ranked with the mechanism ranking's 95 % intervals. Writes ``ranking.md`` and ``ranking.png``;
rerun the same command to resume.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from clearance.cli.options import bounded, positive, si
from clearance.cli.parser import CommandParser
from clearance.cli.paths import check_folder, folder_lock
from clearance.cli.sweep_common import UsageError, check_scheduler, interrupted, usage_error

if TYPE_CHECKING:
    from clearance.run.play_candidates import PlayAtHinge

__all__ = ["DEFAULTS", "main_rank_model", "rank_model_parser"]

DEFAULTS: dict[str, Any] = {
    "clearance_mm": 0.1,
    "bearing_radius_mm": 10.0,
    "youngs_modulus_gpa": 207.0,
    "backlash_arcmin": 5.0,
    "amplitudes": [0.25, 0.5],
    "frequencies_hz": [2.0, 4.0],
    "duration_ms": 1250.0,
    "startup_ms": 250.0,
}
"""The defaults of a robot's ranking (chosen so gymnasium's seven-joint pusher ranks in a few
minutes on 2 cores: benchmarks/robot_ranking.md)."""

MAX_DURATION_MS = 60_000.0
"""Longest run a ranking takes [ms]."""


MIN_STEPS_PER_PERIOD = 10
"""The fewest of the model's own time steps a period of the sizing sinusoid may span (--frequencies-hz's bound)."""


def rank_model_parser() -> argparse.ArgumentParser:
    """Parser of ``clearance rank --model``."""
    from clearance.retrofit import MAX_BACKLASH

    d = DEFAULTS
    p = CommandParser(
        prog="clearance rank", description="Rank a robot's hinges by what their play costs its end effector."
    )
    p.add_argument("--model", required=True, metavar="MODEL.xml", help="the MuJoCo model (MJCF)")
    p.add_argument("--joints", nargs="+", default=None, help="candidate hinges (default: every actuated hinge)")
    p.add_argument(
        "--plays",
        nargs="+",
        choices=("radial", "backlash"),
        default=["radial", "backlash"],
        help="kinds of play each candidate is given alone (default both)",
    )
    p.add_argument("--site", default=None, help="end effector: a site or body (default: the deepest body they move)")
    p.add_argument(
        "--clearance-mm",
        type=positive(float, "--clearance-mm"),
        default=d["clearance_mm"],
        help=f"radial clearance c [mm] (default {d['clearance_mm']:g}, steel)",
    )
    p.add_argument(
        "--bearing-radius-mm",
        type=positive(float, "--bearing-radius-mm"),
        default=d["bearing_radius_mm"],
        help=f"bearing radius [mm] (default {d['bearing_radius_mm']:g})",
    )
    p.add_argument(
        "--youngs-modulus-gpa",
        type=positive(float, "--youngs-modulus-gpa"),
        default=d["youngs_modulus_gpa"],
        help=f"Young's modulus of journal and bearing [GPa] (default {d['youngs_modulus_gpa']:g}, steel; about 2-3 "
        "for a polymer bushing, whose softer contact lets the runs take larger steps)",
    )
    p.add_argument(
        "--contact-mode",
        choices=("exact", "calibrated", "nominal"),
        default="exact",
        help="radial play's contact (default exact: the compiled plugin; calibrated fits a ring per bearing)",
    )
    p.add_argument(
        "--accept-inaccurate",
        action="store_true",
        help="rank radial play with a ring that misses its stated accuracy (its ripple bound, its calibration's "
        "goals) instead of failing that run, as clearance retrofit --accept-inaccurate does",
    )
    cap = math.degrees(MAX_BACKLASH) * 60
    p.add_argument(
        "--backlash-arcmin",
        type=bounded(float, "--backlash-arcmin", hi=cap, why="(10 degrees)"),
        default=d["backlash_arcmin"],
        help=f"backlash half-width b [arcmin] (default {d['backlash_arcmin']:g})",
    )
    p.add_argument(
        "--amplitudes",
        type=bounded(float, "--amplitudes", hi=1.0, why="(a fraction of each actuator's control half-range)"),
        nargs="+",
        default=d["amplitudes"],
        help="sinusoid amplitudes, fractions of each actuator's control half-range (default "
        + " ".join(f"{a:g}" for a in d["amplitudes"])
        + ")",
    )
    p.add_argument(
        "--frequencies-hz",
        type=positive(float, "--frequencies-hz"),
        nargs="+",
        default=d["frequencies_hz"],
        help="sinusoid frequencies [Hz] (default " + " ".join(f"{f:g}" for f in d["frequencies_hz"]) + ")",
    )
    p.add_argument(
        "--duration-ms",
        type=bounded(float, "--duration-ms", hi=MAX_DURATION_MS),
        default=d["duration_ms"],
        help=f"simulated time of each run [ms] (default {d['duration_ms']:g})",
    )
    p.add_argument(
        "--startup-ms",
        type=bounded(float, "--startup-ms", 0.0),
        default=d["startup_ms"],
        help=f"start-up window the score skips [ms] (default {d['startup_ms']:g})",
    )
    p.add_argument("--out", default=None, help="output folder (default clearance-rank-<model>); rerun to resume")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="Dask scheduler address (default: local)")
    p.add_argument(
        "--workers", type=positive(int, "--workers"), default=None, help="local worker processes (default: CPU count)"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


@dataclass(frozen=True)
class _Plan:
    """A checked ranking: its folder, runner, points, end effector, start-up window [s] and hinges."""

    out: Path
    runner: PlayAtHinge
    points: list[dict[str, Any]]
    site: str
    startup: float
    joints: list[str]


def main_rank_model(argv: Sequence[str]) -> int:
    """Run ``clearance rank --model``; returns the exit code (0 done, 1 some runs failed, 2 refused, 130 Ctrl-C)."""
    args = rank_model_parser().parse_args(list(argv))
    try:
        plan = _plan(args)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    out = plan.out
    try:
        return _rank(args, plan)
    except (UsageError, ValueError) as err:
        return usage_error(str(err))
    except KeyboardInterrupt:
        return interrupted(out)


def _plan(args: argparse.Namespace) -> _Plan:
    """Everything checked before any work: the model, candidates, site, plays, grid and folder."""
    import mujoco

    from clearance.analysis.sweeps.robot_ranking import check_grid, play_points
    from clearance.cli.limits import check_clearance
    from clearance.model import Clearance, Material
    from clearance.retrofit import Backlash, RadialPlay
    from clearance.run.play_candidates import PlayAtHinge, actuated_hinges, check_candidates, end_effector
    from clearance.run.retrofitted import point_of
    from clearance.units import UNITS

    path = Path(args.model)
    if not path.is_file():
        raise ValueError(f"--model {path} does not exist" if not path.exists() else f"--model {path} is not a file")
    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as err:
        raise ValueError(f"--model {path} does not compile: {str(err).splitlines()[0]}") from None
    joints = list(args.joints) if args.joints else actuated_hinges(model)
    if not joints:
        raise ValueError(f"--model {path} has no actuated hinge: name candidates with --joints")
    twice = sorted({j for j in joints if joints.count(j) > 1})
    if twice:
        raise ValueError(f"--joints names {twice[0]!r} twice")
    try:
        check_candidates(model, joints, args.plays, str(path))
    except ValueError as err:
        raise ValueError(f"--joints: {err}") from None
    site = args.site or end_effector(model, joints)
    try:
        point_of(model, site)
    except KeyError:
        raise ValueError(f"--site {site!r} is neither a site nor a body of {path}") from None
    duration, startup = si(args.duration_ms, "ms"), si(args.startup_ms, "ms")
    try:
        check_grid(args.amplitudes, args.frequencies_hz, duration, startup)
    except ValueError as err:
        raise ValueError(f"--amplitudes/--frequencies-hz/--duration-ms/--startup-ms: {err}") from None
    top = 1.0 / (MIN_STEPS_PER_PERIOD * model.opt.timestep)
    for f in args.frequencies_hz:
        if f > top:
            raise ValueError(
                f"--frequencies-hz {f:g}: at most {top:g} Hz for {path}: the sinusoid's period must span at least "
                f"{MIN_STEPS_PER_PERIOD} of the model's own time steps ({model.opt.timestep:g} s) to be followed"
            )
    material = Material(args.youngs_modulus_gpa * UNITS["pressure"]["gpa"], 0.3)
    clearance = Clearance(
        si(args.clearance_mm, "mm"),
        si(args.bearing_radius_mm, "mm"),
        bearing_material=material,
        journal_material=material,
    )
    if clearance.radial_clearance >= clearance.bearing_radius:
        raise ValueError(
            f"--clearance-mm {args.clearance_mm:g} must be smaller than --bearing-radius-mm {args.bearing_radius_mm:g}"
        )
    check_clearance("radial play", clearance, f"--clearance-mm {args.clearance_mm:g}")
    radial, backlash = RadialPlay(clearance), Backlash(args.backlash_arcmin * math.pi / 10800)
    sizes = {"radial": radial.clearance.radial_clearance, "backlash": backlash.half_width}
    plays = {k: sizes[k] for k in args.plays}
    out = check_folder(Path(args.out or f"clearance-rank-{path.stem}"))
    check_scheduler(args.scheduler)
    runner = PlayAtHinge(
        str(path.resolve()), site, duration, radial, backlash, args.contact_mode, args.accept_inaccurate
    )
    points = play_points(joints, plays, args.amplitudes, args.frequencies_hz)
    return _Plan(out, runner, points, site, startup, joints)


def _rank(args: argparse.Namespace, plan: _Plan) -> int:
    """The ranking of a checked plan; returns the exit code."""
    from clearance.analysis.figures.robot_ranking_figure import plot_robot_ranking
    from clearance.analysis.sweeps.criticality import NothingToRankError
    from clearance.analysis.sweeps.executor import SchedulerError
    from clearance.analysis.sweeps.robot_ranking import robot_ranking_markdown, run_robot_ranking
    from clearance.results import atomic_write_text

    out, points, site = plan.out, plan.points, plan.site
    print(
        f"{args.model}: {len(plan.joints)} hinges x {', '.join(args.plays)} x {len(args.amplitudes)} amplitudes x "
        f"{len(args.frequencies_hz)} frequencies = {len(points)} runs (each against its twin), end effector {site}"
    )
    try:
        with folder_lock(out):
            ranking = run_robot_ranking(
                plan.runner,
                points,
                site=site,
                startup=plan.startup,
                out_dir=out,
                scheduler_address=args.scheduler,
                progress=not args.no_progress,
                max_workers=args.workers,
            )
            table = robot_ranking_markdown(ranking)
            command = " ".join(["clearance rank", *sys.argv[2:]]) if sys.argv[1:2] == ["rank"] else ""
            head = f"# Play ranking of {args.model}\n\n" + (f"`{command}`\n\n" if command else "")
            atomic_write_text(out / "ranking.md", head + table + "\n![ranking](ranking.png)\n")
            plot_robot_ranking(ranking, path=out / "ranking.png")
    except NothingToRankError as err:
        first = err.failed[0][1] if err.failed else ""
        print(f"error: no run of the ranking ran (first error: {first}); see {out / 'points'}", file=sys.stderr)
        return 1
    except SchedulerError as err:
        return usage_error(f"--scheduler {args.scheduler}: {err}")
    print(table)
    print(f"wrote {out / 'ranking.md'} and {out / 'ranking.png'}")
    if ranking.failed:
        print(
            f"error: {len(ranking.failed)} of {len(points)} runs failed (first: {ranking.failed[0][1]}); the ranking "
            f"uses the others; their rows have status 'error' in {out / 'points'}",
            file=sys.stderr,
        )
        return 1
    return 0
