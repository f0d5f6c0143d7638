"""Build of the optional compiled contact plugin (all other metadata is in pyproject.toml).

The MuJoCo engine plugins of `clearance` (contact_plugin/*.c, registered in clearance_contact.c)
form a plain C shared library, not a Python extension module: MuJoCo loads it with
``mujoco.mj_loadPluginLibrary``. It is compiled against the headers of the mujoco wheel found
in the build environment (``build-system.requires`` pins ``mujoco==4.0.*``) and linked against
that wheel's ``libmujoco.so.<version>`` by full path, with no rpath: the dynamic loader records
only the library's soname and, when MuJoCo loads the plugin, reuses the libmujoco the mujoco
Python package has already loaded.

The extension is optional: without a C compiler (or without the mujoco wheel's library) the
package installs all the same, and `clearance.contact_plugin.is_available()` reports False.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.errors import CompileError

LIBRARY_NAME = "libclearance_journal_bearing"
"""File stem of the built plugin library (its suffix is the platform's: .so, .dylib, .dll)."""


def _mujoco_dir() -> Path:
    """Folder of the mujoco package in the build environment (found without importing it)."""
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise CompileError("the mujoco package is not installed in the build environment")
    for location in spec.submodule_search_locations:
        if (Path(location) / "include" / "mujoco" / "mjplugin.h").is_file():
            return Path(location)
    raise CompileError("the mujoco package in the build environment ships no mujoco/include")


def _mujoco_library(folder: Path) -> Path:
    """The wheel's MuJoCo shared library (libmujoco.so.X.Y.Z, libmujoco.X.Y.Z.dylib, mujoco.dll)."""
    candidates = sorted(folder.glob("libmujoco.so.*")) + sorted(folder.glob("libmujoco*.dylib"))
    if not candidates:
        raise CompileError(f"no libmujoco shared library in {folder}")
    return candidates[0]


def _is_rpath(argument: str) -> bool:
    """Whether a linker argument sets a run-time search path."""
    return argument.startswith(("-Wl,-rpath", "-Wl,-R", "-Wl,--enable-new-dtags", "-R"))


class BuildPlugin(build_ext):
    """build_ext for a MuJoCo plugin library: mujoco's headers, libmujoco by path, no rpath."""

    def build_extensions(self) -> None:
        # Python's own link line may carry an rpath (pyenv and similar builds add
        # -Wl,-rpath,<prefix>/lib); the plugin must have none, so drop it.
        linker = getattr(self.compiler, "linker_so", None)
        if linker:
            self.compiler.set_executable("linker_so", [a for a in linker if not _is_rpath(a)])
        super().build_extensions()

    def build_extension(self, ext: Extension) -> None:
        # A CompileError here (like a missing compiler) only skips the optional extension.
        folder = _mujoco_dir()
        ext.include_dirs = [str(folder / "include"), *ext.include_dirs]
        ext.extra_link_args = [str(_mujoco_library(folder)), "-lm", *ext.extra_link_args]
        super().build_extension(ext)

    def get_ext_filename(self, fullname: str) -> str:
        # A plain shared library named after the plugin, not a Python-ABI-tagged module.
        suffix = {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")
        package = fullname.split(".")[:-1]
        return os.path.join(*package, LIBRARY_NAME + suffix)

    def get_export_symbols(self, ext: Extension) -> list[str]:
        return []  # no PyInit_ function: MuJoCo registers the plugin from a library constructor


setup(
    ext_modules=[
        Extension(
            "clearance.contact_plugin._journal_bearing",
            sources=[
                "contact_plugin/clearance_contact.c",
                "contact_plugin/plugin_util.c",
                "contact_plugin/contact_laws.c",
                "contact_plugin/journal_bearing.c",
                "contact_plugin/work_meter.c",
                "contact_plugin/backlash_stop.c",
                "contact_plugin/film.c",
                "contact_plugin/instep.c",
                "contact_plugin/slider_guide.c",
            ],
            extra_compile_args=["-O2", "-std=c99"],
            optional=True,
        )
    ],
    cmdclass={"build_ext": BuildPlugin},
)
