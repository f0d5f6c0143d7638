"""Command-line options shared by the commands, and the one place units are converted.

Shared by every command: the scenario options (``clearance run``, ``mjcf``, ``reference``,
``calibrate``), the MuJoCo numerics, and the sweep options (``sweep``, ``rank``), so they
accept the same spellings and turn them into the same `Mechanism` and `ModelOptions`. Units
on the command line are the ones people use (mm, rpm, µs, ms); `si` converts them, once,
with the factors of `clearance.units` that scenario files use too.
"""

from __future__ import annotations

import argparse
import inspect
import sys
from pathlib import Path

from clearance.cli.arg_types import bounded, positive, rpm_option, segments_option, timestep_option
from clearance.cli.limits import MAX_DRIVE_RPM, MAX_SEGMENTS, check_mechanism
from clearance.contact_plugin import is_available as plugin_available
from clearance.model import Mechanism
from clearance.options import DEFAULT_TIMESTEP, ContactMode, GeomType, ModelOptions
from clearance.units import UNITS

__all__ = [
    "NUMERICS_FLAGS",
    "DEFAULT_MECHANISM",
    "si",
    "positive",
    "bounded",
    "rpm_option",
    "segments_option",
    "timestep_option",
    "add_clearance_mm",
    "check_clearance_at",
    "add_sweep_args",
    "sweep_out",
    "sweep_options",
    "contact_mode_from_args",
    "add_scenario_args",
    "add_numerics_args",
    "mechanism_from_args",
    "options_from_args",
    "numerics_given",
]

NUMERICS_FLAGS = {
    "--timestep-us": "timestep_us",
    "--segments": "segments",
    "--journal-geom": "journal_geom",
    "--segment-geom": "segment_geom",
    "--contact-mode": "contact_mode",
}
"""MuJoCo-only options: flag -> argparse destination."""

RING_FLAGS = ("--segments", "--journal-geom", "--segment-geom")
"""Numerics of the ring of segments, which the exact contact does not have."""

DEFAULT_MECHANISM = "slider_crank"
"""The mechanism of a command given neither ``--mechanism`` nor ``--scenario``."""

JOURNAL_GEOMS = tuple(g.value for g in GeomType if g is not GeomType.BOX)
SEGMENT_GEOMS = tuple(g.value for g in GeomType)
CONTACT_MODES = (*(m.value for m in ContactMode), "exact_ln")
"""--contact-mode choices; 'exact_ln' is the earlier name of 'exact'."""


_FACTORS = {
    "mm": UNITS["length"]["mm"],
    "rpm": UNITS["angular_speed"]["rpm"],
    "ms": UNITS["time"]["ms"],
    "us": UNITS["time"]["us"],
}


def si(value: float, unit: str) -> float:
    """A command-line value in ``unit`` ('mm', 'rpm', 'ms' or 'us') in SI (m, rad/s, s)."""
    return value * _FACTORS[unit]


def add_scenario_args(p: argparse.ArgumentParser, *, numerics: bool = True, contact_mode: bool = True) -> None:
    """Add the scenario options (and, with ``numerics``, the MuJoCo numerics) to a parser.

    Args:
        p: the parser.
        numerics: offer the MuJoCo numerics group (`add_numerics_args`). Without it the
            numerics flags are still parsed, hidden, so that a command can refuse them
            with its own explanation (`numerics_given`).
        contact_mode: offer ``--contact-mode`` in the numerics group.
    """
    g = p.add_argument_group("scenario")
    from clearance.builders import CATALOGUE

    g.add_argument(
        "--mechanism",
        default=None,
        choices=sorted(CATALOGUE),
        metavar="NAME",
        help=f"mechanism from the catalogue (default: {DEFAULT_MECHANISM}; one of: {', '.join(sorted(CATALOGUE))})",
    )
    g.add_argument(
        "--scenario",
        default=None,
        metavar="TOML",
        help="scenario file (a catalogue builder with overrides, or a whole mechanism); "
        "replaces --mechanism and the options below (giving both is refused; default: none)",
    )
    add_clearance_mm(g)
    g.add_argument(
        "--clearance-at",
        nargs="*",
        default=None,
        metavar="JOINT",
        help="joints with clearance (default: the builder's, rod_slider for the slider-crank); "
        "a slider's prismatic joint (slider_guide) gets play in its guide; "
        "give none for the ideal mechanism",
    )
    g.add_argument(
        "--rpm",
        type=rpm_option("--rpm"),
        default=None,
        help="speed of the driven crank [rpm] (the press: crank 2; default: the builder's, 5000 for the "
        f"slider-crank; at most {MAX_DRIVE_RPM:,.0f})",
    )
    g.add_argument("--gravity", action="store_true", help="gravity 9.81 m/s² along -y")
    if numerics:
        add_numerics_args(p, contact_mode=contact_mode)
    else:
        for flag, dest in NUMERICS_FLAGS.items():
            p.add_argument(flag, dest=dest, default=None, help=argparse.SUPPRESS)


def add_numerics_args(p: argparse.ArgumentParser, *, contact_mode: bool = True) -> None:
    """Add the MuJoCo numerics group: time step, segments, geoms and (optionally) contact mode."""
    dflt = ModelOptions()
    g = p.add_argument_group("numerics")
    steps = ", ".join(f"{m.value} {h * 1e6:g}" for m, h in DEFAULT_TIMESTEP.items())
    g.add_argument(
        "--timestep-us",
        type=timestep_option(),
        default=None,
        help=f"time step [µs] (default: the contact mode's, {steps}; see benchmarks/speed_error.md)",
    )
    g.add_argument(
        "--segments",
        type=segments_option(),
        default=None,
        help=f"bearing segment count N, 8 to {MAX_SEGMENTS} (ring contact modes only; default: chosen by the "
        "ripple rule)",
    )
    g.add_argument(
        "--journal-geom",
        default=None,
        choices=JOURNAL_GEOMS,
        help="journal geom (ring contact modes only; default sphere)",
    )
    g.add_argument(
        "--segment-geom",
        default=None,
        choices=SEGMENT_GEOMS,
        help="bearing segment geom (ring contact modes only; default sphere)",
    )
    if contact_mode:
        g.add_argument(
            "--contact-mode",
            default=None,
            choices=CONTACT_MODES,
            help=f"contact model (default {dflt.contact_mode.value}): exact (each joint's own contact "
            "law on exact circle geometry, computed by the compiled contact plugin; friction included; "
            "'exact_ln' is the same), calibrated (a ring of segments whose soft contact is fitted to LN "
            "impacts once, then reused from the cache; see 'clearance calibrate'; needs no compiler) or "
            "nominal (the ring with formula parameters)",
        )


def numerics_given(args: argparse.Namespace) -> list[str]:
    """The MuJoCo numerics flags given on the command line of a command that hides them."""
    return [flag for flag, dest in NUMERICS_FLAGS.items() if getattr(args, dest, None) is not None]


def mechanism_from_args(args: argparse.Namespace) -> Mechanism:
    """The scenario's `Mechanism`: a scenario file, or a catalogue builder with the options given.

    Raises:
        ValueError: an option given with ``--scenario``, or one the builder does not take; a
            scenario file that cannot be read; a mechanism outside `clearance.cli.limits`.
        ScenarioError, AssemblyError: a bad scenario (both are ValueErrors).
    """
    if args.scenario is not None:
        mech = _scenario_from_args(args)
        check_mechanism(mech, f"--scenario {args.scenario}")
        return mech
    mech = _catalogue_from_args(args)
    given = " ".join(
        f"{flag} {v:g}" for flag, v in (("--clearance-mm", args.clearance_mm), ("--rpm", args.rpm)) if v is not None
    )
    check_mechanism(mech, f"--mechanism {args.mechanism or DEFAULT_MECHANISM}" + (f" {given}" if given else ""))
    return mech


def _scenario_from_args(args: argparse.Namespace) -> Mechanism:
    """The mechanism of ``--scenario``, refusing the options it replaces."""
    from clearance.builders import ScenarioError, load_scenario
    from clearance.builders.scenario import loads_scenario

    given = [
        o
        for o, v in (
            ("--mechanism", args.mechanism),
            ("--clearance-mm", args.clearance_mm),
            ("--clearance-at", args.clearance_at),
            ("--rpm", args.rpm),
        )
        if v is not None
    ]
    if args.gravity:
        given.append("--gravity")
    if given:
        raise ValueError(
            f"--scenario {args.scenario} cannot be given with {', '.join(given)}: the scenario file names its "
            "mechanism and sets its values; change them in the file"
        )
    path = Path(args.scenario)
    if not str(args.scenario):
        raise ValueError("--scenario: give a scenario file (got an empty path)")
    if path.is_dir():
        raise ValueError(f"--scenario {path}: is a folder; give a scenario file (.toml)")
    try:
        return load_scenario(path)
    except OSError as err:
        raise ValueError(f"--scenario {path}: cannot read it ({err.strerror or type(err).__name__})") from None
    except ScenarioError as err:
        from clearance.cli.scenario_sections import DESIGN_SECTIONS, split_section

        if err.key not in DESIGN_SECTIONS:
            raise
        section = str(err.key)
    # a section of a design tool beside the mechanism: this command runs the mechanism, and says so
    split = split_section(path, section)
    found = [s for s in DESIGN_SECTIONS if s in split.document]
    tools = ", ".join(f"[{s}] is for {DESIGN_SECTIONS[s]}" for s in found)
    print(f"note: --scenario {path}: {tools}; this command reads the mechanism", file=sys.stderr)
    return loads_scenario(split.scenario_text, source=str(path))


def _catalogue_from_args(args: argparse.Namespace) -> Mechanism:
    """The catalogue mechanism of ``--mechanism`` with the options given."""
    from clearance.builders import CATALOGUE

    name = args.mechanism or DEFAULT_MECHANISM
    entry = CATALOGUE[name]
    check_clearance_at(args.clearance_at, name, sliders=True)
    builder, speed = entry.builder, entry.speed_keyword
    accepted = inspect.signature(builder).parameters
    overrides = [
        (flag, key, value)
        for flag, key, value in (
            ("--clearance-mm", "radial_clearance", None if args.clearance_mm is None else si(args.clearance_mm, "mm")),
            ("--clearance-at", "clearance_at", None if args.clearance_at is None else tuple(args.clearance_at)),
            ("--rpm", speed, None if args.rpm is None else si(args.rpm, "rpm")),
            ("--gravity", "gravity", 9.81 if args.gravity else None),
        )
        if value is not None
    ]
    refused = [flag for flag, key, _ in overrides if key not in accepted]
    if refused:
        raise ValueError(
            f"mechanism '{name}' does not take {', '.join(refused)} from the command line; "
            "use a scenario file (--scenario)"
        )
    kw = {key: value for _, key, value in overrides}
    try:
        return builder(**kw)
    except ValueError as err:  # a value the builder rejects: say which options gave it
        given = " ".join(flag if key == "gravity" else f"{flag} {_shown(args, flag)}" for flag, key, _ in overrides)
        raise ValueError(f"--mechanism {name}{' ' + given if given else ''}: {err}") from None


def _shown(args: argparse.Namespace, flag: str) -> str:
    v = getattr(args, flag.lstrip("-").replace("-", "_"))
    return " ".join(v) if isinstance(v, list) else f"{v:g}"


def check_clearance_at(joints: list[str] | None, mechanism: str, *, sliders: bool = False) -> None:
    """Refuse ``--clearance-at`` joints that the catalogue mechanism cannot give a clearance, or repeated.

    Args:
        joints: the joints given, or None.
        mechanism: the catalogue mechanism.
        sliders: also accept the prismatic joints of its sliders (a translational clearance).

    Raises:
        ValueError: naming the joints and the choices.
    """
    from clearance.builders import CATALOGUE

    if joints is None:
        return
    info = CATALOGUE[mechanism].info
    clearable = (*info.clearable, *info.sliders) if sliders else info.clearable
    unknown = [j for j in joints if j not in clearable]
    if unknown:
        where = (
            f" (a slider's play, at {', '.join(info.sliders)}, is not taken by this command; 'run', 'reference', "
            "'sweep', 'rank' and 'allocate' take it)"
            if info.sliders and not sliders
            else ""
        )
        raise ValueError(
            f"--clearance-at {' '.join(unknown)}: unknown joint(s) of mechanism '{mechanism}'; the joints that can "
            f"carry a clearance are {', '.join(clearable)} (or give none for the ideal mechanism){where}"
        )
    twice = sorted({j for j in joints if joints.count(j) > 1})
    if twice:
        raise ValueError(f"--clearance-at names {', '.join(twice)} more than once")


def options_from_args(args: argparse.Namespace) -> ModelOptions:
    """`ModelOptions` from the numerics group (SI: the time step in seconds).

    Raises:
        ValueError: a value `ModelOptions` rejects (it names the field); ring numerics
            (``--segments``, ``--journal-geom``, ``--segment-geom``) with the exact contact,
            which has no ring.
    """
    mode = contact_mode_from_args(args)
    if mode is ContactMode.EXACT:
        ring = [flag for flag in RING_FLAGS if getattr(args, NUMERICS_FLAGS[flag], None) is not None]
        if ring:
            raise ValueError(
                f"{', '.join(ring)}: the exact contact has no ring of segments; these apply to "
                "--contact-mode calibrated or nominal"
            )
    return ModelOptions(
        segments=args.segments,
        timestep=0.0 if args.timestep_us is None else si(args.timestep_us, "us"),  # 0: the mode's default
        journal_geom=GeomType(args.journal_geom or GeomType.SPHERE.value),
        segment_geom=GeomType(args.segment_geom or GeomType.SPHERE.value),
        contact_mode=mode,
    )


def add_clearance_mm(p: argparse.ArgumentParser | argparse._ArgumentGroup, *, what: str = "") -> None:
    """Add ``--clearance-mm`` (None: the builder's default clearance), the one definition every command uses.

    Args:
        p: the parser or argument group.
        what: when the option applies, for the help text (e.g. "when sweeping speed").
    """
    p.add_argument(
        "--clearance-mm",
        type=positive(float, "--clearance-mm"),
        default=None,
        help=f"radial clearance c [mm]{' ' + what if what else ''} (default: the builder's; 0.5 for the "
        "slider-crank, 0.1 for the other catalogue mechanisms)",
    )


_STOP_UNITS = {"sweep": "points", "rank": "points (one joint, clearance and speed each)", "allocate": "simulated runs"}
"""What --stop-after counts in each command."""


def add_sweep_args(p: argparse.ArgumentParser, command: str) -> None:
    """Options every sweep command takes: mechanism, numerics, executor, output, progress."""
    from clearance.builders import CATALOGUE

    p.add_argument(
        "--mechanism",
        default=DEFAULT_MECHANISM,
        choices=sorted(CATALOGUE),
        metavar="NAME",
        help=f"catalogue mechanism (default {DEFAULT_MECHANISM}; one of: {', '.join(sorted(CATALOGUE))})",
    )
    p.add_argument("--timestep-us", type=timestep_option(), default=5.0, help="time step [µs] (default 5)")
    p.add_argument(
        "--segments",
        type=segments_option(),
        default=None,
        help=f"bearing segments N, 8 to {MAX_SEGMENTS} (ring contact modes only; default: ripple rule)",
    )
    p.add_argument(
        "--contact-mode",
        default=None,
        choices=CONTACT_MODES,
        help=f"contact model of every run (default {ModelOptions().contact_mode.value}; see 'clearance run --help')",
    )
    p.add_argument(
        "--out", default=None, help=f"output folder (default clearance-{command}-<mechanism>); rerun to resume"
    )
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="Dask scheduler address (default: local processes; needs pip install 'dask[distributed]')",
    )
    p.add_argument(
        "--workers", type=positive(int, "--workers"), default=None, help="local worker processes (default: CPU count)"
    )
    p.add_argument(
        "--stop-after",
        type=positive(int, "--stop-after"),
        default=None,
        help=f"stop after exactly this many {_STOP_UNITS.get(command, 'points')} have finished (exit status 3; "
        "none is computed beyond them; the same command again resumes; default: no stop)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def sweep_out(args: argparse.Namespace, command: str) -> Path:
    """The output folder of a sweep command: ``--out``, else ``clearance-<command>-<mechanism>``."""
    return Path(args.out or f"clearance-{command}-{args.mechanism}")


def sweep_options(args: argparse.Namespace) -> ModelOptions:
    """`ModelOptions` of a sweep command (its own time-step default; the rest the package's).

    Raises:
        ValueError: ``--segments`` with the exact contact, which has no ring.
    """
    mode = contact_mode_from_args(args)
    if mode is ContactMode.EXACT and args.segments is not None:
        raise ValueError(
            "--segments: the exact contact has no ring of segments; it applies to --contact-mode calibrated or nominal"
        )
    return ModelOptions(timestep=si(args.timestep_us, "us"), segments=args.segments, contact_mode=mode)


def contact_mode_from_args(args: argparse.Namespace) -> ContactMode:
    """The contact mode asked for, or the package's default.

    The default is the compiled exact contact. Where the package was installed without a C
    compiler its plugin is missing: a command that was not asked for a contact mode then runs
    the calibrated ring and says so once on stderr; one asked for ``--contact-mode exact`` is
    refused before any work (`clearance.contact_plugin.PluginUnavailableError`).
    """
    given = getattr(args, "contact_mode", None)
    if given is not None:
        return ContactMode(given)
    mode = ModelOptions().contact_mode
    if mode is ContactMode.EXACT and not plugin_available():
        print(
            "warning: the compiled contact plugin is not installed (the package was installed without a C "
            "compiler), so this runs the calibrated ring instead of the exact contact; install a C compiler "
            "and reinstall the package for the exact contact",
            file=sys.stderr,
        )
        return ContactMode.CALIBRATED
    return mode
