"""The command line run in the test's own process, its output captured."""

from __future__ import annotations

import pytest

from clearance.cli import main


def run_cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int | str | None, str, str]:
    """``clearance ARGV...``: (exit code, stdout, stderr); an argparse exit counts as its code."""
    try:
        code = main(argv)
    except SystemExit as stop:
        code = stop.code
    cap = capsys.readouterr()
    return code, cap.out, cap.err
