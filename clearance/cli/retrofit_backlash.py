"""``clearance retrofit`` with gear backlash: the --joint NAME:backlash_arcmin=B form of the command.

Every --joint names backlash (mixing it with radial play is refused); the stop at the ends of
each band is the calibrated one unless ``--backlash-stop`` says otherwise, or, with
``--robot-step MS``, the step-limited stop at the robot's own step
(`clearance.retrofit.robot_step`): the model and ``original.xml`` written at that step, or the
request refused naming the largest usable step and the smallest usable band.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING

from clearance.cli.paths import check_folder, folder_lock, staged_outputs
from clearance.cli.retrofit import joint_values, read_model

if TYPE_CHECKING:
    from clearance.retrofit import Backlash, ControlTable, SineControl

__all__ = ["BACKLASH_KEYS", "backlash_command", "backlash_from_args"]

BACKLASH_KEYS = ("backlash_arcmin", "mesh_stiffness", "restitution")
"""The keys a --joint with backlash takes."""


def backlash_from_args(args: argparse.Namespace) -> dict[str, Backlash]:
    """Hinge name -> `Backlash` where the --joint options name ``backlash_arcmin``; {} where none does.

    Raises:
        ValueError: some --joint name backlash and others not, a backlash joint with radial
            play keys too, a half-width outside (0, 600] arc-minutes (10 degrees), a joint named twice.
    """
    from clearance.retrofit import MAX_BACKLASH, Backlash
    from clearance.retrofit.play import DEFAULT_MESH_RESTITUTION, DEFAULT_MESH_STIFFNESS

    cap = math.degrees(MAX_BACKLASH) * 60
    given = [
        (text, {item.partition("=")[0].strip() for item in text.partition(":")[2].split(",")}) for text in args.joint
    ]
    for text, keys in given:
        if "mesh_stiffness" in keys and "backlash_arcmin" not in keys:
            raise ValueError(
                f"--joint {text!r}: mesh_stiffness is the stop of a backlash band; give backlash_arcmin too"
            )
    with_backlash = [(text, keys) for text, keys in given if "backlash_arcmin" in keys]
    if not with_backlash:
        return {}
    if len(with_backlash) != len(args.joint):
        other = next(text for text, keys in given if "backlash_arcmin" not in keys)
        raise ValueError(
            f"--joint {other!r}: backlash and radial play cannot be mixed in one command yet "
            f"(--joint {with_backlash[0][0]!r} names backlash_arcmin)"
        )
    out: dict[str, Backlash] = {}
    for text, keys in with_backlash:
        name, v = joint_values(args, text)
        extra = sorted(keys - set(BACKLASH_KEYS))
        if extra:
            raise ValueError(
                f"--joint {text!r}: a hinge with backlash takes no radial play keys (got {', '.join(extra)}); "
                "backlash and radial play at one hinge are refused"
            )
        if name in out:
            raise ValueError(f"--joint: hinge '{name}' is named twice")
        b = v["backlash_arcmin"]
        if not 0 < b <= cap:
            raise ValueError(f"--joint {text!r}: backlash_arcmin must be in (0, {cap:g}] (got {b:g})")
        stiffness = v["mesh_stiffness"] if "mesh_stiffness" in keys else DEFAULT_MESH_STIFFNESS
        if not stiffness > 0:
            raise ValueError(f"--joint {text!r}: mesh_stiffness must be > 0 [N m/rad] (got {stiffness:g})")
        e = v["restitution"] if "restitution" in keys else DEFAULT_MESH_RESTITUTION
        if not 0 < e <= 1:
            raise ValueError(f"--joint {text!r}: restitution must be in (0, 1] (got {e:g})")
        out[name] = Backlash.from_arcmin(
            b, mesh_stiffness=stiffness, restitution=e, stop=args.backlash_stop, sensors=args.backlash_sensors
        )
    return out


def _sizing_control(args: argparse.Namespace, path: str) -> SineControl | ControlTable:
    """The sizing motion of --robot-step: the control file, or the sinusoid (checked against the model)."""
    import mujoco

    from clearance.cli.controls import check_sine_amplitude, read_controls
    from clearance.retrofit import SineControl

    try:
        compiled = mujoco.MjSpec.from_file(path).compile()
    except ValueError as err:
        raise ValueError(f"model file {path} does not compile: {err}") from None
    if args.sizing_control is not None:
        return read_controls(args.sizing_control, compiled, "--sizing-control")
    check_sine_amplitude(args.sine_amplitude, compiled, "--sine-amplitude")
    return SineControl(args.sine_amplitude, args.sine_frequency_hz)


def _command_line(args: argparse.Namespace) -> str:
    """The command as given, for the report."""
    line = ["clearance retrofit", args.model, *[f"--joint {j}" for j in args.joint], f"--out {args.out}"]
    if args.backlash_stop != "calibrated":
        line.append(f"--backlash-stop {args.backlash_stop}")
    if args.backlash_sensors != "load":
        line.append(f"--backlash-sensors {args.backlash_sensors}")
    if args.robot_step is not None:
        line.append(f"--robot-step {args.robot_step:g}")
        if args.sizing_control is not None:
            line.append(f"--sizing-control {args.sizing_control}")
        else:
            line.append(f"--sine-amplitude {args.sine_amplitude:g} --sine-frequency-hz {args.sine_frequency_hz:g}")
        line.append(f"--sizing-duration-s {args.sizing_duration_s:g}")
    return " ".join(line)


def backlash_command(args: argparse.Namespace, joints: dict[str, Backlash]) -> int:
    """``clearance retrofit`` with backlash at every named hinge; returns the exit status."""
    from clearance.retrofit import add_backlash
    from clearance.retrofit.output import write_backlash

    if args.robot_step is not None and args.backlash_stop != "calibrated":
        raise ValueError(
            f"--robot-step {args.robot_step:g} with --backlash-stop {args.backlash_stop}: the robot step's own stop "
            "closes the bands; give one of the two"
        )
    out = check_folder(args.out, "--out")
    spec = read_model(Path(args.model))
    control = _sizing_control(args, args.model) if args.robot_step is not None else None
    step = None
    with folder_lock(out):
        try:
            if args.robot_step is not None:
                from clearance.retrofit.robot_step import add_robot_step_backlash
                from clearance.retrofit.robot_step_report import robot_step_report

                step = add_robot_step_backlash(
                    spec, joints, robot_step=args.robot_step * 1e-3, control=control, duration=args.sizing_duration_s
                )
                result = step.retrofit
            else:
                result = add_backlash(spec, joints)
        except ValueError as err:
            raise ValueError(f"{args.model}: {err}") from None
        with staged_outputs(out) as stage:  # every file, or none
            source_dir = Path(args.model).resolve().parent
            written = write_backlash(
                result, stage, source_dir=source_dir, source=str(args.model), command=_command_line(args)
            )
            if step is not None:
                with open(written["report"], "a", encoding="utf-8") as report:
                    report.write("\n" + robot_step_report(step))
        paths = {role: out / p.name for role, p in written.items()}
    for note in result.notes:
        print(note)
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0
