"""``clearance view``: MuJoCo's interactive viewer on a model, at the run's initial state.

``clearance view MODEL.xml`` or ``clearance view RUN_FOLDER`` (a folder written by
``clearance run``: its ``model.xml``, or ``ideal_model.xml`` with ``--ideal``). The model opens
with its keyframe 0 applied (the assembled mechanism at the drive's speed, as the run
started), not MuJoCo's default state in which nothing moves (qpos 0, journals off their
bearings). The compiled contact plugin is loaded first, so exact-contact models open too.

`initial_state` does the loading and can be called without a display; the command then
checks that a display is there and starts ``mujoco.viewer.launch``.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco

__all__ = ["add_parser", "command", "initial_state", "model_path", "display_problem"]

RUN_MODEL = "model.xml"
"""The model of a run's folder (`clearance run` writes it)."""

RUN_IDEAL_MODEL = "ideal_model.xml"
"""The ideal twin's model of a run's folder."""

RETROFIT_TWIN_MODEL = "original.xml"
"""The unmodified twin of a folder written by `clearance retrofit` (its ``--ideal``)."""


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``view`` to the subcommands ``sub`` (argparse's subparsers action)."""
    v = sub.add_parser(
        "view",
        help="open MuJoCo's viewer on a model file or a run's folder, at the run's initial state (keyframe 0)",
    )
    v.add_argument(
        "path",
        metavar="PATH",
        help=f"an MJCF file, or a folder written by 'clearance run' (its {RUN_MODEL})",
    )
    v.add_argument(
        "--ideal",
        action="store_true",
        help=f"with a run's folder: open its ideal twin ({RUN_IDEAL_MODEL}; {RETROFIT_TWIN_MODEL} in a folder "
        "written by 'clearance retrofit')",
    )
    v.set_defaults(run_command=command)


def model_path(path: str | os.PathLike[str], *, ideal: bool = False) -> Path:
    """The MJCF file to open: ``path`` itself, or the model inside a run's folder.

    Args:
        path: an MJCF file, or a folder written by ``clearance run``.
        ideal: take the folder's ideal twin (``ideal_model.xml``, or ``original.xml`` in a
            folder written by ``clearance retrofit``); refused for a file.

    Raises:
        ValueError: the path does not exist, is a folder without the model, or ``ideal``
            is asked of a file (one-line messages naming the path).
    """
    p = Path(path)
    if p.is_dir():
        twin = RETROFIT_TWIN_MODEL if (p / RETROFIT_TWIN_MODEL).is_file() else RUN_IDEAL_MODEL
        name = twin if ideal else RUN_MODEL
        if not (p / name).is_file():
            others = [n for n in (RUN_MODEL, RUN_IDEAL_MODEL, RETROFIT_TWIN_MODEL) if (p / n).is_file()]
            found = f"it holds {', '.join(others)}" if others else "it holds no model"
            raise ValueError(
                f"clearance view: folder {p} has no {name} ({found}): give a folder written by "
                "'clearance run' or an MJCF file"
            )
        return p / name
    if not p.exists():
        raise ValueError(f"clearance view: no such file or folder: {p}")
    if ideal:
        raise ValueError(
            f"clearance view --ideal: {p} is a file; --ideal picks {RUN_IDEAL_MODEL} in a run's folder "
            "(give the folder, or the ideal model's file without --ideal)"
        )
    return p


def initial_state(path: str | os.PathLike[str], *, ideal: bool = False) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """Compile the model of ``path`` and put it in its initial state: keyframe 0 applied.

    The compiled contact plugin is loaded first, so a model using it compiles. A model
    without keyframes stays in MuJoCo's default state. The state is forwarded
    (``mj_forward``), so positions, sensors and contacts are those the viewer shows.

    Args:
        path: an MJCF file, or a folder written by ``clearance run`` (see `model_path`).
        ideal: with a folder, its ideal twin.

    Returns:
        (model, data) at keyframe 0.

    Raises:
        ValueError: see `model_path`; or the XML does not compile (MuJoCo's message, on one line).
        clearance.contact_plugin.PluginUnavailableError: the model uses the compiled contact
            (a journal bearing or an exact backlash stop) and this installation has no plugin
            library.
    """
    import mujoco

    from clearance.contact_plugin import PLUGIN_NAME, PluginUnavailableError, is_available, load
    from clearance.contact_plugin.backlash_stop import PLUGIN_NAME as STOP_PLUGIN_NAME

    file = model_path(path, ideal=ideal)
    load()
    try:
        model = mujoco.MjModel.from_xml_path(str(file))
    except ValueError as err:
        if any(name in str(err) for name in (PLUGIN_NAME, STOP_PLUGIN_NAME)) and not is_available():
            raise PluginUnavailableError() from None
        message = " ".join(line.strip() for line in str(err).splitlines() if line.strip())
        raise ValueError(f"clearance view: {file} does not compile in MuJoCo: {message}") from None
    data = mujoco.MjData(model)
    if model.nkey > 0:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    return model, data


def display_problem() -> str | None:
    """Why no window can be opened here, or None when a display is there to open it on.

    On Linux and the BSDs a window needs ``$DISPLAY`` (X11) or ``$WAYLAND_DISPLAY``; macOS and
    Windows always have one.
    """
    if sys.platform in ("darwin", "win32") or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return None
    return "no display ($DISPLAY and $WAYLAND_DISPLAY are unset)"


def _view_elsewhere(path: str, ideal: bool) -> str:
    """How to view the model from a machine with a display (the end of an error line)."""
    again = f"clearance view {path}{' --ideal' if ideal else ''}"
    return (
        f"copy {path} to a machine with a display and run '{again}' there (clearance installed), "
        "or log in with X forwarding (ssh -X); a ring model ('clearance mjcf') also opens in any "
        "MuJoCo viewer ('python -m mujoco.viewer --mjcf FILE', then load key 0)"
    )


def command(args: argparse.Namespace) -> int:
    """Open the viewer on the model (blocks until its window is closed); returns the exit status.

    Raises:
        ValueError: a bad path, a model that does not compile, or no display (one line each;
            the command line prints it and exits with status 2).
    """
    model, data = initial_state(args.path, ideal=args.ideal)
    problem = display_problem()
    if problem is not None:
        raise ValueError(f"clearance view: {problem}: {_view_elsewhere(args.path, args.ideal)}")
    try:
        import mujoco.viewer
    except (ImportError, RuntimeError) as err:  # no glfw, or no GLFW library
        raise ValueError(
            f"clearance view: MuJoCo's viewer cannot start ({err}): {_view_elsewhere(args.path, args.ideal)}"
        ) from None
    keyframe = "keyframe 0 applied" if model.nkey else "no keyframe: MuJoCo's default state"
    print(f"viewing {model_path(args.path, ideal=args.ideal)} ({keyframe}); close the window to end")
    try:
        mujoco.viewer.launch(model, data)
    except mujoco.FatalError as err:  # GLFW could not open a window on the display
        raise ValueError(
            f"clearance view: MuJoCo's viewer cannot open a window ({err}): {_view_elsewhere(args.path, args.ideal)}"
        ) from None
    return 0
