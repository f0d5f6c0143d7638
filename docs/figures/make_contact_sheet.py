"""Every figure of every catalogue mechanism at 3 and 20 revolutions: one PNG page per mechanism.

Usage:
    python docs/figures/make_contact_sheet.py                 # every mechanism, 3 and 20 revolutions
    python docs/figures/make_contact_sheet.py --mechanisms slider_crank ten_bar
    python docs/figures/make_contact_sheet.py --redraw        # the runs kept in --work, figures redrawn

Each column of a page is one run, made as ``clearance run --mechanism M --revolutions R`` makes
it: the command's preparation and simulation of the run and its ideal twin (default options),
then the report with every figure (`write_report`, the start-up window of one drive period, the
joint reactions' summary), written into ``<work>/<mechanism>/<R>rev``. Each row of the page is one
figure of the report, in the report's order, scaled down to the column's width; a figure a run's
report does not draw (a Poincaré section below its minimum of points) is named in its cell. The
page's head names the commands and the commit.

The ten-bar and the seven-bar press also get a page with a clearance at every joint that can
carry one (``--clearance-at`` all of them), so the contact figures are seen at their joint counts.

A run longer than ``--max-rows`` steps (the press at 20 revolutions: 13.3 million steps of 3 µs)
keeps every k-th step (`simulate_prepared`'s ``output_interval``) so that both runs fit in memory;
the column's head says so. The runs' arrays are kept in the work folder (``result.npz``,
``ideal.npz``) so that ``--redraw`` redraws the figures without simulating again.

Writes ``<out>/<page>.png`` per page and ``<out>/contact_sheet.md`` (the pages, the command, the
commit, the time taken).
"""

from __future__ import annotations

import argparse
import datetime
import gc
import math
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

ROOT = Path(__file__).resolve().parents[2]

REVOLUTIONS = (3.0, 20.0)
"""Run lengths of the columns [revolutions of the slowest speed-driven crank]."""

EVERY_JOINT = ("ten_bar", "seven_bar_press")
"""Mechanisms that also get a page with a clearance at every joint that can carry one."""

EVERY_JOINT_REVOLUTIONS = {"ten_bar": (3.0, 20.0), "seven_bar_press": (3.0,)}
"""Run lengths of those pages (the press's 20 revolutions with seven journals would take hours)."""

MAX_ROWS = 3_000_000
"""Rows per run kept at most (two runs of 3 million rows of the press take about 4 GB)."""

COLUMN_PX = 1100
"""Width of a page's column [pixels]: a wider figure is scaled down to it."""

_MARGIN = 24
_HEAD_PX = 120
_LABEL_PX = 26


@dataclass(frozen=True)
class Page:
    """One page: a mechanism, its clearance joints (None: the builder's) and its run lengths."""

    name: str
    mechanism: str
    clearance_at: tuple[str, ...] | None
    revolutions: tuple[float, ...]

    def command(self, revolutions: float) -> str:
        """The ``clearance run`` command of one column."""
        cmd = f"clearance run --mechanism {self.mechanism} --revolutions {revolutions:g}"
        if self.clearance_at:
            cmd += " --clearance-at " + " ".join(self.clearance_at)
        return cmd


def pages(names: list[str] | None) -> list[Page]:
    """The pages: every catalogue mechanism, then the every-joint pages."""
    from clearance.builders import CATALOGUE

    out = [Page(m, m, None, REVOLUTIONS) for m in CATALOGUE]
    out += [Page(f"{m}_every_joint", m, CATALOGUE[m].info.clearable, EVERY_JOINT_REVOLUTIONS[m]) for m in EVERY_JOINT]
    if names:
        unknown = sorted(set(names) - {p.name for p in out})
        if unknown:
            sys.exit(f"error: --mechanisms {' '.join(unknown)}: no such page (pages: {', '.join(p.name for p in out)})")
        out = [p for p in out if p.name in names]
    return out


def run_folder(work: Path, page: Page, revolutions: float) -> Path:
    """Where one column's run, report and figures are kept."""
    return work / page.name / f"{revolutions:g}rev"


def make_run(page: Page, revolutions: float, folder: Path, *, redraw: bool, max_rows: int, commit: str) -> str:
    """Simulate (or load, with ``redraw``) one column's run and write its report; returns the column's note.

    A simulated run's folder records the commit it was simulated at (``simulated_at.txt``).
    """
    from clearance.analysis.figures.report import write_report
    from clearance.analysis.metrics.reactions import summarise_reactions
    from clearance.builders import CATALOGUE
    from clearance.options import ModelOptions
    from clearance.results import SimulationResult
    from clearance.run.preparation import prepare
    from clearance.run.simulation import default_duration, simulate_prepared

    builder = CATALOGUE[page.mechanism].builder
    mech = builder() if page.clearance_at is None else builder(clearance_at=page.clearance_at)
    options = ModelOptions()
    duration = default_duration(mech, revolutions)
    steps = math.ceil(duration / options.timestep)
    every = max(1, math.ceil(steps / max_rows))
    note = "" if every == 1 else f"rows kept every {every} steps ({steps:,} steps; all of them need too much memory)"
    folder.mkdir(parents=True, exist_ok=True)
    if redraw and (folder / "result.npz").exists():
        result, ideal = SimulationResult.load(folder / "result"), SimulationResult.load(folder / "ideal")
    else:
        interval = None if every == 1 else every * options.timestep
        result = simulate_prepared(prepare(mech, options), duration=duration, output_interval=interval)
        ideal = simulate_prepared(prepare(mech.ideal_twin(), options), duration=duration, output_interval=interval)
        result.save(folder / "result")
        ideal.save(folder / "ideal")
        (folder / "simulated_at.txt").write_text(f"{commit} {datetime.datetime.now().isoformat(timespec='minutes')}\n")
    for old in folder.glob("*.png"):
        old.unlink()
    skip = mech.drive_period or 0.0
    reactions = summarise_reactions(result, ideal, startup=skip)
    t0 = time.perf_counter()
    write_report(folder, result, ideal, skip=skip, processes=2, reactions=reactions)
    print(f"  {page.name} {revolutions:g} rev: {len(result.times):,} rows, report {time.perf_counter() - t0:.1f} s")
    del result, ideal
    gc.collect()
    return note


def report_figures(folder: Path) -> list[str]:
    """The PNGs a report links to, in its order."""
    import re

    text = (folder / "report.md").read_text(encoding="utf-8")
    return list(dict.fromkeys(re.findall(r"\]\(([^)\s]+\.png)\)", text)))


def _font(size: int) -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    from matplotlib import font_manager

    try:
        return ImageFont.truetype(font_manager.findfont("DejaVu Sans"), size)
    except OSError:
        return ImageFont.load_default()


def compose(page: Page, columns: list[tuple[str, str, Path]], path: Path, commit: str) -> None:
    """One page: a column per run (command, note, folder), a row per figure, scaled to the column."""
    names: list[str] = []
    for _, _, folder in columns:
        names += [n for n in report_figures(folder) if n not in names]
    cells: list[list[Image.Image | None]] = []
    heights = []
    for name in names:
        row = []
        for _, _, folder in columns:
            f = folder / name
            if f.exists() and name in report_figures(folder):
                im = Image.open(f).convert("RGB")
                if im.width > COLUMN_PX:  # scaled down to the column, never up
                    im = im.resize((COLUMN_PX, round(im.height * COLUMN_PX / im.width)), Image.Resampling.LANCZOS)
                row.append(im)
            else:
                row.append(None)
        cells.append(row)
        heights.append(max((im.height for im in row if im is not None), default=60))
    width = 2 * _MARGIN + len(columns) * COLUMN_PX + (len(columns) - 1) * _MARGIN
    height = _HEAD_PX + sum(h + _LABEL_PX + _MARGIN for h in heights) + _MARGIN
    sheet = Image.new("RGB", (width, height), "white")
    pen = ImageDraw.Draw(sheet)
    big, small = _font(26), _font(17)
    title = page.mechanism + ("" if page.clearance_at is None else ", a clearance at every joint that can carry one")
    pen.text((_MARGIN, 14), title, font=big, fill="black")
    pen.text(
        (_MARGIN, 50),
        f"python docs/figures/make_contact_sheet.py --mechanisms {page.name}   (commit {commit})",
        font=small,
        fill=(70, 70, 70),
    )
    for c, (cmd, note, _) in enumerate(columns):
        x = _MARGIN + c * (COLUMN_PX + _MARGIN)
        pen.text((x, 80), cmd, font=small, fill=(20, 20, 120))
        if note:
            pen.text((x, 100), note, font=_font(14), fill=(150, 60, 0))
    y = _HEAD_PX
    for name, row, h in zip(names, cells, heights):
        for c, im in enumerate(row):
            x = _MARGIN + c * (COLUMN_PX + _MARGIN)
            pen.text((x, y + 2), name, font=small, fill=(90, 90, 90))
            if im is None:
                pen.text(
                    (x, y + _LABEL_PX + 10),
                    "not drawn by this run's report (see its report.md)",
                    font=small,
                    fill="gray",
                )
            else:
                sheet.paste(im, (x, y + _LABEL_PX))
        y += h + _LABEL_PX + _MARGIN
    # a palette of 256 colours: the figures are flat colours, the page a third of the size
    sheet.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(path, optimize=True)


def _commit() -> str:
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
        return out.stdout.strip() or "unknown"
    except OSError:
        return "unknown"


def main(argv: list[str] | None = None) -> int:
    """Make the pages asked for; write the index."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--mechanisms", nargs="*", default=None, help="pages to make (default: all)")
    p.add_argument("--work", default="/tmp/clearance-contact-sheet", help="folder for the runs and their reports")
    p.add_argument("--out", default=str(Path(__file__).resolve().parent), help="folder for the pages")
    p.add_argument("--redraw", action="store_true", help="load the runs kept in --work instead of simulating")
    p.add_argument("--max-rows", type=int, default=MAX_ROWS, help="rows per run kept at most")
    args = p.parse_args(argv)
    work, out = Path(args.work), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    commit = _commit()
    t0 = time.perf_counter()
    done = []
    for page in pages(args.mechanisms):
        print(f"{page.name}:", flush=True)
        columns = []
        for rev in page.revolutions:
            folder = run_folder(work, page, rev)
            note = make_run(page, rev, folder, redraw=args.redraw, max_rows=args.max_rows, commit=commit)
            columns.append((page.command(rev), note, folder))
        compose(page, columns, out / f"{page.name}.png", commit)
        done.append(page)
    minutes = (time.perf_counter() - t0) / 60
    index = [
        "# Contact sheet: every figure of every catalogue mechanism",
        "",
        f"Made by `python docs/figures/make_contact_sheet.py` at commit {commit} on "
        f"{datetime.date.today().isoformat()} ({minutes:.0f} min on {_cpus()} CPUs). One page per mechanism: a "
        "column per run length (the command above it), a row per figure of the run's report.",
        "",
    ]
    index += [f"- [{p.name}]({p.name}.png): " + "; ".join(f"`{p.command(r)}`" for r in p.revolutions) for p in done]
    stamps = sorted({_stamp(run_folder(work, p, r)) for p in done for r in p.revolutions})
    if args.redraw:
        index += ["", f"Figures redrawn from the runs kept in the work folder, simulated at: {'; '.join(stamps)}."]
    (out / "contact_sheet.md").write_text("\n".join(index) + "\n", encoding="utf-8")
    return 0


def _stamp(folder: Path) -> str:
    """The commit and time a kept run was simulated at ("unknown" for a run kept without them)."""
    f = folder / "simulated_at.txt"
    return f.read_text().strip() if f.exists() else "unknown"


def _cpus() -> int:
    import os

    return os.cpu_count() or 1


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
