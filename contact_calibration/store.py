"""Calibration files: JSON keyed by every input they depend on, in a cache directory.

The directory is ``$CLEARANCE_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/clearance`` or
``~/.cache/clearance``; calibrations live in its ``calibration/`` subfolder. A file is
named ``calib-<first 24 hex digits of the SHA-256 of its canonical key>.json``; the key
holds geometry, materials, law, restitution, friction, effective mass and its range
(rounded to `MASS_DIGITS` significant figures, so a last-bit difference between machines
or thread counts does not force a refit), fit speeds, time step, integrator, impedance,
segment count and shape, geom types, MuJoCo version and fit version. The file stores that
key, so a hash collision or an edited file is detected.

Writes are atomic (a temporary file in the same folder, then `os.replace`), so concurrent
sweep workers never read half a file: at worst two workers fit the same case and the last
rename wins with identical content. A file that cannot be read, parsed or validated is
reported with a `CalibrationCacheWarning` naming it, and rebuilt, never used. A folder
that cannot be written is reported the same way; the fit is then used without being stored.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import warnings
from pathlib import Path
from typing import Any, Protocol

import mujoco
import numpy as np

from clearance.contact_calibration.cylindrical_laws import bearing_length
from clearance.contact_calibration.fit import (
    FIT_VERSION,
    CalibrationResult,
    check_stability,
    default_speeds,
    fit_contact,
    valid_mass_range,
)
from clearance.mjcf.bearing import RingGeometry
from clearance.model import CYLINDRICAL_LAWS, Clearance, Joint
from clearance.options import ContactParameters, ModelOptions
from clearance.results import atomic_write_bytes

__all__ = [
    "CACHE_ENV",
    "MASS_DIGITS",
    "CalibrationCacheWarning",
    "cache_dir",
    "calibration_key",
    "fit_key",
    "calibration_path",
    "load_calibration",
    "save_calibration",
    "calibrate",
    "calibrate_joint",
    "calibrated_parameters",
]


class Sizing(Protocol):
    """What a calibration reads of a clearance joint's sizing (`clearance.run.JointSizing` has it)."""

    @property
    def effective_mass(self) -> float:
        """Median effective mass over the cycle [kg]."""
        ...

    @property
    def effective_mass_range(self) -> tuple[float, float]:
        """(min, max) effective mass over the cycle [kg]."""
        ...

    @property
    def impact_speed(self) -> float:
        """Estimated impact speed [m/s]."""
        ...

    @property
    def penetration_limit(self) -> float:
        """Divergence bound on the penetration [m]."""
        ...


CACHE_ENV = "CLEARANCE_CACHE_DIR"
"""Environment variable naming the cache directory."""


MASS_DIGITS = 9
"""Significant figures of the effective mass and its range in a calibration key."""


class CalibrationCacheWarning(UserWarning):
    """A calibration file was unreadable or inconsistent (it is rebuilt), or could not be
    written (the fit is used without being stored)."""


def cache_dir() -> Path:
    """The calibration folder: ``$CLEARANCE_CACHE_DIR/calibration`` (or the user cache)."""
    root = os.environ.get(CACHE_ENV)
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME")
        root = os.path.join(xdg, "clearance") if xdg else os.path.join(Path.home(), ".cache", "clearance")
    return Path(root) / "calibration"


def calibration_key(
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    *,
    mass: float,
    mass_range: tuple[float, float],
    speeds: np.ndarray,
) -> dict[str, Any]:
    """Everything a calibration depends on, as a JSON-ready dict.

    Floats are kept exact except the effective mass and its range, which are computed
    (cycle median of a MuJoCo quantity) and so may differ in the last bits between
    machines, BLAS builds or thread counts: they are rounded to `MASS_DIGITS` significant
    figures, far below any difference that changes a fit.

    Args:
        clearance: the joint's clearance (geometry, materials, law, cₑ, friction).
        ring: ring geometry (segments, segment radius, contacts per pair).
        options: model options (time step, integrator, geoms, impedance).
        mass: effective mass fitted at [kg].
        mass_range: (min, max) effective mass [kg].
        speeds: fit speeds [m/s].

    Returns:
        The key.
    """
    mat = lambda m: [float(m.youngs_modulus), float(m.poisson_ratio)]  # noqa: E731
    # the bearing length enters a cylindrical law's force only: other keys (and files) stay as they were
    length = {"bearing_length": bearing_length(clearance)} if clearance.law in CYLINDRICAL_LAWS else {}
    return (
        length
        | {
            "bearing_radius": float(clearance.bearing_radius),
            "radial_clearance": float(clearance.radial_clearance),
            "bearing_material": mat(clearance.bearing_material),
            "journal_material": mat(clearance.journal_material),
            "law": clearance.law.value,
            "restitution": float(clearance.restitution),
            "friction": float(clearance.friction),
            "segments": int(ring.segments),
            "segment_radius": float(ring.segment_radius),
            "contacts_per_pair": int(ring.contacts_per_pair),
            "journal_geom": options.journal_geom.value,
            "segment_geom": options.segment_geom.value,
        }
        | fit_key(options, mass=mass, mass_range=mass_range, speeds=speeds)
    )


def fit_key(
    options: ModelOptions, *, mass: float, mass_range: tuple[float, float], speeds: np.ndarray
) -> dict[str, Any]:
    """The part of a calibration key every fit shares: the mass and its range (rounded to
    `MASS_DIGITS` significant figures), the speeds, the step, integrator and impedance, MuJoCo's
    version and the fit's (`calibration_key`)."""
    return {
        "effective_mass": _round_sig(mass),
        "mass_range": [_round_sig(x) for x in mass_range],
        "speeds": [float(v) for v in speeds],
        "timestep": float(options.timestep),
        "integrator": options.integrator,
        "impedance": float(options.impedance),
        "mujoco": mujoco.__version__,
        "fit_version": FIT_VERSION,
    }


def _round_sig(x: float, digits: int = MASS_DIGITS) -> float:
    return float(f"{float(x):.{digits - 1}e}")


def _digest(key: dict[str, Any]) -> str:
    text = json.dumps(key, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def calibration_path(key: dict[str, Any], directory: Path | None = None) -> Path:
    """File of a calibration key: ``<cache_dir>/calib-<sha256[:24]>.json``.

    ``cache_dir()`` is already the ``calibration/`` subfolder of the cache directory.
    """
    return (directory or cache_dir()) / f"calib-{_digest(key)[:24]}.json"


def _validate(result: CalibrationResult) -> None:
    p = result.parameters
    values = [p.stiffness, p.damping, p.impedance_rise, result.mass, *result.mass_range]
    if not all(isinstance(v, float) and math.isfinite(v) for v in values) or p.stiffness <= 0:
        raise ValueError("non-finite or non-positive parameters")


def load_calibration(key: dict[str, Any], directory: Path | None = None) -> CalibrationResult | None:
    """The stored calibration for ``key``, or None when missing or unusable.

    An unusable file (bad JSON, wrong key, missing or non-finite fields) is reported with
    a `CalibrationCacheWarning` naming the file, and None is returned so it gets rebuilt.
    """
    path = calibration_path(key, directory)
    try:
        raw = path.read_bytes()
    except (FileNotFoundError, NotADirectoryError):  # no file there (a missing or non-folder cache)
        return None
    except OSError as exc:
        raw, error = None, exc
    try:
        if raw is None:
            raise error
        doc = json.loads(raw.decode("utf-8"))
        if doc.get("key") != key:
            raise ValueError("its key does not match the requested inputs")
        result = CalibrationResult.from_dict(doc["result"])
        _validate(result)
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        warnings.warn(
            f"calibration file {path} is corrupt or inconsistent ({type(exc).__name__}: "
            f"{exc}); ignoring it and recalibrating",
            CalibrationCacheWarning,
            stacklevel=3,
        )
        return None
    return result


def save_calibration(key: dict[str, Any], result: CalibrationResult, directory: Path | None = None) -> Path:
    """Write a calibration atomically (temporary file + `os.replace`); returns its path."""
    path = calibration_path(key, directory)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps({"key": key, "result": result.to_dict()}, indent=1, sort_keys=True)
    atomic_write_bytes(path, text.encode("utf-8"))
    return path


def calibrate(
    clearance: Clearance,
    ring: RingGeometry,
    options: ModelOptions,
    *,
    mass: float,
    impact_speed: float | None = None,
    speeds: np.ndarray | None = None,
    mass_range: tuple[float, float] | None = None,
    max_penetration: float | None = None,
    use_cache: bool = True,
) -> tuple[CalibrationResult, Path | None]:
    """Calibrate one bearing, reusing a stored calibration with the same inputs.

    Args:
        clearance: the joint's clearance.
        ring: ring geometry.
        options: model options.
        mass: effective mass [kg] (median over the cycle).
        impact_speed: sizing impact speed [m/s]; gives `default_speeds` when ``speeds``
            is None.
        speeds: fit speeds [m/s] (overrides ``impact_speed``).
        mass_range: (min, max) effective mass over the cycle [kg].
        max_penetration: largest expected penetration for the stability check [m]
            (checked on every call, also for a stored calibration).
        use_cache: read and write the cache.

    Returns:
        The calibration and its file (None without cache, or when the cache folder cannot
        be written: a `CalibrationCacheWarning` names the folder then).

    Raises:
        ValueError: neither speeds nor impact_speed given, or bad arguments.
        CalibrationStabilityError: the parameters are unstable at the time step.
    """
    if speeds is None:
        if impact_speed is None:
            raise ValueError("give impact_speed [m/s] or speeds [m/s]")
        speeds = default_speeds(impact_speed)
    speeds = np.sort(np.asarray(speeds, dtype=float))
    mrange = valid_mass_range(mass, mass_range)
    key = calibration_key(clearance, ring, options, mass=mass, mass_range=mrange, speeds=speeds)
    if use_cache:
        hit = load_calibration(key)
        if hit is not None:
            if max_penetration is not None:
                check_stability(
                    ring, hit.parameters, mass=mass, timestep=options.timestep, max_penetration=max_penetration
                )
            return hit, calibration_path(key)
    result = fit_contact(
        clearance, ring, options, mass=mass, speeds=speeds, mass_range=mrange, max_penetration=max_penetration
    )
    if not use_cache:
        return result, None
    try:
        return result, save_calibration(key, result)
    except OSError as exc:
        folder = calibration_path(key).parent
        warnings.warn(
            f"could not store the calibration in {folder} ({type(exc).__name__}: {exc}); "
            f"using the fit without caching it. Set ${CACHE_ENV} to a writable folder to "
            "reuse calibrations between runs",
            CalibrationCacheWarning,
            stacklevel=2,
        )
        return result, None


def calibrate_joint(
    joint: Joint,
    ring: RingGeometry,
    sizing: Sizing,
    options: ModelOptions,
    *,
    speeds: np.ndarray | None = None,
    use_cache: bool = True,
) -> tuple[CalibrationResult, Path | None]:
    """Calibrate a clearance joint of a prepared model at its own sizing (cached).

    The one place that turns a joint's sizing into calibration inputs, so that
    ``clearance calibrate`` writes the file `ContactMode.CALIBRATED` later reads: the
    effective mass is the cycle median with its (min, max) range, the fit speeds span
    impact_speed / 50 to impact_speed (`default_speeds`) unless ``speeds`` is given.

    Args:
        joint: the clearance joint.
        ring: its ring geometry.
        sizing: its `JointSizing` (effective_mass [kg], effective_mass_range [kg],
            impact_speed [m/s], penetration_limit [m] are used).
        options: model options.
        speeds: fit speeds [m/s] instead of the default range (such a fit is stored
            under its own key, not the one a run reuses).
        use_cache: read and write the cache.

    Returns:
        The calibration and its file (None without cache or when the cache folder cannot
        be written, see `calibrate`).

    Raises:
        ValueError: a joint without clearance, or bad arguments.
        CalibrationStabilityError: the fitted contact is unstable at the time step.
    """
    if joint.clearance is None:
        raise ValueError(f"joint '{joint.name}' has no clearance to calibrate")
    return calibrate(
        joint.clearance,
        ring,
        options,
        mass=float(sizing.effective_mass),
        impact_speed=float(sizing.impact_speed),
        speeds=speeds,
        mass_range=sizing.effective_mass_range,
        max_penetration=float(sizing.penetration_limit),
        use_cache=use_cache,
    )


def calibrated_parameters(joint: Joint, ring: RingGeometry, sizing: Sizing, options: ModelOptions) -> ContactParameters:
    """Calibrated per-row contact parameters of a clearance joint (cached).

    The entry point of `ContactMode.CALIBRATED` in `clearance.run.preparation`; it reuses the
    file ``clearance calibrate`` writes for the same scenario and numerics
    (`calibrate_joint`).

    Args:
        joint: the clearance joint.
        ring: its ring geometry.
        sizing: its `JointSizing` (effective_mass [kg], effective_mass_range [kg],
            impact_speed [m/s], penetration_limit [m] are used).
        options: model options.

    Returns:
        The fitted ContactParameters (stiffness, damping and impedance rise) with source
        ``"calibrated: <file>"`` (``"calibrated: not cached"`` when the cache folder could
        not be written).

    Raises:
        CalibrationStabilityError: the fitted contact is unstable at the time step.
    """
    result, path = calibrate_joint(joint, ring, sizing, options)
    return dataclasses.replace(result.parameters, source=f"calibrated: {path or 'not cached'}")
