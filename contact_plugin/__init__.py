"""clearance.contact_plugin: exact journal–bearing contact computed inside MuJoCo.

`clearance.journal_bearing` is a MuJoCo engine plugin written in C
(``contact_plugin/journal_bearing.c``, whose header comment is the full specification). One
plugin instance per clearance joint computes, from two sites and two radii, the exact
circle-in-circle penetration, a normal force from any `clearance.model.ContactLaw` (the
formulas of `clearance.contact_calibration.laws`, reproduced operation by operation) and
Ambrósio friction, and applies them as passive forces at the contact points. No ring of
collision geoms and no constraint rows are involved. Its state (approach speed of the current
impact, dissipated work, last sample) lives in ``mjData.plugin_state``, so it is part of
``mjSTATE_PLUGIN`` and travels through chunked and threaded ``mujoco.rollout`` runs. A plugin
sensor reports 8 values per joint (`clearance.contact_plugin.attributes.SENSOR_FIELDS`).

Cost (measured with mujoco.rollout on one thread, journal and bearing with three planar dofs
each or a fixed bearing, 2 us steps, implicitfast): 435k-500k steps/s against 560k-600k for the
same bodies with no contact, i.e. about 0.3 us per step per joint out of contact and 0.6 us in
sliding contact with friction.

Installation: the library is compiled by ``pip install`` (``setup.py``, an optional extension
built against the mujoco wheel of the build environment). Without a C compiler the package
installs all the same, without the library: `is_available` is then False and asking for the
plugin raises `PluginUnavailableError`. Nothing falls back silently to another contact model.

Loading: the package registers `load` as a ``mujoco.plugins`` entry point, which
``import mujoco`` (4.0) calls in every process, so any process that imports mujoco (rollout
workers, spawned subprocesses, the viewer) can compile models that use the plugin. This module
is imported during ``import mujoco``: it must stay cheap (standard library only here) and must
not import mujoco at module level.

Usage: `clearance.contact_plugin.attributes.add_journal_bearing` validates every attribute in
Python and adds one plugin instance and its sensor to a ``mujoco.MjSpec``.

The same library registers a second plugin, ``clearance.work``: a sensor that integrates the
work done on a model by each kind of force (actuators, equality and contact constraint rows,
dampers, plugin passive forces), step by step, so that an energy balance closes from rollout
sensor rows; `clearance.contact_plugin.energy.add_energy_meter` adds it with MuJoCo's kinetic
and potential energy sensors. A third, ``clearance.backlash_stop``, closes a backlash band with
the gear mesh's impact law (`clearance.contact_calibration.laws.mesh_torque`) as passive torques
on its two hinges; `clearance.contact_plugin.backlash_stop.add_backlash_stop` adds it.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

__all__ = [
    "LIBRARY_FILE",
    "PLUGIN_NAME",
    "PluginUnavailableError",
    "is_available",
    "library_path",
    "load",
    "require",
]

PLUGIN_NAME = "clearance.journal_bearing"
"""Name under which the library registers the plugin with MuJoCo."""

LIBRARY_FILE = "libclearance_journal_bearing" + {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")
"""File name of the built plugin library, next to this module (see setup.py)."""

_lock = threading.Lock()
_loaded: Path | None = None
_HERE = Path(__file__).resolve().parent  # resolved once: a preparation asks for the library several times


class PluginUnavailableError(RuntimeError):
    """The compiled contact plugin was asked for but its library is not installed."""

    def __init__(self) -> None:
        super().__init__(
            f"the compiled contact plugin '{PLUGIN_NAME}' is not available: clearance was "
            f"installed without a C compiler (or its compilation failed), so {LIBRARY_FILE} "
            "was not built. To fix it, install a C compiler (for example `apt install gcc`, or "
            "Xcode's command line tools on macOS) and reinstall clearance from its source "
            "(`pip install --force-reinstall --no-deps .`, or `pip install -e .` for a "
            "development checkout); the build log then shows the compilation. "
            "`--contact-mode calibrated` works without the plugin."
        )


def library_path() -> Path | None:
    """Path of the built plugin library, or None if the package was installed without it.

    Returns:
        The library next to this module (an editable install builds it there too), or None.
    """
    path = _HERE / LIBRARY_FILE
    return path if path.is_file() else None


def load() -> None:
    """Load the plugin library into MuJoCo, once per process; do nothing if it is absent.

    This is the ``mujoco.plugins`` entry point, called at the end of ``import mujoco``; calling
    it again is harmless. A library that cannot be loaded (for example one built against
    another MuJoCo) raises, which ``import mujoco`` turns into a RuntimeWarning.
    """
    global _loaded
    path = library_path()
    if path is None or _loaded == path:
        return
    # Outside the lock: a first `import mujoco` calls this function again (entry point), and
    # during `import mujoco` the partly initialised module is returned, which is enough here.
    import mujoco

    with _lock:
        if _loaded != path:
            mujoco.mj_loadPluginLibrary(str(path))
            _loaded = path


def is_available() -> bool:
    """Whether the plugin library is installed and loaded into MuJoCo in this process.

    Returns:
        True once `load` has loaded the library (it is tried here if it has not run yet).
    """
    path = library_path()
    if path is None:
        return False
    try:
        load()
    except Exception:  # a library that fails to load is not available
        return False
    return _loaded == path


def require() -> None:
    """Make sure the plugin is loaded, or say how to get it.

    Raises:
        PluginUnavailableError: if the package was installed without the compiled library.
    """
    if library_path() is None:
        raise PluginUnavailableError()
    load()
