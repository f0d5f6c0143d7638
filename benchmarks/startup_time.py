"""Time of the default ``clearance run``, from typing it to every output written.

Usage:  python benchmarks/startup_time.py [--runs 5] [--out benchmarks/startup_time.md]

The console script (``clearance`` beside this Python) runs ``clearance run --out <tmp>`` once
as a warm-up (it fills the calibration cache and the file system's caches), then ``--runs``
times, each into a fresh folder, and the wall time from starting the process to its exit is
taken. Every run must exit with status 0, write the same files as the warm-up (the fixed
outputs, and every figure its report.md links to, none empty), and leave no process behind
(it runs in a session of its own; after its exit that session must be empty). The median of
the runs is the number; the goal is 1.5 s.

A further run, ``python -X importtime`` calling the command's entry point as the console
script does, gives the breakdown: every import (from the import-time lines, self times summed
by package, so nothing is counted twice), the command's stages (model building, stepping,
summary, report and figures, file writing), each less the imports made inside it, and the
interpreter's exit after the command returned. Its total is that of one profiled run; what
none of these accounts for (interpreter start, argument parsing, console lines, garbage
collection) is "the rest". mujoco's own import and the plugin load are timed on their own.

Timings on a machine shared with other work vary: the load average at the start is written
beside the table.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.abc
import importlib.machinery
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import types
from collections import defaultdict
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

GOAL_S = 1.5
"""The median the default run should not exceed [s]."""

FIXED_OUTPUTS = (
    "result.npz",
    "result.json",
    "ideal.npz",
    "ideal.json",
    "summary.csv",
    "reactions.csv",
    "report.md",
    "model.xml",
    "ideal_model.xml",
)
"""Files every default run writes besides its figures (README's table)."""

WRITING = "writing files other than PNG (arrays, models, summary, report text)"

STAGES: dict[str, dict[str, str]] = {
    "clearance.run.preparation": {"prepare": "model building (the run's and the ideal twin's)"},
    "clearance.run.simulation": {"simulate_prepared": "stepping (both runs, with the readout)"},
    "clearance.analysis.metrics.summary": {"summarise": "summary numbers"},
    "clearance.analysis.figures.report": {"write_report": "report and figures (drawing, PNG writing)"},
    "clearance.results": {
        "SimulationResult.save": WRITING,
        "atomic_write_text": WRITING,
        "atomic_write_bytes": WRITING,
    },
}
"""Module -> {function or Class.method: stage}: the stages of the profiled run."""

PACKAGES = ("numpy", "mujoco", "scipy", "matplotlib", "PIL", "clearance", "rerun", "tqdm")
"""Packages whose import time is shown on its own line, each with the modules it imports that
no other of them imports first (glfw with mujoco, pyparsing with matplotlib, ...)."""

MARK = "startup-stage"
"""Prefix of the stage marks written to stderr between the import-time lines."""


def console_script() -> str:
    """The ``clearance`` console script of this Python's environment."""
    here = Path(sys.executable).parent / ("clearance.exe" if os.name == "nt" else "clearance")
    found = str(here) if here.exists() else shutil.which("clearance")
    if found is None:
        sys.exit("error: no 'clearance' console script beside this Python or on PATH: pip install -e .")
    return found


def expected_files(folder: Path) -> set[str]:
    """The fixed outputs and every figure the folder's report.md links to."""
    report = (folder / "report.md").read_text(encoding="utf-8") if (folder / "report.md").exists() else ""
    return set(FIXED_OUTPUTS) | set(re.findall(r"\]\(([^)\s]+\.png)\)", report))


def check_outputs(folder: Path, reference: set[str] | None) -> set[str]:
    """Every expected output is there and not empty (and the same set as ``reference``); returns the set."""
    written = {p.name for p in folder.iterdir() if p.is_file()}
    missing = sorted(n for n in expected_files(folder) if n not in written or (folder / n).stat().st_size == 0)
    if missing:
        raise SystemExit(f"error: {folder} lacks (or has empty) {missing}")
    if reference is not None and written != reference:
        raise SystemExit(f"error: {folder} holds {sorted(written ^ reference)} unlike the warm-up run")
    return written


def timed_run(script: str, folder: Path) -> float:
    """Wall time [s] of ``clearance run --out folder`` from start to exit; checks status and leftovers."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [script, "run", "--out", str(folder)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    _, stderr = proc.communicate()
    elapsed = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"error: clearance run exited with {proc.returncode}:\n{stderr}")
    try:  # the run had a session (and process group) of its own: nothing may be left in it
        os.killpg(proc.pid, 0)
    except ProcessLookupError:
        pass
    else:
        raise SystemExit(f"error: processes of the run (group {proc.pid}) are still alive after its exit")
    return elapsed


# -- the profiled run (a child process) ---------------------------------------------------------


class _StageTimer:
    """Wall time of each stage, less the time of stages nested in it; marks stderr at each edge."""

    def __init__(self) -> None:
        self.exclusive: dict[str, float] = defaultdict(float)
        self._stack: list[list[Any]] = []

    def wrap(self, stage: str, func: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any, **kwargs: Any) -> Any:
            print(f"{MARK} begin {stage}", file=sys.stderr, flush=True)
            frame = [stage, time.perf_counter(), 0.0]
            self._stack.append(frame)
            try:
                return func(*args, **kwargs)
            finally:
                self._stack.pop()
                total = time.perf_counter() - frame[1]
                self.exclusive[stage] += total - frame[2]
                if self._stack:
                    self._stack[-1][2] += total
                print(f"{MARK} end {stage}", file=sys.stderr, flush=True)

        return timed


class _PatchOnImport(importlib.abc.MetaPathFinder):
    """Wraps the staged functions of a module as soon as it has been executed (no early import)."""

    def __init__(self, timer: _StageTimer) -> None:
        self.timer = timer

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: types.ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname not in STAGES:
            return None
        spec = None
        for finder in sys.meta_path:  # the others (the editable install's maps package folders)
            if finder is not self and hasattr(finder, "find_spec"):
                spec = finder.find_spec(fullname, path, target)
                if spec is not None:
                    break
        if spec is None or spec.loader is None:
            return spec
        loader, timer = spec.loader, self.timer
        execute = loader.exec_module

        def exec_module(module: types.ModuleType) -> None:
            execute(module)
            for dotted, stage in STAGES[fullname].items():
                *owner_path, name = dotted.split(".")
                owner: Any = module
                for part in owner_path:
                    owner = getattr(owner, part)
                setattr(owner, name, timer.wrap(stage, getattr(owner, name)))

        loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec


def profiled_child(out: str, result_file: str) -> None:
    """Run the default command in this process with stage timers; write the stage times as JSON."""
    timer = _StageTimer()
    sys.meta_path.insert(0, _PatchOnImport(timer))
    t0 = time.perf_counter()
    from clearance.cli import main

    sys.argv = ["clearance", "run", "--out", out, "--no-progress"]
    status = main()  # as the console script calls it (so with its exit)
    total = time.perf_counter() - t0
    Path(result_file).write_text(
        json.dumps({"status": status, "stages": timer.exclusive, "in_process": total, "returned_at": time.time()})
    )


def _import_lines(stderr: str) -> list[tuple[str | None, float, float, int, str]]:
    """(stage open when it ended, self [s], cumulative [s], depth, package) of each import-time line.

    The package is the first of `PACKAGES` met going up from the module through the modules
    that imported it ("other": the standard library and the like, imported by none of them).
    """
    rows: list[tuple[str | None, float, float, int, str]] = []
    stack: list[str] = []
    for line in stderr.splitlines():
        if line.startswith(MARK):
            _, edge, stage = line.split(" ", 2)
            if edge == "begin":
                stack.append(stage)
            else:
                stack.pop()
        elif line.startswith("import time:") and "self [us]" not in line:
            own, cumulative, name = line[len("import time:") :].split("|")
            depth = (len(name) - len(name.lstrip()) - 1) // 2  # one space, then two per level
            rows.append((stack[-1] if stack else None, int(own) * 1e-6, int(cumulative) * 1e-6, depth, name.strip()))
    # lines come children first; read backwards, a line's importer is the last one seen a level up
    owner: dict[int, str] = {}
    for i in range(len(rows) - 1, -1, -1):
        stage, own, cumulative, depth, name = rows[i]
        root = name.split(".")[0]
        package = root if root in PACKAGES else owner.get(depth - 1, "other")
        owner[depth] = package
        rows[i] = (stage, own, cumulative, depth, package)
    return rows


def breakdown() -> dict[str, Any]:
    """One profiled run: wall time, import time by package and by stage, and the stages less imports."""
    with tempfile.TemporaryDirectory() as tmp:
        stages_file = Path(tmp) / "stages.json"
        t0 = time.perf_counter()
        proc = subprocess.run(
            [sys.executable, "-X", "importtime", __file__, "--profile-child", str(Path(tmp) / "out"), str(stages_file)],
            capture_output=True,
            text=True,
        )
        wall = time.perf_counter() - t0
        ended = time.time()
        child = json.loads(stages_file.read_text()) if stages_file.exists() else {"status": None}
        if proc.returncode != 0 or child["status"] != 0:
            raise SystemExit(f"error: the profiled run failed:\n{proc.stderr[-3000:]}")
    rows = _import_lines(proc.stderr)
    by_package: dict[str, float] = defaultdict(float)
    in_stage: dict[str | None, float] = defaultdict(float)
    for stage, own, cumulative, depth, package in rows:
        by_package[package] += own
        if depth == 0:  # a top-level import: its own and its children's time
            in_stage[stage] += cumulative
    imports = sum(by_package.values())
    stages = {stage: max(0.0, t - in_stage.get(stage, 0.0)) for stage, t in child["stages"].items()}
    return {
        "wall": wall,
        "imports": imports,
        "imports_in_stages": sum(v for k, v in in_stage.items() if k is not None),
        "by_package": dict(by_package),
        "mujoco": mujoco_costs(),
        "stages": stages,
        "exit": ended - child["returned_at"],
        "rest": wall - imports - sum(stages.values()) - (ended - child["returned_at"]),
    }


MUJOCO_CHILD = """
import importlib.metadata as md, json, time
import numpy
entry_points = md.entry_points
md.entry_points = lambda **kw: [] if kw.get("group") == "mujoco.plugins" else entry_points(**kw)
t0 = time.perf_counter()
import mujoco
t1 = time.perf_counter()
md.entry_points = entry_points
import clearance.contact_plugin as plugin
t2 = time.perf_counter()
plugin.load()
t3 = time.perf_counter()
print(json.dumps([t1 - t0, t3 - t2, plugin.is_available()]))
"""
"""``import mujoco`` (numpy already imported) with its plugin entry points held back, then the
compiled contact plugin loaded."""


def mujoco_costs(repeats: int = 5) -> tuple[float, float]:
    """Medians over fresh interpreters: (import mujoco after numpy, without plugins [s]; loading ours [s])."""
    imports, loads = [], []
    for _ in range(repeats):
        out = subprocess.run([sys.executable, "-c", MUJOCO_CHILD], capture_output=True, text=True, check=True)
        t_import, t_load, loaded = json.loads(out.stdout)
        if not loaded:
            raise SystemExit("error: the compiled contact plugin is not installed: the default run cannot be timed")
        imports.append(t_import)
        loads.append(t_load)
    return statistics.median(imports), statistics.median(loads)


def _git_state() -> str:
    root = Path(__file__).resolve().parents[1]
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"], cwd=root, capture_output=True, text=True
        )
        return commit + (" with uncommitted changes in the working tree" if dirty.stdout.strip() else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown (not a git checkout)"


def _table(times: list[float], prof: dict[str, Any], load: str, script: str) -> str:
    median = statistics.median(times)
    verdict = "meets" if median <= GOAL_S else "misses"
    lines = [
        "# Start-up: the default `clearance run`, start to exit",
        "",
        "```",
        "clearance run --out <fresh folder>     # 5 times, after one warm-up run",
        "python benchmarks/startup_time.py     # this table",
        "```",
        "",
        f"{datetime.date.today().isoformat()}, commit {_git_state()}; {platform.python_implementation()} "
        f"{platform.python_version()} on {platform.machine()}, {os.cpu_count()} CPUs, load average {load} at the start; "
        f"console script {Path(script).name} (default scenario: slider-crank, c = 0.5 mm, 5000 rpm, 3 revolutions, "
        "exact contact at 3 µs, warm calibration cache). Each run exited with status 0, wrote every output "
        "(the fixed files and every figure its report links to) and left no process behind.",
        "",
        "| run | wall time [s] |",
        "|---|---|",
        *[f"| {i + 1} | {t:.3f} |" for i, t in enumerate(times)],
        f"| **median** | **{median:.3f}** |",
        "",
        f"The median {verdict} the goal of {GOAL_S} s.",
        "",
        f"## Breakdown of one profiled run ({prof['wall']:.3f} s under `python -X importtime`, in-process)",
        "",
        "| part | time [s] |",
        "|---|---|",
        f"| imports, all (of them inside the stages below: {prof['imports_in_stages']:.3f}) | {prof['imports']:.3f} |",
        *[
            f"| &nbsp;&nbsp;{pkg} | {t:.3f} |"
            for pkg, t in sorted(prof["by_package"].items(), key=lambda kv: -kv[1])
            if t >= 0.0005
        ],
        *[f"| {stage}, less its imports | {t:.3f} |" for stage, t in prof["stages"].items()],
        f"| the interpreter's exit, after the command returned | {prof['exit']:.3f} |",
        f"| the rest (interpreter start, argument parsing, console lines, garbage collection) | {prof['rest']:.3f} |",
        "",
        "Imports are the self times of the import-time lines, summed by package: each module counts "
        "for the first of those packages met going up through the modules that imported it "
        "(`mujoco` holds glfw, which its renderer imports, and the compiled contact plugin, loaded "
        "by its import through the `mujoco.plugins` entry point; `matplotlib` holds pyparsing and "
        "its other dependencies; `clearance` is this package's own modules and what they alone "
        "import; `other`: the standard library imported by none of them). Each stage is the wall "
        "time of its functions less the stages nested in it and less the imports made inside it.",
        "",
        f"mujoco on its own, median of 5 fresh interpreters: `import mujoco` {prof['mujoco'][0]:.3f} s "
        f"(numpy already imported, its plugin entry points held back), then loading the compiled contact plugin "
        f"(`clearance.contact_plugin.load`, what the entry point calls) {prof['mujoco'][1] * 1e3:.1f} ms. Both are "
        "paid by every process that imports mujoco.",
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=5, help="timed runs (default 5)")
    ap.add_argument("--out", default=str(Path(__file__).with_name("startup_time.md")), help="table to write")
    ap.add_argument("--profile-child", nargs=2, metavar=("OUT", "JSON"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.profile_child:
        profiled_child(*args.profile_child)
        return
    if args.runs < 1:
        ap.error(f"--runs must be >= 1 (got {args.runs})")
    script = console_script()
    load = " / ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "unknown"
    with tempfile.TemporaryDirectory() as tmp:
        warm = Path(tmp) / "warm-up"
        print(f"warm-up: {script} run --out {warm}", flush=True)
        timed_run(script, warm)
        reference = check_outputs(warm, None)
        times = []
        for i in range(args.runs):
            folder = Path(tmp) / f"run{i + 1}"
            times.append(timed_run(script, folder))
            check_outputs(folder, reference)
            print(f"run {i + 1}: {times[-1]:.3f} s", flush=True)
    prof = breakdown()
    from _tables import write_keeping_reading  # here: it imports clearance, which the profiled run must not find loaded

    text = write_keeping_reading(args.out, _table(times, prof, load, script))
    print(text)


if __name__ == "__main__":
    main()
