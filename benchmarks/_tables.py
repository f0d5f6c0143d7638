"""Writing a benchmark's generated table while keeping its hand-written reading.

A benchmark script regenerates the top of its Markdown file; the text from a ``## Reading``
heading on is written by hand from the numbers and is kept across reruns.
"""

from __future__ import annotations

from pathlib import Path

from clearance.results import atomic_write_text

READING = "\n## Reading"


def write_keeping_reading(path: str | Path, generated: str) -> str:
    """Write ``generated`` to ``path`` (atomically), followed by the file's old reading, if any.

    Returns:
        The text written.
    """
    p = Path(path)
    old = p.read_text(encoding="utf-8") if p.exists() else ""
    text = generated + (old[old.index(READING) :] if READING in old else "")
    atomic_write_text(p, text)
    return text
