"""``clearance retrofit``: radial play or gear backlash at hinges of any MuJoCo model.

    clearance retrofit MODEL.xml --joint NAME [--joint NAME ...] --out DIR

writes DIR/model.xml (the retrofitted model: stock MuJoCo opens it), DIR/original.xml (the
unmodified model, saved with the same asset-path fixes) and DIR/retrofit.md (every change,
the sizing, the calibration, the time step and the speed cost). The options below set every
hinge's play; a hinge's own values follow its name, with units in the keys:
``--joint elbow:clearance_mm=0.2,bearing_radius_mm=8,youngs_modulus_gpa=2.4``.

``--joint elbow:backlash_arcmin=5`` gives an actuated hinge gear backlash instead: a motor side
that takes its actuators, the hinge (the link) turning within +-5' of it (`clearance.retrofit.backlash`).
The stop at either end of the band is calibrated to the gear mesh's impact law with
``mesh_stiffness`` K [N m/rad] (default 1e4: a small robot gearbox's torsional stiffness, as
strain-wave gear catalogues give it, recalled) and ``restitution`` e (default 0.8: lubricated
steel teeth, recalled): ``--joint elbow:backlash_arcmin=5,mesh_stiffness=3e4,restitution=0.7``;
``--backlash-stop recipe`` keeps MuJoCo's default limit instead, ``--backlash-stop exact`` closes the band
with the law itself (the compiled plugin); ``--backlash-sensors motor`` puts the
hinge's jointpos and jointvel sensors on the motor side. Every --joint then names
backlash, and the play, numerics and sizing options do not apply.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from clearance.cli.limits import check_clearance, check_steps
from clearance.cli.options import bounded, positive, segments_option, si, timestep_option
from clearance.cli.outputs import calibration_lines
from clearance.cli.paths import check_folder, folder_lock, staged_outputs
from clearance.model import ContactLaw, Material
from clearance.units import UNITS
from clearance.units import format_quantity as q

if TYPE_CHECKING:
    import mujoco

    from clearance.retrofit import RadialPlay

__all__ = ["add_parser", "command", "joint_values", "read_model", "JOINT_KEYS"]

JOINT_KEYS = {
    "clearance_mm": "--clearance-mm",
    "bearing_radius_mm": "--bearing-radius-mm",
    "youngs_modulus_gpa": "--youngs-modulus-gpa",
    "poisson_ratio": "--poisson-ratio",
    "restitution": "--restitution",
    "friction": "--friction",
    "eccentricity_x_mm": "",
    "eccentricity_y_mm": "",
    "bearing_length_mm": "",
    "backlash_arcmin": "",
    "mesh_stiffness": "",
}
"""Per-joint keys of ``--joint NAME:key=value,...`` -> the option they override ('': none; the
journal's start in its bearing frame, [mm], defaults to the centre; ``bearing_length_mm``, the
bearing's length L a cylindrical law uses, defaults to the bore 2 R_B; ``backlash_arcmin`` gives
the hinge gear backlash of that half-width instead of radial play, with its stop's
``mesh_stiffness`` [N m/rad] and ``restitution``)."""

DESCRIPTION = (
    "Give hinges of any MuJoCo model radial play (each hinge gains two in-plane slides, its parent a ring "
    "bearing and its child a journal; or, with --contact-mode exact, the compiled exact contact) or gear "
    "backlash (--joint NAME:backlash_arcmin=B: a motor side that takes the hinge's actuators, the link turning "
    "within +-B arcmin of it). Writes DIR/model.xml (stock MuJoCo opens a ring model), DIR/original.xml, "
    "DIR/retrofit.md (every change, the sizing, the calibration, the time step, the speed cost) and "
    "DIR/retrofit.json for 'clearance run --model DIR'. A hinge's own values follow its name, with units in the "
    "keys: --joint elbow:clearance_mm=0.2,bearing_radius_mm=8,youngs_modulus_gpa=2.4."
)
"""The help's description: plain text, as a terminal shows it."""


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``retrofit`` to the subcommands ``sub`` (argparse's subparsers action)."""
    from clearance.retrofit import DEFAULT_BEARING_RADIUS, DEFAULT_RADIAL_CLEARANCE

    p = sub.add_parser(
        "retrofit",
        help="give hinges of any MuJoCo model radial play (a journal in a ring bearing) or gear backlash",
        description=DESCRIPTION,
    )
    p.add_argument("model", metavar="MODEL.xml", help="the MuJoCo model (MJCF) to retrofit")
    p.add_argument(
        "--joint",
        action="append",
        required=True,
        metavar="NAME[:key=value,...]",
        help="a hinge, or a loop closure's connect equality, to give radial play (repeat for more); its own values "
        "may follow, keys " + ", ".join(JOINT_KEYS),
    )
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    play = p.add_argument_group("play (every hinge, unless its --joint says otherwise)")
    play.add_argument(
        "--clearance-mm",
        type=positive(float, "--clearance-mm"),
        default=DEFAULT_RADIAL_CLEARANCE * 1e3,
        help=f"radial clearance c [mm] (default {DEFAULT_RADIAL_CLEARANCE * 1e3:g})",
    )
    play.add_argument(
        "--bearing-radius-mm",
        type=positive(float, "--bearing-radius-mm"),
        default=DEFAULT_BEARING_RADIUS * 1e3,
        help=f"bearing radius R_B [mm] (default {DEFAULT_BEARING_RADIUS * 1e3:g})",
    )
    play.add_argument(
        "--youngs-modulus-gpa",
        type=positive(float, "--youngs-modulus-gpa"),
        default=207.0,
        help="Young's modulus of journal and bearing [GPa] (default 207, steel; about 2-3 for a polymer bushing)",
    )
    play.add_argument(
        "--poisson-ratio",
        type=bounded(float, "--poisson-ratio", 0.0, 0.5),
        default=0.3,
        help="Poisson's ratio of journal and bearing (default 0.3)",
    )
    play.add_argument(
        "--restitution",
        type=bounded(float, "--restitution", hi=1.0),
        default=0.9,
        help="coefficient of restitution (default 0.9)",
    )
    play.add_argument(
        "--friction",
        type=bounded(float, "--friction", 0.0),
        default=0.0,
        help="Coulomb friction coefficient (default 0)",
    )
    play.add_argument(
        "--law",
        default=ContactLaw.LANKARANI_NIKRAVESH.value,
        choices=[law.value for law in ContactLaw if law is not ContactLaw.IMPACT],
        help="contact law the ring is calibrated against (default lankarani_nikravesh)",
    )
    num = p.add_argument_group("numerics")
    num.add_argument(
        "--contact-mode",
        default="calibrated",
        choices=("calibrated", "nominal", "exact"),
        help="calibrated (default: the ring's soft contact fitted to the law at each bearing's effective mass, "
        "cached), nominal (the ring with formula parameters) or exact (no ring: the compiled plugin's exact "
        "contact; the written model then needs the plugin, which opens it wherever clearance is installed)",
    )
    num.add_argument(
        "--timestep-us",
        type=timestep_option(),
        default=None,
        help="time step [µs] (default: the largest 1/2/5 x 10^k with omega*h <= 0.2 at every bearing, "
        "at most the model's own)",
    )
    num.add_argument(
        "--segments", type=segments_option(), default=None, help="ring segments per bearing (default: the ripple rule)"
    )
    num.add_argument(
        "--journal-geom",
        default="sphere",
        choices=("sphere", "capsule", "cylinder"),
        help="the journal's geom in its ring (ring contact modes only; default sphere: exact circle-in-circle "
        "geometry in the plane)",
    )
    num.add_argument(
        "--segment-geom",
        default="sphere",
        choices=("sphere", "capsule", "box", "cylinder"),
        help="the geom of each ring segment (ring contact modes only; default sphere)",
    )
    motion = p.add_argument_group("sizing motion (the unmodified model under a sinusoid on every actuator)")
    motion.add_argument(
        "--sine-amplitude",
        type=positive(float, "--sine-amplitude"),
        default=0.5,
        help="fraction of each actuator's control half-range, above 0 (no motion sizes nothing) and at most 1 for "
        "an actuator with a ctrlrange (default 0.5)",
    )
    motion.add_argument(
        "--sine-frequency-hz", type=positive(float, "--sine-frequency-hz"), default=1.0, help="[Hz] (default 1)"
    )
    motion.add_argument(
        "--sizing-control",
        default=None,
        metavar="CTRL.csv",
        help="size from the motion under this control file instead of the sinusoid (header time_s and one column "
        "per actuator, its name or #k; linear in between, held beyond): a servo's set point, a recorded sequence "
        "(default: none, the sinusoid)",
    )
    motion.add_argument(
        "--sizing-duration-s", type=positive(float, "--sizing-duration-s"), default=1.0, help="[s] (default 1)"
    )
    p.add_argument("--no-speed", action="store_true", help="do not measure the speed cost")
    p.add_argument(
        "--accept-inaccurate",
        action="store_true",
        help="keep a ring that misses its stated accuracy (its force ripple bound, its calibration's goals) with a "
        "warning in the console and the report, instead of refusing it",
    )
    p.add_argument(
        "--backlash-stop",
        default="calibrated",
        choices=("calibrated", "recipe", "exact"),
        help="the stop at the ends of a backlash band: calibrated (default: fitted to the gear mesh's impact law, "
        "mesh_stiffness default 1e4 N m/rad and restitution 0.8, both recalled typical values; the time step is "
        "lowered where the stop needs it), exact (the law itself, computed by the compiled plugin "
        "clearance.backlash_stop; the same time step rule; the written model needs the plugin) or recipe (MuJoCo's "
        "two hinges and a limit at its default solref and solimp, the model's time step)",
    )
    p.add_argument(
        "--backlash-sensors",
        default="load",
        choices=("load", "motor"),
        help="where a backlashed hinge's jointpos and jointvel sensors read: load (default: the link, the hinge's own "
        "angle) or motor (the motor side, as an encoder on the motor); its jointactuatorfrc sensors follow the "
        "actuators to the motor side either way",
    )
    p.add_argument(
        "--robot-step",
        type=positive(float, "--robot-step"),
        default=None,
        metavar="MS",
        help="backlash at the step the robot runs at [ms] (e.g. 1 or 2): each band closed by the stiffest stop that "
        "step represents (MuJoCo's soft limit, its spring time constant two steps, damping fitted to the exact "
        "stop's rebound and impulse), the model and original.xml at that step, no plugin; refused, naming the "
        "largest usable step and the smallest usable band, where the stop would sink more than 20 %% of the band "
        "under the sizing motion. Radial play likewise: each journal held within c by a tendon-limit stop (no "
        "ring, no friction), the model at that step; refused, naming the smallest usable clearance and the "
        "largest usable step (default: none, the calibrated stop or ring at its own fine step)",
    )
    p.set_defaults(run_command=command)


def joint_values(args: argparse.Namespace, text: str) -> tuple[str, dict[str, float]]:
    """(hinge name, its values in command-line units) from ``NAME[:key=value,...]``."""
    values = {
        key: float(getattr(args, flag[2:].replace("-", "_"))) if flag else 0.0 for key, flag in JOINT_KEYS.items()
    }
    name, sep, rest = text.partition(":")
    if not name:
        raise ValueError(f"--joint {text!r}: give the hinge's name first")
    if not sep:
        return name, values
    given: set[str] = set()
    for item in rest.split(","):
        key, eq, value = item.partition("=")
        key = key.strip()
        if key not in JOINT_KEYS or not eq:
            raise ValueError(f"--joint {text!r}: '{item}' is not key=value with a key among {', '.join(JOINT_KEYS)}")
        if key in given:
            raise ValueError(f"--joint {text!r}: {key} is given twice; give each key once")
        given.add(key)
        try:
            v = float(value)
        except ValueError:
            raise ValueError(f"--joint {text!r}: {key} must be a number (got {value!r})") from None
        if not math.isfinite(v):
            raise ValueError(f"--joint {text!r}: {key} must be a finite number (got {value!r})")
        values[key] = v
    return name, values


def plays_from_args(args: argparse.Namespace) -> dict[str, RadialPlay]:
    """Hinge name -> `RadialPlay` from the options (SI), checked before any work.

    Raises:
        ValueError: a bad value (named with its option or joint key), a clearance not smaller
            than the bearing radius, a joint named twice.
    """
    from clearance.model import Clearance
    from clearance.retrofit import RadialPlay

    gpa = UNITS["pressure"]["gpa"]
    plays: dict[str, RadialPlay] = {}
    for text in args.joint:
        name, v = joint_values(args, text)
        if name in plays:
            raise ValueError(f"--joint: hinge '{name}' is named twice")
        where = f"hinge '{name}'"
        for key in ("clearance_mm", "bearing_radius_mm", "youngs_modulus_gpa", "restitution"):
            if not v[key] > 0:
                raise ValueError(f"{where}: {key} must be > 0 (got {v[key]:g})")
        if not 0 <= v["poisson_ratio"] < 0.5 or v["friction"] < 0 or v["restitution"] > 1:
            raise ValueError(
                f"{where}: poisson_ratio must be in [0, 0.5), friction >= 0 and restitution <= 1 "
                f"(got {v['poisson_ratio']:g}, {v['friction']:g}, {v['restitution']:g})"
            )
        if v["clearance_mm"] >= v["bearing_radius_mm"]:
            raise ValueError(
                f"{where}: the radial clearance {v['clearance_mm']:g} mm must be smaller than the bearing radius "
                f"{v['bearing_radius_mm']:g} mm (--clearance-mm, --bearing-radius-mm)"
            )
        if v["bearing_length_mm"] < 0:
            raise ValueError(f"{where}: bearing_length_mm must be > 0 (got {v['bearing_length_mm']:g})")
        ecc = math.hypot(v["eccentricity_x_mm"], v["eccentricity_y_mm"])
        if ecc >= v["clearance_mm"]:
            raise ValueError(
                f"{where}: the initial eccentricity ({v['eccentricity_x_mm']:g}, {v['eccentricity_y_mm']:g}) mm must "
                f"be smaller than the radial clearance {v['clearance_mm']:g} mm"
            )
        material = Material(v["youngs_modulus_gpa"] * gpa, v["poisson_ratio"])
        clearance = Clearance(
            si(v["clearance_mm"], "mm"),
            si(v["bearing_radius_mm"], "mm"),
            bearing_material=material,
            journal_material=material,
            restitution=v["restitution"],
            friction=v["friction"],
            law=ContactLaw(args.law),
            bearing_length=si(v["bearing_length_mm"], "mm") if v["bearing_length_mm"] else None,
        )
        check_clearance(where, clearance, f"--joint {text}")
        eccentricity = (si(v["eccentricity_x_mm"], "mm"), si(v["eccentricity_y_mm"], "mm"))
        plays[name] = RadialPlay(clearance, eccentricity)
    return plays


def read_model(path: Path) -> mujoco.MjSpec:
    """The model file's spec; a missing or unreadable file is refused naming it."""
    import mujoco

    if not path.is_file():
        raise ValueError(f"model file {path} does not exist" if not path.exists() else f"{path} is not a file")
    try:
        return mujoco.MjSpec.from_file(str(path))
    except ValueError as err:
        raise ValueError(f"model file {path} cannot be read by MuJoCo: {err}") from None


def _command_line(args: argparse.Namespace) -> str:
    parts = ["clearance retrofit", args.model, *[f"--joint {j}" for j in args.joint], f"--out {args.out}"]
    for flag in (
        "--clearance-mm",
        "--bearing-radius-mm",
        "--youngs-modulus-gpa",
        "--poisson-ratio",
        "--restitution",
        "--friction",
        "--law",
        "--contact-mode",
        "--timestep-us",
        "--segments",
        "--journal-geom",
        "--segment-geom",
        "--sine-amplitude",
        "--sine-frequency-hz",
        "--sizing-control",
        "--sizing-duration-s",
        "--robot-step",
    ):
        value = getattr(args, flag[2:].replace("-", "_"))
        if value is not None:
            parts.append(f"{flag} {value:g}" if isinstance(value, float) else f"{flag} {value}")
    if args.no_speed:
        parts.append("--no-speed")
    if args.accept_inaccurate:
        parts.append("--accept-inaccurate")
    return " ".join(parts)


def command(args: argparse.Namespace) -> int:
    """Run ``clearance retrofit``; returns the exit status (2: refused)."""

    from clearance.cli.retrofit_backlash import backlash_command, backlash_from_args
    from clearance.retrofit import RetrofitOptions, SineControl, retrofit, write_retrofit

    backlash = backlash_from_args(args)
    if backlash:
        return backlash_command(args, backlash)
    if args.robot_step is not None and not args.robot_step <= 10.0:
        raise ValueError(f"--robot-step {args.robot_step:g}: must be at most 10 [ms] (a robot's step is 1-10 ms)")
    if args.robot_step is not None and args.timestep_us is not None:
        raise ValueError(
            f"--timestep-us {args.timestep_us:g} and --robot-step {args.robot_step:g} both given: with radial play at "
            "the robot's step the model runs at that step; give one of the two"
        )
    plays = plays_from_args(args)
    options = RetrofitOptions(
        contact_mode=args.contact_mode,
        segments=args.segments,
        journal_geom=args.journal_geom,
        segment_geom=args.segment_geom,
        timestep=None if args.timestep_us is None else si(args.timestep_us, "us"),
        control=SineControl(args.sine_amplitude, args.sine_frequency_hz),  # or the control file, read below
        sizing_duration=args.sizing_duration_s,
        measure_speed=not args.no_speed,
        accept_inaccurate=args.accept_inaccurate,
        robot_step=None if args.robot_step is None else si(args.robot_step, "ms"),
    )
    out = check_folder(args.out, "--out")
    path = Path(args.model)
    spec = read_model(path)
    check_steps(args.sizing_duration_s, spec.option.timestep, f"--sizing-duration-s {args.sizing_duration_s:g}")
    from clearance.cli.controls import check_sine_amplitude, read_controls

    try:
        compiled = spec.compile()
    except ValueError as err:
        raise ValueError(f"model file {path} does not compile: {err}") from None
    if args.sizing_control is not None:
        options = replace(options, control=read_controls(args.sizing_control, compiled, "--sizing-control"))
    else:
        check_sine_amplitude(args.sine_amplitude, compiled, "--sine-amplitude")
    started = time.time()
    with folder_lock(out):
        try:
            result = retrofit(spec, plays, options)
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from None
        with staged_outputs(out) as stage:  # beside out: the models' relative asset paths hold there too
            written = write_retrofit(
                result, stage, source_dir=path.resolve().parent, source=str(path), command=_command_line(args)
            )
        paths = {role: out / p.name for role, p in written.items()}
    for h in result.hinges.values():
        s = h.sizing
        print(
            f"{h.name}: c = {q(h.play.clearance.radial_clearance, 'm')}, "
            f"{f'{s.segments} segments' if s.segments else 'no ring'}, effective mass "
            f"{s.effective_mass:.3g} kg, peak load {q(s.peak_load, 'N')}, contact {h.contact.parameters.source}"
        )
        for line in calibration_lines({h.name: {"source": h.contact.parameters.source}}, started):
            print(line.strip())
    print(f"time step {q(result.timestep, 's')} (the model's own {q(result.twin.opt.timestep, 's')})")
    if result.speed is not None:
        slower = result.speed.per_simulated_second
        print(
            f"speed cost: {result.speed.retrofitted.steps_per_second:,.0f} steps/s against "
            f"{result.speed.unmodified.steps_per_second:,.0f}; one simulated second takes "
            + (f"{slower:,.0f} times as long" if slower >= 100 else f"{slower:.3g} times as long")
        )
    for note in result.notes:
        print(f"note: {note}")
    for warning in result.warnings:
        print(f"warning: {warning}")
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0
