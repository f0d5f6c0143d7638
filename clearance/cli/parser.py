"""The argument parser every command uses: a refused option is one line, the usage block is for --help.

argparse prints its whole usage block (a dozen lines for ``clearance run``) before an error;
the commands print one line instead, naming the command, the option, the value and what was
expected, and where the options are described: ``clearance run: error: argument --rpm: --rpm
must be a number (got 'abc'); see 'clearance run --help'``. The exit status stays argparse's 2.
"""

from __future__ import annotations

import argparse
import sys
from typing import NoReturn

from clearance.cli.messages import USAGE_ERROR, one_line

__all__ = ["CommandParser", "VersionAction", "version_text"]


class CommandParser(argparse.ArgumentParser):
    """An `argparse.ArgumentParser` whose errors are one line on stderr (exit status 2).

    Sub-command parsers made with ``add_subparsers`` are of the same class, so every command
    of ``clearance`` refuses a bad option the same way.
    """

    def error(self, message: str) -> NoReturn:
        """Print ``<prog>: error: <message>; see '<prog> --help'`` on one line and exit with status 2."""
        self.exit(USAGE_ERROR, f"{self.prog}: error: {one_line(message)}; see '{self.prog} --help'\n")

    def exit(self, status: int = 0, message: str | None = None) -> NoReturn:
        """Exit with ``status`` after writing ``message`` (if any) to stderr, flushed first."""
        sys.stdout.flush()
        super().exit(status, message)


class VersionAction(argparse.Action):
    """``--version``: print `version_text` and exit 0; the versions are looked up only when asked for."""

    def __init__(self, option_strings: list[str], dest: str = argparse.SUPPRESS, **kwargs: object) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, help="print the versions and exit")

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        print(version_text())
        parser.exit()


def version_text() -> str:
    """``clearance <version> (mujoco <version>, Python <version>)``, without importing MuJoCo."""
    from importlib.metadata import PackageNotFoundError, version

    from clearance.version import __version__

    try:
        mujoco = version("mujoco")
    except PackageNotFoundError:
        mujoco = "not installed"
    py = ".".join(str(v) for v in sys.version_info[:3])
    return f"clearance {__version__} (mujoco {mujoco}, Python {py})"
