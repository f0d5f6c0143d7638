"""SimulationResult persistence: lossless round trip, atomic files."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

from clearance.results import JointResult, SimulationResult


def _result(n=50):
    rng = np.random.default_rng(0)
    return SimulationResult(
        times=np.arange(n) * 1e-6,
        outputs={
            "slider_x": rng.normal(size=n),
            "slider_x_vel": rng.normal(size=n),
            "slider_x_acc": rng.normal(size=n),
        },
        joints={
            "rod_slider": JointResult(
                rng.normal(size=(n, 2)), rng.normal(size=(n, 2)), rng.normal(size=n), rng.normal(size=(n, 2))
            )
        },
        drive_angle=rng.normal(size=(n, 1)),
        drive_speed=rng.normal(size=(n, 1)),
        drive_torque=rng.normal(size=(n, 1)),
        link_poses=rng.normal(size=(n, 3, 3)),
        closure_violation=np.zeros(n),
        metadata={"solver": "mujoco", "segments": {"rod_slider": 144}, "time_step": 1e-6},
    )


@pytest.mark.parametrize("compress", [False, True])
def test_round_trip_is_lossless(tmp_path, compress):
    r = _result()
    npz, js = r.save(tmp_path / "run", compress=compress)
    assert npz.exists() and js.exists()
    with zipfile.ZipFile(npz) as z:  # stored as they are by default (fast), deflated on request
        assert {i.compress_type for i in z.infolist()} == {zipfile.ZIP_DEFLATED if compress else zipfile.ZIP_STORED}
    back = SimulationResult.load(tmp_path / "run.npz")
    assert np.array_equal(back.times, r.times)
    for k in r.outputs:
        assert np.array_equal(back.outputs[k], r.outputs[k])
    for f in ("eccentricity", "eccentricity_rate", "penetration", "contact_force"):
        assert np.array_equal(getattr(back.joints["rod_slider"], f), getattr(r.joints["rod_slider"], f))
    assert np.array_equal(back.link_poses, r.link_poses)
    assert back.metadata == r.metadata
    assert not list(tmp_path.glob(".*tmp"))  # no temporary files left behind


def test_slicing_and_concatenation():
    r = _result(10)
    joined = SimulationResult.concatenate([r.sliced(slice(0, 4)), r.sliced(slice(4, 10))])
    assert np.array_equal(joined.times, r.times)
    assert len(r.decimated(3)) == 4


def test_output_files_get_the_usual_mode_of_a_new_file(tmp_path):
    """Atomic writes end with 0o666 minus the umask (like open()), not mkstemp's private 0o600."""
    import os
    import stat

    from clearance.contact_calibration.store import save_calibration
    from clearance.results import atomic_write_text

    old = os.umask(0o022)
    try:
        for mask in (0o022, 0o027):
            os.umask(mask)
            folder = tmp_path / f"umask{mask:o}"
            atomic_write_text(folder / "summary.csv", "a,b\n")
            atomic_write_text(folder / "summary.csv", "a,b,c\n")  # replacing a file too
            npz, js = _result().save(folder / "run")
            for p in (folder / "summary.csv", npz, js):
                assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~mask, p.name
        os.umask(0o022)

        class _Result:  # save_calibration only needs to_dict()
            def to_dict(self):
                return {"parameters": None}

        path = save_calibration({"k": 1}, _Result(), tmp_path / "cache")
        assert stat.S_IMODE(path.stat().st_mode) == 0o644  # calibration files too
    finally:
        os.umask(old)
    assert not list(tmp_path.rglob(".*tmp"))  # no temporary files left behind
