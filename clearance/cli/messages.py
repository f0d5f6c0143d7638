"""How the commands report a refusal or a fault: one line on stderr, exit status 2 or 1."""

from __future__ import annotations

import sys

__all__ = ["FAULT", "USAGE_ERROR", "error", "one_line"]

USAGE_ERROR = 2
"""Exit status of a command refused (bad input) or stopped by an error."""

FAULT = 1
"""Exit status of a command stopped by a fault during its work (a full disk, a folder gone read-only)."""


def one_line(text: str) -> str:
    """``text`` on one line: its lines joined with '; ' (MuJoCo's compiler errors span two)."""
    return "; ".join(part.strip() for part in str(text).splitlines() if part.strip())


def error(message: object, *, prefix: str = "error") -> int:
    """Print ``<prefix>: message`` on one line to stderr; return `USAGE_ERROR`."""
    print(f"{prefix}: {one_line(str(message))}", file=sys.stderr)
    return USAGE_ERROR
