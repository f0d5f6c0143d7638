"""Every retrofit checked on a fixed, versioned list of third-party robots.

    pip install --no-deps robosuite==1.5.2 gymnasium-robotics==1.4.2   (the extra "corpus"; --no-deps keeps numpy)
    python benchmarks/retrofit_corpus.py [--models panda,ur5e] [--fresh] [--table-only]

For each model of `CORPUS` and each operation (radial play and backlash with the exact contact or
stop; with a calibrated ring or stop on the `CALIBRATED` subset) `clearance.run.retrofit_check`
tries every hinge alone (eligible, ineligible or refused for a listed reason), then retrofits the
accepted hinges together and checks the invariants: compiles; masses; ranges, reference angles,
constraint softness, sensors, actuators, keyframes; zero play reproduces the twin over 0.1 s (with
the twin's own sensitivity to a rounding-size nudge); ring precision. Each model's results are
written to ``retrofit_corpus_parts/<model>.json`` as soon as they are done: a rerun skips the models
already there (``--fresh`` redoes them), so the corpus runs in parts on a shared machine. The
table (``retrofit_corpus.md``) is rebuilt from every part present, with the load each part ran at.
Calibrations read and write the usual store (a second run is warm).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import importlib.util
import json
import math
import os
import platform
import subprocess
import sys
import time
import warnings
from pathlib import Path

import mujoco
from _tables import write_keeping_reading

from clearance.results import atomic_write_text
from clearance.retrofit.play import Refusal
from clearance.run.retrofit_check import DRIVE, DURATION, INELIGIBLE, Operation, OperationCheck, check_operation

CORPUS_VERSION = 2
"""Raise when the list, an operation or a check changes: parts of another version are redone."""

PACKAGES = {"robosuite": "1.5.2", "gymnasium_robotics": "1.4.2", "gymnasium": "1.4.0"}
"""Import name -> the version the corpus was written against (another one is run, and said so)."""

_DIST = {"robosuite": "robosuite", "gymnasium_robotics": "gymnasium-robotics", "gymnasium": "gymnasium"}

CORPUS: dict[str, tuple[str, str]] = {
    "panda": ("robosuite", "models/assets/robots/panda/robot.xml"),
    "panda_qpos0": ("robosuite", "models/assets/robots/panda/robot.xml"),
    "ur5e": ("robosuite", "models/assets/robots/ur5e/robot.xml"),
    "iiwa": ("robosuite", "models/assets/robots/iiwa/robot.xml"),
    "kinova3": ("robosuite", "models/assets/robots/kinova3/robot.xml"),
    "jaco": ("robosuite", "models/assets/robots/jaco/robot.xml"),
    "sawyer": ("robosuite", "models/assets/robots/sawyer/robot.xml"),
    "xarm7": ("robosuite", "models/assets/robots/xarm7/robot.xml"),
    "fetch": ("gymnasium_robotics", "envs/assets/fetch/reach.xml"),
    "shadow_hand": ("gymnasium_robotics", "envs/assets/hand/reach.xml"),
    "ant": ("gymnasium", "envs/mujoco/assets/ant.xml"),
    "half_cheetah": ("gymnasium", "envs/mujoco/assets/half_cheetah.xml"),
    "hopper": ("gymnasium", "envs/mujoco/assets/hopper.xml"),
    "humanoid": ("gymnasium", "envs/mujoco/assets/humanoid.xml"),
    "walker2d": ("gymnasium", "envs/mujoco/assets/walker2d.xml"),
    "swimmer": ("gymnasium", "envs/mujoco/assets/swimmer.xml"),
}
"""Model -> (package, its file inside the package), version `CORPUS_VERSION`."""

START: dict[str, tuple[float, ...]] = {
    "panda": (0.0, math.pi / 16, 0.0, -math.pi / 2 - math.pi / 3, 0.0, math.pi - 0.2, math.pi / 4),
    "ur5e": (-0.470, -1.735, 2.480, -2.275, -1.590, -1.991),
    "iiwa": (0.000, 0.650, 0.000, -1.890, 0.000, 0.600, 0.000),
    "kinova3": (0.000, 0.650, 0.000, 1.890, 0.000, 0.600, -math.pi / 2),
    "jaco": (3.192, 3.680, -0.000, 1.170, 0.050, 3.760, 3.142),
    "sawyer": (0.0, -1.18, 0.00, 2.18, 0.00, 0.57, -1.57),
    "xarm7": (0.0, 0.0, 0.0, 0.39 * math.pi, 0.0, 0.39 * math.pi, 0.0),
}
"""Each robosuite arm's start pose [rad], its joints in model order: ``init_qpos`` of its robot class in
robosuite 1.5.2 (robosuite/models/robots/manipulators/<name>_robot.py), where robosuite starts it; the
model file has no keyframe, and its qpos0 is not a pose robosuite uses (the Panda's fifth and seventh
links interpenetrate by 5 mm there and its fourth joint is 0.07 rad outside its range). The checks
start from it as the model's first keyframe. ``panda_qpos0`` is the Panda from qpos0, kept in the table
to show what such a start does."""

OUTSIDE_SUMMARY = ("panda_qpos0",)
"""Rows of the table not counted in its summary (a corpus model again, from another start)."""

CALIBRATED = ("ur5e", "half_cheetah")
"""Models also checked with calibrated rings and stops (a calibration costs seconds to minutes cold)."""

HERE = Path(__file__).resolve().parent
PARTS = HERE / "retrofit_corpus_parts"


def model_path(package: str, inside: str) -> Path:
    """The model file inside an installed package (found without importing it)."""
    spec = importlib.util.find_spec(package)
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit(
            f"{package} is not installed: pip install --no-deps robosuite==1.5.2 gymnasium-robotics==1.4.2"
        )
    return Path(next(iter(spec.submodule_search_locations))) / inside


def _commit() -> str:
    """The commit the package runs from (``git describe --always --dirty``), or 'unknown'."""
    out = subprocess.run(
        ["git", "-C", str(HERE), "describe", "--always", "--dirty"], capture_output=True, text=True, check=False
    )
    return out.stdout.strip() or "unknown"


def _operations(name: str) -> list[Operation]:
    ops = [Operation.RADIAL_EXACT, Operation.BACKLASH_EXACT]
    return ops + ([Operation.RADIAL_CALIBRATED, Operation.BACKLASH_CALIBRATED] if name in CALIBRATED else [])


def _record(check: OperationCheck) -> dict:
    z = check.zero_play
    return {
        "operation": check.operation.value,
        "hinges": check.hinges,
        "ineligible": {h: r.name for h, r in check.ineligible.items()},
        "refused": {h: (r.name if isinstance(r, Refusal) else f"unlisted: {r}") for h, r in check.refused.items()},
        "accepted": check.accepted,
        "broken": check.broken,
        "tracebacks": check.tracebacks,
        "timestep": check.timestep,
        "seconds": round(check.seconds, 1),
        "loops": check.loops,
        "zero_play": None
        if z is None
        else {"site": z.site, "deviation": z.deviation, "bound": z.bound, "sensitivity": z.sensitivity},
    }


def run_model(name: str) -> dict:
    """Every operation on one model; its part (also written to `PARTS`)."""
    package, inside = CORPUS[name]
    path = model_path(package, inside)
    load0, t0 = os.getloadavg()[0], time.perf_counter()
    spec = mujoco.MjSpec.from_file(str(path))
    if name in START:
        start = START[name]
        if spec.compile().nq != len(start) or spec.keys:
            raise SystemExit(f"{name}: {inside} has changed (coordinates or keyframes); update START")
        spec.add_key(name="corpus_start", qpos=list(start))
    operations = []
    for op in _operations(name):
        check = check_operation(spec, op)
        operations.append(_record(check))
        z = check.zero_play
        print(
            f"{name} {op.value}: accepted {len(check.accepted)}, refused {len(check.refused)}, "
            f"ineligible {len(check.ineligible)}, broken {check.broken}, tracebacks {check.tracebacks}, "
            + ("" if z is None else f"drift {z.deviation * 1e6:.3g}/{z.bound * 1e6:.3g} um, ")
            + f"{check.seconds:.0f} s",
            flush=True,
        )
    part = {
        "model": name,
        "corpus_version": CORPUS_VERSION,
        "package": package,
        "package_version": importlib.metadata.version(_DIST[package]),
        "file": inside,
        "start": "qpos0" if name not in START else "robosuite's init_qpos (keyframe)",
        "load": [round(load0, 2), round(os.getloadavg()[0], 2)],
        "seconds": round(time.perf_counter() - t0, 1),
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, MuJoCo {mujoco.__version__}",
        "commit": _commit(),
        "operations": operations,
    }
    PARTS.mkdir(exist_ok=True)
    atomic_write_text(PARTS / f"{name}.json", json.dumps(part, indent=1) + "\n")
    return part


def outcome(op: dict) -> str:
    """One cell: pass, the invariant that broke, chaos, or a traceback."""
    if op["tracebacks"]:
        return f"**traceback** {op['tracebacks'][0]}"
    z = op["zero_play"]
    if op["broken"]:
        chaotic = z is not None and z["sensitivity"] is not None and z["sensitivity"] >= 0.1 * z["bound"]
        return f"{'undecided (chaotic twin)' if chaotic else '**broken**'}: {op['broken']}"
    unlisted = [r for r in op["refused"].values() if r.startswith("unlisted")]
    if unlisted:
        return f"**unlisted refusal** {unlisted[0]}"
    if not op["accepted"]:
        return "none accepted"
    return "pass"


def _table(parts: list[dict]) -> list[str]:
    rows = [
        "| model | operation | hinges | eligible | ineligible | refused (listed reason) | outcome "
        "| zero-play drift / bound [µm] | twin nudged [µm] | step [s] | time [s] |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for part in parts:
        for op in part["operations"]:
            z = op["zero_play"]
            refused = ", ".join(f"{h} ({r.lower()})" for h, r in op["refused"].items()) or "—"
            inel = ", ".join(f"{h} ({r.lower()})" for h, r in op["ineligible"].items())
            eligible = len(op["hinges"]) - len(op["ineligible"])
            drift = "—" if z is None else f"{z['deviation'] * 1e6:.3g} / {z['bound'] * 1e6:.3g}"
            nudged = "—" if z is None or z["sensitivity"] is None else f"{z['sensitivity'] * 1e6:.3g}"
            step = "—" if op["timestep"] is None else f"{op['timestep']:.0e}"
            rows.append(
                f"| {part['model']} | {op['operation']} | {len(op['hinges'])} | {eligible} | "
                f"{len(op['ineligible'])}{' (' + inel + ')' if inel else ''} | {refused} | {outcome(op)} | {drift} "
                f"| {nudged} | {step} | {op['seconds']:.0f} |"
            )
    return rows


def _summary(parts: list[dict]) -> list[str]:
    lines = [
        "| operation | models | hinges | ineligible | eligible | refused | share refused (of eligible; of all hinges) "
        "| pass | broken | undecided (chaos) | tracebacks |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    reasons: dict[str, int] = {}
    natures: dict[str, int] = {}
    for op_name in [o.value for o in Operation]:
        ops = [op for part in parts for op in part["operations"] if op["operation"] == op_name]
        if not ops:
            continue
        hinges = sum(len(op["hinges"]) for op in ops)
        eligible = sum(len(op["hinges"]) - len(op["ineligible"]) for op in ops)
        refused = sum(len(op["refused"]) for op in ops)
        for op in ops:
            for r in op["refused"].values():
                key = "unlisted" if r.startswith("unlisted") else r
                reasons[key] = reasons.get(key, 0) + 1
            for r in op["ineligible"].values():
                natures[r] = natures.get(r, 0) + 1
        cells = [outcome(op) for op in ops]
        lines.append(
            f"| {op_name} | {len(ops)} | {hinges} | {hinges - eligible} | {eligible} | {refused} "
            f"| {refused / max(eligible, 1):.1%}; {refused / max(hinges, 1):.1%} "
            f"| {sum(c == 'pass' for c in cells)} | {sum(c.startswith('**broken') for c in cells)} "
            f"| {sum(c.startswith('undecided') for c in cells)} | {sum(c.startswith('**traceback') for c in cells)} |"
        )
    lines += [
        "",
        f"Over all operations, refusals by listed reason: {_by_reason(reasons)}; ineligible by nature: "
        f"{_by_reason(natures)} (backlash names a hinge without an actuator no_actuator before its body).",
    ]
    return lines


def _outside(parts: list[dict]) -> list[str]:
    """The rows outside the summary, each operation's outcome in a sentence."""
    lines = []
    for part in parts:
        if part["model"] in OUTSIDE_SUMMARY:
            cells = "; ".join(f"{op['operation']}: {outcome(op)}" for op in part["operations"])
            lines += ["", f"Not in the summary: {part['model']} (from {part.get('start', 'qpos0')}): {cells}."]
    return lines


def _by_reason(counts: dict[str, int]) -> str:
    return (
        ", ".join(
            f"{k.lower()} ({Refusal[k].value}): {v}" if k in Refusal.__members__ else f"{k}: {v}"
            for k, v in sorted(counts.items())
        )
        or "none"
    )


def write_table(out: Path) -> None:
    """``retrofit_corpus.md`` from every part of this corpus version."""
    parts = []
    for name in CORPUS:
        f = PARTS / f"{name}.json"
        if f.exists() and (part := json.loads(f.read_text()))["corpus_version"] == CORPUS_VERSION:
            parts.append(part)
    missing = [n for n in CORPUS if n not in {p["model"] for p in parts}]
    total = sum(p["seconds"] for p in parts)
    loads = [x for p in parts for x in p["load"]]
    versions = sorted({f"{p['package']} {p['package_version']}" for p in parts})
    commits = sorted({p.get("commit", "unknown") for p in parts})
    text = "\n".join(
        [
            "# Retrofits on a corpus of real robots",
            "",
            f"Generated by `python benchmarks/retrofit_corpus.py` (corpus version {CORPUS_VERSION}: {len(CORPUS) - len(OUTSIDE_SUMMARY)} models "
            f"from {', '.join(versions)}; {parts[0]['machine'] if parts else ''}; package at {', '.join(commits)}). "
            f"The parts ran for {total / 60:.1f} min "
            f"in all at load averages {min(loads, default=0):.1f}-{max(loads, default=0):.1f} on a shared 2-core machine "
            "(each part's load at its start and end is in its JSON), with the calibration store warm from earlier runs"
            + (f"; not run yet: {', '.join(missing)}" if missing else "")
            + ".",
            "",
            "Eligible: radial play at every hinge, backlash at every hinge with an actuator of its own (joint=), except "
            f"where a hinge cannot take play by its nature ({', '.join(sorted(r.name.lower() for r in INELIGIBLE))}): a "
            "hinge beside two slides in a body on the world turns a planar floating base (the runners' rooty, the "
            "swimmer's free_body_rot), one of the base's freedoms relative to the world, with no bearing and no gear, as "
            "a free joint has none. Every other hinge that is not retrofitted is refused for a listed reason; the share "
            "of refusals is given of the eligible hinges and of all hinges.",
            "",
            f"Zero play: radial play of 1 µm (exact contact) or 10 µm (calibrated ring), or a backlash band of 0.1', at every "
            f"accepted hinge at once, from the model's first keyframe (robosuite's arms: their start pose in robosuite, `START`) or qpos0; the end effector (the named body deepest below them, not below a refused hinge) over "
            f"{DURATION:g} s under a sinusoid of {DRIVE.amplitude:g} of each control half-range at {DRIVE.frequency:g} Hz, "
            'against the unmodified model at the same step; bound 10 x the geometric play. "Twin nudged": the unmodified '
            "model's own drift when its start moves by 1e-12 rad or m; where that reaches a tenth of the bound the check "
            "cannot tell play from chaos (undecided). Rings (calibrated rows): the default play, 0.1 mm, written and read back "
            "within 1 % of c. No corpus model closes a loop with a connect (the loop check is issue 27's four-bar).",
            "",
            "## Summary",
            "",
            *_summary([p for p in parts if p["model"] not in OUTSIDE_SUMMARY]),
            *_outside(parts),
            "",
            "## Model x operation",
            "",
            *_table(parts),
            "",
        ]
    )
    write_keeping_reading(out, text)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--models", default=None, help=f"comma-separated subset of {', '.join(CORPUS)}")
    p.add_argument("--fresh", action="store_true", help="redo models whose part is already written")
    p.add_argument("--table-only", action="store_true", help="rebuild the table from the parts")
    p.add_argument("--out", default=str(HERE / "retrofit_corpus.md"))
    args = p.parse_args()
    names = list(CORPUS) if args.models is None else args.models.split(",")
    unknown = [n for n in names if n not in CORPUS]
    if unknown:
        p.error(f"--models: unknown {', '.join(unknown)} (the corpus: {', '.join(CORPUS)})")
    warnings.filterwarnings("ignore", message="compiler attribute 'settotalmass' is deprecated")
    for package, version in PACKAGES.items():
        have = importlib.metadata.version(_DIST[package]) if importlib.util.find_spec(package) else None
        if have != version:
            print(f"note: {package} {have} installed, the corpus was written against {version}", file=sys.stderr)
    if not args.table_only:
        for name in names:
            done = PARTS / f"{name}.json"
            if done.exists() and not args.fresh and json.loads(done.read_text())["corpus_version"] == CORPUS_VERSION:
                print(f"{name}: done already ({done.name}; --fresh redoes it)")
                continue
            run_model(name)
    write_table(Path(args.out))


if __name__ == "__main__":
    main()
