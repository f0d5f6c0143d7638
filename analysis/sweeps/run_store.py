"""A resumable batch of named runs: simulated in parallel, kept on disk, loaded by name.

Studies and reports need many single runs (a mechanism, a duration, options), some of
them long. `run_batch` simulates the runs that are not on disk yet through a
`concurrent.futures` executor (a local ``spawn`` process pool by default) and keeps each
finished run in ``<store>/<name>.npz/.json`` at once, so an interrupted batch resumes.

Peaks need full-rate data but long runs are large, so each run keeps two things: a
`RunDigest` computed from every step (output extremes, per-joint contact statistics),
and the result itself, decimated to every ``keep_every``-th step for figures, sections and
statistics. A run is identified by its name and a key (the mechanism, duration, options
and decimation, written out); a stored run whose key differs is simulated again.

This module receives mechanism factories (picklable callables point -> `Mechanism`, e.g.
`clearance.analysis.sweeps.sweep.KeywordFactory`), as the sweeps do; it never builds models.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from concurrent.futures import Executor, as_completed
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from clearance.analysis.sweeps.executor import Progress, open_executor
from clearance.analysis.sweeps.sweep import MechanismFactory
from clearance.model import Mechanism
from clearance.options import ModelOptions
from clearance.results import SimulationResult, atomic_write_text

__all__ = ["RunDigest", "RunSpec", "RunStore", "digest_result", "run_batch"]


@dataclass(frozen=True)
class RunSpec:
    """One named run of a batch.

    Attributes:
        name: file stem in the store (letters, digits, ``_``, ``-``; no dot, which would
            read as a file suffix).
        make_mechanism: picklable callable point -> `Mechanism`.
        point: its argument (JSON-like parameters).
        duration: simulated time [s].
        options: `ModelOptions` (None: defaults).
        keep_every: rows kept on disk: every k-th step (the digest uses every step).
        window_start: start of the digest's steady window [s] (after the start-up
            transient); None: one period of the first constant-speed drive.
    """

    name: str
    make_mechanism: MechanismFactory
    point: Mapping[str, Any]
    duration: float
    options: ModelOptions | None = None
    keep_every: int = 1
    window_start: float | None = None

    def __post_init__(self) -> None:
        if not self.name or not all(ch.isalnum() or ch in "_-" for ch in self.name):
            raise ValueError(f"RunSpec.name must be letters, digits, '_' or '-' (got {self.name!r})")
        if not (np.isfinite(self.duration) and self.duration > 0):
            raise ValueError(f"RunSpec.duration must be > 0 s (got {self.duration!r})")
        if not isinstance(self.keep_every, int) or self.keep_every < 1:
            raise ValueError(f"RunSpec.keep_every must be a positive integer (got {self.keep_every!r})")

    def mechanism(self) -> Mechanism:
        """The `Mechanism` of this run."""
        return self.make_mechanism(self.point)

    def key(self) -> str:
        """What identifies the run's content (mechanism, duration, options, decimation)."""
        return repr((self.mechanism(), float(self.duration), self.options, self.keep_every, self.window_start))


@dataclass(frozen=True)
class RunDigest:
    """Full-rate numbers of one run.

    Attributes:
        name: run name.
        status: ``ok`` or ``error``.
        error: error message ('' if ok).
        window_start: start of the steady window [s].
        outputs: output name (also ``_vel``/``_acc``) -> ``{"max", "min", "max_abs",
            "steady_max_abs"}`` [SI units of the output]; ``steady_`` values over t >=
            window_start.
        joints: clearance joint or slider with play -> `JointSummary` fields over the whole run, plus
            ``steady_peak_force`` and ``steady_p95_force`` [N] over t >= window_start.
        wall_time_s: simulation wall time [s].
        steps: steps simulated.
    """

    name: str
    status: str
    error: str = ""
    window_start: float = 0.0
    outputs: dict[str, dict[str, float]] = field(default_factory=dict)
    joints: dict[str, dict[str, float]] = field(default_factory=dict)
    wall_time_s: float = float("nan")
    steps: int = 0


def digest_result(name: str, result: SimulationResult, window_start: float) -> RunDigest:
    """The `RunDigest` of a full-rate result (see `RunDigest`).

    Args:
        name: run name.
        result: the run, every step kept.
        window_start: start of the steady window [s].
    """
    from clearance.analysis.metrics.summary import contact_series, joint_summary

    steady = result.times >= window_start
    outs = {}
    for k, v in result.outputs.items():
        a = np.abs(v)
        outs[k] = {
            "max": float(v.max()),
            "min": float(v.min()),
            "max_abs": float(a.max()),
            "steady_max_abs": float(a[steady].max()) if steady.any() else float("nan"),
        }
    joints = {}
    for j in (*result.joints, *result.sliders):  # a slider: its deepest corner, its net force
        d = asdict(joint_summary(result, j))
        d.pop("joint")
        d.pop("output_rms_deviation")
        penetration, force = contact_series(result, j)
        f = force[steady]
        on = penetration[steady] > 0
        d["steady_peak_force"] = float(f.max()) if len(f) else 0.0
        d["steady_p95_force"] = float(np.percentile(f[on], 95)) if on.any() else 0.0
        joints[j] = d
    md = result.metadata
    return RunDigest(
        name,
        "ok",
        "",
        float(window_start),
        outs,
        joints,
        float(md.get("wall_time_s", np.nan)),
        int(md.get("steps", len(result.times))),
    )


def _window_start(spec: RunSpec, mechanism: Mechanism) -> float:
    if spec.window_start is not None:
        return float(spec.window_start)
    for d in mechanism.drives:
        try:
            return float(d.period)
        except ValueError:
            continue
    return 0.0


def _run_one(spec: RunSpec, store: str) -> str:
    """Simulate one run and keep it (runs in a worker); returns the name."""
    from clearance.run.simulation import simulate

    stem = Path(store) / spec.name
    mech = spec.mechanism()
    start = _window_start(spec, mech)
    try:
        res = simulate(mech, duration=spec.duration, options=spec.options)
        digest = digest_result(spec.name, res, start)
        res.decimated(spec.keep_every).save(stem, compress=True)
    except Exception as err:
        digest = RunDigest(spec.name, "error", f"{type(err).__name__}: {err}", start)
    # the digest is written last: its presence marks a finished run
    atomic_write_text(stem.with_suffix(".digest.json"), json.dumps({"key": spec.key(), **asdict(digest)}, indent=1))
    return spec.name


class RunStore:
    """Finished runs of a store folder, loaded by name."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)

    def _digest_path(self, name: str) -> Path:
        return self.folder / f"{name}.digest.json"

    def _read(self, name: str) -> dict[str, Any]:
        """The digest file of a run as read.

        Raises:
            FileNotFoundError: no such run in the store.
            ValueError: the file is unreadable (cut short, say); the message says why.
        """
        d = json.loads(self._digest_path(name).read_text(encoding="utf-8"))
        if not isinstance(d, dict):
            raise ValueError(f"a JSON object was expected, not {type(d).__name__}")
        return d

    def has(self, spec: RunSpec) -> bool:
        """The run is on disk with the same key.

        An unreadable digest (cut short, say) counts as not on disk, with a `RuntimeWarning`
        naming it, so `run_batch` simulates that run again and replaces the file.
        """
        import warnings

        if not self._digest_path(spec.name).exists():
            return False
        try:
            return self._read(spec.name).get("key") == spec.key()
        except ValueError as err:
            warnings.warn(
                f"run digest {self._digest_path(spec.name)} is unreadable ({err}); run '{spec.name}' is "
                "simulated again",
                RuntimeWarning,
                stacklevel=2,
            )
            return False

    def digest(self, name: str) -> RunDigest:
        """The run's `RunDigest`.

        Raises:
            FileNotFoundError: no such run in the store.
            ValueError: its digest file is unreadable.
        """
        try:
            d = self._read(name)
        except ValueError as err:
            raise ValueError(
                f"run digest {self._digest_path(name)} is unreadable ({err}); delete it and run the batch "
                f"again to simulate run '{name}' anew"
            ) from None
        d.pop("key", None)
        return RunDigest(**d)

    def result(self, name: str) -> SimulationResult:
        """The run's kept (decimated) result.

        Raises:
            FileNotFoundError: no such run, or the run failed (see its digest).
        """
        return SimulationResult.load(self.folder / f"{name}.npz")


def run_batch(
    runs: Sequence[RunSpec],
    store: str | Path,
    *,
    executor: Executor | None = None,
    max_workers: int | None = None,
    progress: bool = True,
) -> RunStore:
    """Simulate the runs not yet in the store (in parallel) and return the store.

    Args:
        runs: the runs; names must be unique.
        store: store folder (created).
        executor: executor to use (not shut down here); default a local ``spawn``
            process pool of ``max_workers`` processes.
        max_workers: local process count (default: CPU count).
        progress: show a tqdm progress bar (runs done, time remaining).

    Returns:
        The `RunStore` holding every run (failed runs have digests with status ``error``).

    Raises:
        ValueError: duplicate run names.
    """
    names = [r.name for r in runs]
    if len(set(names)) != len(names):
        raise ValueError(f"run names must be unique (repeated: {sorted({n for n in names if names.count(n) > 1})})")
    folder = Path(store)
    folder.mkdir(parents=True, exist_ok=True)
    kept = RunStore(folder)
    todo = [r for r in runs if not kept.has(r)]
    if not todo:
        return kept
    # longest first, so the pool is not left waiting on one long run at the end
    order = sorted(todo, key=lambda r: -r.duration / (r.options.timestep if r.options else 1e-6))
    with (
        open_executor(executor, max_workers=max_workers) as pool,
        Progress(len(runs), enabled=progress, initial=len(runs) - len(todo)) as bar,
    ):
        futures = [pool.executor.submit(_run_one, r, str(folder)) for r in order]
        for fut in as_completed(futures):
            fut.result()
            bar.step()
    return kept
