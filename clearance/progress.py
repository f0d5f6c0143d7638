"""Progress displays: a tqdm bar on a terminal, a line every few seconds anywhere else.

A bar redraws itself in place with carriage returns; written into a log file or a pipe (a
batch job, CI, ``clearance run > log``) it reads as one line stuck at its first state. Where
stderr is not a terminal `progress_bar` returns a `LineProgress` instead, which prints one
plain line (``simulate: 45% (5.4k of 12k steps), 2.1 s, about 2.6 s left``) at most every
`LINE_EVERY_S` seconds, and a last line at the end of a display that printed any.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Protocol, TextIO

__all__ = ["LINE_EVERY_S", "LineProgress", "ProgressDisplay", "progress_bar"]

LINE_EVERY_S = 10.0
"""Seconds between two progress lines where stderr is not a terminal (``$CLEARANCE_PROGRESS_EVERY_S``)."""


class ProgressDisplay(Protocol):
    """What the package's loops use of a progress display (a subset of tqdm's bar)."""

    n: float

    def update(self, n: float = 1) -> object:
        """Count ``n`` more units done."""
        ...

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        """Show ``s`` beside the count."""
        ...

    def close(self) -> None:
        """End the display."""
        ...


def _every_s() -> float:
    """The interval between progress lines [s]: `LINE_EVERY_S`, or ``$CLEARANCE_PROGRESS_EVERY_S``."""
    text = os.environ.get("CLEARANCE_PROGRESS_EVERY_S", "")
    try:
        value = float(text)
    except ValueError:
        return LINE_EVERY_S
    return value if value >= 0 else LINE_EVERY_S


def _count(x: float) -> str:
    """A count for people: 950, 12k, 3.4M."""
    for factor, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(x) >= factor:
            return f"{x / factor:.3g}{suffix}"
    return f"{x:.4g}"


class LineProgress:
    """A progress display of plain lines, for a stream that is not a terminal.

    Args:
        total: units of the whole task (0 or None: unknown).
        desc: what is counted (``simulate``, ``sweep``).
        unit: the unit's name, singular (``step``, ``point``).
        initial: units already done (a resumed sweep).
        every_s: seconds between two lines (None: `LINE_EVERY_S` or its environment variable).
        stream: where the lines go (default stderr).
    """

    def __init__(
        self,
        total: float | None,
        *,
        desc: str,
        unit: str,
        initial: float = 0,
        every_s: float | None = None,
        stream: TextIO | None = None,
    ) -> None:
        self.total = float(total or 0)
        self.n = float(initial)
        self.desc, self.unit = desc, unit
        self.every_s = _every_s() if every_s is None else every_s
        self.stream = stream
        self.postfix = ""
        self.printed = 0
        self._printed_n = float("nan")
        self._initial = float(initial)
        self._t0 = self._last = time.monotonic()

    def update(self, n: float = 1) -> None:
        """Count ``n`` more units; print a line if `every_s` has passed since the last one."""
        self.n += n
        now = time.monotonic()
        if now - self._last >= self.every_s:
            self._print(now)

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        """Show ``s`` at the end of the next line."""
        self.postfix = s

    def close(self) -> None:
        """Print the last line, if any line was printed and the count moved since."""
        if self.printed and self.n != self._printed_n:
            self._print(time.monotonic(), last=True)

    def _print(self, now: float, *, last: bool = False) -> None:
        elapsed = now - self._t0
        units = self.unit + ("" if self.total == 1 else "s")
        if self.total > 0:
            share = f"{self.n / self.total:.0%} ({_count(self.n)} of {_count(self.total)} {units})"
        else:
            share = f"{_count(self.n)} {units}"
        text = f"{self.desc}: {share}, {elapsed:.1f} s"
        rate = (self.n - self._initial) / elapsed if elapsed > 0 else 0.0
        if not last and self.total > 0 and rate > 0 and self.n < self.total:
            text += f", about {(self.total - self.n) / rate:.1f} s left"
        if last:
            text += ", done" if self.total > 0 and self.n >= self.total else ", stopped"
        if self.postfix:
            text += f" [{self.postfix}]"
        print(text, file=self.stream or sys.stderr, flush=True)
        self.printed += 1
        self._printed_n = self.n
        self._last = now


def progress_bar(
    total: float | None, *, desc: str, unit: str, initial: float = 0, **tqdm_options: object
) -> ProgressDisplay:
    """A progress display: tqdm's bar where stderr is a terminal, else a `LineProgress`.

    Args:
        total: units of the whole task.
        desc: what is counted.
        unit: the unit's name.
        initial: units already done.
        tqdm_options: further options of the tqdm bar (``unit_scale``, ``leave``, ``smoothing``).

    Returns:
        An object with ``n``, ``update``, ``set_postfix_str`` and ``close``.
    """
    if not sys.stderr.isatty():
        return LineProgress(total, desc=desc, unit=unit, initial=initial)
    from tqdm import tqdm

    bar: ProgressDisplay = tqdm(total=total, desc=desc, unit=unit, initial=initial, **tqdm_options)
    return bar
